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
