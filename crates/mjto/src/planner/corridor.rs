//! The lead/tilt allowance as a corridor of the q5 QP along the whole cut (kerf, issue 16
//! item 3; `options.orientation_corridor: allowance`).
//!
//! Measured on the tube saddle r/R 0.4 at 10 m/min (a closed loop that starts and ends where
//! the tool axis passes the vertical, dq5/ds ≈ 20 rad/m there), seed 001's q5 QP peaked at
//! 8.95 of 10 m/min (BENCHMARKS.md) because of two constraints:
//! * eq. 45's zero end slopes `q_u(0) = q_u(1) = 0`: q5 starts flat and must catch up with
//!   the tilt, 323 rad/s³ of jerk at both ends at the constant-feed bounds (Table 2: 200), so
//!   the QP is infeasible at f and its bounds are relaxed to ~8.5 m/min;
//! * the allowance is only seen at the RTOs (eq. 57-60): between them the spline left the 10°
//!   tilt allowance, the dense check inserted an RTO, and the next QP relaxed to 7.15 m/min.
//!
//! So, with `allowance`:
//! * with the time-optimal law a rotary QP infeasible at f with zero end slopes gets free ones
//!   ([`RotaryQp::free_end_slopes`]): from rest the joint velocity is zero whatever `q_u` is,
//!   and TOPP3 limits the ramps by the joint jerk `q_u s⃛ / σ` (eq. 7);
//! * the q5 QP gets, at the CL points between the RTOs where it would leave the allowance, the
//!   interval of q5 whose tool axis (with the q4 the q4 QP chose) is inside it (active sets,
//!   [`Context::q5_in_allowance`]): the QP itself chooses the least-jerk tilt inside the
//!   lead/tilt-feasible set along the whole cut, e.g. a fraction of the nominal tilt, as a
//!   hand-made plan does.
//!
//! # The interval
//!
//! With q4 fixed, `O(q5) = cos q5 ẑ + sin q5 e`, `e = (cos q4, sin q4, 0)` (eq. 2): a great
//! circle. The allowance `|lead| ≤ φ_max, |tilt| ≤ ϕ_max` is the intersection of four
//! half-spaces through the origin (`O·t ≤ tan φ_max O·n`, ...), a convex spherical polygon
//! around the nominal axis n; its intersection with a great circle is one arc. So the
//! interval is found by bisection outward from the point of the circle nearest to n,
//! `q5* = atan2(n·e, n·ẑ)`, each side to [`BISECTION_TOLERANCE`].

use kerf_bspline::BSpline;
use nalgebra::Vector3;

use super::feed::rotary_coefficients;
use super::{Context, RtoState};
use crate::kinematics::tool_axis;
use crate::optimal_feed::FeedMode;
use crate::request::OrientationCorridor;
use crate::rotary::RotaryQp;
use crate::PlanError;

/// Fraction of the lead/tilt allowance the corridor gives the q5 QP (kerf). The corridor
/// holds at the CL points only; the spline between them moves by O(h²·q5'') more, and the
/// dense check of every Δt sample stays the arbiter (a sample outside the allowance still
/// inserts an RTO there).
pub const CORRIDOR_FRACTION: f64 = 0.98;

/// Most active-set rounds of the q5 corridor per QP ([`Context::q5_in_allowance`]).
pub const CORRIDOR_ROUNDS: usize = 6;

/// CL points on each side of a point outside the allowance that get a corridor row with it
/// (the solution moves its excess to the neighbours otherwise, one round each).
pub const CORRIDOR_PAD: usize = 3;

/// Width of the bracket at which the bisection of an interval end stops (rad).
pub const BISECTION_TOLERANCE: f64 = 1e-9;

/// The interval of q5 whose tool axis `tool_axis(q4, q5)` is inside the allowance.
///
/// # Arguments
/// * `q4` - the C-axis angle (rad).
/// * `n` - the nominal unit tool axis.
/// * `inside` - whether a tool axis is inside the allowance (convex around `n`, see the
///   module documentation).
/// * `stroke` - the q5 stroke `(min, max)` (rad).
///
/// # Returns
/// `Some((lo, hi))` inside the stroke, or `None` when no q5 with this q4 is inside the
/// allowance (or within the stroke).
pub fn tilt_interval(
    q4: f64,
    n: &Vector3<f64>,
    inside: &dyn Fn(&Vector3<f64>) -> bool,
    stroke: (f64, f64),
) -> Option<(f64, f64)> {
    let e = Vector3::new(q4.cos(), q4.sin(), 0.0);
    let centre = n.dot(&e).atan2(n.z);
    let ok = |q5: f64| inside(&tool_axis(q4, q5));
    if !centre.is_finite() || !ok(centre) {
        return None;
    }
    // Past a quarter turn from the centre O·n ≤ 0: outside any allowance below π/2.
    let end = |direction: f64| {
        let (mut good, mut bad) = (centre, centre + direction * std::f64::consts::FRAC_PI_2);
        if ok(bad) {
            return bad;
        }
        while (bad - good).abs() > BISECTION_TOLERANCE {
            let mid = 0.5 * (good + bad);
            if ok(mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        good
    };
    let (lo, hi) = (end(-1.0).max(stroke.0), end(1.0).min(stroke.1));
    (lo <= hi).then_some((lo, hi))
}

impl Context<'_> {
    /// Whether the request asks for the allowance corridor (`options.orientation_corridor`).
    pub(super) fn corridor_on(&self) -> bool {
        self.request.options.orientation_corridor == OrientationCorridor::Allowance
    }

    /// The first solve of one rotary QP under `options.orientation_corridor`: independent of
    /// the other axis, so q4's and q5's run side by side ([`super::feed::rotary_pair`]).
    ///
    /// # Returns
    /// * `none` (seed 001): [`rotary_coefficients`] of `problem`.
    /// * `allowance` (kerf): with the time-optimal law, zero end slopes (eq. 45) when the
    ///   problem is feasible so at the requested feedrate, else free ones
    ///   ([`RotaryQp::free_end_slopes`]; still infeasible: the feedrate bisection of
    ///   [`rotary_coefficients`]).
    ///
    /// # Errors
    /// As [`rotary_coefficients`].
    pub(super) fn rotary_first(
        corridor: bool,
        mode: FeedMode,
    ) -> impl Fn(&RotaryQp) -> Result<Vec<f64>, PlanError> + Sync {
        move |problem| {
            if corridor {
                end_slopes_as_needed(problem, mode)
            } else {
                rotary_coefficients(problem, mode)
            }
        }
    }

    /// The q5 QP's coefficients inside the allowance, from its first solve
    /// ([`Context::rotary_first`]) and the q4 spline chosen.
    ///
    /// # Arguments
    /// * `problem` - the q5 QP of seed 001 (eq. 61, with kerf's RTO boxes), without corridor.
    /// * `first` - its first solve.
    /// * `q4` - the q4 spline.
    /// * `rtos` - the RTOs (their CL points get no corridor row: their box or pick is there).
    ///
    /// # Returns
    /// * `none` (seed 001): `first`.
    /// * `allowance` (kerf): the corridor is added by active sets: the CL points whose axis is
    ///   outside [`CORRIDOR_FRACTION`] of the allowance get their interval ([`tilt_interval`])
    ///   as a row, [`CORRIDOR_PAD`] points on each side of each run too, and the QP is solved
    ///   again, at most [`CORRIDOR_ROUNDS`] times. A solution inside every interval is the
    ///   optimum of the QP with the whole corridor (a convex problem whose relaxation's optimum
    ///   is feasible), at the cost of the rows that bind, not of one row per CL point (case 2:
    ///   628). A corridor that makes the QP infeasible for another reason than its kinematic
    ///   bounds (against an RTO's box or pick next to it: both inside the allowance, the
    ///   corridor inside [`CORRIDOR_FRACTION`] of it with the q4 of the spline) is dropped, as
    ///   seed 001; the dense check then inserts RTOs where the allowance is left.
    ///
    /// # Errors
    /// As [`rotary_coefficients`].
    pub(super) fn q5_in_allowance(
        &self,
        problem: &RotaryQp,
        first: Vec<f64>,
        q4: &BSpline,
        rtos: &[RtoState],
    ) -> Result<Vec<f64>, PlanError> {
        let mode = self.request.options.feed_law;
        if !self.corridor_on() {
            return Ok(first);
        }
        let mut coeffs = first;
        let r = self.request;
        let (max_lead, max_tilt) = (
            r.max_lead_angle * CORRIDOR_FRACTION,
            r.max_tilt_angle * CORRIDOR_FRACTION,
        );
        let inside = |i: usize, o: &Vector3<f64>| {
            let (lead, tilt) = self.frames.lead_tilt_at(i, o);
            lead.abs() <= max_lead && tilt.abs() <= max_tilt
        };
        let stroke = {
            let l = self.limits()[4];
            (l.min, l.max)
        };
        let n = self.v.u.len();
        let q4_at: Vec<f64> = self.v.u.iter().map(|&u| q4.eval(u)[0]).collect();
        let mut free: Vec<bool> = (0..n)
            .map(|i| !rtos.iter().any(|rto| rto.cl_index == i))
            .collect();
        let mut rows: Vec<(f64, f64, f64)> = Vec::new();
        for _ in 0..CORRIDOR_ROUNDS {
            let q5 = BSpline::new(problem.knots.clone(), coeffs.clone())
                .map_err(super::bspline_error)?;
            let outside: Vec<usize> = (0..n)
                .filter(|&i| free[i] && !inside(i, &tool_axis(q4_at[i], q5.eval(self.v.u[i])[0])))
                .collect();
            let mut added = 0;
            for &i in &outside {
                for k in i.saturating_sub(CORRIDOR_PAD)..=(i + CORRIDOR_PAD).min(n - 1) {
                    if !free[k] {
                        continue;
                    }
                    free[k] = false;
                    let inside_k = |o: &Vector3<f64>| inside(k, o);
                    if let Some((lo, hi)) =
                        tilt_interval(q4_at[k], &self.v.axes[k], &inside_k, stroke)
                    {
                        rows.push((self.v.u[k], lo, hi));
                        added += 1;
                    }
                }
            }
            if added == 0 {
                break;
            }
            rows.sort_by(|a, b| a.0.total_cmp(&b.0));
            let with = RotaryQp {
                corridor: &rows,
                ..*problem
            };
            self.budget.check("the rotary-axis QPs")?;
            match end_slopes_as_needed(&with, mode) {
                Ok(c) => coeffs = c,
                Err(PlanError::Infeasible { family, detail, .. }) => {
                    log::debug!(
                        "{} QP infeasible with the allowance corridor ({family}: {detail}); solved without it",
                        problem.axis_name
                    );
                    return end_slopes_as_needed(problem, mode);
                }
                Err(e) => return Err(e),
            }
        }
        Ok(coeffs)
    }
}

/// With the time-optimal law: zero end slopes (seed 001 eq. 45) when the problem is feasible
/// so at the requested feedrate, else free ones (see [`Context::rotary_first`]).
/// With the constant law the end slopes stay zero: its S-curve ramps run at the request's path
/// jerk, which a nonzero `q_u` would turn into joint jerk (`q_u s⃛ / σ`, eq. 7).
fn end_slopes_as_needed(problem: &RotaryQp, mode: FeedMode) -> Result<Vec<f64>, PlanError> {
    if mode == FeedMode::Constant {
        return rotary_coefficients(problem, mode);
    }
    if let Some(coeffs) = problem.try_solve()? {
        return Ok(coeffs);
    }
    let free = RotaryQp {
        free_end_slopes: true,
        ..*problem
    };
    rotary_coefficients(&free, mode)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lead/tilt box around n = ẑ with t = x̂, b = ŷ.
    fn around_z(max_lead: f64, max_tilt: f64) -> impl Fn(&Vector3<f64>) -> bool {
        move |o: &Vector3<f64>| o.x.atan2(o.z).abs() <= max_lead && o.y.atan2(o.z).abs() <= max_tilt
    }

    #[test]
    fn interval_in_the_lead_plane_is_the_lead_allowance() {
        // q4 = 0: q5 tilts the axis toward x̂ = t, the lead plane.
        let (lo, hi) = tilt_interval(0.0, &Vector3::z(), &around_z(0.2, 0.1), (-1.0, 1.0)).unwrap();
        assert!(
            (lo + 0.2).abs() < 1e-8 && (hi - 0.2).abs() < 1e-8,
            "{lo} {hi}"
        );
        // q4 = π/2: toward ŷ = b, the tilt plane.
        let (lo, hi) = tilt_interval(
            std::f64::consts::FRAC_PI_2,
            &Vector3::z(),
            &around_z(0.2, 0.1),
            (-1.0, 1.0),
        )
        .unwrap();
        assert!(
            (lo + 0.1).abs() < 1e-8 && (hi - 0.1).abs() < 1e-8,
            "{lo} {hi}"
        );
    }

    #[test]
    fn interval_is_centred_on_the_nearest_point_and_cut_by_the_stroke() {
        // n tilted by 0.5 rad toward x̂; lead measured from n: the interval is 0.5 ± 0.2.
        let n = tool_axis(0.0, 0.5);
        let t = tool_axis(0.0, 0.5 + std::f64::consts::FRAC_PI_2);
        let inside = move |o: &Vector3<f64>| o.dot(&t).atan2(o.dot(&n)).abs() <= 0.2;
        let (lo, hi) = tilt_interval(0.0, &n, &inside, (-1.0, 1.0)).unwrap();
        assert!(
            (lo - 0.3).abs() < 1e-8 && (hi - 0.7).abs() < 1e-8,
            "{lo} {hi}"
        );
        let (lo, hi) = tilt_interval(0.0, &n, &inside, (-1.0, 0.6)).unwrap();
        assert!((lo - 0.3).abs() < 1e-8 && hi == 0.6, "{lo} {hi}");
        assert!(tilt_interval(0.0, &n, &inside, (-1.0, 0.2)).is_none());
    }

    #[test]
    fn no_interval_when_q4_leaves_no_q5_inside() {
        // n tilted 0.5 rad toward x̂, q4 a quarter turn off: the circle passes 0.5 rad away.
        let n = tool_axis(0.0, 0.5);
        let inside = move |o: &Vector3<f64>| o.angle(&n) <= 0.2;
        assert!(tilt_interval(std::f64::consts::FRAC_PI_2, &n, &inside, (-1.0, 1.0)).is_none());
    }
}
