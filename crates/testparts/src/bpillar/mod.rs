//! A B-pillar-like stamped test workpiece and the two cut requests of
//! seed 001 section 3, built on it.
//!
//! Seed 001 demonstrates MJTO on an automotive B-pillar (Figure 7) that is
//! not published. This module generates a stand-in with the features its
//! two case studies need:
//!
//! * a **hat-section sheet** (thickness 1.5 mm): two flanges, two side walls
//!   at 77° to the flanges, a top, a concave fillet between each flange and
//!   wall and a convex fillet between each wall and the top;
//! * a **spine** along the part's length (workpiece x): straight at the
//!   foot, then gently curved (radius 8 m), then a **sharp kink** (20° with
//!   a 50 mm bend radius, like a B-pillar's upper bend), then straight;
//! * a **deep, wide foot** with generous fillets, blended smoothly into the
//!   narrower pillar body (the reason is in [`BPillarParams`]).
//!
//! The mesh ([`BPillar::mesh`]) is a closed thin solid: the outer
//! (head-side) surface, the inner surface offset by the thickness along the
//! surface normals, and the edge strips around the free edges. Triangles are
//! oriented with outward normals (positive signed volume).
//!
//! The cut paths are CL points on the outer surface with the unit outward
//! surface normal as the nominal tool axis, sampled like a G-code
//! interpolator: the CAM blocks are the mesh vertices along the cut (points
//! and vertex normals), the interpolator moves at constant spacing `f Δt`
//! along the polyline and interpolates the orientation between blocks by
//! quaternion interpolation (slerp), as seed 001 section 3.2 describes its
//! input ("a standard G-code interpolator using QI for the orientation").
//! Every CL point therefore lies exactly on the mesh.
//!
//! * [`trim_case`]: case 1 (seed 001 section 3.1, Table 1): a 0.8 m side
//!   trim along a flange near the wall, tool axis near vertical (q4 is
//!   ill-defined there, and the fork arms of the head reach the wall unless
//!   q4 turns them along the cut), six RTOs.
//! * [`corner_case`]: case 2 (section 3.2, Table 1): a cut across the hat
//!   section at the foot, flange → concave fillet → wall → convex fillet →
//!   top, 628 CL points at 1 mm, two 77° tool-axis changes between adjacent
//!   RTOs, ten RTOs.
//!
//! [`write_files`] writes `urdf/meshes/bpillar.obj` and
//! `crates/mjto/cases/case{1,2}.yaml`; `cargo run -p kerf_testparts
//! --example gen_bpillar -- --out .` calls it. The output is deterministic (no
//! randomness; coordinates rounded to 1 nm, axes to 1e-12).
//!
//! Frames: the workpiece frame has x along the spine (from the foot), y
//! across the section, z towards the head side of the flanges. All lengths
//! in metres, angles in radians.

mod cl_path;
mod corner_case;
mod files;
mod params;
mod part;
mod request;
mod section;
mod spine;
mod surface;
mod trim_case;

pub use cl_path::ClPath;
pub use corner_case::{corner_case, CornerCaseParams};
pub use files::{generate, write_files, Generated};
pub use params::BPillarParams;
pub use part::BPillar;
pub use request::{request_yaml, rto_angle_changes};
pub use section::HatSection;
pub use surface::SurfaceVertex;
pub use trim_case::{trim_case, TrimCaseParams};

/// The mesh reference written into both requests.
pub const MESH_REFERENCE: &str = "package://kerf/urdf/meshes/bpillar.obj";

/// Path of the mesh file relative to the repository root.
pub const MESH_FILE: &str = "urdf/meshes/bpillar.obj";

/// Path of the case 1 request relative to the repository root.
pub const CASE1_FILE: &str = "crates/mjto/cases/case1.yaml";

/// Path of the case 2 request relative to the repository root.
pub const CASE2_FILE: &str = "crates/mjto/cases/case2.yaml";

/// The command that regenerates every generated file (run from the
/// repository root).
pub const REGENERATE_COMMAND: &str = "cargo run -p kerf_testparts --example gen_bpillar -- --out .";

/// Shortest accepted straight piece of a section (flange, wall, top) and
/// shortest spine segment (m): shorter ones would give degenerate triangles.
const MIN_PIECE: f64 = 1e-3;

/// Step of the central difference that gives the change of the section
/// along the spine in the transition (m).
const SECTION_FD_STEP: f64 = 1e-5;
