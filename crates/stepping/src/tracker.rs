//! The exact velocity tracker: the jerk decision that brings an axis to a
//! target velocity, with zero acceleration, as fast as the jerk and
//! acceleration limits allow, without overshoot.
//!
//! With `s(n, m) = n + m|m|` the velocity at which the acceleration can be
//! settled ([`State::settled_velocity`]), the tracker takes the most
//! aggressive sign `u` toward the target such that the next state can
//! still settle on the correct side of it. One of the three signs always
//! qualifies: the ramp of `a` toward zero keeps `s` unchanged. An even
//! target (every velocity at `m = 0` reachable from rest is even,
//! [`crate::lattice`]) is then reached exactly and held.
//!
//! This is the tail policy of kerf's reading of RPRO ([`crate::rpro`]):
//! "track a velocity" families are what its look-ahead tries.

use crate::lattice::{Lattice, State};

/// Jerk sign that moves `s` toward velocity index `target` (even, within
/// `[0, lattice.max_n]`).
///
/// # Returns
/// A sign in {−1, 0, 1} that [`Lattice::allows`] at `s`, provided `s` is
/// a state of the lattice from which the acceleration can be settled
/// inside the velocity bounds.
///
/// # Performance
/// O(1).
#[inline]
pub fn track(lattice: &Lattice, s: State, target: i64) -> i64 {
    let settle = s.settled_velocity();
    let order: [i64; 3] = if settle <= target {
        [1, 0, -1]
    } else {
        [-1, 0, 1]
    };
    for u in order {
        let t = s.step(u);
        if t.m.abs() > lattice.max_m || t.n < 0 || t.n > lattice.max_n {
            continue;
        }
        let ts = t.settled_velocity();
        let ok = if settle <= target {
            ts <= target
        } else {
            ts >= target
        };
        if ok {
            return u;
        }
    }
    // Unreachable for settle-able states (module documentation); settle the
    // acceleration as the safe default.
    -s.m.signum()
}

/// Position change and number of periods of the tracker's stop from `s`
/// (tracking velocity 0 until at rest).
///
/// # Returns
/// `(Δq, periods)`; `None` if `s` cannot settle at rest within
/// `max_periods`.
///
/// # Performance
/// O(periods) ≤ O(max_m + max_n / max_m).
pub fn stop(lattice: &Lattice, s: State, max_periods: usize) -> Option<(i64, usize)> {
    let mut t = s;
    for k in 0..=max_periods {
        if t.at_rest() {
            return Some((t.q - s.q, k));
        }
        t = t.step(track(lattice, t, 0));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::Limits;

    #[test]
    fn every_even_target_is_reached_exactly_and_held() {
        // Starts reachable from rest: n − m² even (module `lattice`).
        let lat = Lattice::new(Limits::new(0.1, 2.0, 20.0), 0.002).unwrap();
        for target in (0..=lat.max_n)
            .step_by(2)
            .filter(|t| t % 94 == 0 || *t < 12)
        {
            for start in [
                State::REST,
                State {
                    q: 0,
                    n: lat.max_n,
                    m: 0,
                },
                State { q: 0, n: 200, m: 6 },
            ] {
                if !lat.allows(start, 0) {
                    continue;
                }
                let mut s = start;
                let mut reached = None;
                for k in 0..20_000 {
                    let u = track(&lat, s, target);
                    assert!(lat.allows(s, u), "target {target} from {start:?}, step {k}");
                    s = s.step(u);
                    if s.n == target && s.m == 0 {
                        reached = Some(k);
                        break;
                    }
                }
                assert!(reached.is_some(), "target {target} from {start:?}: {s:?}");
                assert_eq!(s.step(track(&lat, s, target)).n, target);
            }
        }
    }

    #[test]
    fn stop_ends_at_rest_within_the_limits() {
        let lat = Lattice::new(Limits::new(0.1, 2.0, 20.0), 0.002).unwrap();
        let s = State {
            q: 0,
            n: lat.max_n,
            m: 0,
        };
        let (dq, k) = stop(&lat, s, 10_000).unwrap();
        assert!(dq > 0 && k > 0);
        // v²/(2A) + v·A/(2J) bounds the jerk-limited stop from v at a = 0.
        let v = lat.velocity(s);
        let bound = v * v / (2.0 * 2.0) + v * 2.0 / (2.0 * 20.0);
        assert!(
            lat.unit_p * dq as f64 <= bound * 1.05,
            "{} > {bound}",
            lat.unit_p * dq as f64
        );
    }
}
