//! The RK4 tracks of the order-1 delays along the equilibrium and the
//! chip of a tooth at any time.

use std::f64::consts::PI;

use nalgebra::Vector2;

use super::geometry::{Ctx, Here, Traj};
use super::interp::{hermite1, locate_guess, wrap};
use super::{engaged, ChipState, DelayTrack, EquilibriumSettings, Geometry};
use crate::error::ChatterError;
use crate::model::force_direction;

/// The order-1 delay of tooth j at time t from its RK4 track (Hermite
/// interpolation between nodes), with the track's eq. 3-4 geometry when t
/// is (bit for bit) one of its node times, where the interpolant is the
/// node value: `None` where the tooth has no track.
fn track_lookup(
    tracks: &[DelayTrack],
    times: &[f64],
    period: f64,
    tooth: usize,
    t: f64,
) -> Option<(f64, Option<Geometry>)> {
    let tt = wrap(t, period);
    for tr in tracks.iter().filter(|tr| tr.tooth == tooth) {
        let last = tr.first + tr.tau.len() - 1;
        if tt >= times[tr.first] && tt <= times[last] {
            let k = locate_guess(&times[tr.first..=last], tt);
            let (t0, t1) = (times[tr.first + k], times[tr.first + k + 1]);
            let h = t1 - t0;
            let s = ((tt - t0) / h).clamp(0.0, 1.0);
            let tau = hermite1(
                s,
                h,
                tr.tau[k],
                tr.taudot[k],
                tr.tau[k + 1],
                tr.taudot[k + 1],
            );
            // at s = 0 (1) the interpolant is tau[k] (tau[k + 1]) exactly
            let node = match s {
                0.0 => Some(k),
                1.0 => Some(k + 1),
                _ => None,
            }
            .filter(|&n| t.to_bits() == times[tr.first + n].to_bits());
            return Some((tau, node.map(|n| tr.geometry[n])));
        }
    }
    None
}

pub(super) fn track_delay(
    tracks: &[DelayTrack],
    times: &[f64],
    period: f64,
    tooth: usize,
    t: f64,
) -> Option<f64> {
    track_lookup(tracks, times, period, tooth, t).map(|(tau, _)| tau)
}

/// Sines and cosines of the tooth angles φ_j(t) at the times where the
/// fixed-point iteration evaluates them; they do not change between
/// iterations, so they are computed once ([`AngleTable::new`]), with the
/// same expression as [`Ctx::here`] (bit-identical).
pub(super) struct AngleTable {
    /// For every step k and every tooth engaged on it (in the order of
    /// `engaged_steps[k]`, steps one after the other): the tooth and its
    /// angle data at the [`Point`]s `Start` (t_k), `TrackMid` (t_k + h/2,
    /// the RK4 midpoint of the delay tracks), `ForceMid` ((t_k + t_{k+1})/2,
    /// the force midpoint of the shooting) and `End` (t_{k+1}).
    entries: Vec<(usize, [PointAngle; 4])>,
    /// Index of step k's first entry (one more element: the end).
    offsets: Vec<usize>,
}

/// The tooth angle's sine and cosine ([`Ctx::here`]) and the cutting-force
/// direction `b(φ)` of the reduced angle ([`force_direction`]) at one time.
#[derive(Debug, Clone, Copy)]
struct PointAngle {
    sin: f64,
    cos: f64,
    force_direction: Vector2<f64>,
}

/// The evaluation times of a step in an [`AngleTable`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Point {
    Start = 0,
    TrackMid = 1,
    ForceMid = 2,
    End = 3,
}

impl Point {
    /// The time of this point on step k.
    pub(super) fn time(self, times: &[f64], k: usize) -> f64 {
        let (ta, tb) = (times[k], times[k + 1]);
        match self {
            Point::Start => ta,
            Point::TrackMid => ta + 0.5 * (tb - ta),
            Point::ForceMid => 0.5 * (ta + tb),
            Point::End => tb,
        }
    }
}

impl AngleTable {
    pub(super) fn new(ctx: &Ctx, times: &[f64], engaged_steps: &[Vec<usize>]) -> Self {
        let points = [Point::Start, Point::TrackMid, Point::ForceMid, Point::End];
        let mut entries = Vec::with_capacity(engaged_steps.iter().map(Vec::len).sum());
        let mut offsets = Vec::with_capacity(engaged_steps.len() + 1);
        for (k, teeth) in engaged_steps.iter().enumerate() {
            offsets.push(entries.len());
            for &j in teeth {
                entries.push((
                    j,
                    points.map(|p| {
                        let phi = ctx.phi(j, p.time(times, k));
                        let (sin, cos) = phi.sin_cos();
                        PointAngle {
                            sin,
                            cos,
                            force_direction: force_direction(
                                wrap(phi, 2.0 * PI),
                                ctx.process.kt,
                                ctx.process.kn,
                            ),
                        }
                    }),
                ));
            }
        }
        offsets.push(entries.len());
        Self { entries, offsets }
    }

    fn entry(&self, k: usize, tooth: usize) -> Option<&[PointAngle; 4]> {
        let range = self.offsets.get(k).copied()?..self.offsets.get(k + 1).copied()?;
        self.entries
            .get(range)?
            .iter()
            .find(|(j, _)| *j == tooth)
            .map(|(_, angles)| angles)
    }

    /// [`Ctx::here`] for tooth j at a point of step k, or `None` if the
    /// tooth is not engaged on step k.
    pub(super) fn here(&self, traj: &Traj, k: usize, tooth: usize, point: Point) -> Option<Here> {
        let a = self.entry(k, tooth)?[point as usize];
        let (p, v) = match point {
            Point::Start => traj.node_state(k),
            Point::End => traj.node_state(k + 1),
            _ => traj.state(point.time(traj.times, k)),
        };
        Some(Here {
            s: a.sin,
            c: a.cos,
            p,
            v,
        })
    }

    /// `force_direction(φ_j mod 2π, K_t, K_n)` at a point of step k, or
    /// `None` if the tooth is not engaged on step k.
    pub(super) fn force_direction(
        &self,
        k: usize,
        tooth: usize,
        point: Point,
    ) -> Option<Vector2<f64>> {
        Some(self.entry(k, tooth)?[point as usize].force_direction)
    }
}

/// Order-1 delay tracks: Newton at the start of every maximal run of steps
/// in which a tooth is engaged, then RK4 on eq. 6 node by node. Each node
/// keeps the eq. 3-4 geometry of its delay (τ̇ = −g_t/g_τ, and the chip
/// there for [`chip_with`]).
pub(super) fn build_tracks(
    ctx: &Ctx,
    traj: &Traj,
    times: &[f64],
    engaged_steps: &[Vec<usize>],
    angles: &AngleTable,
) -> Result<Vec<DelayTrack>, ChatterError> {
    let mut tracks = Vec::new();
    let here_at = |k: usize, j: usize, point: Point| {
        angles
            .here(traj, k, j, point)
            .unwrap_or_else(|| ctx.here(traj, j, point.time(times, k)))
    };
    for j in 0..ctx.process.teeth {
        let mut k = 0;
        while k < engaged_steps.len() {
            if !engaged_steps[k].contains(&j) {
                k += 1;
                continue;
            }
            let first = k;
            let mut end = k;
            while end < engaged_steps.len() && engaged_steps[end].contains(&j) {
                end += 1;
            }
            let t0 = times[first];
            let here0 = here_at(first, j, Point::Start);
            let mut tau = ctx.newton_at(traj, &here0, j, 1, t0, ctx.period)?;
            let geo0 = ctx.geometry_at(traj, &here0, 1, t0, tau);
            let mut taus = vec![tau];
            let mut dots = vec![-geo0.g_t / geo0.g_tau];
            let mut geometry = vec![geo0];
            for s in first..end {
                let (ta, tb) = (times[s], times[s + 1]);
                let h = tb - ta;
                let k1 = dots[dots.len() - 1];
                let tm = ta + 0.5 * h;
                let mid = here_at(s, j, Point::TrackMid);
                let k2 = ctx.taudot_at(traj, &mid, tm, tau + 0.5 * h * k1);
                let k3 = ctx.taudot_at(traj, &mid, tm, tau + 0.5 * h * k2);
                let end_here = here_at(s, j, Point::End);
                let k4 = ctx.taudot_at(traj, &end_here, tb, tau + h * k3);
                tau += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                if !tau.is_finite() {
                    return Err(ChatterError::NonFinite {
                        what: format!("RK4 delay integration (eq. 6), tooth {j}"),
                    });
                }
                let geo = ctx.geometry_at(traj, &end_here, 1, tb, tau);
                taus.push(tau);
                dots.push(-geo.g_t / geo.g_tau);
                geometry.push(geo);
            }
            tracks.push(DelayTrack {
                tooth: j,
                first,
                tau: taus,
                taudot: dots,
                geometry,
            });
            k = end;
        }
    }
    Ok(tracks)
}

pub(super) fn chip_at(
    ctx: &Ctx,
    traj: &Traj,
    tracks: &[DelayTrack],
    settings: &EquilibriumSettings,
    times: &[f64],
    tooth: usize,
    t: f64,
) -> Result<ChipState, ChatterError> {
    let here = ctx.here(traj, tooth, t);
    chip_with(ctx, traj, tracks, settings, times, tooth, t, &here)
}

/// [`chip_at`] with [`Ctx::here`] given (it must be `ctx.here(traj, tooth, t)`).
#[allow(clippy::too_many_arguments)]
pub(super) fn chip_with(
    ctx: &Ctx,
    traj: &Traj,
    tracks: &[DelayTrack],
    settings: &EquilibriumSettings,
    times: &[f64],
    tooth: usize,
    t: f64,
    here: &Here,
) -> Result<ChipState, ChatterError> {
    let phi = ctx.phi(tooth, t);
    let (tau1, geo1) = match track_lookup(tracks, times, ctx.period, tooth, t) {
        Some((tau, Some(geo))) => (tau, geo),
        Some((tau, None)) => (tau, ctx.geometry_at(traj, here, 1, t, tau)),
        None => {
            let tau = ctx.newton_at(traj, here, tooth, 1, t, ctx.period)?;
            (tau, ctx.geometry_at(traj, here, 1, t, tau))
        }
    };
    let mut best = (geo1, 1usize, tau1);
    for order in 2..=settings.max_regeneration {
        if chip_lower_bound(ctx, traj, here, order).is_some_and(|lb| lb > best.0.h) {
            // this order's chip exceeds the best one: it cannot give the
            // minimum (its Newton solve is skipped)
            continue;
        }
        // no-vibration scaling: τ^m − mT ≈ m (τ^1 − T), i.e. τ^m ≈ m τ^1
        let guess = order as f64 * tau1;
        let tau = ctx.newton_at(traj, here, tooth, order, t, guess)?;
        let geo = ctx.geometry_at(traj, here, order, t, tau);
        if geo.h < best.0.h {
            best = (geo, order, tau);
        }
    }
    let (geo, order, delay) = best;
    if !geo.h.is_finite() {
        return Err(ChatterError::NonFinite {
            what: format!("chip thickness (eq. 4), tooth {tooth}"),
        });
    }
    let inside = engaged(ctx.process, phi);
    Ok(ChipState {
        phi: wrap(phi, 2.0 * PI),
        chip: geo.h,
        order,
        delay,
        g_tau: geo.g_tau,
        h_tau: geo.h_tau,
        in_contact: inside && (geo.h > 0.0 || ctx.feed == 0.0),
    })
}

/// A lower bound of the eq. 4 chip `h^m` of regeneration order `m ≥ 2`
/// (seed 004 eq. 3-4, module documentation of [`super`]) at the state
/// `here`, valid for every delay τ^m with `|τ^m − m T| ≤ T/2` that solves
/// eq. 3 (the branch [`Ctx::newton_at`] accepts), including the rounding of
/// its Newton iterate and of the chip's evaluation; `None` when no bound
/// follows (one tooth, or a vibration velocity comparable to the cutting
/// speed). It lets [`chip_at`] skip the Newton solve of an order whose chip
/// cannot be the minimum, leaving every chip state bit-identical.
///
/// Derivation. Write `ε = τ − m T` (so `δ = Ω ε`, as `Ω T = 2π/N_t`) and
/// `d = õ(t − τ) − õ(t)`; the equilibrium is T-periodic, so
/// `|d| ≤ L |ε| + J` ([`super::geometry::TrajBounds`]). Eq. 3 gives
/// `R sin(Ω ε) = −f τ cos φ − d·w` with `|w| = 1`; with `|Ω ε| ≤ π/N_t ≤ π/2`,
/// `|sin(Ω ε)| ≥ (2/π) Ω |ε|`, hence
///
/// `|ε| ≤ E = (f m T |cos φ| + J) / (2 R Ω/π − f − L)` (if the denominator is > 0).
///
/// Eq. 4 is `h = R (1 − cos δ) + f τ sin φ + d·c` with `|c| = 1`, so
///
/// `h^m ≥ f (m T sin φ − E |sin φ|) − (L E + J)`.
///
/// Rounding (the Newton iterate solves eq. 3 to `|step| ≤ 1e-15 T`, the
/// delayed time is reduced modulo T, the chip is a sum of a few products)
/// is covered by the slacks `1e-12 T` on ε, `1e-12 R` on eq. 3 and on h.
pub(super) fn chip_lower_bound(ctx: &Ctx, traj: &Traj, here: &Here, order: usize) -> Option<f64> {
    if ctx.process.teeth < 2 {
        return None;
    }
    let (lip, jump) = (traj.bounds.lipschitz, traj.bounds.wrap_jump);
    let r = ctx.process.radius;
    let f = ctx.feed;
    let period = ctx.period;
    let nominal = order as f64 * period;
    let slack_t = 1e-12 * period;
    let slack_x = 1e-12 * r;
    let den = 2.0 * r * ctx.omega / PI - f - lip;
    if !(den > 0.0 && jump.is_finite()) {
        return None;
    }
    let e = (f * nominal * here.c.abs() + lip * slack_t + jump + slack_x) / den + slack_t;
    let lb = f * (nominal * here.s - e * here.s.abs()) - (lip * e + jump) - slack_x;
    lb.is_finite().then_some(lb)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::equilibrium::Equilibrium;
    use crate::model::{MillingProcess, Modal2, Mode};

    fn modal(hz: f64, zeta: f64, mass: f64) -> Modal2 {
        let mode = Mode {
            natural_frequency_hz: hz,
            damping_ratio: zeta,
            modal_mass: mass,
        };
        Modal2::from_modes(mode, mode).unwrap()
    }

    fn process(teeth: usize, entry: f64, exit: f64) -> MillingProcess {
        MillingProcess {
            teeth,
            radius: 0.04,
            axial_depth: 3e-3,
            kt: 6.44e8,
            kn: 2.37e8,
            entry_angle: entry,
            exit_angle: exit,
        }
    }

    /// The cut of [`chip_at`] without skipping any order (the implementation
    /// before the skip): chip, order, delay, g_τ, h_τ.
    fn all_orders(eq: &Equilibrium, tooth: usize, t: f64) -> (f64, usize, f64, f64, f64) {
        let (ctx, traj) = (eq.ctx(), eq.traj());
        let here = ctx.here(&traj, tooth, t);
        let tau1 = track_delay(&eq.tracks, &eq.times, ctx.period, tooth, t).unwrap_or_else(|| {
            ctx.newton_at(&traj, &here, tooth, 1, t, ctx.period)
                .unwrap()
        });
        let mut best = (ctx.geometry_at(&traj, &here, 1, t, tau1), 1usize, tau1);
        for order in 2..=eq.settings.max_regeneration {
            let tau = ctx
                .newton_at(&traj, &here, tooth, order, t, order as f64 * tau1)
                .unwrap();
            let geo = ctx.geometry_at(&traj, &here, order, t, tau);
            if geo.h < best.0.h {
                best = (geo, order, tau);
            }
        }
        (best.0.h, best.1, best.2, best.0.g_tau, best.0.h_tau)
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The precomputed angles and node states give the bits of the direct
    /// evaluation ([`Ctx::here`], [`Traj::state`], [`force_direction`]) at
    /// every point of every engaged step.
    #[test]
    fn angle_table_and_node_states_are_bit_identical() {
        let process = process(3, 0.5 * PI, PI);
        let eq = Equilibrium::compute(
            &modal(25.0, 0.05, 50.0),
            &process,
            2600.0,
            0.05,
            &EquilibriumSettings::default(),
        )
        .unwrap();
        let (ctx, traj) = (eq.ctx(), eq.traj());
        for k in 0..eq.times.len() {
            let (p, v) = traj.node_state(k);
            let (q, w) = traj.state(eq.times[k]);
            assert_eq!(
                bits(&[p.x, p.y, v.x, v.y]),
                bits(&[q.x, q.y, w.x, w.y]),
                "node {k}"
            );
        }
        let engaged_steps: Vec<Vec<usize>> = eq
            .times
            .windows(2)
            .map(|w| {
                (0..process.teeth)
                    .filter(|&j| engaged(&process, ctx.phi(j, 0.5 * (w[0] + w[1]))))
                    .collect()
            })
            .collect();
        let table = AngleTable::new(&ctx, &eq.times, &engaged_steps);
        let mut checked = 0;
        for (k, teeth) in engaged_steps.iter().enumerate() {
            for &j in teeth {
                for point in [Point::Start, Point::TrackMid, Point::ForceMid, Point::End] {
                    let t = point.time(&eq.times, k);
                    let a = table.here(&traj, k, j, point).unwrap();
                    let b = ctx.here(&traj, j, t);
                    assert_eq!(
                        bits(&[a.s, a.c, a.p.x, a.p.y, a.v.x, a.v.y]),
                        bits(&[b.s, b.c, b.p.x, b.p.y, b.v.x, b.v.y]),
                        "step {k} tooth {j} {point:?}"
                    );
                    let f = table.force_direction(k, j, point).unwrap();
                    let g = force_direction(wrap(ctx.phi(j, t), 2.0 * PI), process.kt, process.kn);
                    assert_eq!(bits(&[f.x, f.y]), bits(&[g.x, g.y]));
                    checked += 1;
                }
            }
            assert!(table.here(&traj, k, process.teeth, Point::Start).is_none());
        }
        assert!(checked > 400, "{checked}");
    }

    /// The chip lower bound holds for every order's Newton chip, the chip
    /// states with skipped orders are bit-identical to those of the full
    /// search, and the bound skips most solves on the cut of seed 004.
    #[test]
    fn skipped_orders_never_give_the_chip() {
        let cases = [
            // (modal, process, rpm, feed, force exponent, max order)
            (
                modal(25.0, 0.05, 50.0),
                process(2, 0.75 * PI, PI),
                3000.0,
                0.04,
                1.0,
                3,
            ),
            (
                modal(25.0, 0.05, 50.0),
                process(2, 0.75 * PI, PI),
                750.0,
                0.06,
                1.0,
                3,
            ),
            (
                modal(30.0, 0.05, 28.0),
                process(2, 0.75 * PI, PI),
                3000.0,
                0.04,
                0.75,
                3,
            ),
            (
                modal(80.0, 0.03, 6.0),
                process(2, 0.75 * PI, PI),
                2800.0,
                0.06,
                1.0,
                4,
            ),
            (
                modal(25.0, 0.05, 50.0),
                process(4, 0.0, 0.4 * PI),
                2000.0,
                0.02,
                1.0,
                5,
            ),
            (
                modal(25.0, 0.05, 50.0),
                process(3, 0.5 * PI, PI),
                4000.0,
                0.06,
                0.75,
                3,
            ),
            (
                modal(25.0, 0.05, 50.0),
                process(2, 0.75 * PI, PI),
                3000.0,
                0.0,
                1.0,
                3,
            ),
        ];
        for (k, (modal, process, rpm, feed, exponent, orders)) in cases.into_iter().enumerate() {
            let mut settings = EquilibriumSettings {
                max_regeneration: orders,
                ..EquilibriumSettings::default()
            };
            settings.force_law.exponent = exponent;
            let eq = Equilibrium::compute(&modal, &process, rpm, feed, &settings).unwrap();
            let (ctx, traj) = (eq.ctx(), eq.traj());
            let (mut solves, mut skipped) = (0, 0);
            for tooth in 0..process.teeth {
                for i in 0..=400 {
                    let t = eq.period * i as f64 / 400.0;
                    if !engaged(&process, ctx.phi(tooth, t)) {
                        continue;
                    }
                    let here = ctx.here(&traj, tooth, t);
                    for order in 2..=orders {
                        let (_, h) = eq.chip_of_order(tooth, order, t).unwrap();
                        solves += 1;
                        if let Some(lb) = chip_lower_bound(&ctx, &traj, &here, order) {
                            assert!(h >= lb, "case {k}: order {order} t {t:e}: h {h:e} < {lb:e}");
                            if lb > eq.chip_of_order(tooth, 1, t).unwrap().1 {
                                skipped += 1;
                            }
                        }
                    }
                    let cs = eq.chip_state(tooth, t).unwrap();
                    let full = all_orders(&eq, tooth, t);
                    let fast = (cs.chip, cs.order, cs.delay, cs.g_tau, cs.h_tau);
                    assert_eq!(
                        format!("{fast:?}"),
                        format!("{full:?}"),
                        "case {k}: tooth {tooth} t {t:e}"
                    );
                }
            }
            let fraction = skipped as f64 / solves as f64;
            println!(
                "case {k}: {skipped} of {solves} higher-order solves skippable ({fraction:.2})"
            );
            // on the cuts of seed 004 (down milling [0.75π, π]) away from
            // resonance, most solves are skipped (measured 0.9)
            if k == 0 || k == 2 {
                assert!(fraction > 0.7, "case {k}: only {fraction:.2} skippable");
            }
        }
    }
}
