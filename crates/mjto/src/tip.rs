//! The tool tip's velocity: seed 001 eq. 2, `C = M + q6 O(q4, q5)`, differentiated.
//!
//! The feed is the speed of the tool tip along the cut. The time law moves the path parameter
//! s at ṡ, and the tip moves at `|dC/ds| ṡ`: the M-path spline (eq. 62) reproduces the CL path
//! to its fit error, not its arc length exactly, so `|dC/ds|` differs from 1 where the path
//! turns tightly (measured: up to 1.9 % on a 15 mm slot end). The planner bounds the tip's
//! speed, not only ṡ (kerf, issue 16).

use nalgebra::Vector3;

/// `dC = dM + dq6 O + q6 (∂O/∂q4 dq4 + ∂O/∂q5 dq5)` for joint rates `dq` (per second, or per
/// metre of path for derivatives in s), with `O = (c4 s5, s4 s5, c5)` (eq. 2).
pub fn tip_rate(q: &[f64; 6], dq: &[f64; 6]) -> Vector3<f64> {
    let (s4, c4) = q[3].sin_cos();
    let (s5, c5) = q[4].sin_cos();
    let o = Vector3::new(c4 * s5, s4 * s5, c5);
    let o_q4 = Vector3::new(-s4 * s5, c4 * s5, 0.0);
    let o_q5 = Vector3::new(c4 * c5, s4 * c5, -s5);
    Vector3::new(dq[0], dq[1], dq[2]) + dq[5] * o + q[5] * (dq[3] * o_q4 + dq[4] * o_q5)
}

/// The speed of the tool tip (m/s) at joints `q` moving at `qd`.
pub fn tip_speed(q: &[f64; 6], qd: &[f64; 6]) -> f64 {
    tip_rate(q, qd).norm()
}
