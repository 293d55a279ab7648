//! The simulated robot without DDS: commands and goals move the commanded position, the
//! measured position follows it through the transport delay, faults change what is published.
//! Times are driver times (seconds since start, monotonic); stamps are given by the caller.

use kerf_msgs::{
    builtin_interfaces::Time,
    control_msgs::{FollowJointTrajectoryFeedback, FollowJointTrajectoryResult},
    sensor_msgs::JointState,
    std_msgs::Header,
    trajectory_msgs::JointTrajectoryPoint,
};

use crate::{
    cli::Config,
    delay::DelayLine,
    faults::Fault,
    noise::Gaussian,
    trajectory::{Goal, Trajectory},
};

/// How far (joint units) a goal's first point may be from the commanded position, and the
/// measured end from the last point.
pub const START_TOLERANCE: f64 = 0.01;
/// How far the noise-free measured position may be from a goal's last point at its end.
pub const GOAL_TOLERANCE: f64 = 0.01;

/// Why a command was not applied.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Ignored {
    /// A goal is running.
    DuringGoal,
}

/// How a goal ended.
#[derive(Debug, Clone, PartialEq)]
pub struct GoalEnd {
    /// SUCCEEDED (true) or ABORTED (false).
    pub succeeded: bool,
    /// The action result.
    pub result: FollowJointTrajectoryResult,
}

impl GoalEnd {
    fn aborted(error_code: i32, error_string: String) -> Self {
        Self {
            succeeded: false,
            result: FollowJointTrajectoryResult {
                error_code,
                error_string,
            },
        }
    }
}

/// What the driver counted, for the summary at exit.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Counters {
    /// Commands applied.
    pub commands: u64,
    /// Commands ignored as malformed.
    pub invalid_commands: u64,
    /// Commands ignored because a goal was running.
    pub commands_during_goal: u64,
    /// Goals accepted.
    pub goals_accepted: u64,
    /// Goals rejected.
    pub goals_rejected: u64,
    /// Joint states published.
    pub states: u64,
}

/// Faults in force and one-shot faults waiting for the next published state.
#[derive(Debug, Clone, Default)]
struct Faults {
    dropped: bool,
    frozen: Option<Vec<f64>>,
    reject_goals: bool,
    stamp_back: bool,
    nan: bool,
    fewer_joints: bool,
}

#[derive(Debug, Clone)]
struct Running {
    trajectory: Trajectory,
    start: f64,
    /// When the last point was commanded.
    ended_at: Option<f64>,
    desired: (Vec<f64>, Vec<f64>),
}

/// The simulated robot.
#[derive(Debug, Clone)]
pub struct Driver {
    joints: Vec<String>,
    delay: f64,
    noise: f64,
    rng: Gaussian,
    line: DelayLine,
    /// Velocity of the commanded position (a goal's; 0 under commands).
    commanded_velocity: Vec<f64>,
    faults: Faults,
    goal: Option<Running>,
    /// Time and noise-free measured position of the last tick.
    clean: Option<(f64, Vec<f64>)>,
    /// Measured position (with noise) and velocity of the last tick.
    measured: (Vec<f64>, Vec<f64>),
    last_stamp: Option<Time>,
    /// Counters for the summary.
    pub counters: Counters,
}

impl Driver {
    /// A driver at rest at the configured initial position.
    pub fn new(cfg: &Config) -> Self {
        let n = cfg.joints.len();
        Self {
            joints: cfg.joints.clone(),
            delay: cfg.delay,
            noise: cfg.noise,
            rng: Gaussian::new(cfg.seed),
            line: DelayLine::new(cfg.delay, cfg.initial.clone()),
            commanded_velocity: vec![0.0; n],
            faults: Faults::default(),
            goal: None,
            clean: None,
            measured: (cfg.initial.clone(), vec![0.0; n]),
            last_stamp: None,
            counters: Counters::default(),
        }
    }

    /// The joint names.
    pub fn joints(&self) -> &[String] {
        &self.joints
    }

    /// Whether a goal is running.
    #[cfg(test)]
    pub fn has_goal(&self) -> bool {
        self.goal.is_some()
    }

    /// Whether new goals are rejected (`reject_goals`).
    pub fn rejects_goals(&self) -> bool {
        self.faults.reject_goals
    }

    /// Applies a position command (one per joint, in joint order, checked by the caller).
    ///
    /// # Errors
    /// [`Ignored::DuringGoal`] while a goal runs (counted).
    pub fn command(&mut self, now: f64, position: Vec<f64>) -> Result<(), Ignored> {
        if self.goal.is_some() {
            self.counters.commands_during_goal += 1;
            return Err(Ignored::DuringGoal);
        }
        self.counters.commands += 1;
        self.commanded_velocity.iter_mut().for_each(|v| *v = 0.0);
        self.line.push(now, position);
        Ok(())
    }

    /// Counts a malformed command.
    pub fn count_invalid(&mut self) -> u64 {
        self.counters.invalid_commands += 1;
        self.counters.invalid_commands
    }

    /// Ends the running goal without moving on (preemption); `true` if one was running.
    pub fn preempt(&mut self) -> bool {
        self.goal.take().is_some()
    }

    /// Ends the running goal and holds the commanded position; `true` if one was running.
    pub fn cancel(&mut self) -> bool {
        self.commanded_velocity.iter_mut().for_each(|v| *v = 0.0);
        self.goal.take().is_some()
    }

    /// Starts an accepted goal at `now` from the commanded position and velocity.
    ///
    /// # Errors
    /// The goal's end (ABORTED, PATH_TOLERANCE_VIOLATED) when its first point is more than
    /// [`START_TOLERANCE`] from the commanded position; nothing moves then.
    pub fn start_goal(&mut self, now: f64, goal: Goal) -> Result<(), GoalEnd> {
        self.counters.goals_accepted += 1;
        let here = self.line.head().to_vec();
        let far = here
            .iter()
            .zip(goal.first_positions())
            .enumerate()
            .map(|(j, (a, b))| (j, (b - a).abs()))
            .find(|(_, d)| d.is_nan() || *d > START_TOLERANCE);
        if let Some((j, d)) = far {
            self.commanded_velocity.iter_mut().for_each(|v| *v = 0.0);
            return Err(GoalEnd::aborted(
                FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED,
                format!(
                    "the first point is {d:.6} from the current position on joint '{}' ({} \
                     there, {} commanded); at most {START_TOLERANCE} is allowed",
                    self.joints.get(j).map_or("?", |s| s.as_str()),
                    goal.first_positions().get(j).copied().unwrap_or(f64::NAN),
                    here.get(j).copied().unwrap_or(f64::NAN),
                ),
            ));
        }
        let v0 = self.commanded_velocity.clone();
        let desired = (here.clone(), v0.clone());
        self.goal = Some(Running {
            trajectory: goal.start_from(here, v0),
            start: now,
            ended_at: None,
            desired,
        });
        Ok(())
    }

    /// Applies a fault (not [`Fault::Die`], which the caller handles).
    pub fn apply(&mut self, fault: Fault) {
        let f = &mut self.faults;
        match fault {
            Fault::Drop => f.dropped = true,
            Fault::Resume => {
                f.dropped = false;
                f.frozen = None;
            }
            Fault::StampBack => f.stamp_back = true,
            Fault::Nan => f.nan = true,
            Fault::FewerJoints => f.fewer_joints = true,
            Fault::Freeze => {
                let here = self
                    .clean
                    .as_ref()
                    .map_or_else(|| self.measured.0.clone(), |(_, p)| p.clone());
                f.frozen.get_or_insert(here);
            }
            Fault::RejectGoals => f.reject_goals = true,
            Fault::AcceptGoals => f.reject_goals = false,
            Fault::Die => {}
        }
    }

    /// One integration step at `now`: advances a running goal, moves the measured state.
    ///
    /// # Returns
    /// The state to publish (none under `drop`), and the end of the running goal if it ended.
    pub fn tick(&mut self, now: f64, stamp: Time) -> (Option<JointState>, Option<GoalEnd>) {
        if let Some(g) = self.goal.as_mut() {
            let t = now - g.start;
            let (p, v) = g.trajectory.sample(t);
            if p.as_slice() != self.line.head() {
                self.line.push(now, p.clone());
            }
            self.commanded_velocity.clone_from(&v);
            g.desired = (p, v);
            if g.ended_at.is_none() && t >= g.trajectory.duration() {
                g.ended_at = Some(now);
            }
        }
        let clean = match &self.faults.frozen {
            Some(p) => p.clone(),
            None => self.line.output(now).to_vec(),
        };
        let velocity = match &self.clean {
            Some((t0, p0)) if now > *t0 => clean
                .iter()
                .zip(p0)
                .map(|(a, b)| (a - b) / (now - t0))
                .collect(),
            _ => vec![0.0; clean.len()],
        };
        let end = self.goal_end(now, &clean);
        let mut position = clean.clone();
        if self.noise > 0.0 {
            for x in &mut position {
                *x += self.noise * self.rng.standard();
            }
        }
        self.clean = Some((now, clean));
        self.measured = (position, velocity);
        let state = (!self.faults.dropped).then(|| self.state(stamp));
        (state, end)
    }

    /// The end of the running goal at `now`, given the noise-free measured position.
    fn goal_end(&mut self, now: f64, clean: &[f64]) -> Option<GoalEnd> {
        let g = self.goal.as_ref()?;
        let ended = g.ended_at?;
        if now - self.delay < ended {
            return None;
        }
        let last = g.trajectory.last_positions();
        let off = clean
            .iter()
            .zip(last)
            .enumerate()
            .map(|(j, (a, b))| (j, (a - b).abs()))
            .find(|(_, d)| d.is_nan() || *d > GOAL_TOLERANCE);
        self.goal = None;
        self.commanded_velocity.iter_mut().for_each(|v| *v = 0.0);
        Some(match off {
            None => GoalEnd {
                succeeded: true,
                result: FollowJointTrajectoryResult::default(),
            },
            Some((j, d)) => GoalEnd::aborted(
                FollowJointTrajectoryResult::GOAL_TOLERANCE_VIOLATED,
                format!(
                    "joint '{}' is {d:.6} from its last point at the end (tolerance {GOAL_TOLERANCE})",
                    self.joints.get(j).map_or("?", |s| s.as_str())
                ),
            ),
        })
    }

    /// The measured state with the one-shot faults applied (they are used up).
    fn state(&mut self, wall: Time) -> JointState {
        let f = &mut self.faults;
        let stamp = match (std::mem::take(&mut f.stamp_back), self.last_stamp) {
            (true, Some(prev)) => {
                Time::from_nanos(prev.as_nanos() - 1_000_000_000).unwrap_or(Time::ZERO)
            }
            (true, None) => Time::from_nanos(wall.as_nanos() - 1_000_000_000).unwrap_or(Time::ZERO),
            (false, _) => wall,
        };
        let mut s = JointState {
            header: Header {
                stamp,
                frame_id: String::new(),
            },
            name: self.joints.clone(),
            position: self.measured.0.clone(),
            velocity: self.measured.1.clone(),
            effort: Vec::new(),
        };
        if std::mem::take(&mut f.nan) {
            if let Some(x) = s.position.first_mut() {
                *x = f64::NAN;
            }
        }
        if std::mem::take(&mut f.fewer_joints) {
            s.name.pop();
            s.position.pop();
            s.velocity.pop();
        }
        self.last_stamp = Some(stamp);
        self.counters.states += 1;
        s
    }

    /// Feedback of the running goal (desired, actual = the measured state, error).
    pub fn feedback(&self, stamp: Time) -> Option<FollowJointTrajectoryFeedback> {
        let g = self.goal.as_ref()?;
        let (dp, dv) = &g.desired;
        let (ap, av) = &self.measured;
        let diff = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x - y).collect();
        let point = |p: &[f64], v: &[f64]| JointTrajectoryPoint {
            positions: p.to_vec(),
            velocities: v.to_vec(),
            ..Default::default()
        };
        Some(FollowJointTrajectoryFeedback {
            header: Header {
                stamp,
                frame_id: String::new(),
            },
            joint_names: self.joints.clone(),
            desired: point(dp, dv),
            actual: point(ap, av),
            error: JointTrajectoryPoint {
                positions: diff(dp, ap),
                velocities: diff(dv, av),
                ..Default::default()
            },
            ..Default::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::parse_from;
    use kerf_msgs::{
        builtin_interfaces::Duration, control_msgs::FollowJointTrajectoryGoal,
        trajectory_msgs::JointTrajectoryPoint,
    };

    fn driver(extra: &[&str]) -> Driver {
        let mut args = vec!["sim_driver", "--joints", "a,b", "--initial", "1,2"];
        args.extend_from_slice(extra);
        Driver::new(&parse_from(args).unwrap())
    }

    fn stamp(s: f64) -> Time {
        Time::from_secs_f64(1e9 + s).unwrap()
    }

    fn goal(points: &[([f64; 2], f64)]) -> Goal {
        let mut g = FollowJointTrajectoryGoal::default();
        g.trajectory.joint_names = vec!["a".into(), "b".into()];
        g.trajectory.points = points
            .iter()
            .map(|(p, t)| JointTrajectoryPoint {
                positions: p.to_vec(),
                time_from_start: Duration::from_secs_f64(*t).unwrap(),
                ..Default::default()
            })
            .collect();
        Goal::check(&g, &["a".into(), "b".into()]).unwrap()
    }

    #[test]
    fn commands_arrive_after_the_delay() {
        let mut d = driver(&["--delay", "0.1"]);
        let (s, _) = d.tick(0.0, stamp(0.0));
        assert_eq!(s.unwrap().position, [1.0, 2.0]);
        d.command(0.0, vec![3.0, 4.0]).unwrap();
        assert_eq!(d.tick(0.05, stamp(0.05)).0.unwrap().position, [1.0, 2.0]);
        let s = d.tick(0.1, stamp(0.1)).0.unwrap();
        assert_eq!(s.position, [3.0, 4.0]);
        assert!((s.velocity[0] - 40.0).abs() < 1e-9, "{:?}", s.velocity);
        assert_eq!(d.tick(0.2, stamp(0.2)).0.unwrap().velocity, [0.0, 0.0]);
    }

    #[test]
    fn one_shot_faults_and_drop() {
        let mut d = driver(&["--delay", "0"]);
        let s0 = d.tick(0.0, stamp(0.0)).0.unwrap();
        d.apply(Fault::StampBack);
        d.apply(Fault::Nan);
        d.apply(Fault::FewerJoints);
        let s1 = d.tick(0.004, stamp(0.004)).0.unwrap();
        assert_eq!(
            s1.header.stamp.as_nanos(),
            s0.header.stamp.as_nanos() - 1_000_000_000
        );
        assert!(s1.position[0].is_nan());
        assert_eq!(
            (s1.name.len(), s1.position.len(), s1.velocity.len()),
            (1, 1, 1)
        );
        let s2 = d.tick(0.008, stamp(0.008)).0.unwrap();
        assert_eq!(s2.position, [1.0, 2.0]);
        assert_eq!(s2.header.stamp, stamp(0.008));
        d.apply(Fault::Drop);
        assert!(d.tick(0.012, stamp(0.012)).0.is_none());
        d.apply(Fault::Resume);
        assert!(d.tick(0.016, stamp(0.016)).0.is_some());
    }

    #[test]
    fn freeze_holds_the_measured_position() {
        let mut d = driver(&["--delay", "0"]);
        d.tick(0.0, stamp(0.0));
        d.apply(Fault::Freeze);
        d.command(0.01, vec![5.0, 5.0]).unwrap();
        assert_eq!(d.tick(0.01, stamp(0.01)).0.unwrap().position, [1.0, 2.0]);
        d.apply(Fault::Resume);
        assert_eq!(d.tick(0.02, stamp(0.02)).0.unwrap().position, [5.0, 5.0]);
    }

    #[test]
    fn goals_run_end_and_block_commands() {
        let mut d = driver(&["--delay", "0.01"]);
        d.tick(0.0, stamp(0.0));
        d.start_goal(0.0, goal(&[([1.0, 2.0], 0.0), ([2.0, 3.0], 0.1)]))
            .unwrap();
        assert_eq!(d.command(0.0, vec![0.0, 0.0]), Err(Ignored::DuringGoal));
        let mut end = None;
        let mut t = 0.0;
        while end.is_none() && t < 1.0 {
            t += 0.004;
            let (s, e) = d.tick(t, stamp(t));
            end = e;
            if end.is_some() {
                assert_eq!(s.unwrap().position, [2.0, 3.0]);
            } else {
                assert!(d.feedback(stamp(t)).is_some());
            }
        }
        let end = end.unwrap();
        assert!(end.succeeded, "{end:?}");
        assert!(t >= 0.11 - 1e-9, "{t}");
        assert!(!d.has_goal());
        assert!(d.command(t, vec![0.0, 0.0]).is_ok());
        assert_eq!(d.counters.commands_during_goal, 1);
    }

    #[test]
    fn a_far_first_point_is_aborted_and_a_frozen_end_too() {
        let mut d = driver(&["--delay", "0"]);
        d.tick(0.0, stamp(0.0));
        let e = d.start_goal(0.0, goal(&[([1.5, 2.0], 0.0)])).unwrap_err();
        assert_eq!(
            e.result.error_code,
            FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED
        );
        assert!(
            e.result.error_string.contains("'a'"),
            "{}",
            e.result.error_string
        );
        assert!(!d.has_goal());
        d.apply(Fault::Freeze);
        d.start_goal(0.0, goal(&[([1.0, 2.0], 0.0), ([1.0, 3.0], 0.05)]))
            .unwrap();
        let mut end = None;
        let mut t = 0.0;
        while end.is_none() && t < 1.0 {
            t += 0.004;
            end = d.tick(t, stamp(t)).1;
        }
        let end = end.unwrap();
        assert_eq!(
            end.result.error_code,
            FollowJointTrajectoryResult::GOAL_TOLERANCE_VIOLATED
        );
    }

    #[test]
    fn cancel_holds_where_it_is() {
        let mut d = driver(&["--delay", "0"]);
        d.tick(0.0, stamp(0.0));
        d.start_goal(0.0, goal(&[([1.0, 2.0], 0.0), ([2.0, 2.0], 1.0)]))
            .unwrap();
        d.tick(0.5, stamp(0.5));
        assert!(d.cancel());
        let p = d.tick(0.6, stamp(0.6)).0.unwrap().position;
        assert!((p[0] - 1.5).abs() < 1e-12, "{p:?}");
        assert_eq!(d.tick(0.7, stamp(0.7)).0.unwrap().position, p);
    }

    #[test]
    fn noise_has_the_given_spread() {
        let mut d = driver(&["--delay", "0", "--noise", "0.01", "--seed", "7"]);
        let n = 4000;
        let mut sum2 = 0.0;
        for k in 0..n {
            let s = d.tick(k as f64 * 0.004, stamp(0.0)).0.unwrap();
            sum2 += (s.position[0] - 1.0).powi(2);
            assert_eq!(s.velocity, [0.0, 0.0], "velocity is noise-free");
        }
        let sd = (sum2 / n as f64).sqrt();
        assert!((sd - 0.01).abs() < 0.0006, "{sd}");
    }
}
