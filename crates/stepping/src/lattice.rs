//! The exact motion lattice of one axis under per-period jerk decisions.
//!
//! Seed 002 (eq. 1, section 2.A): every period Δt the axis accelerates,
//! keeps its motion or decelerates, and position, velocity and acceleration
//! follow from the jerk. kerf reads the three decisions as the jerk
//! `u·J`, `u ∈ {+1, 0, −1}`, held over the period. The exact integration of
//! a constant jerk over Δt,
//!
//! ```text
//! a₁ = a + u J Δt
//! v₁ = v + a Δt + u J Δt²/2
//! p₁ = p + v Δt + a Δt²/2 + u J Δt³/6
//! ```
//!
//! keeps every state on a lattice: `a = m·J Δt`, `v = n·J Δt²/2`,
//! `p = p₀ + q·J Δt³/6` with integers
//!
//! ```text
//! m₁ = m + u,   n₁ = n + 2m + u,   q₁ = q + 3n + 3m + u.
//! ```
//!
//! kerf steps the integers, so a run is exact and reproducible: no rounding
//! accumulates over thousands of periods, a state at rest is exactly at
//! rest, and equal states compare equal. `n − m²` keeps its parity, so from
//! rest every state with `m = 0` has an even `n`.

use serde::{Deserialize, Serialize};

use crate::{
    error::StepError,
    limits::{check_period, Limits},
};

/// One decision of a period (seed 002 section 2.A).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Action {
    /// Jerk +J over the period.
    Accelerate,
    /// Jerk 0: acceleration unchanged.
    Keep,
    /// Jerk −J over the period.
    Decelerate,
}

impl Action {
    /// The three actions, in the order of the networks' outputs.
    pub const ALL: [Action; 3] = [Action::Accelerate, Action::Keep, Action::Decelerate];

    /// The jerk sign `u`.
    pub fn sign(self) -> i64 {
        match self {
            Action::Accelerate => 1,
            Action::Keep => 0,
            Action::Decelerate => -1,
        }
    }

    /// The action of jerk sign `u` (`None` unless `u ∈ {−1, 0, 1}`).
    pub fn from_sign(u: i64) -> Option<Action> {
        match u {
            1 => Some(Action::Accelerate),
            0 => Some(Action::Keep),
            -1 => Some(Action::Decelerate),
            _ => None,
        }
    }

    /// Index in [`Action::ALL`].
    pub fn index(self) -> usize {
        match self {
            Action::Accelerate => 0,
            Action::Keep => 1,
            Action::Decelerate => 2,
        }
    }

    /// Name as printed and parsed ("accelerate", "keep", "decelerate").
    pub fn name(self) -> &'static str {
        match self {
            Action::Accelerate => "accelerate",
            Action::Keep => "keep",
            Action::Decelerate => "decelerate",
        }
    }
}

/// A lattice state: position `q`, velocity `n`, acceleration `m` in lattice
/// units ([`Lattice`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub struct State {
    /// Position index: `p = p₀ + q·J Δt³/6`.
    pub q: i64,
    /// Velocity index: `v = n·J Δt²/2`.
    pub n: i64,
    /// Acceleration index: `a = m·J Δt`.
    pub m: i64,
}

impl State {
    /// At rest at the origin.
    pub const REST: State = State { q: 0, n: 0, m: 0 };

    /// The state one period later under jerk sign `u` (exact).
    #[inline]
    pub fn step(self, u: i64) -> State {
        State {
            q: self.q + 3 * self.n + 3 * self.m + u,
            n: self.n + 2 * self.m + u,
            m: self.m + u,
        }
    }

    /// The velocity index reached by bringing the acceleration to zero as
    /// fast as the jerk allows: `n + m·|m|` (sum of `2m_k ∓ 1` over the ramp).
    #[inline]
    pub fn settled_velocity(self) -> i64 {
        self.n + self.m * self.m.abs()
    }

    /// At rest (`n = m = 0`).
    pub fn at_rest(self) -> bool {
        self.n == 0 && self.m == 0
    }
}

/// Units and bounds of one axis's lattice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Control period Δt [s].
    pub period: f64,
    /// The limits it was built from.
    pub limits: Limits,
    /// Position unit J Δt³/6.
    pub unit_p: f64,
    /// Velocity unit J Δt²/2.
    pub unit_v: f64,
    /// Acceleration unit J Δt.
    pub unit_a: f64,
    /// Largest velocity index: `⌊V / unit_v⌋`, even (so it can be held).
    pub max_n: i64,
    /// Largest |acceleration index|: `⌊A / unit_a⌋`.
    pub max_m: i64,
}

/// Relative slack of the floors, so that a limit that is an exact multiple
/// of its unit in decimal (A = 2 m/s², J Δt = 0.02 m/s²) keeps its last
/// step despite the binary rounding of the quotient.
const FLOOR_SLACK: f64 = 1e-9;

/// Largest velocity index kerf accepts (position steps stay far from i64
/// overflow over 10¹² periods).
const MAX_INDEX: i64 = 1 << 40;

impl Lattice {
    /// The lattice of `limits` at `period`.
    ///
    /// # Errors
    /// [`StepError::InvalidParameter`] for bad limits or period, or when the
    /// acceleration limit is below one jerk step (`A < J Δt`) or the
    /// velocity limit below one velocity step (`V < J Δt²`): such an axis
    /// could not move.
    pub fn new(limits: Limits, period: f64) -> Result<Self, StepError> {
        limits.validate()?;
        check_period(period)?;
        let unit_a = limits.jerk * period;
        let unit_v = unit_a * period / 2.0;
        let unit_p = unit_v * period / 3.0;
        let max_m = (limits.acceleration / unit_a * (1.0 + FLOOR_SLACK)).floor();
        if max_m < 1.0 {
            return Err(StepError::InvalidParameter {
                name: "acceleration limit".to_string(),
                value: limits.acceleration,
                reason: format!(
                    "below one jerk step J·Δt = {unit_a} (jerk {} × period {period} s)",
                    limits.jerk
                ),
            });
        }
        let n = (limits.velocity / unit_v * (1.0 + FLOOR_SLACK)).floor();
        let max_n = if n >= MAX_INDEX as f64 {
            MAX_INDEX
        } else {
            (n as i64) & !1
        };
        if max_n < 2 {
            return Err(StepError::InvalidParameter {
                name: "velocity limit".to_string(),
                value: limits.velocity,
                reason: format!("below one velocity step J·Δt² = {}", 2.0 * unit_v),
            });
        }
        Ok(Self {
            period,
            limits,
            unit_p,
            unit_v,
            unit_a,
            max_n,
            max_m: (max_m as i64).min(MAX_INDEX),
        })
    }

    /// Whether `u` is allowed at `s`: the next state keeps |a| ≤ A and
    /// 0 ≤ v ≤ V, and can still settle its acceleration inside the velocity
    /// bounds (0 ≤ `settled_velocity` ≤ V).
    #[inline]
    pub fn allows(&self, s: State, u: i64) -> bool {
        let t = s.step(u);
        t.m.abs() <= self.max_m
            && (0..=self.max_n).contains(&t.n)
            && (0..=self.max_n).contains(&t.settled_velocity())
    }

    /// Position [m or rad] of `s` relative to the origin.
    pub fn position(&self, s: State) -> f64 {
        s.q as f64 * self.unit_p
    }

    /// Velocity of `s`.
    pub fn velocity(&self, s: State) -> f64 {
        s.n as f64 * self.unit_v
    }

    /// Acceleration of `s`.
    pub fn acceleration(&self, s: State) -> f64 {
        s.m as f64 * self.unit_a
    }

    /// Jerk of sign `u`.
    pub fn jerk(&self, u: i64) -> f64 {
        u as f64 * self.limits.jerk
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_steps_equal_the_exact_integration() {
        let lat = Lattice::new(Limits::new(0.1, 2.0, 20.0), 0.002).unwrap();
        let (mut p, mut v, mut a) = (0.0f64, 0.0f64, 0.0f64);
        let mut s = State::REST;
        let dt = lat.period;
        for (k, u) in [1, 1, 0, 1, -1, 0, -1, -1, 1, 0]
            .iter()
            .cycle()
            .take(60)
            .enumerate()
        {
            let j = lat.jerk(*u);
            p += v * dt + a * dt * dt / 2.0 + j * dt.powi(3) / 6.0;
            v += a * dt + j * dt * dt / 2.0;
            a += j * dt;
            s = s.step(*u);
            assert!((lat.position(s) - p).abs() < 1e-15, "step {k}");
            assert!((lat.velocity(s) - v).abs() < 1e-13);
            assert!((lat.acceleration(s) - a).abs() < 1e-12);
        }
    }

    #[test]
    fn settled_velocity_is_where_a_fastest_ramp_ends() {
        for m in -6..=6 {
            let mut s = State { q: 0, n: 100, m };
            let want = s.settled_velocity();
            while s.m != 0 {
                s = s.step(-s.m.signum());
            }
            assert_eq!(s.n, want, "m = {m}");
        }
    }

    #[test]
    fn limits_below_one_step_are_refused() {
        assert!(Lattice::new(Limits::new(0.1, 0.01, 20.0), 0.002).is_err());
        assert!(Lattice::new(Limits::new(1e-6, 2.0, 20.0), 0.002).is_err());
        assert!(Lattice::new(Limits::new(0.1, 2.0, f64::NAN), 0.002).is_err());
        let lat = Lattice::new(Limits::new(0.1, 2.0, 20.0), 0.002).unwrap();
        assert_eq!(lat.max_m, 50);
        assert!(
            lat.max_n % 2 == 0
                && lat.velocity(State {
                    q: 0,
                    n: lat.max_n,
                    m: 0
                }) <= 0.1
        );
    }
}
