//! [`TimedRun`]: a run's smoothed path with its feed plan: where the tool
//! is at every moment of the run.

use kerf_toolpath::{derivatives_at, FeedPlan, PathSample, SmoothedPath};

/// A run smoothed, sampled and timed.
#[derive(Debug, Clone)]
pub struct TimedRun {
    /// The smoothed path, program frame.
    pub path: SmoothedPath,
    /// Its planning samples.
    pub samples: Vec<PathSample>,
    /// Its feed plan, from rest to rest.
    pub plan: FeedPlan,
}

impl TimedRun {
    /// Duration of the feed plan \[s\].
    pub fn duration(&self) -> f64 {
        self.plan.time
    }

    /// Arc length, speed and tangential acceleration at time `t` (clamped
    /// to [0, duration]): the plan's constant-jerk phase that holds t,
    /// integrated exactly ([`kerf_toolpath::feed::PlacedPhase::at`]).
    pub fn state(&self, t: f64) -> (f64, f64, f64) {
        let t = t.clamp(0.0, self.plan.time);
        let phases = &self.plan.phases;
        if phases.is_empty() {
            return (0.0, 0.0, 0.0);
        }
        let k = phases.partition_point(|p| p.t0 <= t).saturating_sub(1);
        let (s, v, a) = phases[k].at(t - phases[k].t0);
        (s.clamp(0.0, self.plan.length), v.max(0.0), a)
    }

    /// The tool's position at time `t`, with its velocity and acceleration
    /// in the program frame: ṗ = p′ v, p̈ = p″ v² + p′ a (chain rule on
    /// p(s(t)); p′ and p″ by [`derivatives_at`]).
    pub fn motion(&self, t: f64) -> PathMotion {
        let (s, v, a) = self.state(t);
        let (point, d1, d2) = derivatives_at(&self.path, &self.samples, s);
        PathMotion {
            s,
            speed: v,
            acceleration: a,
            point,
            tangent: d1,
            curvature_normal: d2,
        }
    }
}

/// The tool along a run at one moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathMotion {
    /// Arc length \[m\].
    pub s: f64,
    /// Speed \[m/s\].
    pub speed: f64,
    /// Tangential acceleration \[m/s²\].
    pub acceleration: f64,
    /// Position \[m\].
    pub point: [f64; 3],
    /// dp/ds (unit).
    pub tangent: [f64; 3],
    /// d²p/ds² = κ n \[1/m\].
    pub curvature_normal: [f64; 3],
}
