//! [`WaypointMove`]: consecutive [`JointMove`] legs through via poses, and sampling a move at
//! a period.

use crate::limits::{check_configuration, check_limits};
use crate::{ApproachError, JointLimit, JointMove, Role, Sample};

/// Most samples one move may be sampled into (at the control period, for the clearance check
/// or for the executor): 10⁶, i.e. 4000 s at 4 ms. It bounds the memory and the clearance
/// queries a bad input can cost.
pub const MAX_SAMPLES: usize = 1_000_000;

/// A motion through waypoints `q_0 → q_1 → … → q_n`, one [`JointMove`] per leg.
///
/// This first version stops at every via pose: each leg is rest-to-rest (velocity and
/// acceleration 0 at the via pose), which is simple, exactly limit-respecting and keeps each
/// joint monotone on each leg (what the clearance bound of [`crate::ClearanceCheck`] needs),
/// at the cost of the time spent braking and restarting. Blending through the via pose is
/// left for later.
#[derive(Debug, Clone, PartialEq)]
pub struct WaypointMove {
    legs: Vec<JointMove>,
    /// Start time of each leg (s).
    offsets: Vec<f64>,
    duration: f64,
}

impl WaypointMove {
    /// The fastest move through `waypoints` within `limits`, each leg at its own minimum
    /// duration.
    ///
    /// # Arguments
    /// * `waypoints` – at least 2 configurations.
    /// * `limits` – one [`JointLimit`] per joint.
    ///
    /// # Returns
    /// [`ApproachError::TooFewWaypoints`], or [`JointMove::new`]'s errors naming waypoint `i`
    /// as [`Role::Waypoint`] `i`.
    ///
    /// # Performance
    /// O(waypoints × joints).
    pub fn through<W: AsRef<[f64]>>(
        waypoints: &[W],
        limits: &[JointLimit],
    ) -> Result<Self, ApproachError> {
        if waypoints.len() < 2 {
            return Err(ApproachError::TooFewWaypoints {
                found: waypoints.len(),
            });
        }
        check_limits(limits)?;
        for (i, w) in waypoints.iter().enumerate() {
            check_configuration(Role::Waypoint(i), w.as_ref(), limits)?;
        }
        let mut legs = Vec::with_capacity(waypoints.len() - 1);
        for (i, pair) in waypoints.windows(2).enumerate() {
            let leg =
                JointMove::new(pair[0].as_ref(), pair[1].as_ref(), limits).map_err(
                    |e| match e {
                        ApproachError::NonFiniteDuration { .. } => {
                            ApproachError::NonFiniteDuration {
                                role: Role::Waypoint(i + 1),
                            }
                        }
                        other => other,
                    },
                )?;
            legs.push(leg);
        }
        Self::from_legs(legs)
    }

    /// A move of the given legs, one after the other.
    ///
    /// # Returns
    /// [`ApproachError::TooFewWaypoints`] for no leg; [`ApproachError::DisconnectedLegs`]
    /// when a leg does not start exactly where the previous one ends.
    pub fn from_legs(legs: Vec<JointMove>) -> Result<Self, ApproachError> {
        if legs.is_empty() {
            return Err(ApproachError::TooFewWaypoints { found: 0 });
        }
        for (i, pair) in legs.windows(2).enumerate() {
            if pair[0].end() != pair[1].start() {
                return Err(ApproachError::DisconnectedLegs {
                    leg: i + 1,
                    previous: i,
                });
            }
        }
        let mut offsets = Vec::with_capacity(legs.len());
        let mut duration = 0.0;
        for leg in &legs {
            offsets.push(duration);
            duration += leg.duration();
        }
        Ok(Self {
            legs,
            offsets,
            duration,
        })
    }

    /// The legs.
    pub fn legs(&self) -> &[JointMove] {
        &self.legs
    }

    /// Start time of each leg (s).
    pub fn leg_offsets(&self) -> &[f64] {
        &self.offsets
    }

    /// Total duration (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The first configuration.
    pub fn start(&self) -> &[f64] {
        self.legs.first().map_or(&[], JointMove::start)
    }

    /// The last configuration.
    pub fn end(&self) -> &[f64] {
        self.legs.last().map_or(&[], JointMove::end)
    }

    /// The leg running at time `t` and its start time: the last leg starting at or before
    /// `t` (the first leg for `t < 0` or NaN).
    fn leg_at(&self, t: f64) -> Option<(&JointMove, f64)> {
        let i = self.offsets.iter().rposition(|&o| o <= t).unwrap_or(0);
        Some((self.legs.get(i)?, *self.offsets.get(i)?))
    }

    /// The state at time `t` (s), clamped to [0, duration] (NaN reads as 0).
    ///
    /// # Returns
    /// A [`Sample`] with the clamped global time. At a via pose the next leg's start is
    /// returned, which equals the previous leg's end (both at rest).
    ///
    /// # Performance
    /// O(legs + joints).
    pub fn sample(&self, t: f64) -> Sample {
        match self.leg_at(t) {
            Some((leg, offset)) => {
                let mut s = leg.sample(t - offset);
                s.t += offset;
                s
            }
            None => Sample::default(),
        }
    }

    /// The move sampled every `period`: `t = 0, period, 2·period, …` below the duration, then
    /// the end at the duration (at rest, exactly the last waypoint).
    ///
    /// # Arguments
    /// * `period` – the sampling period (s), finite and > 0 (the executor's control period).
    ///
    /// # Returns
    /// The samples, time-ordered; [`ApproachError::InvalidPeriod`], or
    /// [`ApproachError::TooManySamples`] above [`MAX_SAMPLES`].
    ///
    /// # Performance
    /// O(samples × joints); three allocations per sample.
    pub fn samples(&self, period: f64) -> Result<Vec<Sample>, ApproachError> {
        let count = sample_count(self.duration, period)?;
        let mut out = Vec::with_capacity(count + 1);
        for k in 0..count {
            out.push(self.sample(k as f64 * period));
        }
        out.push(self.sample(self.duration));
        Ok(out)
    }
}

/// The number of samples `k · period` strictly below `duration` (less one part in 10⁹ of a
/// period, so that a duration of `n` periods gives `n` samples plus the end).
///
/// # Returns
/// [`ApproachError::InvalidPeriod`], or [`ApproachError::TooManySamples`] above
/// [`MAX_SAMPLES`].
pub(crate) fn sample_count(duration: f64, period: f64) -> Result<usize, ApproachError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(ApproachError::InvalidPeriod { period });
    }
    let ratio = duration / period;
    if ratio.is_nan() || ratio >= MAX_SAMPLES as f64 {
        return Err(ApproachError::TooManySamples {
            duration,
            period,
            samples: ratio,
            max: MAX_SAMPLES,
        });
    }
    if ratio <= 0.0 {
        // A zero-duration move: only its end.
        return Ok(0);
    }
    // ceil(ratio − 1e-9) counts 0, 1, …, up to the last time below the end.
    Ok((ratio - 1e-9).ceil().max(1.0) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Vec<JointLimit> {
        vec![JointLimit {
            name: "a".into(),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 1.0,
            max_acceleration: 4.0,
            max_jerk: 40.0,
        }]
    }

    #[test]
    fn via_pose_is_passed_at_rest() {
        let m = WaypointMove::through(&[[0.0], [1.0], [-0.5]], &limits()).unwrap();
        assert_eq!(m.legs().len(), 2);
        let t_via = m.leg_offsets()[1];
        let s = m.sample(t_via);
        assert_eq!(s.q, vec![1.0]);
        assert_eq!(s.qd, vec![0.0]);
        assert_eq!(m.end(), &[-0.5]);
        assert!((m.duration() - m.legs()[0].duration() - m.legs()[1].duration()).abs() < 1e-15);
    }

    #[test]
    fn samples_end_exactly_at_the_end() {
        let m = WaypointMove::through(&[[0.0], [1.0]], &limits()).unwrap();
        let s = m.samples(0.01).unwrap();
        let last = s.last().unwrap();
        assert_eq!((last.t, last.q.clone()), (m.duration(), vec![1.0]));
        assert!(s.windows(2).all(|w| w[1].t > w[0].t));
        // A duration of exactly n periods: n samples plus the end.
        let exact = m.legs()[0].with_duration(2.0).unwrap();
        let exact = WaypointMove::from_legs(vec![exact]).unwrap();
        assert_eq!(exact.samples(0.25).unwrap().len(), 9);
        assert!(matches!(
            m.samples(0.0),
            Err(ApproachError::InvalidPeriod { .. })
        ));
        assert!(matches!(
            m.samples(1e-12),
            Err(ApproachError::TooManySamples { .. })
        ));
    }

    #[test]
    fn waypoint_errors_name_the_waypoint() {
        let e = WaypointMove::through(&[[0.0], [1.0], [5.0]], &limits()).unwrap_err();
        assert!(
            matches!(
                e,
                ApproachError::OutOfLimits {
                    role: Role::Waypoint(2),
                    ..
                }
            ),
            "{e}"
        );
        let one: [[f64; 1]; 1] = [[0.0]];
        assert!(matches!(
            WaypointMove::through(&one, &limits()),
            Err(ApproachError::TooFewWaypoints { found: 1 })
        ));
        let a = JointMove::new(&[0.0], &[1.0], &limits()).unwrap();
        let b = JointMove::new(&[0.5], &[1.0], &limits()).unwrap();
        assert!(matches!(
            WaypointMove::from_legs(vec![a, b]),
            Err(ApproachError::DisconnectedLegs { leg: 1, .. })
        ));
    }
}
