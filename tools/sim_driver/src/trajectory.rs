//! FollowJointTrajectory goals: the checks that accept or reject one, and the motion the
//! driver runs for it (cubic Hermite where both ends give velocities, linear otherwise).

use kerf_msgs::{builtin_interfaces::Duration, control_msgs::FollowJointTrajectoryGoal};

/// Largest magnitude of a goal's positions and velocities (joint units).
pub const MAX_GOAL_VALUE: f64 = 1e6;

/// One knot of the motion: a time after the goal's start, a position and maybe a velocity.
#[derive(Debug, Clone, PartialEq)]
struct Knot {
    t: f64,
    p: Vec<f64>,
    v: Option<Vec<f64>>,
}

/// A checked goal, in the driver's joint order.
#[derive(Debug, Clone, PartialEq)]
pub struct Goal {
    points: Vec<Knot>,
}

/// The motion of a started goal: the start state, then the goal's points.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    knots: Vec<Knot>,
}

fn seconds(d: &Duration) -> Option<f64> {
    (d.nanosec < 1_000_000_000 && !d.is_negative()).then(|| d.as_secs_f64())
}

/// Checks `values` (named `what`) has `n` entries, or none when `optional`; all finite and
/// at most [`MAX_GOAL_VALUE`] in magnitude.
fn check(values: &[f64], n: usize, optional: bool, what: &str) -> Result<(), String> {
    if values.len() != n && !(optional && values.is_empty()) {
        let need = if optional { "none or " } else { "" };
        return Err(format!(
            "{what} has {} values, {need}{n} expected",
            values.len()
        ));
    }
    match values
        .iter()
        .position(|x| !x.is_finite() || x.abs() > MAX_GOAL_VALUE)
    {
        Some(i) => Err(format!(
            "{what}[{i}] = {} is not finite or beyond {MAX_GOAL_VALUE}",
            values[i]
        )),
        None => Ok(()),
    }
}

impl Goal {
    /// Checks a goal against the driver's `joints` and reorders it to them.
    ///
    /// # Errors
    /// Why the goal is rejected: other joints, no points, wrong array lengths, a value not
    /// finite, a negative or decreasing `time_from_start`, a multi-DOF part.
    pub fn check(goal: &FollowJointTrajectoryGoal, joints: &[String]) -> Result<Goal, String> {
        let traj = &goal.trajectory;
        let names = &traj.joint_names;
        let n = joints.len();
        let mut order = Vec::with_capacity(n);
        for j in joints {
            match names.iter().position(|x| x == j) {
                Some(i) => order.push(i),
                None => break,
            }
        }
        if names.len() != n || order.len() != n {
            return Err(format!(
                "joint_names {names:?} must be exactly the driver's joints {joints:?} (any order)"
            ));
        }
        let mdof = &goal.multi_dof_trajectory;
        if !mdof.joint_names.is_empty() || !mdof.points.is_empty() {
            return Err("multi-DOF trajectories are not supported".into());
        }
        if traj.points.is_empty() {
            return Err("the trajectory has no points".into());
        }
        let mut points = Vec::with_capacity(traj.points.len());
        let mut last_t = 0.0;
        for (k, pt) in traj.points.iter().enumerate() {
            check(&pt.positions, n, false, &format!("points[{k}].positions"))?;
            check(&pt.velocities, n, true, &format!("points[{k}].velocities"))?;
            check(
                &pt.accelerations,
                n,
                true,
                &format!("points[{k}].accelerations"),
            )?;
            if pt.effort.iter().any(|x| !x.is_finite()) {
                return Err(format!("points[{k}].effort has a value that is not finite"));
            }
            let Some(t) = seconds(&pt.time_from_start) else {
                return Err(format!(
                    "points[{k}].time_from_start {:?} is negative or not normalized",
                    pt.time_from_start
                ));
            };
            if t < last_t {
                return Err(format!(
                    "points[{k}].time_from_start {t} s is earlier than the point before ({last_t} s)"
                ));
            }
            last_t = t;
            let reorder = |v: &[f64]| order.iter().map(|&i| v[i]).collect::<Vec<f64>>();
            points.push(Knot {
                t,
                p: reorder(&pt.positions),
                v: (!pt.velocities.is_empty()).then(|| reorder(&pt.velocities)),
            });
        }
        Ok(Goal { points })
    }

    /// The first point's positions.
    pub fn first_positions(&self) -> &[f64] {
        self.points.first().map_or(&[][..], |k| k.p.as_slice())
    }

    /// The motion from position `p0` and velocity `v0` at time 0 through the goal's points.
    pub fn start_from(self, p0: Vec<f64>, v0: Vec<f64>) -> Trajectory {
        let mut knots = Vec::with_capacity(self.points.len() + 1);
        knots.push(Knot {
            t: 0.0,
            p: p0,
            v: Some(v0),
        });
        knots.extend(self.points);
        Trajectory { knots }
    }
}

impl Trajectory {
    /// When the last point is reached (s after the start).
    pub fn duration(&self) -> f64 {
        self.knots.last().map_or(0.0, |k| k.t)
    }

    /// The last point's positions.
    pub fn last_positions(&self) -> &[f64] {
        self.knots.last().map_or(&[][..], |k| k.p.as_slice())
    }

    /// Position and velocity `t` seconds after the start; the last point, at rest, after the
    /// end.
    pub fn sample(&self, t: f64) -> (Vec<f64>, Vec<f64>) {
        let i = self.knots.partition_point(|k| k.t <= t);
        let (Some(a), Some(b)) = (self.knots.get(i.wrapping_sub(1)), self.knots.get(i)) else {
            let p = if i == 0 {
                self.knots.first()
            } else {
                self.knots.last()
            };
            let p = p.map(|k| k.p.clone()).unwrap_or_default();
            let v = vec![0.0; p.len()];
            return (p, v);
        };
        // a.t <= t < b.t, so h > 0.
        let h = b.t - a.t;
        let s = (t - a.t) / h;
        match (&a.v, &b.v) {
            (Some(va), Some(vb)) => {
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10, h01, h11) = (
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    s3 - 2.0 * s2 + s,
                    -2.0 * s3 + 3.0 * s2,
                    s3 - s2,
                );
                let (d00, d10, d01, d11) = (
                    6.0 * s2 - 6.0 * s,
                    3.0 * s2 - 4.0 * s + 1.0,
                    -6.0 * s2 + 6.0 * s,
                    3.0 * s2 - 2.0 * s,
                );
                let mut p = Vec::with_capacity(a.p.len());
                let mut v = Vec::with_capacity(a.p.len());
                for j in 0..a.p.len() {
                    let (pa, pb, ma, mb) = (a.p[j], b.p[j], va[j] * h, vb[j] * h);
                    p.push(h00 * pa + h10 * ma + h01 * pb + h11 * mb);
                    v.push((d00 * pa + d10 * ma + d01 * pb + d11 * mb) / h);
                }
                (p, v)
            }
            _ => {
                let p = a.p.iter().zip(&b.p).map(|(x, y)| x + s * (y - x)).collect();
                let v = a.p.iter().zip(&b.p).map(|(x, y)| (y - x) / h).collect();
                (p, v)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_msgs::trajectory_msgs::JointTrajectoryPoint;

    fn joints() -> Vec<String> {
        vec!["a".into(), "b".into()]
    }

    fn point(p: [f64; 2], v: Option<[f64; 2]>, t: f64) -> JointTrajectoryPoint {
        JointTrajectoryPoint {
            positions: p.to_vec(),
            velocities: v.map(|v| v.to_vec()).unwrap_or_default(),
            time_from_start: Duration::from_secs_f64(t).unwrap(),
            ..Default::default()
        }
    }

    fn goal(names: &[&str], points: Vec<JointTrajectoryPoint>) -> FollowJointTrajectoryGoal {
        let mut g = FollowJointTrajectoryGoal::default();
        g.trajectory.joint_names = names.iter().map(|s| s.to_string()).collect();
        g.trajectory.points = points;
        g
    }

    #[test]
    fn reorders_and_interpolates() {
        // Given as (b, a): b 0 -> 2 linear, then Hermite with velocities.
        let g = goal(
            &["b", "a"],
            vec![
                point([0.0, 1.0], None, 0.0),
                point([2.0, 1.0], Some([0.0, 0.0]), 1.0),
                point([2.0, 3.0], Some([0.0, 0.0]), 2.0),
            ],
        );
        let g = Goal::check(&g, &joints()).unwrap();
        assert_eq!(g.first_positions(), [1.0, 0.0]);
        let t = g.start_from(vec![1.0, 0.0], vec![0.0, 0.0]);
        assert_eq!(t.duration(), 2.0);
        assert_eq!(t.last_positions(), [3.0, 2.0]);
        // Segment 1 is linear (the point at 0 s gives no velocities).
        let (p, v) = t.sample(0.5);
        assert_eq!((p, v), (vec![1.0, 1.0], vec![0.0, 2.0]));
        // Segment 2 is Hermite from rest to rest: half-way, half the move, peak 1.5 × mean.
        let (p, v) = t.sample(1.5);
        assert!(
            (p[0] - 2.0).abs() < 1e-12 && (v[0] - 3.0).abs() < 1e-12,
            "{p:?} {v:?}"
        );
        assert_eq!(t.sample(2.0), (vec![3.0, 2.0], vec![0.0, 0.0]));
        assert_eq!(t.sample(99.0).0, [3.0, 2.0]);
        assert_eq!(t.sample(-1.0).0, [1.0, 0.0]);
    }

    #[test]
    fn rejects_bad_goals() {
        let ok = || vec![point([0.0, 0.0], None, 1.0)];
        let cases: Vec<(FollowJointTrajectoryGoal, &str)> = vec![
            (goal(&["a"], ok()), "joint_names"),
            (goal(&["a", "c"], ok()), "joint_names"),
            (goal(&["a", "a"], ok()), "joint_names"),
            (goal(&["a", "b", "c"], ok()), "joint_names"),
            (goal(&["a", "b"], vec![]), "no points"),
            (
                goal(&["a", "b"], vec![point([0.0, f64::NAN], None, 1.0)]),
                "positions[1]",
            ),
            (
                goal(
                    &["a", "b"],
                    vec![point([0.0, 0.0], Some([f64::INFINITY, 0.0]), 1.0)],
                ),
                "velocities[0]",
            ),
            (
                goal(
                    &["a", "b"],
                    vec![point([0.0, 0.0], None, 2.0), point([0.0, 0.0], None, 1.0)],
                ),
                "earlier",
            ),
        ];
        for (g, needle) in cases {
            let e = Goal::check(&g, &joints()).unwrap_err();
            assert!(e.contains(needle), "{e} lacks {needle}");
        }
        let mut short = goal(&["a", "b"], ok());
        short.trajectory.points[0].positions.pop();
        assert!(Goal::check(&short, &joints()).is_err());
        let mut negative = goal(&["a", "b"], ok());
        negative.trajectory.points[0].time_from_start = Duration {
            sec: -1,
            nanosec: 0,
        };
        assert!(Goal::check(&negative, &joints()).is_err());
        let mut mdof = goal(&["a", "b"], ok());
        mdof.multi_dof_trajectory.joint_names.push("x".into());
        assert!(Goal::check(&mdof, &joints()).is_err());
    }

    #[test]
    fn equal_times_jump() {
        let g = goal(
            &["a", "b"],
            vec![point([0.0, 0.0], None, 0.0), point([1.0, 1.0], None, 0.0)],
        );
        let t = Goal::check(&g, &joints())
            .unwrap()
            .start_from(vec![0.0, 0.0], vec![0.0, 0.0]);
        assert_eq!(t.sample(0.0).0, [1.0, 1.0]);
    }
}
