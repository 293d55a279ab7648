//! Fuzz targets of every parser and message conversion of kerf (issue 11, item 7).
//!
//! Each target is a plain `fn(&[u8])` ([`TARGETS`]): it feeds the bytes to one parser or
//! conversion and checks that whatever comes back is a value — a request or an error — never
//! a panic, a stack overflow or an unbounded run. Where a target's input is accepted it also
//! checks a cheap property that must hold for every accepted input (an accepted request
//! validates without panicking, a validated path is finite, a decoded message re-encodes to
//! the same bytes, …); a broken property panics, so it is found like a crash.
//!
//! Issue 33 (item 8) adds the classes of input of its number probe and of file references:
//! `cut_numbers`, `mill_numbers` and `gcode_msg` ([`numbers`]: request messages with hostile
//! numbers, through `check_numbers` and the node's conversion), `file_uri` and
//! `capped_reader` ([`files`]: file references resolved against allowed roots, capped reads).
//!
//! Text targets read the bytes as UTF-8 (lossily: invalid sequences become U+FFFD, as nothing
//! that reaches a kerf parser can be anything but a Rust `str`). Message targets build the
//! message from the bytes with [`arbitrary`] ([`gen`]); the `cdr` target decodes them as a
//! node's subscription does.
//!
//! Three drivers run the same targets:
//!
//! * `cargo test -p kerf_fuzz` (part of `cargo test --workspace`): replays the committed
//!   corpus `fuzz/corpus/<target>/` and runs a short deterministic mutation fuzz
//!   ([`mutate`], `tests/fuzz.rs`);
//! * `cargo run --release -p kerf_fuzz -- run --seconds N` for a longer run of the same
//!   mutator ([`mutate::run_for`]);
//! * the coverage-guided libFuzzer drivers of `fuzz/libfuzzer/` (outside the workspace;
//!   `BENCHMARKS.md`, "Fuzzing").

pub mod files;
pub mod gen;
pub mod mutate;
pub mod numbers;
pub mod targets;

pub use files::{capped_reader, file_uri};
pub use numbers::{cut_numbers, gcode_msg, mill_numbers};
pub use targets::*;

/// A fuzz target: takes any bytes, panics only on a bug.
pub type Target = fn(&[u8]);

/// Every target, by name (the name is its corpus directory under `fuzz/corpus/` and its
/// libFuzzer binary under `fuzz/libfuzzer/`).
pub const TARGETS: &[(&str, Target)] = &[
    ("cut_text", targets::cut_text),
    ("cut_lines", targets::cut_lines),
    ("cut_yaml", targets::cut_yaml),
    ("cut_json", targets::cut_json),
    ("mill_text", targets::mill_text),
    ("mill_yaml", targets::mill_yaml),
    ("mill_json", targets::mill_json),
    ("document", targets::document),
    ("mesh_stl", targets::mesh_stl),
    ("mesh_obj", targets::mesh_obj),
    ("cut_msg", targets::cut_msg),
    ("mill_msg", targets::mill_msg),
    ("trajectory_msg", targets::trajectory_msg),
    ("cdr", targets::cdr),
    ("gcode_program", targets::gcode_program),
    ("gcode_text", targets::gcode_text),
    ("cut_numbers", numbers::cut_numbers),
    ("mill_numbers", numbers::mill_numbers),
    ("gcode_msg", numbers::gcode_msg),
    ("file_uri", files::file_uri),
    ("capped_reader", files::capped_reader),
];

/// The target called `name`.
pub fn target(name: &str) -> Option<Target> {
    TARGETS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The directory of the committed corpus (`fuzz/corpus`).
pub fn corpus_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus")
}
