//! Jerk-limited speed changes along a path: the symmetric S-curve from v₀ to
//! v₁ with zero acceleration at both ends, at most A in acceleration and J in
//! jerk: the jerk-limited S-shape acceleration/deceleration that seed 000
//! uses for its baselines (its reference Lin et al., 2007), written as
//! phases of constant jerk.

/// A piece of motion with constant jerk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phase {
    /// Duration \[s\].
    pub duration: f64,
    /// Jerk \[m/s³\].
    pub jerk: f64,
}

/// Time of the S-curve from v₀ to v₁ \[s\]: |Δv|/A + A/J when the
/// acceleration reaches A (|Δv| ≥ A²/J), else 2 √(|Δv|/J).
pub fn scurve_time(v0: f64, v1: f64, a: f64, j: f64) -> f64 {
    let dv = (v1 - v0).abs();
    if dv >= a * a / j {
        dv / a + a / j
    } else {
        2.0 * (dv / j).sqrt()
    }
}

/// Distance of the S-curve from v₀ to v₁ \[m\]: (v₀ + v₁)/2 times its time
/// (its acceleration profile is symmetric in time).
pub fn scurve_distance(v0: f64, v1: f64, a: f64, j: f64) -> f64 {
    0.5 * (v0 + v1) * scurve_time(v0, v1, a, j)
}

/// The phases of the S-curve from v₀ to v₁ (empty when equal).
pub fn scurve_phases(v0: f64, v1: f64, a: f64, j: f64) -> Vec<Phase> {
    let dv = (v1 - v0).abs();
    if dv == 0.0 {
        return Vec::new();
    }
    let sign = if v1 > v0 { 1.0 } else { -1.0 };
    if dv >= a * a / j {
        let tj = a / j;
        vec![
            Phase {
                duration: tj,
                jerk: sign * j,
            },
            Phase {
                duration: dv / a - tj,
                jerk: 0.0,
            },
            Phase {
                duration: tj,
                jerk: -sign * j,
            },
        ]
    } else {
        let t = (dv / j).sqrt();
        vec![
            Phase {
                duration: t,
                jerk: sign * j,
            },
            Phase {
                duration: t,
                jerk: -sign * j,
            },
        ]
    }
}

/// The highest v₁ ≥ v₀ reachable by one S-curve within `distance` (and at
/// most `cap`), by bisection on [`scurve_distance`] (increasing in v₁).
pub fn reachable(v0: f64, distance: f64, cap: f64, a: f64, j: f64) -> f64 {
    if scurve_distance(v0, cap, a, j) <= distance {
        return cap;
    }
    let (mut lo, mut hi) = (v0, cap);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if scurve_distance(v0, mid, a, j) <= distance {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The highest v₁ ≥ v₀ (at most `cap`) whose S-curve from v₀ fits in
/// `distance`, in closed form: the inverse of [`scurve_distance`] in v₁.
/// Below the knee (Δv < A²/J), with x = √Δv the distance
/// (2v₀ + x²) x / √J is a depressed cubic x³ + 2v₀ x = d √J (one real root,
/// by Cardano's formula, polished by Newton from above); above it,
/// d = (v₀ + Δv/2)(Δv/A + A/J) is a quadratic in Δv. The result is stepped
/// down until its S-curve fits (as [`reachable`], which bisects instead;
/// the two agree to 1e-9, `tests/feed_optimal.rs`).
pub fn reachable_closed_form(v0: f64, distance: f64, cap: f64, a: f64, j: f64) -> f64 {
    if cap <= v0 || scurve_distance(v0, cap, a, j) <= distance {
        return cap.max(v0);
    }
    let knee = a * a / j;
    let dv = if distance <= scurve_distance(v0, v0 + knee, a, j) {
        let q = distance * j.sqrt();
        let p = 2.0 * v0;
        // Cardano without cancellation: x = c − p/(3c), c = ∛(q/2 + √(q²/4 + p³/27)),
        // nudged above the root (and within the upper bound min(∛q, q/p)).
        let c = (0.5 * q + (0.25 * q * q + p * p * p / 27.0).sqrt()).cbrt();
        let mut x = if c > 0.0 { c - p / (3.0 * c) } else { 0.0 };
        x = (x * (1.0 + 1e-12)).min(q.cbrt());
        if p > 0.0 {
            x = x.min(q / p);
        }
        // Convex and increasing: Newton from above decreases to the root.
        for _ in 0..50 {
            let f = x * x * x + p * x - q;
            let df = 3.0 * x * x + p;
            if f <= 0.0 || df <= 0.0 {
                break;
            }
            let next = x - f / df;
            if next >= x {
                break;
            }
            x = next;
        }
        x * x
    } else {
        let qa = 0.5 / a;
        let qb = v0 / a + 0.5 * a / j;
        let qc = v0 * a / j - distance;
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        // The root with the larger sign, without cancellation: 2c / (−b − √disc).
        (-2.0 * qc) / (qb + disc)
    };
    let mut v1 = (v0 + dv.max(0.0)).min(cap);
    // Rounding (v₀ + Δv loses Δv's low bits): step down by doubling steps.
    let mut step = v1 * f64::EPSILON;
    while v1 > v0 && scurve_distance(v0, v1, a, j) > distance {
        v1 = (v1 - step).max(v0);
        step *= 2.0;
    }
    v1
}
