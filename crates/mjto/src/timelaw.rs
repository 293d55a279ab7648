//! The feed profile `s(t)` along the CL path and the chain rule from path
//! derivatives to time derivatives (seed 001 eq. 1, 4, 6-7; Table 1:
//! feedrate f, path acceleration 8 m/s², path jerk 80 m/s³).
//!
//! The paper assumes a constant feedrate `ṡ = f` (eq. 13), which cannot
//! start or stop a real axis. kerf uses the jerk-limited "7-segment"
//! S-curve instead: from rest, jerk `+J` until the acceleration reaches
//! `A`, constant `A`, jerk `-J` until `ṡ` reaches the peak feed, cruise,
//! then the mirror image down to rest, with `|s̈| ≤ A` and `|s⃛| ≤ J`
//! everywhere. The planner's QP bounds (eq. 15, 40-42) still use the
//! constant `f`, which bounds `ṡ` from above; the dense limit check
//! evaluates the real law through [`chain_rule`] (eq. 7).
//!
//! Ramp from rest to `v` (rest-to-rest, zero end accelerations):
//! * `v ≥ A²/J`: jerk phases of `A/J`, constant-acceleration phase
//!   `v/A - A/J`, ramp time `v/A + A/J`;
//! * `v < A²/J`: `A` is not reached, peak acceleration `√(vJ)`, two jerk
//!   phases of `√(v/J)`.
//!
//! The ramp covers `d(v) = v · T_ramp(v) / 2` (the velocity profile is
//! point-symmetric about its midpoint). When `2 d(f) > σ` the path is too
//! short to reach `f`; the largest reachable peak `v` solves `2 d(v) = σ`
//! exactly: `v = (σ² J / 4)^{1/3}` if that is `≤ A²/J`, else
//! `v = (-A²/J + √(A⁴/J² + 4 A σ)) / 2`.

use crate::PlanError;

/// Largest number of samples [`TimeLaw::checked_sample_times`] callers in
/// this crate accept (the QI baseline): 10⁶ samples are 66 min at
/// Δt = 4 ms, and 48 MB per joint-vector array.
pub const MAX_SAMPLES: usize = 1_000_000;

/// A rest-to-rest, jerk-limited feed profile over a path of length σ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeLaw {
    sigma: f64,
    feed: f64,
    peak: f64,
    jerk: f64,
    /// Peak path acceleration reached (≤ the limit A).
    acc_peak: f64,
    /// Duration of one jerk phase.
    t_jerk: f64,
    /// Duration of the constant-acceleration phase.
    t_const_acc: f64,
    /// Duration of the whole ramp (3 phases).
    t_ramp: f64,
    /// Duration of the cruise.
    t_cruise: f64,
    /// State (s, ṡ) at the end of phase 1 and phase 2 of the ramp.
    s1: f64,
    v1: f64,
    s2: f64,
    v2: f64,
    /// Path length covered by the ramp.
    d_ramp: f64,
}

/// Ramp timing `(t_jerk, t_const_acc, acc_peak)` from rest to `v`.
fn ramp(v: f64, acc: f64, jerk: f64) -> (f64, f64, f64) {
    if v * jerk >= acc * acc {
        (acc / jerk, v / acc - acc / jerk, acc)
    } else {
        let tj = (v / jerk).sqrt();
        (tj, 0.0, jerk * tj)
    }
}

fn positive(field: &str, v: f64) -> Result<f64, PlanError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(PlanError::invalid(
            field,
            format!("{v} must be finite and > 0"),
        ))
    }
}

impl TimeLaw {
    /// The S-curve over a path of length `sigma` (module docs).
    ///
    /// # Arguments
    /// * `sigma` - path length σ (m).
    /// * `feed` - programmed feedrate f (m/s), the cruise speed.
    /// * `acc` - path acceleration limit A (m/s²).
    /// * `jerk` - path jerk limit J (m/s³).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (fields `path length`, `feedrate`,
    /// `feed_acceleration`, `feed_jerk`) when an argument is not finite
    /// and positive.
    pub fn new(sigma: f64, feed: f64, acc: f64, jerk: f64) -> Result<Self, PlanError> {
        let sigma = positive("path length", sigma)?;
        let feed = positive("feedrate", feed)?;
        let acc = positive("feed_acceleration", acc)?;
        let jerk = positive("feed_jerk", jerk)?;
        let distance = |v: f64| {
            let (tj, tc, _) = ramp(v, acc, jerk);
            v * (2.0 * tj + tc) / 2.0
        };
        let peak = if 2.0 * distance(feed) <= sigma {
            feed
        } else {
            let v_small = (sigma * sigma * jerk / 4.0).cbrt();
            let v = if v_small * jerk <= acc * acc {
                v_small
            } else {
                let a2j = acc * acc / jerk;
                (-a2j + (a2j * a2j + 4.0 * acc * sigma).sqrt()) / 2.0
            };
            v.min(feed)
        };
        let (t_jerk, t_const_acc, _) = ramp(peak, acc, jerk);
        let d_ramp = peak * (2.0 * t_jerk + t_const_acc) / 2.0;
        let t_cruise = ((sigma - 2.0 * d_ramp) / peak).max(0.0);
        Ok(Self::from_phases(
            sigma,
            feed,
            jerk,
            t_jerk,
            t_const_acc,
            t_cruise,
        ))
    }

    /// The law with jerk `jerk` in phases of `t_jerk`, `t_const_acc` and a cruise of
    /// `t_cruise` (s): peak acceleration `J t_j`, peak feed `J t_j (t_j + t_a)`.
    fn from_phases(
        sigma: f64,
        feed: f64,
        jerk: f64,
        t_jerk: f64,
        t_const_acc: f64,
        t_cruise: f64,
    ) -> Self {
        let acc_peak = jerk * t_jerk;
        let peak = acc_peak * (t_jerk + t_const_acc);
        let t_ramp = 2.0 * t_jerk + t_const_acc;
        let d_ramp = peak * t_ramp / 2.0;
        let v1 = jerk * t_jerk * t_jerk / 2.0;
        let s1 = jerk * t_jerk.powi(3) / 6.0;
        let v2 = v1 + acc_peak * t_const_acc;
        let s2 = s1 + v1 * t_const_acc + acc_peak * t_const_acc * t_const_acc / 2.0;
        Self {
            sigma,
            feed,
            peak,
            jerk,
            acc_peak,
            t_jerk,
            t_const_acc,
            t_ramp,
            t_cruise,
            s1,
            v1,
            s2,
            v2,
            d_ramp,
        }
    }

    /// The law with every phase a whole number of controller periods `dt` (kerf, issue 16).
    ///
    /// The executor interpolates between the plan's samples with quintic Hermite segments
    /// (JTC). Where the feed's jerk jumps inside a step (a corner of the S-curve) the quintic
    /// through position, velocity and acceleration at the step's ends overshoots the jerk:
    /// measured on case 1 (Δt = 10 ms), q1 executed 129.5 m/s³ where the law has 80 and the
    /// limit is 120. With every phase boundary on the sample grid the feed's jerk is constant
    /// within each step. The jerk and constant-acceleration phases are rounded up to multiples
    /// of `dt`, the cruise to the shortest multiple that keeps the peak feed at most f, and the
    /// jerk is recomputed so the path length stays σ: `σ = J t_j (t_j + t_a)(2 t_j + t_a + t_c)`,
    /// peak feed `σ / (2 t_j + t_a + t_c)`. Longer ramps give a lower jerk and acceleration
    /// (`J t_j = v / (t_j + t_a)`), so every limit still holds; the law is slower by the
    /// roundings (case 1: 2.5291 → 2.55 s).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `sample_period`) when `dt` is not finite and
    /// positive.
    pub fn on_grid(&self, dt: f64) -> Result<Self, PlanError> {
        let dt = positive("sample_period", dt)?;
        // A duration already on the grid (to rounding) stays; 0 stays 0.
        let up = |t: f64| (t / dt - 1e-9).ceil().max(0.0) * dt;
        let (tj, ta) = (up(self.t_jerk).max(dt), up(self.t_const_acc));
        let tc = if self.t_cruise > 0.0 {
            up((self.sigma / self.feed - 2.0 * tj - ta).max(0.0))
        } else {
            0.0
        };
        let jerk = self.sigma / (tj * (tj + ta) * (2.0 * tj + ta + tc));
        Ok(Self::from_phases(self.sigma, self.feed, jerk, tj, ta, tc))
    }

    /// Total duration T (s).
    pub fn duration(&self) -> f64 {
        2.0 * self.t_ramp + self.t_cruise
    }

    /// The cruise speed reached (m/s): the feedrate, or less on a path too
    /// short to reach it.
    pub fn peak_feed(&self) -> f64 {
        self.peak
    }

    /// The programmed feedrate f (m/s).
    pub fn feed(&self) -> f64 {
        self.feed
    }

    /// The path length σ (m).
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Duration of the cruise at [`TimeLaw::peak_feed`] (s); 0 when the
    /// path is too short to cruise.
    pub fn cruise_duration(&self) -> f64 {
        self.t_cruise
    }

    /// The stretches of the path and the limit each phase runs at: jerk phases at the path
    /// jerk, the constant-acceleration phase at the path acceleration, the cruise at the
    /// feedrate (only when it is reached), then the mirror image.
    ///
    /// # Returns
    /// `(s_start, s_end, limit)` in path order; zero-length phases are left out and adjacent
    /// phases at the same limit merged.
    pub fn phases(&self) -> Vec<(f64, f64, &'static str)> {
        let mut ramp = vec![
            (0.0, self.s1, "path jerk"),
            (self.s1, self.s2, "path acceleration"),
            (self.s2, self.d_ramp, "path jerk"),
        ];
        ramp.retain(|p| p.1 > p.0);
        let mut out = ramp.clone();
        if self.t_cruise > 0.0 {
            out.push((self.d_ramp, self.sigma - self.d_ramp, "feedrate"));
        }
        out.extend(
            ramp.iter()
                .rev()
                .map(|&(a, b, name)| (self.sigma - b, self.sigma - a, name)),
        );
        // Adjacent phases at the same limit are one stretch (the two jerk phases of a ramp
        // that does not reach the acceleration limit, the ramps of a path too short to cruise).
        let mut merged: Vec<(f64, f64, &'static str)> = Vec::with_capacity(out.len());
        for p in out {
            match merged.last_mut() {
                Some(last) if last.2 == p.2 => last.1 = p.1,
                _ => merged.push(p),
            }
        }
        merged
    }

    /// `[s, ṡ, s̈, s⃛]` at time `t` (m, m/s, m/s², m/s³), `t` clamped to
    /// `[0, T]`. At a phase boundary the jerk is that of the phase that
    /// starts there (the last phase at T). A NaN `t` gives NaN.
    ///
    /// The second half is the mirror image of the first:
    /// `s(t) = σ - s(T - t)`, `ṡ(t) = ṡ(T - t)`, `s̈(t) = -s̈(T - t)`,
    /// `s⃛(t) = s⃛(T - t)`, so `s(T) = σ` exactly.
    ///
    /// # Performance
    /// O(1).
    pub fn eval(&self, t: f64) -> [f64; 4] {
        if t.is_nan() {
            return [f64::NAN; 4];
        }
        let total = self.duration();
        let t = t.clamp(0.0, total);
        if t < total / 2.0 {
            self.first_half(t, false)
        } else {
            let [s, v, a, j] = self.first_half(total - t, true);
            [self.sigma - s, v, -a, j]
        }
    }

    /// The first half `[0, T/2]`: ramp then cruise. At a phase boundary
    /// `tau` belongs to the phase that starts there (`ends_closed =
    /// false`) or to the one that ends there (`true`, used through the
    /// mirror, where that phase is the one starting at `T - tau`).
    fn first_half(&self, tau: f64, ends_closed: bool) -> [f64; 4] {
        let (tj, tc, jm, ap) = (self.t_jerk, self.t_const_acc, self.jerk, self.acc_peak);
        let before = |end: f64| if ends_closed { tau <= end } else { tau < end };
        if before(tj) {
            [jm * tau.powi(3) / 6.0, jm * tau * tau / 2.0, jm * tau, jm]
        } else if tc > 0.0 && before(tj + tc) {
            let d = tau - tj;
            [
                self.s1 + self.v1 * d + ap * d * d / 2.0,
                self.v1 + ap * d,
                ap,
                0.0,
            ]
        } else if before(self.t_ramp) {
            let d = tau - tj - tc;
            [
                self.s2 + self.v2 * d + ap * d * d / 2.0 - jm * d.powi(3) / 6.0,
                self.v2 + ap * d - jm * d * d / 2.0,
                ap - jm * d,
                -jm,
            ]
        } else {
            [
                self.d_ramp + self.peak * (tau - self.t_ramp),
                self.peak,
                0.0,
                0.0,
            ]
        }
    }

    /// Sample times `0, dt, 2dt, …` and `T` as the last sample; a grid
    /// sample closer than `dt·1e-6` to T is dropped (T replaces it).
    ///
    /// # Arguments
    /// * `dt` - controller sample period Δt (s), finite and > 0 (the
    ///   request's validated `sample_period`). Any other value yields just
    ///   `[0, T]`; use [`TimeLaw::checked_sample_times`] to reject it.
    ///
    /// # Performance
    /// O(T/dt) time and memory, unbounded: on request paths use
    /// [`TimeLaw::checked_sample_times`] with a sample cap.
    pub fn sample_times(&self, dt: f64) -> Vec<f64> {
        let total = self.duration();
        if !(dt.is_finite() && dt > 0.0) {
            return vec![0.0, total];
        }
        grid_times(total, dt, MAX_SAMPLES)
    }

    /// [`TimeLaw::sample_times`] with checks.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `sample_period`) when `dt` is
    /// not finite and positive or the trajectory would need more than
    /// `max_samples` samples.
    pub fn checked_sample_times(&self, dt: f64, max_samples: usize) -> Result<Vec<f64>, PlanError> {
        checked_grid_times(self.duration(), dt, max_samples)
    }
}

/// Times `0, dt, 2dt, …` below `total` (at most `max_samples` of them) and `total` as the
/// last; a grid time closer than `dt·1e-6` to `total` is dropped (`total` replaces it).
fn grid_times(total: f64, dt: f64, max_samples: usize) -> Vec<f64> {
    let count = (total / dt).floor().min(max_samples as f64);
    let mut times = Vec::with_capacity(count as usize + 2);
    let mut i = 0_u64;
    loop {
        let t = i as f64 * dt;
        if t >= total - dt * 1e-6 || times.len() >= max_samples {
            break;
        }
        times.push(t);
        i += 1;
    }
    times.push(total);
    times
}

/// The controller sample times of a trajectory of duration `total`: `0, dt, 2dt, …` and
/// `total` as the last sample (a grid time closer than `dt·1e-6` to it is dropped).
///
/// # Errors
/// [`PlanError::InvalidRequest`] (field `sample_period`) when `dt` is not finite and positive,
/// `total` is not finite and positive, or the trajectory would need more than `max_samples`
/// samples.
pub fn checked_grid_times(total: f64, dt: f64, max_samples: usize) -> Result<Vec<f64>, PlanError> {
    let dt = positive("sample_period", dt)?;
    let total = positive("trajectory duration", total)?;
    let needed = (total / dt).ceil() + 1.0;
    if needed > max_samples as f64 {
        return Err(PlanError::invalid(
            "sample_period",
            format!(
                "{dt} s over a {total:.3} s trajectory needs {needed} samples, more than {max_samples}"
            ),
        ));
    }
    Ok(grid_times(total, dt, max_samples))
}

/// Chain rule of seed 001 eq. 6/7: from the geometric derivatives
/// `[q, q_u, q_uu, q_uuu]` and the time law `[s, ṡ, s̈, s⃛]` to
/// `[q, q̇, q̈, q⃛]`, with `u̇ = ṡ/σ`, `ü = s̈/σ`, `u⃛ = s⃛/σ` (eq. 4):
///
/// * `q̇ = q_u u̇`
/// * `q̈ = q_uu u̇² + q_u ü`
/// * `q⃛ = q_uuu u̇³ + 3 q_uu u̇ ü + q_u u⃛`
///
/// # Arguments
/// * `q_u` - `[q, dq/du, d²q/du², d³q/du³]` at `u = s/σ`.
/// * `s` - `[s, ṡ, s̈, s⃛]` from [`TimeLaw::eval`].
/// * `sigma` - path length σ (m).
pub fn chain_rule(q_u: [f64; 4], s: [f64; 4], sigma: f64) -> [f64; 4] {
    let [q, qu, quu, quuu] = q_u;
    let (ud, udd, uddd) = (s[1] / sigma, s[2] / sigma, s[3] / sigma);
    [
        q,
        qu * ud,
        quu * ud * ud + qu * udd,
        quuu * ud * ud * ud + 3.0 * quu * ud * udd + qu * uddd,
    ]
}
