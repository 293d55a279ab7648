//! ROS-free trajectory executor core: validation, interpolation, tolerances, motion state
//! machine.
//!
//! The reference semantics are those of ros2_control's `joint_trajectory_controller` (JTC),
//! ROS 2 Jazzy, with `interpolation_method: splines`; the differences are listed below. A thin
//! ROS node converts `control_msgs/FollowJointTrajectory` goals into [`TrajectoryRequest`] and
//! [`GoalTolerances`], calls [`Executor::update`] every control period, writes
//! [`Cycle::reference`] to the hardware and reports [`GoalEvent`]s as action results.
//!
//! Units are SI throughout: seconds, and joint units (rad or m) per second (squared).
//! All times are `f64` seconds on one clock. The resolution of an `f64` at 1.7·10⁹ s (Unix
//! time) is 238 ns; a node that wants sub-µs timing passes times relative to a recent origin.
//!
//! # Overview
//! * [`validate()`] checks a request against the robot model ([`JointLimits`]) and a current
//!   state, and builds a [`ValidatedTrajectory`]: segment polynomials in model joint order on
//!   absolute time, sampled in O(1) amortized per cycle.
//! * [`check_executable`] is that validation from rest at the first point: what a planner
//!   runs on its output before publishing it.
//! * [`prepare`] does the request-only part of validation (nearly all its cost) so that it
//!   can run off the control thread; [`Executor::submit_prepared`] finishes it in O(joints).
//! * [`Executor`] runs one goal at a time: preemption, cancel with a controlled stop
//!   ([`StopProfile`]), path and goal tolerances ([`tolerance`]).
//! * [`MockHardware`] follows commands, exactly or with a first-order lag.
//! * [`roots`] isolates real polynomial roots, used for the exact extrema of segments.
//!
//! # Interpolation (as JTC)
//! Between two states: quintic Hermite if both have velocities and accelerations, cubic
//! Hermite if both have velocities, else linear (JTC `Trajectory::interpolate_between_points`).
//! Before the first point a start segment runs from the current commanded state
//! (position, velocity, acceleration) to it. After the last point its positions are held at
//! zero velocity.
//!
//! # Limits
//! Positions, velocities and accelerations are checked at their exact extrema on every
//! segment — the interval ends and the real roots of the derivative polynomials — not only
//! at the waypoints, because cubic and quintic segments overshoot. A linear segment has
//! constant velocity; where velocity is discontinuous (between linear segments, from a moving
//! state into a linear start segment, into the final hold) the step is commanded within one
//! control period and is checked as the acceleration `|Δv| / control_period`. Every check
//! allows a relative slack of [`LIMIT_SLACK`] (1e-9) so that trajectories generated exactly at
//! a limit are not rejected for rounding.
//!
//! # Differences from JTC
//! * **Joint limits are enforced** on the whole interpolated curve; JTC does not check limits.
//! * **First point due at the start time** (`time_from_start` 0 with the start now): JTC jumps
//!   to it; here its positions must equal the current commanded positions within
//!   [`ExecutorConfig::start_tolerance`] (default 1e-3), else `StartMismatch`, since a jump
//!   would be commanded.
//! * **Start time in the past** is accepted only while the first point is still ahead
//!   (`start + time_from_start[0] > now`); the start segment is then shorter and still
//!   limit-checked. JTC accepts it as long as the trajectory *end* is ahead and would jump
//!   into the middle of the trajectory; here that is OLD_HEADER_TIMESTAMP.
//! * **Start time in the future**: when the commanded state is at rest it is held until the
//!   start time and the start segment runs from the start time to the first point. JTC's
//!   start segment begins on receipt, so the robot would creep toward the first point before
//!   the start time. A moving state cannot be held: then the start segment begins now, as in
//!   JTC.
//! * **Start state** is the current *commanded* state (JTC `interpolate_from_desired_state`/
//!   `open_loop_control`), not the measured one, so preemption is continuous.
//! * **Cancel and path-tolerance aborts** bring the motion to a controlled stop: all joints
//!   decelerate together, linearly in velocity, each within its acceleration limit
//!   ([`StopProfile`]). JTC holds the position instantly, which would exceed the acceleration
//!   limits at speed.
//!   As in JTC, the goal's outcome (CANCELED, or ABORTED for a path tolerance) is reported when
//!   the stop begins; the stop lasts at most max |v| / a_max, and a new goal may start from the
//!   stopping state at any time.
//! * **Invalid tolerances** in a goal (unknown joint, negative value other than −1, invalid
//!   goal time) reject the goal; JTC logs them and falls back to the defaults.
//! * **Effort** in a point is rejected (no effort command interface); JTC accepts effort with
//!   an effort command interface.
//! * **Partial goals and integration** (`allow_partial_joints_goal`,
//!   `allow_integration_in_goal_trajectories`) are not supported: all joints and positions are
//!   required, as with the JTC defaults.
//! * **NaN and infinity** anywhere in a request are rejected.
//! * **Rejections carry result codes**: [`ExecutorError::error_code`]. JTC rejects invalid
//!   goals in its goal callback without a result.
//! * **Time** never runs backwards: [`Executor::update`] rejects an earlier `now`, and requests
//!   are timed at no earlier than the last update.

pub mod error;
pub mod executable;
pub mod executor;
pub mod measured;
pub mod mock;
pub mod roots;
pub mod slack;
pub mod spline;
pub mod stop;
pub mod tolerance;
pub mod trajectory;
pub mod types;
pub mod validate;
pub mod watchdog;

pub use error::{
    ExecutorError, GOAL_TOLERANCE_VIOLATED, INVALID_GOAL, INVALID_JOINTS, OLD_HEADER_TIMESTAMP,
    PATH_TOLERANCE_VIOLATED, SUCCESSFUL,
};
pub use executable::check_executable;
pub use executor::{Cycle, Executor, Feedback, GoalEvent, GoalId, Outcome};
pub use measured::{measured_state, MeasuredState, NamedState};
pub use mock::MockHardware;
pub use slack::LIMIT_SLACK;
pub use stop::StopProfile;
pub use tolerance::{resolve as resolve_tolerances, ResolvedTolerances};
pub use trajectory::ValidatedTrajectory;
pub use types::{
    ExecutorConfig, GoalTolerances, JointLimits, JointSample, JointTolerance, TrajectoryPoint,
    TrajectoryRequest,
};
pub use validate::{prepare, validate, PreparedTrajectory};
pub use watchdog::FeedbackWatchdog;
