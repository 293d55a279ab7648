//! The cuts a job shop brings (issue 16, item 4): parts and cut requests for the MJTO planner
//! beyond seed 001's two cases.
//!
//! Parts (closed thin solids, [`sheet::thick_sheet`]: the head-side surface, the far surface
//! one thickness below it and strips closing the rim, outward-oriented):
//! * `tube`: a Ø100 × 3 mm round tube along x ([`TubeParams`]);
//! * `panel`: a rolled 2 mm sheet, radius 500 mm, convex towards the head ([`PanelParams`]);
//! * `channel`: a 3 mm U channel, 300 mm wide inside, 120 mm walls with 60 mm top flanges,
//!   bends R6 ([`ChannelParams`]);
//! * `angle`: a 4 mm angle with a 300 mm wall beside a 300 mm floor, bend R8
//!   ([`AngleParams`]).
//!
//! Cases ([`JobShopCase`], each with the answer the contract demands,
//! [`Expectation`]):
//! * saddle cuts for branch/main radius ratios 0.4, 0.7, 0.95 ([`saddle_curve`]);
//! * holes and a slot on the rolled panel;
//! * trims near the channel's walls and on its flange, a closed cut-out beside a wall;
//! * a trim and a hole next to the angle's tall wall, where the nominal axis collides and a
//!   tilt inside the allowance does not;
//! * the refusals: a feed out of reach (INFEASIBLE) and a trim too close to the wall
//!   (COLLISION).
//!
//! Every CL point lies on the true head-side surface, the nominal tool axis is its unit
//! normal, the points are `f Δt` apart along the curve (closed contours: the nearest whole
//! number of steps not longer, last point = first point). The mesh is the surface to within
//! [`Part::surface_tolerance`] (facet sag) and its facet normals to within
//! [`Part::axis_tolerance`].
//!
//! [`write_files`] writes `urdf/meshes/jobshop_*.obj` and `crates/mjto/cases/jobshop/*.yaml`;
//! `cargo run -p kerf_testparts --example gen_jobshop -- --out .` calls it. The output is
//! deterministic (coordinates rounded to 1 nm, axes to 1e-12). Frames: workpiece frame as
//! each part documents; every request places its workpiece unrotated, with the nominal M
//! points centred at (0.8, 0.7, 1.0) m in the machine frame. SI units throughout.

mod case;
mod channel;
mod contour;
mod files;
mod holes;
mod panel;
mod part;
mod path;
mod profile;
mod saddle;
pub mod sheet;
mod tube;
mod walls;

pub use case::{Expectation, JobShopCase};
pub use channel::{AngleParams, ChannelParams};
pub use contour::Outline;
pub use files::{case_yaml, generate, write_files, JobShop};
pub use panel::PanelParams;
pub use part::Part;
pub use path::{sample_curve, ClPath};
pub use profile::{bent_profile, extrude, ProfileVertex};
pub use saddle::saddle_curve;
pub use tube::TubeParams;

/// The command that regenerates every job-shop file (run from the repository root).
pub const REGENERATE_COMMAND: &str = "cargo run -p kerf_testparts --example gen_jobshop -- --out .";

/// Largest number of triangles of a job-shop mesh.
pub const MAX_TRIANGLES: usize = 6000;
