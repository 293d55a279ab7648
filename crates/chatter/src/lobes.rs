//! Stability lobes of the constant-delay milling model: for each spindle
//! speed, the critical axial depth a_lim at which the chatter indicator
//! |μ|max (spectral radius of the monodromy matrix, [`crate::spectral`])
//! first reaches 1 (Insperger & Stépán 2004 IJNME 61:117 §5; Ding et al.
//! 2010 IJMTM 50:502 §4 draw the same boundary as the |μ| = 1 contour).
//!
//! # Method
//!
//! The [`Discretization`] (matrix exponentials) depends on the spindle
//! speed only, so it is built once per speed; the per-unit-depth equation
//! ([`constant_delay_dde_unit_depth`]) is built once too and scaled by the
//! depth ([`scale_dde`]). Because stability pockets exist (|μ| may go above
//! 1 and back below as depth grows), the depth range is first scanned
//! coarsely from below to bracket the FIRST crossing, then the bracket is
//! bisected to the stated tolerance. A crossing narrower than one scan
//! step can be missed; the scan step is `(max_depth − min_depth)/scan_points`.

use crate::directional::{constant_delay_dde_unit_depth, scale_dde};
use crate::error::{check_non_negative, check_positive, ChatterError};
use crate::fdm::{Discretization, DEFAULT_STEPS};
use crate::model::{MillingProcess, Modal2, PeriodicDde};

/// Settings of [`stability_lobes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeOptions {
    /// Sub-intervals per period m (≥ 2; issue 4 asks ≥ 40).
    pub steps: usize,
    /// Smallest depth examined [m] (≥ 0).
    pub min_depth: f64,
    /// Largest depth examined [m].
    pub max_depth: f64,
    /// Number of coarse scan intervals over `[min_depth, max_depth]`.
    pub scan_points: usize,
    /// Bisection stops when the bracket is narrower than this [m].
    pub tolerance: f64,
}

impl Default for LobeOptions {
    /// m = 40, depths 0–10 mm, 20 scan intervals (0.5 mm), tolerance 1 µm.
    fn default() -> Self {
        Self {
            steps: DEFAULT_STEPS,
            min_depth: 0.0,
            max_depth: 0.01,
            scan_points: 20,
            tolerance: 1e-6,
        }
    }
}

impl LobeOptions {
    fn validate(&self) -> Result<(), ChatterError> {
        check_non_negative("minimum depth [m]", self.min_depth)?;
        check_positive("maximum depth [m]", self.max_depth)?;
        check_positive("depth tolerance [m]", self.tolerance)?;
        if self.max_depth <= self.min_depth {
            return Err(ChatterError::InvalidParameter {
                name: "maximum depth [m]".to_string(),
                value: self.max_depth,
                reason: format!("must be > the minimum depth {}", self.min_depth),
            });
        }
        if self.scan_points == 0 {
            return Err(ChatterError::InvalidParameter {
                name: "scan points".to_string(),
                value: 0.0,
                reason: "must be >= 1".to_string(),
            });
        }
        Ok(())
    }
}

/// One point of a stability-lobe diagram.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobePoint {
    /// Spindle speed [rev/min].
    pub rpm: f64,
    /// Critical axial depth a_lim [m] (midpoint of the final bracket,
    /// within `tolerance`), `None` if the cut stays stable up to
    /// `max_depth`. Equal to `min_depth` if already unstable there.
    pub critical_depth: Option<f64>,
    /// |μ|max at the stable end of the final bracket.
    pub stable_radius: f64,
    /// Number of spectral-radius evaluations spent on this speed.
    pub evaluations: usize,
}

/// Critical depth of one equation per unit depth on one discretization
/// (coarse scan + bisection, module documentation).
///
/// # Errors
/// Errors of [`Discretization::spectral_radius`]; invalid options.
pub fn critical_depth(
    disc: &Discretization,
    unit: &PeriodicDde,
    opts: &LobeOptions,
) -> Result<(Option<f64>, f64, usize), ChatterError> {
    opts.validate()?;
    let mut evaluations = 0;
    let mut rho_at = |depth: f64| -> Result<f64, ChatterError> {
        evaluations += 1;
        disc.spectral_radius(&scale_dde(unit, depth)?)
    };
    let span = opts.max_depth - opts.min_depth;
    let mut lo = opts.min_depth;
    let mut rho_lo = rho_at(lo)?;
    if rho_lo >= 1.0 {
        return Ok((Some(lo), rho_lo, evaluations));
    }
    let mut hi = None;
    for k in 1..=opts.scan_points {
        let d = opts.min_depth + span * k as f64 / opts.scan_points as f64;
        let rho = rho_at(d)?;
        if rho >= 1.0 {
            hi = Some(d);
            break;
        }
        lo = d;
        rho_lo = rho;
    }
    let Some(mut hi) = hi else {
        return Ok((None, rho_lo, evaluations));
    };
    // Bisection: capped by the number of halvings the tolerance needs.
    let cap = ((hi - lo) / opts.tolerance).log2().ceil().max(0.0) as usize + 1;
    for _ in 0..cap.min(200) {
        if hi - lo <= opts.tolerance {
            break;
        }
        let mid = 0.5 * (lo + hi);
        let rho = rho_at(mid)?;
        if rho >= 1.0 {
            hi = mid;
        } else {
            lo = mid;
            rho_lo = rho;
        }
    }
    Ok((Some(0.5 * (lo + hi)), rho_lo, evaluations))
}

/// Stability-lobe diagram of the constant-delay milling model
/// (Insperger & Stépán 2004 eq. 44) for a list of spindle speeds.
///
/// # Arguments
/// * `modal` — tool-tip dynamics.
/// * `process` — milling process (its axial depth is ignored: depth is the
///   unknown).
/// * `rpms` — spindle speeds [rev/min].
/// * `opts` — discretization, depth range, scan and tolerance.
///
/// # Returns
/// One [`LobePoint`] per speed, in order.
///
/// # Errors
/// Invalid inputs; errors of the spectral radius (non-convergence is
/// reported, never hidden).
///
/// # Performance
/// One [`Discretization`] per speed plus ~(scan + log₂(step/tol)) spectral
/// radii (≈ 0.2 ms each at m = 40).
pub fn stability_lobes(
    modal: &Modal2,
    process: &MillingProcess,
    rpms: &[f64],
    opts: &LobeOptions,
) -> Result<Vec<LobePoint>, ChatterError> {
    opts.validate()?;
    rpms.iter()
        .map(|&rpm| {
            let unit = constant_delay_dde_unit_depth(process, rpm, opts.steps)?;
            let disc = Discretization::new(modal, unit.period, opts.steps, unit.period)?;
            let (critical, stable_radius, evaluations) = critical_depth(&disc, &unit, opts)?;
            Ok(LobePoint {
                rpm,
                critical_depth: critical,
                stable_radius,
                evaluations,
            })
        })
        .collect()
}

/// Critical axial depth of the **state-dependent** model (or of whatever
/// [`DelayModel`](crate::indicator::DelayModel) `settings` selects) at one
/// spindle speed and one feed: the smallest depth at which the chatter
/// indicator [`chatter_indicator`](crate::indicator::chatter_indicator)
/// reaches |μ|max = 1 (Floquet: the boundary of seed 004 eq. 8; Bachrathy,
/// Insperger & Stépán 2011 draw the same |μ| = 1 contour in the depth–speed
/// plane).
///
/// # Method
///
/// Unlike the constant-delay model, the state-dependent variational
/// system is not linear in the depth: the periodic equilibrium (seed 004
/// eq. 3-6: the forced vibration, its feed-dependent delays and
/// loss-of-contact windows) scales with `a_p`, and with a nonlinear force
/// law `F ∝ a_p h^x_F` the cutting stiffness depends on the equilibrium
/// chip. So there is no per-unit-depth equation to scale
/// ([`scale_dde`] does not apply); every depth is a full evaluation
/// (equilibrium + linearization + discretization + spectral radius) with
/// `process.axial_depth` set to that depth. The search is the one of
/// [`critical_depth`]: a coarse scan from `min_depth` upward brackets the
/// FIRST crossing (stability pockets exist), then bisection to
/// `opts.tolerance`. A depth of exactly 0 has no cutting force (and the
/// process check refuses it), so a zero `min_depth` is evaluated at
/// `opts.tolerance` instead.
///
/// # Arguments
/// * `modal` — tool-tip dynamics.
/// * `process` — milling process; its `axial_depth` is ignored (it is the
///   unknown).
/// * `rpm` — spindle speed [rev/min].
/// * `feed` — feed [m/s] (≥ 0).
/// * `settings` — delay model, force law, wall term; `opts.steps`
///   replaces `settings.steps` so one m governs the search.
/// * `opts` — depth range, scan intervals, tolerance.
///
/// # Returns
/// `Some(a_lim)` [m] (midpoint of the final bracket, within
/// `opts.tolerance`; the first examined depth if already unstable there),
/// `None` if |μ| < 1 up to `opts.max_depth`.
///
/// # Errors
/// Invalid options or inputs ([`ChatterError::InvalidParameter`]); every
/// error of [`chatter_indicator`](crate::indicator::chatter_indicator) at
/// any examined depth (an equilibrium that does not converge is reported,
/// never skipped).
///
/// # Performance
/// About `scan_points + log₂(scan step / tolerance)` indicator evaluations
/// (≈ 30 for the defaults), each ≈ 0.5–1.5 ms at m = 40.
pub fn state_dependent_critical_depth(
    modal: &Modal2,
    process: &MillingProcess,
    rpm: f64,
    feed: f64,
    settings: &crate::indicator::IndicatorSettings,
    opts: &LobeOptions,
) -> Result<Option<f64>, ChatterError> {
    opts.validate()?;
    check_positive("spindle speed [rpm]", rpm)?;
    check_non_negative("feed [m/s]", feed)?;
    let settings = settings.steps(opts.steps);
    settings.validate()?;
    let first = if opts.min_depth > 0.0 {
        opts.min_depth
    } else {
        opts.tolerance.min(opts.max_depth)
    };
    let rho_at = |depth: f64| -> Result<f64, ChatterError> {
        let p = MillingProcess {
            axial_depth: depth,
            ..*process
        };
        crate::indicator::chatter_indicator(modal, &p, rpm, feed, &settings)
            .map(|ind| ind.spectral_radius)
    };
    first_crossing(rho_at, first, opts)
}

/// The scan + bisection of [`critical_depth`] over an arbitrary |μ|(depth)
/// starting at `first` (≥ `opts.min_depth`): `Some(first)` if unstable
/// there, `None` if stable up to `opts.max_depth`, else the midpoint of
/// the final bracket. The bisection is capped by the number of halvings
/// the tolerance needs (at most 200).
fn first_crossing(
    mut rho_at: impl FnMut(f64) -> Result<f64, ChatterError>,
    first: f64,
    opts: &LobeOptions,
) -> Result<Option<f64>, ChatterError> {
    let finite = |rho: f64| -> Result<f64, ChatterError> {
        if rho.is_finite() {
            Ok(rho)
        } else {
            Err(ChatterError::NonFinite {
                what: "chatter indicator |mu|max in the depth search".to_string(),
            })
        }
    };
    if finite(rho_at(first)?)? >= 1.0 {
        return Ok(Some(first));
    }
    let span = opts.max_depth - opts.min_depth;
    let mut lo = first;
    let mut hi = None;
    for k in 1..=opts.scan_points {
        let d = opts.min_depth + span * k as f64 / opts.scan_points as f64;
        if d <= lo {
            continue;
        }
        if finite(rho_at(d)?)? >= 1.0 {
            hi = Some(d);
            break;
        }
        lo = d;
    }
    let Some(mut hi) = hi else {
        return Ok(None);
    };
    let cap = ((hi - lo) / opts.tolerance).log2().ceil().max(0.0) as usize + 1;
    for _ in 0..cap.min(200) {
        if hi - lo <= opts.tolerance {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if finite(rho_at(mid)?)? >= 1.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Some(0.5 * (lo + hi)))
}
