//! Conversions between ROS messages and the executor core's plain types.

use kerf_executor::{
    ExecutorError, GoalTolerances, JointSample, JointTolerance, TrajectoryRequest, INVALID_GOAL,
    INVALID_JOINTS,
};
use kerf_msgs::numbers::{NumberError, NumberFields};
use kerf_msgs::{
    builtin_interfaces::{Duration, Time},
    control_msgs::{FollowJointTrajectoryGoal, JointTolerance as JointToleranceMsg},
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};

/// Why a request was refused: a `control_msgs/FollowJointTrajectory` result code and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rejection {
    /// Result code (`INVALID_GOAL`, `INVALID_JOINTS`, …).
    pub code: i32,
    /// What exactly is wrong.
    pub message: String,
}

impl From<ExecutorError> for Rejection {
    fn from(e: ExecutorError) -> Self {
        Self {
            code: e.error_code(),
            message: e.to_string(),
        }
    }
}

/// The clock of a node: a monotonic origin and the system time it corresponds to.
///
/// The executor core runs on seconds since the origin (an `f64` keeps sub-ns resolution for
/// months), messages carry system time (ROS time without `use_sim_time`).
///
/// A simulated clock ([`Clock::simulated`]) reads the time the control loop sets
/// ([`Clock::set`]: the simulated cell's time) instead of the monotonic clock; its origin is
/// still the system time at the start, so stamps of either kind are close while the
/// simulation keeps pace with the wall clock.
#[derive(Debug, Clone)]
pub struct Clock {
    origin: std::time::Instant,
    origin_ns: i64,
    /// The simulated time (s since the origin) as `f64` bits; `None` for the system clock.
    sim: Option<std::sync::Arc<std::sync::atomic::AtomicU64>>,
}

impl Clock {
    /// Starts the clock now.
    pub fn start() -> Self {
        let origin_ns = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as i64)
            .unwrap_or(0);
        Self {
            origin: std::time::Instant::now(),
            origin_ns,
            sim: None,
        }
    }

    /// A simulated clock starting now at 0 s; it advances only by [`Clock::set`].
    pub fn simulated() -> Self {
        Self {
            sim: Some(std::sync::Arc::new(std::sync::atomic::AtomicU64::new(
                0.0f64.to_bits(),
            ))),
            ..Self::start()
        }
    }

    /// Whether this clock is simulated.
    pub fn is_simulated(&self) -> bool {
        self.sim.is_some()
    }

    /// Sets the simulated time (s since the origin); no effect on a system clock.
    pub fn set(&self, t: f64) {
        if let Some(sim) = &self.sim {
            sim.store(t.to_bits(), std::sync::atomic::Ordering::Release);
        }
    }

    /// Seconds since the origin.
    pub fn now(&self) -> f64 {
        match &self.sim {
            Some(sim) => f64::from_bits(sim.load(std::sync::atomic::Ordering::Acquire)),
            None => self.origin.elapsed().as_secs_f64(),
        }
    }

    /// The ROS time of a clock reading.
    pub fn stamp(&self, t: f64) -> Time {
        Time::from_nanos(self.origin_ns + (t * 1e9).round() as i64).unwrap_or(Time::ZERO)
    }

    /// A ROS time on this clock (s since the origin).
    pub fn from_stamp(&self, stamp: &Time) -> f64 {
        (stamp.as_nanos() - self.origin_ns) as f64 * 1e-9
    }
}

fn duration_secs(d: &Duration, what: &str) -> Result<f64, Rejection> {
    if d.nanosec >= 1_000_000_000 {
        return Err(Rejection {
            code: INVALID_GOAL,
            message: format!("{what}: nanosec {} is not below 1e9", d.nanosec),
        });
    }
    Ok(d.as_secs_f64())
}

/// A number outside its declared rule ([`kerf_msgs::numbers::trajectory`]) as the executor's
/// refusal: INVALID_GOAL, the message naming the field (`points[3].positions[1] = NaN: must be
/// finite`).
pub fn number_rejection(e: NumberError) -> Rejection {
    Rejection {
        code: INVALID_GOAL,
        message: format!("{NUMBER_REJECTION}{e}"),
    }
}

/// [`number_rejection`], naming also the joint of a per-joint array entry
/// (`points[2].positions[4]` of joints `joint_1` … `joint_6`: `(joint joint_5)`).
fn joint_rejection(e: NumberError, joint_names: &[String]) -> Rejection {
    let joint = e
        .field
        .strip_suffix(']')
        .and_then(|f| f.rsplit_once('['))
        .filter(|(head, _)| {
            [".positions", ".velocities", ".accelerations", ".effort"]
                .iter()
                .any(|a| head.ends_with(a))
        })
        .and_then(|(_, j)| j.parse::<usize>().ok())
        .and_then(|j| joint_names.get(j))
        .map(|name| format!(" (joint {name})"));
    let mut rejection = number_rejection(e);
    if let Some(joint) = joint {
        rejection.message.push_str(&joint);
    }
    rejection
}

/// How the message of a [`number_rejection`] starts.
pub const NUMBER_REJECTION: &str = "invalid number: ";

/// `rejection` with the field of a [`number_rejection`] named inside the message that holds
/// the trajectory (`prefix` `trajectory.` for the `ValidateTrajectory` request, whose
/// trajectory the prepare worker checks); any other rejection unchanged.
pub fn number_rejection_within(rejection: Rejection, prefix: &str) -> Rejection {
    let field = format!("{NUMBER_REJECTION}field `");
    match rejection.message.strip_prefix(&field) {
        Some(rest) => Rejection {
            code: rejection.code,
            message: format!("{field}{prefix}{rest}"),
        },
        None => rejection,
    }
}

/// Converts a `trajectory_msgs/JointTrajectory` (stamp 0 = start now) with the one
/// conversion every kerf node uses ([`kerf_ros::planner::trajectory_request`]: the planners'
/// executability check converts their plans the same way), after checking every number
/// against its declared rule.
///
/// # Errors
/// [`Rejection`] INVALID_GOAL for a number outside its rule (the field named) and for what
/// the conversion refuses.
pub fn trajectory_request(
    msg: &JointTrajectory,
    clock: &Clock,
) -> Result<TrajectoryRequest, Rejection> {
    msg.check_numbers()
        .map_err(|e| joint_rejection(e, &msg.joint_names))?;
    convert_trajectory(msg, clock)
}

/// [`trajectory_request`] without the number check (done by the caller).
fn convert_trajectory(
    msg: &JointTrajectory,
    clock: &Clock,
) -> Result<TrajectoryRequest, Rejection> {
    kerf_ros::planner::trajectory_request(msg, |stamp| clock.from_stamp(stamp)).map_err(|message| {
        Rejection {
            code: INVALID_GOAL,
            message,
        }
    })
}

fn tolerances(list: &[JointToleranceMsg]) -> Vec<JointTolerance> {
    list.iter()
        .map(|t| JointTolerance {
            name: t.name.clone(),
            position: t.position,
            velocity: t.velocity,
            acceleration: t.acceleration,
        })
        .collect()
}

/// Converts a FollowJointTrajectory goal, after checking every number of it (trajectory,
/// tolerances, times) against its declared rule. Multi-DOF trajectories and component
/// tolerances are refused: this executor drives single-DOF joints only.
///
/// # Errors
/// [`Rejection`] INVALID_GOAL naming the field for a number outside its rule
/// (`trajectory.points[0].velocities[2] = inf: must be finite`), INVALID_JOINTS for a
/// multi-DOF trajectory, INVALID_GOAL for what the conversion refuses.
pub fn goal_request(
    goal: &FollowJointTrajectoryGoal,
    clock: &Clock,
) -> Result<(TrajectoryRequest, GoalTolerances), Rejection> {
    goal.check_numbers()
        .map_err(|e| joint_rejection(e, &goal.trajectory.joint_names))?;
    let md = &goal.multi_dof_trajectory;
    if !md.joint_names.is_empty() || !md.points.is_empty() {
        return Err(Rejection {
            code: INVALID_JOINTS,
            message: format!(
                "multi_dof_trajectory is not supported (joints {:?}); this executor drives \
                 single-DOF joints only",
                md.joint_names
            ),
        });
    }
    if !goal.component_path_tolerance.is_empty() || !goal.component_goal_tolerance.is_empty() {
        return Err(Rejection {
            code: INVALID_GOAL,
            message: "component_path_tolerance / component_goal_tolerance apply to multi-DOF \
                      joints, which this executor does not drive"
                .into(),
        });
    }
    let req = convert_trajectory(&goal.trajectory, clock)?;
    let tol = GoalTolerances {
        path: tolerances(&goal.path_tolerance),
        goal: tolerances(&goal.goal_tolerance),
        goal_time: duration_secs(&goal.goal_time_tolerance, "goal_time_tolerance")?,
    };
    Ok((req, tol))
}

/// A `JointTrajectoryPoint` from a joint sample (time_from_start given).
pub fn point(sample: &JointSample, time_from_start: f64) -> JointTrajectoryPoint {
    JointTrajectoryPoint {
        positions: sample.positions.clone(),
        velocities: sample.velocities.clone(),
        accelerations: sample.accelerations.clone(),
        effort: Vec::new(),
        time_from_start: Duration::from_secs_f64(time_from_start).unwrap_or(Duration::ZERO),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_msgs::trajectory_msgs::MultiDOFJointTrajectory;

    #[test]
    fn converts_times_and_refuses_malformed_durations() {
        let clock = Clock::start();
        let mut msg = JointTrajectory {
            joint_names: vec!["a".into()],
            points: vec![JointTrajectoryPoint {
                positions: vec![1.0],
                time_from_start: Duration {
                    sec: 1,
                    nanosec: 500_000_000,
                },
                ..Default::default()
            }],
            ..Default::default()
        };
        let req = trajectory_request(&msg, &clock).unwrap();
        assert_eq!(req.start_time, None);
        assert_eq!(req.points[0].time_from_start, 1.5);
        msg.header.stamp = clock.stamp(2.0);
        let req = trajectory_request(&msg, &clock).unwrap();
        assert!((req.start_time.unwrap() - 2.0).abs() < 1e-6);
        msg.points[0].time_from_start.nanosec = 1_000_000_000;
        let err = trajectory_request(&msg, &clock).unwrap_err();
        assert_eq!(err.code, INVALID_GOAL);
        // Refused by the declared rule of the field (issue 33), before the conversion.
        assert!(
            err.message.contains("`points[0].time_from_start.nanosec`"),
            "{}",
            err.message
        );
    }

    fn two_points() -> JointTrajectory {
        let point = |t: i32| JointTrajectoryPoint {
            positions: vec![0.1, 0.2],
            velocities: vec![0.0, 0.0],
            time_from_start: Duration { sec: t, nanosec: 0 },
            ..Default::default()
        };
        JointTrajectory {
            joint_names: vec!["a".into(), "b".into()],
            points: vec![point(0), point(1)],
            ..Default::default()
        }
    }

    /// Issue 33: NaN, infinite and huge positions, velocities and times are refused by the
    /// declared rules, the field named, on the topic and in a goal (INVALID_GOAL).
    #[test]
    fn bad_numbers_are_refused_naming_the_field() {
        let clock = Clock::start();
        assert!(trajectory_request(&two_points(), &clock).is_ok());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e308] {
            for (path, set) in [
                (
                    "points[1].positions[0]",
                    (|m: &mut JointTrajectory, v| m.points[1].positions[0] = v)
                        as fn(&mut JointTrajectory, f64),
                ),
                ("points[0].velocities[1]", |m, v| {
                    m.points[0].velocities[1] = v
                }),
                ("points[1].accelerations[0]", |m, v| {
                    m.points[1].accelerations = vec![v, 0.0]
                }),
            ] {
                let mut msg = two_points();
                set(&mut msg, bad);
                let e = trajectory_request(&msg, &clock).unwrap_err();
                assert_eq!(e.code, INVALID_GOAL);
                assert!(e.message.contains(&format!("`{path}`")), "{}", e.message);
                assert!(
                    e.message.ends_with(")"),
                    "the joint is named: {}",
                    e.message
                );
                let goal = FollowJointTrajectoryGoal {
                    trajectory: msg,
                    ..Default::default()
                };
                let e = goal_request(&goal, &clock).unwrap_err();
                assert_eq!(e.code, INVALID_GOAL);
                assert!(
                    e.message.contains(&format!("`trajectory.{path}`")),
                    "{}",
                    e.message
                );
            }
        }
        // Times: the integer fields' extremes.
        let mut msg = two_points();
        msg.points[1].time_from_start.sec = i32::MAX;
        let e = trajectory_request(&msg, &clock).unwrap_err();
        assert!(
            e.message
                .contains("`points[1].time_from_start.sec` = 2147483647"),
            "{}",
            e.message
        );
        let mut msg = two_points();
        msg.header.stamp.sec = i32::MIN;
        let e = trajectory_request(&msg, &clock).unwrap_err();
        assert!(e.message.contains("`header.stamp.sec`"), "{}", e.message);
        let goal = FollowJointTrajectoryGoal {
            trajectory: two_points(),
            goal_time_tolerance: Duration {
                sec: -1,
                nanosec: 0,
            },
            path_tolerance: vec![JointToleranceMsg {
                name: "a".into(),
                position: f64::NAN,
                ..Default::default()
            }],
            ..Default::default()
        };
        let e = goal_request(&goal, &clock).unwrap_err();
        assert!(
            e.message.contains("`path_tolerance[0].position` = NaN"),
            "{}",
            e.message
        );
        // The validate service's answer names the field under `trajectory`, as the request's
        // own check does.
        let mut req = kerf_msgs::srv::ValidateTrajectoryRequest {
            trajectory: two_points(),
        };
        req.trajectory.points[0].positions[1] = f64::INFINITY;
        let worker = trajectory_request(&req.trajectory, &clock).unwrap_err();
        let e = number_rejection_within(worker, "trajectory.");
        assert!(e.message.ends_with("(joint b)"), "{}", e.message);
        let own = req.check_numbers().unwrap_err();
        assert!(e.message.contains(&own.to_string()), "{}", e.message);
        assert_eq!(e.code, INVALID_GOAL);
        assert!(
            e.message
                .contains("`trajectory.points[0].positions[1]` = inf"),
            "{}",
            e.message
        );
    }

    #[test]
    fn refuses_multi_dof_goals() {
        let clock = Clock::start();
        let goal = FollowJointTrajectoryGoal {
            multi_dof_trajectory: MultiDOFJointTrajectory {
                joint_names: vec!["base".into()],
                ..Default::default()
            },
            ..Default::default()
        };
        assert_eq!(
            goal_request(&goal, &clock).unwrap_err().code,
            INVALID_JOINTS
        );
    }
}
