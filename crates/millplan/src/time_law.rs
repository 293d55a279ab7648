//! The executed time law s(t) of a milling plan: how far along the path the
//! tool is at each time (issue 13, item 1).
//!
//! # The law
//! ṡ = f(s) · R(t) / c(s), with
//! * f(s) — the planned feed, smooth along the path
//!   ([`crate::spline1d::StepProfile`] through the segments' feeds at their
//!   midpoints);
//! * c(s) ≥ 1 — the slowdown field ([`crate::slowdown::SlowdownField`]),
//!   raised where the joints' limits need it;
//! * R(t) = S(t/T_r) · S((T − t)/T_r) — the start from rest and the stop at
//!   rest over the ramp time T_r, S the smootherstep
//!   ([`crate::spline1d::smootherstep`]): R, R' and R'' vanish at t = 0 and
//!   t = T, so the tool starts and stops with zero speed, acceleration and
//!   jerk along the path.
//!
//! # Construction
//! The total time T is not known before the law is integrated. The start
//! half is integrated forward from (t = 0, s = 0) with R = S(t/T_r), the end
//! half backward from s = L with R = S(σ/T_r) (σ the time before the end),
//! both by the classical fourth-order Runge–Kutta method on a fixed step,
//! until they reach the middle of the path s_J = L/2. There both ramps must
//! be over (R = 1; else [`TimeLaw::new`] returns `None` and the caller
//! shortens T_r), so the two halves solve the same autonomous equation
//! ds/dt = f/c and join with a continuous speed and its derivatives; the
//! last partial step to s_J is the quadrature t = ∫ c/f ds (Simpson).
//!
//! # Exact uniform slowdown
//! Multiplying c and T_r by k maps the law onto t → k t: every joint
//! velocity is divided by k, acceleration by k², jerk by k³ (used by
//! [`crate::timing`] as its last resort).

use crate::slowdown::SlowdownField;
use crate::spline1d::{smootherstep, StepProfile};

/// The state of the tool along the path at one time.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathState {
    /// Time from the start \[s\].
    pub time: f64,
    /// Arc length \[m\].
    pub s: f64,
    /// ṡ \[m/s\].
    pub speed: f64,
    /// s̈ \[m/s²\].
    pub acceleration: f64,
}

/// s(t) of the module documentation, tabulated.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeLaw {
    feed: StepProfile,
    slowdown: SlowdownField,
    length: f64,
    ramp_time: f64,
    end: f64,
    t: Vec<f64>,
    s: Vec<f64>,
    sd: Vec<f64>,
}

/// Most integration steps of one half (a law that needs more is refused).
const MAX_STEPS: usize = 4_000_000;

impl TimeLaw {
    /// Integrates the law (module documentation).
    ///
    /// # Arguments
    /// * `feed` — f(s), > 0 on [0, `length`].
    /// * `slowdown` — c(s) on [0, `length`].
    /// * `length` — the path length L \[m\], > 0.
    /// * `ramp_time` — T_r \[s\], > 0.
    /// * `step` — the Runge–Kutta step \[s\], > 0.
    ///
    /// # Returns
    /// `None` when a ramp is not over at the middle of the path (shorten
    /// `ramp_time`), when an argument is not positive and finite, or when a
    /// half needs more than 4 000 000 steps.
    pub fn new(
        feed: &StepProfile,
        slowdown: &SlowdownField,
        length: f64,
        ramp_time: f64,
        step: f64,
    ) -> Option<Self> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !(positive(length) && positive(ramp_time) && positive(step)) {
            return None;
        }
        let join = 0.5 * length;
        // f/c along each half, the feed's interval kept from one call to the next.
        let rate = |hint: &mut usize, s: f64| feed.eval_near(s, hint).value / slowdown.eval(s).0;
        let (mut ahead, mut behind) = (0, 0);
        let forward = half(
            &mut |s| rate(&mut ahead, s),
            0.0,
            join,
            ramp_time,
            step,
            1.0,
        )?;
        let backward = half(
            &mut |s| rate(&mut behind, s),
            length,
            join,
            ramp_time,
            step,
            -1.0,
        )?;
        let (tf, sf, vf) = forward;
        let (tb, sb, vb) = backward;
        let (Some(&t_join), Some(&sigma_join)) = (tf.last(), tb.last()) else {
            return None;
        };
        let end = t_join + sigma_join;
        let mut t = tf;
        let mut s = sf;
        let mut sd = vf;
        for k in (0..tb.len() - 1).rev() {
            t.push(end - tb[k]);
            s.push(sb[k]);
            sd.push(vb[k]);
        }
        Some(Self {
            feed: feed.clone(),
            slowdown: slowdown.clone(),
            length,
            ramp_time,
            end,
            t,
            s,
            sd,
        })
    }

    /// The total time T \[s\].
    pub fn duration(&self) -> f64 {
        self.end
    }

    /// The ramp time T_r \[s\].
    pub fn ramp_time(&self) -> f64 {
        self.ramp_time
    }

    /// The length L the law runs over \[m\].
    pub fn length(&self) -> f64 {
        self.length
    }

    /// R(t) and dR/dt.
    fn ramp(&self, t: f64) -> (f64, f64) {
        let (a, da, _) = smootherstep(t / self.ramp_time);
        let (b, db, _) = smootherstep((self.end - t) / self.ramp_time);
        (a * b, (da * b - a * db) / self.ramp_time)
    }

    /// ṡ and s̈ at (t, s) from the law itself.
    fn derivatives(&self, t: f64, s: f64) -> (f64, f64) {
        let f = self.feed.eval(s);
        let (c, dc, _) = self.slowdown.eval(s);
        let (r, dr) = self.ramp(t);
        let speed = f.value * r / c;
        // d/dt (f R / c) = f' ṡ R/c + f R'/c − f R c' ṡ / c².
        let acceleration =
            f.d1 * speed * r / c + f.value * dr / c - f.value * r * dc * speed / (c * c);
        (speed, acceleration)
    }

    /// The state at time `t` (clamped to [0, T]).
    pub fn at_time(&self, t: f64) -> PathState {
        let t = t.clamp(0.0, self.end);
        let i = self
            .t
            .partition_point(|x| *x <= t)
            .saturating_sub(1)
            .min(self.t.len() - 2);
        let h = self.t[i + 1] - self.t[i];
        let x = (t - self.t[i]) / h;
        // Cubic Hermite on (s, ṡ) of the Runge–Kutta nodes.
        let (x2, x3) = (x * x, x * x * x);
        let s = (2.0 * x3 - 3.0 * x2 + 1.0) * self.s[i]
            + (x3 - 2.0 * x2 + x) * h * self.sd[i]
            + (-2.0 * x3 + 3.0 * x2) * self.s[i + 1]
            + (x3 - x2) * h * self.sd[i + 1];
        let s = s.clamp(0.0, self.length);
        let (speed, acceleration) = self.derivatives(t, s);
        PathState {
            time: t,
            s,
            speed,
            acceleration,
        }
    }

    /// The state where the tool is at arc length `s` (clamped to [0, L]).
    pub fn at_arc_length(&self, s: f64) -> PathState {
        let s = s.clamp(0.0, self.length);
        if s <= 0.0 {
            return self.at_time(0.0);
        }
        if s >= self.length {
            return self.at_time(self.end);
        }
        let i = self
            .s
            .partition_point(|x| *x <= s)
            .saturating_sub(1)
            .min(self.s.len() - 2);
        // Safeguarded Newton on the monotone Hermite piece.
        let (mut lo, mut hi) = (self.t[i], self.t[i + 1]);
        let mut t = lo + (hi - lo) * (s - self.s[i]) / (self.s[i + 1] - self.s[i]).max(1e-300);
        for _ in 0..60 {
            let p = self.at_time(t);
            let f = p.s - s;
            if f.abs() <= 1e-13 * self.length {
                break;
            }
            if f > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            let newton = t - f / p.speed;
            t = if p.speed > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= 1e-15 * self.end.max(1.0) {
                break;
            }
        }
        self.at_time(t)
    }
}

/// One half of the law: times, arc lengths and speeds from `from` to
/// `join` (direction `dir`), the last node exactly at `join`.
type Half = (Vec<f64>, Vec<f64>, Vec<f64>);

fn half(
    rate: &mut dyn FnMut(f64) -> f64,
    from: f64,
    join: f64,
    ramp_time: f64,
    step: f64,
    dir: f64,
) -> Option<Half> {
    let mut rhs = |t: f64, s: f64| dir * rate(s) * smootherstep(t / ramp_time).0;
    let (mut t, mut s) = (0.0, from);
    let (mut ts, mut ss, mut vs) = (vec![t], vec![s], vec![0.0]);
    for _ in 0..MAX_STEPS {
        let k1 = rhs(t, s);
        let k2 = rhs(t + 0.5 * step, s + 0.5 * step * k1);
        let k3 = rhs(t + 0.5 * step, s + 0.5 * step * k2);
        let k4 = rhs(t + step, s + step * k3);
        let next = s + step / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        if !next.is_finite() {
            return None;
        }
        if (next - join) * dir >= 0.0 {
            // The last partial step: R = 1 required, t = ∫ c/f ds (Simpson).
            if t < ramp_time {
                return None;
            }
            let n = 8;
            let h = (join - s) / n as f64;
            let mut sum = 0.0;
            for k in 0..=n {
                let w = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                sum += w / rate(s + k as f64 * h);
            }
            let dt = (h * sum / 3.0).abs();
            ts.push(t + dt);
            ss.push(join);
            vs.push(rate(join));
            return Some((ts, ss, vs));
        }
        t += step;
        s = next;
        ts.push(t);
        ss.push(s);
        vs.push(rhs(t, s).abs());
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_feed_law() {
        let feed = StepProfile::new("f", &[0.0, 1.0], &[0.05, 0.05]).unwrap();
        let c = SlowdownField::new(1.0, 10).unwrap();
        let law = TimeLaw::new(&feed, &c, 1.0, 0.5, 0.004).unwrap();
        // Each ramp loses half its time: T = L/f + T_r.
        assert!(
            (law.duration() - (20.0 + 0.5)).abs() < 1e-6,
            "{}",
            law.duration()
        );
        let start = law.at_time(0.0);
        assert_eq!((start.s, start.speed, start.acceleration), (0.0, 0.0, 0.0));
        let mid = law.at_time(10.0);
        assert!((mid.speed - 0.05).abs() < 1e-12 && mid.acceleration.abs() < 1e-12);
        let end = law.at_time(law.duration());
        assert!((end.s - 1.0).abs() < 1e-12 && end.speed.abs() < 1e-12);
        let back = law.at_arc_length(0.3217);
        assert!((back.s - 0.3217).abs() < 1e-12);
        assert!((law.at_time(back.time).s - 0.3217).abs() < 1e-12);
        // A ramp longer than half the path is refused.
        assert!(TimeLaw::new(&feed, &c, 1.0, 30.0, 0.004).is_none());
    }
}
