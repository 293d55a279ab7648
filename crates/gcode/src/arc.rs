//! Arc geometry of G2/G3: the centre from IJK offsets or a radius R, the
//! radius check and the swept angle (NISTIR 6556 section 3.5.3, "Arc at
//! Feed Rate": the centre format and the radius format).

use std::f64::consts::TAU;

use crate::motion::{ArcMove, Plane};

/// How the arc was given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ArcSpec {
    /// The centre \[m\] (already absolute).
    Center([f64; 3]),
    /// The radius \[m\] (negative: the arc of more than half a turn).
    Radius(f64),
}

/// Builds the arc from `start` to `end`.
///
/// # Arguments
/// * `plane`, `clockwise` — G17/18/19 and G2 or G3.
/// * `spec` — centre or radius.
/// * `turns` — the P word (≥ 1; 1 without P).
/// * `tolerance` — `(absolute [m], relative)`: a centre-format arc whose end
///   radius differs from its start radius by more than both is refused; a
///   radius-format arc whose chord exceeds 2|R| by more than both is
///   refused (within them the centre is the chord's midpoint).
///
/// # Errors
/// A message for the caller's [`crate::GcodeError::Arc`].
pub(crate) fn build_arc(
    start: [f64; 3],
    end: [f64; 3],
    plane: Plane,
    clockwise: bool,
    spec: ArcSpec,
    turns: u32,
    tolerance: (f64, f64),
) -> Result<ArcMove, String> {
    let [a, b, n] = plane.axes();
    let allowed = |r: f64| tolerance.0.max(tolerance.1 * r);
    let center = match spec {
        ArcSpec::Center(c) => {
            let mut c = c;
            c[n] = start[n];
            let r0 = (start[a] - c[a]).hypot(start[b] - c[b]);
            let r1 = (end[a] - c[a]).hypot(end[b] - c[b]);
            if r0 <= tolerance.0 {
                return Err(format!(
                    "centre coincides with the start point (radius {r0:.3e} m)"
                ));
            }
            if (r1 - r0).abs() > allowed(r0) {
                return Err(format!(
                    "end point is not on the circle: radius at the start {r0:.9} m, at the end \
                     {r1:.9} m (difference {:.3e} m, tolerance {:.3e} m)",
                    (r1 - r0).abs(),
                    allowed(r0)
                ));
            }
            c
        }
        ArcSpec::Radius(r) => {
            if r == 0.0 {
                return Err("radius R = 0".to_string());
            }
            let (da, db) = (end[a] - start[a], end[b] - start[b]);
            let d = da.hypot(db);
            if d <= tolerance.0 {
                return Err(
                    "radius format with the end at the start (a full circle needs I, J, K)"
                        .to_string(),
                );
            }
            let half = 0.5 * d;
            let excess = half - r.abs();
            if excess > allowed(r.abs()) {
                return Err(format!(
                    "radius |R| = {:.9} m is smaller than half the chord {half:.9} m",
                    r.abs()
                ));
            }
            // h = √(r² − (d/2)²), as |r| √((1 − q)(1 + q)) with q = (d/2)/|r|: r² overflows
            // for |R| above 1e154 m (found by fuzzing: R with 166 digits).
            let q = (half / r.abs()).min(1.0);
            let h = r.abs() * ((1.0 - q) * (1.0 + q)).max(0.0).sqrt();
            // Left normal of the chord; the short arc's centre lies left of
            // the chord for G3 and right for G2, the long arc's (R < 0) on
            // the other side.
            let (na, nb) = (-db / d, da / d);
            let side = if clockwise == (r < 0.0) { 1.0 } else { -1.0 };
            let mut c = start;
            c[a] = start[a] + 0.5 * da + side * h * na;
            c[b] = start[b] + 0.5 * db + side * h * nb;
            c
        }
    };
    let radius = (start[a] - center[a]).hypot(start[b] - center[b]);
    let a0 = (start[b] - center[b]).atan2(start[a] - center[a]);
    let a1 = (end[b] - center[b]).atan2(end[a] - center[a]);
    let mut sweep = a1 - a0;
    // Same point in the plane: a full turn (centre format only, above).
    let same = (end[a] - start[a]).hypot(end[b] - start[b]) <= tolerance.0;
    if clockwise {
        while sweep >= 0.0 {
            sweep -= TAU;
        }
        while sweep < -TAU {
            sweep += TAU;
        }
        if same {
            sweep = -TAU;
        }
    } else {
        while sweep <= 0.0 {
            sweep += TAU;
        }
        while sweep > TAU {
            sweep -= TAU;
        }
        if same {
            sweep = TAU;
        }
    }
    let extra_turns = turns.saturating_sub(1);
    sweep += f64::from(extra_turns) * if clockwise { -TAU } else { TAU };
    Ok(ArcMove {
        start,
        end,
        center,
        plane,
        clockwise,
        extra_turns,
        radius,
        sweep,
    })
}
