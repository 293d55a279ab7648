//! The periodic forced response the perturbed simulation starts from.

use nalgebra::{Matrix4, Vector2, Vector4};

use super::classify::fraction;
use super::cutter::Cutter;
use super::history::PeriodicHistory;
use super::integrate::{rk4_step, Structure};
use super::{internal, SimulationSettings, StepSample};
use crate::error::ChatterError;

/// The periodic forced response and what it took.
pub(super) struct Orbit {
    pub(super) history: PeriodicHistory,
    pub(super) samples: Vec<StepSample>,
    pub(super) iterations: usize,
    pub(super) contact_fraction: f64,
}

/// The T-periodic forced response by the fixed-point iteration of the
/// module documentation.
pub(super) fn periodic_response(
    s: &Structure,
    cutter: &Cutter,
    h: f64,
    n: usize,
    settings: &SimulationSettings,
) -> Result<Orbit, ChatterError> {
    // The sub-step pattern of every step of the period (the simulator's).
    let mut pattern = Vec::with_capacity(n);
    for k in 0..n {
        let mut edges = Vec::new();
        cutter.substeps(k as f64 * h, h, &mut edges);
        pattern.push(edges.iter().map(|e| e.time).collect::<Vec<f64>>());
    }
    // RK4 transition matrix of ż = A z over one sub-step of length dt:
    // P(dt) = Σ_{i≤4} (dt A)^i / i!; over the period Φ = Π P(dt).
    let rk4_matrix = |dt: f64| {
        let ha = s.a * dt;
        let mut p = Matrix4::<f64>::identity();
        let mut term = Matrix4::<f64>::identity();
        for i in 1..=4 {
            term = term * ha / i as f64;
            p += term;
        }
        p
    };
    let mut phi = Matrix4::<f64>::identity();
    for bounds in &pattern {
        for w in bounds.windows(2) {
            phi = rk4_matrix(w[1] - w[0]) * phi;
        }
    }
    let inv = (Matrix4::identity() - phi)
        .try_inverse()
        .ok_or(ChatterError::Unsupported {
            reason: "undamped structure resonant with the tooth period: no periodic forced \
                     response (I - Phi singular)"
                .to_string(),
        })?;

    let mut hist = PeriodicHistory {
        step: h,
        pos: vec![Vector2::zeros(); n],
        vel: vec![Vector2::zeros(); n],
    };
    let mut warm = cutter.nominal_delays();
    // Stage forces per step and sub-step.
    let mut forces: Vec<Vec<[Vector2<f64>; 4]>> = pattern
        .iter()
        .map(|b| vec![[Vector2::zeros(); 4]; b.len().saturating_sub(1)])
        .collect();
    let mut chips = vec![(0.0, 0usize); n];
    let mut change = f64::NAN;
    for iteration in 1..=settings.orbit_max_iterations {
        let (mut engaged, mut contact) = (0usize, 0usize);
        for (k, ((fk, ck), bounds)) in forces
            .iter_mut()
            .zip(chips.iter_mut())
            .zip(pattern.iter())
            .enumerate()
        {
            // The RK4 stage forces of the simulator's step from the
            // iterate's state z_k, delayed values from the iterate.
            let mut o = hist.pos.get(k).copied().ok_or_else(internal)?;
            let mut v = hist.vel.get(k).copied().ok_or_else(internal)?;
            for (i, (w, fs)) in bounds.windows(2).zip(fk.iter_mut()).enumerate() {
                let (ta, tb) = (w[0], w[1]);
                let mid = 0.5 * (ta + tb);
                let c0 = cutter.force(ta, mid, o, &hist, &mut warm)?;
                if i == 0 {
                    engaged += c0.engaged;
                    contact += c0.contact;
                    *ck = (c0.chip, c0.order);
                }
                let mut stage = [c0.force; 4];
                let mut next = 1;
                (o, v) = rk4_step(s, ta, tb - ta, o, v, c0.force, |tt, oo| {
                    let f = cutter.force(tt, mid, oo, &hist, &mut warm)?.force;
                    if let Some(slot) = stage.get_mut(next) {
                        *slot = f;
                    }
                    next += 1;
                    Ok(f)
                })?;
                *fs = stage;
            }
        }
        let run = |z0: Vector4<f64>, store: Option<&mut PeriodicHistory>| {
            let mut o = Vector2::new(z0[0], z0[1]);
            let mut v = Vector2::new(z0[2], z0[3]);
            let mut out = store;
            for (k, (fk, bounds)) in forces.iter().zip(pattern.iter()).enumerate() {
                if let Some(st) = out.as_deref_mut() {
                    if let (Some(ps), Some(vs)) = (st.pos.get_mut(k), st.vel.get_mut(k)) {
                        *ps = o;
                        *vs = v;
                    }
                }
                for (w, f) in bounds.windows(2).zip(fk.iter()) {
                    let mut next = 1;
                    (o, v) = rk4_step(s, w[0], w[1] - w[0], o, v, f[0], |_, _| {
                        let fs = f.get(next).copied().ok_or_else(internal);
                        next += 1;
                        fs
                    })?;
                }
            }
            Ok::<Vector4<f64>, ChatterError>(Vector4::new(o.x, o.y, v.x, v.y))
        };
        let from_rest = run(Vector4::zeros(), None)?;
        let z0 = inv * from_rest;
        let mut next = PeriodicHistory {
            step: h,
            pos: vec![Vector2::zeros(); n],
            vel: vec![Vector2::zeros(); n],
        };
        run(z0, Some(&mut next))?;
        change = next
            .pos
            .iter()
            .zip(hist.pos.iter())
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        if !change.is_finite() {
            return Err(ChatterError::NonFinite {
                what: "periodic forced response".to_string(),
            });
        }
        hist = next;
        if change <= settings.orbit_tolerance {
            let samples = (0..n)
                .map(|k| StepSample {
                    time: k as f64 * h,
                    position: hist.pos.get(k).copied().unwrap_or_default(),
                    velocity: hist.vel.get(k).copied().unwrap_or_default(),
                    force: forces
                        .get(k)
                        .and_then(|f| f.first())
                        .map(|f| f[0])
                        .unwrap_or_default(),
                    chip: chips.get(k).map(|c| c.0).unwrap_or_default(),
                    order: chips.get(k).map(|c| c.1).unwrap_or_default(),
                })
                .collect();
            return Ok(Orbit {
                history: hist,
                samples,
                iterations: iteration,
                contact_fraction: fraction(contact, engaged),
            });
        }
    }
    Err(ChatterError::NotConverged {
        what: "periodic forced response (fixed-point iteration)".to_string(),
        iterations: settings.orbit_max_iterations,
        residual: change,
    })
}
