//! Collision checking of the laser cutting head against the workpiece.
//!
//! The head is the set of URDF `<collision>` primitives (box, cylinder,
//! sphere) of the links `z_ram`, `c_axis`, `a_axis` and `nozzle` of
//! `urdf/laser_cutter.urdf` (and, if they carry geometry, the gantry links
//! `x_carriage` and `y_carriage`). They are placed by a specialised forward
//! kinematics of the chain of seed 001 eq. 2,
//! `Trans(q1, q2, q3) · Rz(q4) · Ry(q5) · Trans(0, 0, q6)`, and tested with
//! parry3d against a BVH-accelerated
//! [`TriMesh`](parry3d_f64::shape::TriMesh) of the workpiece.
//!
//! * A configuration collides when some head shape is within `clearance`
//!   of a workpiece triangle: every head primitive is inflated by the
//!   clearance (a parry [`RoundShape`](parry3d_f64::shape::RoundShape),
//!   i.e. the Minkowski sum with a ball of that radius), so an intersection test is exactly the test
//!   `distance <= clearance`.
//! * The workpiece is a surface (sheet metal, as the B-pillar of seed
//!   001): a head shape entirely enclosed by a closed mesh without touching
//!   any triangle is not reported. Head shapes are centimetres wide, sheet
//!   parts millimetres thick, so this does not occur in practice.
//! * The nozzle is tested first (it is nearest the part), then the tilt
//!   housing (`a_axis`), the fork and C-axis motor (`c_axis`), the ram; a
//!   link whose bounding box misses the workpiece bounding box is skipped
//!   without any triangle test, then every shape's own box is matched
//!   against the mesh BVH, as parry's composite test does. Each candidate
//!   triangle first meets a few separating axes (`separation`: a gap
//!   beyond the clearance + [`SEPARATION_MARGIN`] proves it clear); only
//!   the others get parry's exact triangle test. The verdicts are parry's
//!   ([`CollisionWorld::colliding_links_exhaustive`] is the path without
//!   the first stage, for tests and benches).
//! * A sampled trajectory is checked by conservative advancement
//!   ([`CollisionWorld::colliding_links_along`], `sweep`): a query at an
//!   anchor sample certifies a distance, and the following samples that the
//!   shape provably cannot cross it in need no query; same verdicts as one
//!   query per sample.
//! * [`CollisionWorld::distance`] (module `distance`) answers the exact
//!   distance of the head, not inflated, from the workpiece, and
//!   [`HeadModel::lipschitz`] bounds how fast any head point moves per unit
//!   of each joint: together they certify whole motions by conservative
//!   advancement (`kerf_approach`, issue 27).
//! * The geometry runs on `parry3d-f64` (the f64 build of parry3d 0.31).
//!   The f32 build's GJK test of a cylinder against a large triangle
//!   reports contact across a 1 mm gap (the nozzle above a flange at 3°
//!   tilt) as soon as the triangle is a centimetre off the query origin;
//!   the f64 build returns the true 0.86 mm (checked in
//!   `tests/collision.rs`). Coordinates are still taken relative to the
//!   centre of the workpiece bounding box.

mod distance;
mod head;
mod lipschitz;
mod separation;
mod sweep;
mod world;

pub use distance::Distance;
pub use head::{HeadLink, HeadModel, HeadShape, Primitive};
pub use lipschitz::RIM_SIDES;
pub use separation::SEPARATION_MARGIN;
pub use sweep::{MAX_BACKOFF, MAX_EXPAND, MAX_WINDOW};
pub use world::CollisionWorld;
