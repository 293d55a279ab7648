//! kerf_approach: the ROS-free core of "every plan starts where the robot is" (issue 27).
//!
//! Every planner answer gets an **approach**, a jerk-limited joint motion from the robot's
//! current joint state to the first process point, and a **retract**, from the last process
//! point to a safe pose (or a distance along the tool axis). Both are certified
//! collision-free against the workpiece and the cell objects: every configuration of the
//! motion, not only its samples, keeps the node's clearance. When the direct motion is not
//! clear the approach goes via a safe pose above the part; when no route is clear the answer
//! is an error naming the obstacle, never a motion into it.
//!
//! The crate is generic over the robot and the collision world: a robot is its
//! [`JointLimit`]s and per-joint Lipschitz bounds, the world is a closure returning the
//! signed distance to the nearest obstacle and its name ([`Clearance`]). The nodes wire their
//! FK and parry models into that closure.
//!
//! | module | concept |
//! |---|---|
//! | [`profile`] | the minimum-jerk quintic (Flash & Hogan 1985) and its analytic peaks |
//! | [`limits`] | [`JointLimit`]: position, velocity, acceleration, jerk |
//! | [`joint_move`] | [`JointMove`]: synchronised rest-to-rest motion at the shortest duration |
//! | [`waypoints`] | [`WaypointMove`]: legs through via poses; sampling at a period |
//! | [`sample`] | [`Sample`]: `(t, q, q̇, q̈)` |
//! | [`clearance`] | [`Clearance`], [`ClosestSample`], [`Violation`] |
//! | [`advance`] | [`ClearanceCheck`]: conservative advancement between samples, with proof |
//! | [`settings`] | [`ApproachSettings`] and its validating builder |
//! | [`planner`] | [`ApproachPlanner::approach`]: direct, else via a safe pose, else error |
//! | [`retract`] | [`ApproachPlanner::retract`], [`tool_axis_target`] |
//! | [`stitch`] | [`Stitched`]: approach + process + retract as one [`Timeline`] |
//! | [`start`] | [`StartSpec`]: current, given, none, or the default |
//! | [`frame`] | [`frame()`]: approach, lead-in, process, lead-out, retract for one plan ([`Surroundings`]) |
//! | [`role`], [`route`] | labels of configurations and moves in errors |
//! | [`error`] | [`ApproachError`] |
//!
//! ```
//! use kerf_approach::{ApproachPlanner, ApproachSettings, Clearance, JointLimit};
//!
//! // One prismatic joint moving a point along x; a wall at x = 1 m.
//! let limits = vec![JointLimit {
//!     name: "x".into(),
//!     min_position: -2.0,
//!     max_position: 2.0,
//!     max_velocity: 0.5,
//!     max_acceleration: 2.0,
//!     max_jerk: 20.0,
//! }];
//! let world = |q: &[f64]| Clearance::new(1.0 - q[0], "wall");
//! let settings = ApproachSettings::builder()
//!     .clearance(0.05)
//!     .lipschitz(vec![1.0])
//!     .build()?;
//! let planner = ApproachPlanner::new(settings, limits, &world)?;
//! let approach = planner.approach(&[0.0], &[0.9])?;
//! assert!(approach.closest.distance >= 0.05);
//! let samples = approach.path.samples(0.004)?;
//! assert_eq!(samples.last().map(|s| s.q.clone()), Some(vec![0.9]));
//! // Into the wall: refused, naming it.
//! let e = planner.approach(&[0.0], &[0.99]).unwrap_err();
//! assert!(e.to_string().contains("wall"));
//! # Ok::<(), kerf_approach::ApproachError>(())
//! ```

pub mod advance;
pub mod clearance;
pub mod error;
pub mod frame;
pub mod joint_move;
pub mod limits;
pub mod planner;
pub mod profile;
pub mod retract;
pub mod role;
pub mod route;
pub mod sample;
pub mod settings;
pub mod start;
pub mod stitch;
pub mod waypoints;

pub use advance::{ClearanceCheck, Verdict};
pub use clearance::{Clearance, ClosestSample, Violation, ViolationKind};
pub use error::ApproachError;
pub use frame::{frame, FrameSettings, FrameSettingsBuilder, Framed, Stage, Surroundings};
pub use joint_move::JointMove;
pub use limits::JointLimit;
pub use planner::{ApproachPlanner, CheckedMove};
pub use retract::{tool_axis_target, IK_POSITION_TOLERANCE, IK_ROTATION_TOLERANCE};
pub use role::Role;
pub use route::Route;
pub use sample::Sample;
pub use settings::{ApproachSettings, ApproachSettingsBuilder};
pub use start::StartSpec;
pub use stitch::{Boundary, Stitched, Timeline};
pub use waypoints::{WaypointMove, MAX_SAMPLES};
