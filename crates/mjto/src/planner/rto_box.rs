//! RTOs as boxes inside the feasible domain (kerf, issue 16 item 3): the
//! boxes of the selected candidates, and the choice of an inserted RTO by
//! the jerk it causes.
//!
//! Seed 001 pins every RTO to one GFD grid pick (eq. 57-60, 62-64). With
//! `options.rto_constraint: box` each RTO instead carries the largest box
//! of collision-free, lead/tilt-feasible grid samples around its pick
//! ([`Gfd::free_box`]), and the QPs choose the orientation of least jerk
//! inside it; the dense check of every Δt sample stays the arbiter.

use crate::collision::CollisionWorld;
use crate::gfd::{Gfd, GridBox};
use crate::request::RtoConstraint;
use crate::PlanError;

use super::{Context, RtoState};

/// Largest growth of an RTO box around its candidate, in grid steps per
/// side, for (q4, q5, q6) (kerf). With the default grid (13 × 9 × 5 over
/// ±0.35 rad of axis sweep, ±0.3 rad, the q6 span) that is up to ±1/3 of
/// the q4 span, ±0.15 rad of q5 and ±15 mm of standoff, at most 5 × 5 × 3
/// collision queries per RTO.
pub const BOX_STEPS: [usize; 3] = [2, 2, 1];

/// Free candidates looked at when inserting an RTO (kerf): the nearest ones
/// (eq. 55) to the trajectory; those as near as the nearest are told apart
/// by [`jerk_proxy`].
pub const INSERT_CHOICES: usize = 6;

/// Third divided difference of four points `(u, q)` (kerf's discrete jerk
/// proxy, issue 16 item 3: q''' ≈ 6 · q[u0, u1, u2, u3] for a cubic through
/// them; seed 001 has no such term).
fn third_divided_difference(p: &[(f64, f64)]) -> Option<f64> {
    let [a, b, c, d] = p else { return None };
    let dd = |x: (f64, f64), y: (f64, f64)| (y.1 - x.1) / (y.0 - x.0);
    let ab = dd(*a, *b);
    let bc = dd(*b, *c);
    let cd = dd(*c, *d);
    let abc = (bc - ab) / (c.0 - a.0);
    let bcd = (cd - bc) / (d.0 - b.0);
    let v = (bcd - abc) / (d.0 - a.0);
    v.is_finite().then_some(v)
}

/// Discrete jerk proxy of a value `q` at `u` among its neighbours (kerf,
/// issue 16 item 3): the sum over the axes of the squared third divided
/// differences (scaled by 6, the jerk of the interpolating cubic in u) of
/// every window of four consecutive points that contains `(u, q)`.
///
/// # Arguments
/// * `before`, `after` - up to two neighbouring `(u, [q4, q5])` on each side,
///   in path order.
/// * `u`, `q` - the new point.
///
/// # Returns
/// The proxy, 0 when there are fewer than four points in all.
pub fn jerk_proxy(
    before: &[(f64, [f64; 2])],
    after: &[(f64, [f64; 2])],
    u: f64,
    q: [f64; 2],
) -> f64 {
    let mut points: Vec<(f64, [f64; 2])> = before.to_vec();
    let at = points.len();
    points.push((u, q));
    points.extend_from_slice(after);
    let mut total = 0.0;
    for start in 0..points.len().saturating_sub(3) {
        if !(start..start + 4).contains(&at) {
            continue;
        }
        for axis in 0..2 {
            let window: Vec<(f64, f64)> = points[start..start + 4]
                .iter()
                .map(|(u, v)| (*u, v[axis]))
                .collect();
            if let Some(d) = third_divided_difference(&window) {
                total += (6.0 * d).powi(2);
            }
        }
    }
    total
}

impl Context<'_> {
    /// The box of candidate `p` of `gfd` under `options.rto_constraint`:
    /// `None` for `equality`; for `box` [`Gfd::free_box`] with
    /// [`BOX_STEPS`], grown away from `away_from` (a configuration known to
    /// fail).
    pub(super) fn rto_box(
        &self,
        gfd: &mut Gfd,
        p: usize,
        away_from: Option<[f64; 3]>,
        world: &CollisionWorld,
    ) -> Result<Option<GridBox>, PlanError> {
        match self.request.options.rto_constraint {
            RtoConstraint::Equality => Ok(None),
            RtoConstraint::Box => Ok(gfd.free_box(p, BOX_STEPS, away_from, world, &self.budget)?),
        }
    }

    /// The boxes of the initial RTOs (selected candidates `chosen`).
    pub(super) fn initial_boxes(
        &self,
        gfds: &mut [Gfd],
        chosen: &[usize],
        rtos: &mut [RtoState],
        world: &CollisionWorld,
    ) -> Result<(), PlanError> {
        for ((g, &p), r) in gfds.iter_mut().zip(chosen).zip(rtos.iter_mut()) {
            r.bounds = self.rto_box(g, p, None, world)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn third_difference_of_a_cubic_is_its_leading_coefficient() {
        // q = 2u³ − u: q''' = 12 = 6 · 2.
        let f = |u: f64| 2.0 * u * u * u - u;
        let p: Vec<(f64, f64)> = [0.0, 0.1, 0.35, 0.4].iter().map(|&u| (u, f(u))).collect();
        let d = third_divided_difference(&p).unwrap();
        assert!((6.0 * d - 12.0).abs() < 1e-9, "{d}");
        assert!(third_divided_difference(&p[..3]).is_none());
    }

    #[test]
    fn jerk_proxy_prefers_the_smooth_value() {
        // Neighbours on a straight line: the value on the line has no jerk,
        // a bump has some, a bigger bump more.
        let before = [(0.0, [0.0, 1.0]), (0.1, [0.1, 1.0])];
        let after = [(0.3, [0.3, 1.0]), (0.4, [0.4, 1.0])];
        let on_line = jerk_proxy(&before, &after, 0.2, [0.2, 1.0]);
        let bump = jerk_proxy(&before, &after, 0.2, [0.25, 1.0]);
        let bigger = jerk_proxy(&before, &after, 0.2, [0.2, 1.1]);
        assert!(on_line < 1e-18, "{on_line}");
        assert!(bump > 0.0 && bigger > bump, "{bump} {bigger}");
        // Fewer than four points: no proxy.
        assert_eq!(jerk_proxy(&before[..1], &after[..1], 0.2, [5.0, 5.0]), 0.0);
    }
}
