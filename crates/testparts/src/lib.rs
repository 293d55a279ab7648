//! Test parts for the kerf planners, kept out of the planner libraries.
//!
//! [`bpillar`] generates the B-pillar-like stamped workpiece
//! (`urdf/meshes/bpillar.obj`) and the two cut requests of seed 001
//! section 3 (`crates/mjto/cases/case{1,2}.yaml`) that the MJTO planner's
//! tests, benchmarks and end-to-end tests run on. Regenerate the committed
//! files with `cargo run -p kerf_testparts --example gen_bpillar -- --out .`
//! from the repository root.
//!
//! [`jobshop`] generates the parts and cut requests of issue 16 item 4 (saddle cuts, holes
//! and slots on curved sheet, trims near walls, closed contours, refusals):
//! `urdf/meshes/jobshop_*.obj` and `crates/mjto/cases/jobshop/*.yaml`, regenerated with
//! `cargo run -p kerf_testparts --example gen_jobshop -- --out .`.
//!
//! [`straight::straight_cut`] is a three-point cut with a hand-made plan whose QI baseline is
//! known exactly.

pub mod bpillar;
pub mod error;
pub mod jobshop;
mod placement;
mod rounding;
pub mod straight;

pub use error::TestPartError;
