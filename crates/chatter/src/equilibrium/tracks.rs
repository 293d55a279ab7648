//! The RK4 tracks of the order-1 delays along the equilibrium and the
//! chip of a tooth at any time.

use std::f64::consts::PI;

use super::geometry::{Ctx, Traj};
use super::interp::{hermite1, locate};
use super::{engaged, ChipState, DelayTrack, EquilibriumSettings};
use crate::error::ChatterError;

pub(super) fn track_delay(
    tracks: &[DelayTrack],
    times: &[f64],
    period: f64,
    tooth: usize,
    t: f64,
) -> Option<f64> {
    let tt = t.rem_euclid(period);
    for tr in tracks.iter().filter(|tr| tr.tooth == tooth) {
        let last = tr.first + tr.tau.len() - 1;
        if tt >= times[tr.first] && tt <= times[last] {
            let k = locate(&times[tr.first..=last], tt);
            let (t0, t1) = (times[tr.first + k], times[tr.first + k + 1]);
            let h = t1 - t0;
            let s = ((tt - t0) / h).clamp(0.0, 1.0);
            return Some(hermite1(
                s,
                h,
                tr.tau[k],
                tr.taudot[k],
                tr.tau[k + 1],
                tr.taudot[k + 1],
            ));
        }
    }
    None
}

/// Order-1 delay tracks: Newton at the start of every maximal run of steps
/// in which a tooth is engaged, then RK4 on eq. 6 node by node.
pub(super) fn build_tracks(
    ctx: &Ctx,
    traj: &Traj,
    times: &[f64],
    engaged_steps: &[Vec<usize>],
) -> Result<Vec<DelayTrack>, ChatterError> {
    let mut tracks = Vec::new();
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
            let here0 = ctx.here(traj, j, t0);
            let mut tau = ctx.newton_at(traj, &here0, j, 1, t0, ctx.period)?;
            let mut taus = vec![tau];
            let mut dots = vec![ctx.taudot_at(traj, &here0, t0, tau)];
            for s in first..end {
                let (ta, tb) = (times[s], times[s + 1]);
                let h = tb - ta;
                let k1 = dots[dots.len() - 1];
                let tm = ta + 0.5 * h;
                let mid = ctx.here(traj, j, tm);
                let k2 = ctx.taudot_at(traj, &mid, tm, tau + 0.5 * h * k1);
                let k3 = ctx.taudot_at(traj, &mid, tm, tau + 0.5 * h * k2);
                let end_here = ctx.here(traj, j, tb);
                let k4 = ctx.taudot_at(traj, &end_here, tb, tau + h * k3);
                tau += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                if !tau.is_finite() {
                    return Err(ChatterError::NonFinite {
                        what: format!("RK4 delay integration (eq. 6), tooth {j}"),
                    });
                }
                taus.push(tau);
                dots.push(ctx.taudot_at(traj, &end_here, tb, tau));
            }
            tracks.push(DelayTrack {
                tooth: j,
                first,
                tau: taus,
                taudot: dots,
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
    let phi = ctx.phi(tooth, t);
    let here = ctx.here(traj, tooth, t);
    let tau1 = match track_delay(tracks, times, ctx.period, tooth, t) {
        Some(tau) => tau,
        None => ctx.newton_at(traj, &here, tooth, 1, t, ctx.period)?,
    };
    let mut best = (ctx.geometry_at(traj, &here, 1, t, tau1), 1usize, tau1);
    for order in 2..=settings.max_regeneration {
        // no-vibration scaling: τ^m − mT ≈ m (τ^1 − T), i.e. τ^m ≈ m τ^1
        let guess = order as f64 * tau1;
        let tau = ctx.newton_at(traj, &here, tooth, order, t, guess)?;
        let geo = ctx.geometry_at(traj, &here, order, t, tau);
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
        phi: phi.rem_euclid(2.0 * PI),
        chip: geo.h,
        order,
        delay,
        g_tau: geo.g_tau,
        h_tau: geo.h_tau,
        in_contact: inside && (geo.h > 0.0 || ctx.feed == 0.0),
    })
}
