//! [`JointMove`]: a synchronised rest-to-rest minimum-jerk motion between two configurations.

use crate::limits::{check_configuration, check_limits};
use crate::{profile, ApproachError, JointLimit, Role, Sample};

/// A rest-to-rest point-to-point joint motion `q_a → q_b` within per-joint velocity,
/// acceleration and jerk limits.
///
/// Every joint follows the minimum-jerk quintic of [`crate::profile`] (Flash & Hogan 1985)
/// over one shared duration `T`:
///
/// ```text
/// q(t) = q_a + (q_b − q_a) s(t/T),   s(τ) = 10τ³ − 15τ⁴ + 6τ⁵
/// ```
///
/// so all joints start and stop together and the joint-space path is the straight segment.
/// The shortest `T` meeting every limit is
///
/// ```text
/// T_min = max over joints j of max(15/8·|Δ_j|/v_j, sqrt(10/√3·|Δ_j|/a_j), cbrt(60·|Δ_j|/j_j))
/// ```
///
/// ([`profile::min_duration`]: 15/8, 10/√3 and 60 are the peaks of `|s'|`, `|s''|`, `|s'''|`
/// on [0, 1]). Velocity and acceleration are 0 at both ends; the jerk steps to `±60 Δ/T³` at
/// the ends, within the jerk limit. Each joint is monotone and never leaves
/// `[min(q_a, q_b), max(q_a, q_b)]`, hence never leaves its position limits.
#[derive(Debug, Clone, PartialEq)]
pub struct JointMove {
    start: Vec<f64>,
    end: Vec<f64>,
    delta: Vec<f64>,
    duration: f64,
    min_duration: f64,
}

impl JointMove {
    /// The fastest move from `start` to `end` within `limits`.
    ///
    /// # Arguments
    /// * `start`, `end` – configurations, one finite position per joint, inside the position
    ///   limits.
    /// * `limits` – one [`JointLimit`] per joint.
    ///
    /// # Returns
    /// The move with duration `T_min`, or an error naming the bad limit, joint or position
    /// ([`Role::Waypoint`] 0 for `start`, 1 for `end`), or
    /// [`ApproachError::NonFiniteDuration`].
    ///
    /// # Performance
    /// O(joints): one square and one cube root per joint.
    pub fn new(start: &[f64], end: &[f64], limits: &[JointLimit]) -> Result<Self, ApproachError> {
        check_limits(limits)?;
        check_configuration(Role::Waypoint(0), start, limits)?;
        check_configuration(Role::Waypoint(1), end, limits)?;
        let delta: Vec<f64> = end.iter().zip(start).map(|(b, a)| b - a).collect();
        let mut min_duration = 0.0f64;
        for (d, l) in delta.iter().zip(limits) {
            let t = profile::min_duration(*d, l.max_velocity, l.max_acceleration, l.max_jerk);
            if !t.is_finite() {
                return Err(ApproachError::NonFiniteDuration {
                    role: Role::Waypoint(1),
                });
            }
            min_duration = min_duration.max(t);
        }
        Ok(Self {
            start: start.to_vec(),
            end: end.to_vec(),
            delta,
            duration: min_duration,
            min_duration,
        })
    }

    /// The same move slowed down to `duration` (every peak scales down: velocity by
    /// `T_min/T`, acceleration by its square, jerk by its cube).
    ///
    /// # Returns
    /// [`ApproachError::InvalidDuration`] when `duration` is not finite or is below
    /// [`JointMove::min_duration`].
    pub fn with_duration(&self, duration: f64) -> Result<Self, ApproachError> {
        if !(duration.is_finite() && duration >= self.min_duration) {
            return Err(ApproachError::InvalidDuration {
                duration,
                min: self.min_duration,
            });
        }
        Ok(Self {
            duration,
            ..self.clone()
        })
    }

    /// The duration `T` (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The shortest duration meeting every joint's limits (s).
    pub fn min_duration(&self) -> f64 {
        self.min_duration
    }

    /// The start configuration `q_a`.
    pub fn start(&self) -> &[f64] {
        &self.start
    }

    /// The end configuration `q_b`.
    pub fn end(&self) -> &[f64] {
        &self.end
    }

    /// The joint count.
    pub fn joint_count(&self) -> usize {
        self.start.len()
    }

    /// The normalised time `τ = t/T` in [0, 1]; NaN and `t ≤ 0` give 0, `t ≥ T` gives 1.
    fn tau(&self, t: f64) -> f64 {
        if t >= self.duration {
            1.0
        } else if t > 0.0 {
            t / self.duration
        } else {
            0.0
        }
    }

    /// The state at time `t` (s), clamped to [0, T] (NaN reads as 0).
    ///
    /// # Returns
    /// A [`Sample`] with `t` clamped and `q`, `q̇`, `q̈`. At `t ≥ T` the position is exactly
    /// `q_b` (not `q_a + Δ`, which may differ in the last bit).
    ///
    /// # Performance
    /// O(joints), three allocations; [`JointMove::position_into`] allocates nothing.
    pub fn sample(&self, t: f64) -> Sample {
        let tau = self.tau(t);
        let n = self.joint_count();
        let clamped = if t >= self.duration {
            self.duration
        } else if t > 0.0 {
            t
        } else {
            0.0
        };
        let mut out = Sample::at_rest(clamped, vec![0.0; n]);
        self.position_into(t, &mut out.q);
        if self.duration > 0.0 && tau < 1.0 {
            let sd = profile::velocity(tau) / self.duration;
            let sdd = profile::acceleration(tau) / (self.duration * self.duration);
            for ((v, a), d) in out.qd.iter_mut().zip(out.qdd.iter_mut()).zip(&self.delta) {
                *v = d * sd;
                *a = d * sdd;
            }
        }
        out
    }

    /// Writes the positions at time `t` (clamped as in [`JointMove::sample`]) into `out`
    /// (the first `min(out.len(), joints)` entries).
    pub fn position_into(&self, t: f64, out: &mut [f64]) {
        let tau = self.tau(t);
        if tau >= 1.0 {
            out.iter_mut().zip(&self.end).for_each(|(o, e)| *o = *e);
            return;
        }
        let s = profile::position(tau);
        for ((o, a), d) in out.iter_mut().zip(&self.start).zip(&self.delta) {
            *o = a + d * s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Vec<JointLimit> {
        ["a", "b"]
            .iter()
            .map(|n| JointLimit {
                name: (*n).into(),
                min_position: -3.0,
                max_position: 3.0,
                max_velocity: 2.0,
                max_acceleration: 5.0,
                max_jerk: 50.0,
            })
            .collect()
    }

    #[test]
    fn ends_at_rest_exactly_at_the_goal() {
        let m = JointMove::new(&[0.1, -0.2], &[1.3, 0.7], &limits()).unwrap();
        assert!(m.duration() > 0.0);
        let s = m.sample(m.duration());
        assert_eq!(s.q, vec![1.3, 0.7]);
        assert_eq!(s.qd, vec![0.0, 0.0]);
        let s0 = m.sample(f64::NAN);
        assert_eq!((s0.t, s0.q.clone()), (0.0, vec![0.1, -0.2]));
        let late = m.sample(1e9);
        assert_eq!(late.t, m.duration());
    }

    #[test]
    fn binding_joint_meets_its_peak() {
        let m = JointMove::new(&[0.0, 0.0], &[2.0, 0.5], &limits()).unwrap();
        // Joint a: velocity 15/8·2/2 = 1.875 s, acceleration sqrt(5.77·2/5) = 1.52 s,
        // jerk cbrt(60·2/50) = 1.34 s: velocity binds.
        assert!((m.duration() - 1.875).abs() < 1e-12);
        let mid = m.sample(m.duration() / 2.0);
        assert!((mid.qd[0] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn zero_motion_has_zero_duration() {
        let m = JointMove::new(&[0.5, 0.5], &[0.5, 0.5], &limits()).unwrap();
        assert_eq!(m.duration(), 0.0);
        assert_eq!(m.sample(0.3).q, vec![0.5, 0.5]);
        assert!(m.with_duration(1.0).is_ok());
    }

    #[test]
    fn too_short_or_nan_durations_are_refused() {
        let m = JointMove::new(&[0.0, 0.0], &[1.0, 1.0], &limits()).unwrap();
        for d in [m.duration() * 0.99, f64::NAN, f64::INFINITY, -1.0] {
            assert!(matches!(
                m.with_duration(d),
                Err(ApproachError::InvalidDuration { .. })
            ));
        }
        let slow = m.with_duration(2.0 * m.duration()).unwrap();
        assert_eq!(slow.min_duration(), m.duration());
    }

    #[test]
    fn unbounded_joints_with_huge_moves_are_refused() {
        let mut l = limits();
        l[0].min_position = f64::NEG_INFINITY;
        l[0].max_position = f64::INFINITY;
        let e = JointMove::new(&[-1e308, 0.0], &[1e308, 0.0], &l).unwrap_err();
        assert!(matches!(e, ApproachError::NonFiniteDuration { .. }), "{e}");
    }
}
