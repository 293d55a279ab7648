//! kerf's G-code front end, part 1: the reader (issue 14, item 1). A
//! program in the RS-274/NGC subset LinuxCNC reads ([`interpreter`]) or a
//! plain point list ([`points`]) becomes a sequence of [`Motion`]s in SI
//! units (metres, metres per second, seconds), streamed line by line
//! ([`Program`]: bounded memory for programs of millions of lines). Every
//! error names its line and column ([`GcodeError`]); nothing is skipped
//! silently (the block delete switch is a setting, and what it skips is
//! counted).
//!
//! Why no lexer crate: the `gcode` crate reads every number as `f32` and skips
//! malformed input by default; `g-code` keeps exact decimals and
//! spans, but brings its own parser generator and `rust_decimal` for what is
//! here a 200-line lexer that keeps `f64` (Rust's correctly rounded
//! `str::parse`) and reports line and column; the modal layer would be ours
//! either way.

mod arc;
pub mod error;
pub mod interpreter;
pub mod lexer;
pub mod motion;
pub mod points;
pub mod program;
pub mod settings;

pub use error::GcodeError;
pub use interpreter::{Interpreter, PathControl, MAX_ARC_TURNS};
pub use motion::{ArcMove, Motion, Plane};
pub use points::{read_points, PointUnit};
pub use program::{read_program, Program};
pub use settings::ReaderSettings;
