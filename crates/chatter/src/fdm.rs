//! Full discretization of the linear periodic milling DDE into its
//! monodromy (Floquet transition) matrix.
//!
//! # The equation
//!
//! A [`PeriodicDde`] is `M p̈ + C ṗ + K p = −A(t) p(t) + Σ_k B_k(t) p(t − τ_k(t))`
//! (seed 004 eq. 8; `A = B = a_p H(t)`, `τ = T` for the constant-delay model).
//! With the state `x = (p, ṗ)` (4 components) it reads
//!
//! ```text
//! ẋ(t) = A₀ x(t) + L (−A(t) p(t) + Σ_k B_k(t) p(t − τ_k)),
//! A₀ = [0, I; −M⁻¹K, −M⁻¹C],   L = [0; M⁻¹]   (4×2).
//! ```
//!
//! # The discretization (Ding, Zhu, Zhang & Ding 2010, IJMTM 50:502, eq. 5–15)
//!
//! The period is cut into m sub-intervals `[t_i, t_{i+1}]`, `t_i = i Δt`,
//! `Δt = T/m`. The variation-of-constants formula over one sub-interval is
//! (Ding 2010 eq. 6)
//!
//! ```text
//! x_{i+1} = Φ₀ x_i + ∫₀^Δt e^{A₀(Δt−s)} L f(t_i + s) ds,   Φ₀ = e^{A₀Δt}.
//! ```
//!
//! Full discretization keeps `A₀` exact and approximates the forcing `f`:
//! the gains are the sub-interval averages carried by the [`DdeSample`]s
//! (as in first-order semi-discretization, Insperger & Stépán 2004 IJNME
//! 61:117 §3, which keeps interrupted cutting accurate), and the states are
//! interpolated linearly between grid points (Ding 2010 eq. 8–9):
//! `p(t_i + s) ≈ (1 − s/Δt) p_i + (s/Δt) p_{i+1}`, and the delayed value
//! `p(t − τ)` is itself a linear interpolation between the two grid points
//! around `t − τ` (first-order SDM's treatment of a delay that is not a
//! multiple of Δt, Insperger & Stépán 2004 eq. 19). With
//!
//! ```text
//! Φ₁ = ∫₀^Δt e^{A₀u} du,    Φ₂ = (1/Δt) ∫₀^Δt e^{A₀u} (Δt − u) du
//! ```
//!
//! (so `∫ e^{A₀(Δt−s)} (1 − s/Δt) ds = Φ₁ − Φ₂` and `∫ e^{A₀(Δt−s)} s/Δt ds = Φ₂`,
//! substituting u = Δt − s) the step becomes, with `G₁ = (Φ₁ − Φ₂) L`,
//! `G₂ = Φ₂ L` (4×2),
//!
//! ```text
//! x_{i+1} = Φ₀ x_i − G₁ A_i p_i − G₂ A_i p_{i+1}
//!           + Σ_k [G₁ B_{k,i} p(t_i − τ_k) + G₂ B_{k,i} p(t_{i+1} − τ_k)].
//! ```
//!
//! `p_{i+1}` appears on both sides (Ding 2010 eq. 13, the `(I − F₀,₁)⁻¹`
//! factor). Because `G₂ A_i` only acts on the displacement, the implicit
//! part reduces to a 2×2 solve: writing `W = G₂ A_i = [W₁; W₂]` (two 2×2
//! blocks), `p_{i+1} = (I + W₁)⁻¹ r_p` and `ṗ_{i+1} = r_v − W₂ p_{i+1}`
//! where `(r_p, r_v)` is the explicit right-hand side.
//!
//! # Φ₀, Φ₁, Φ₂ by one matrix exponential (Van Loan 1978)
//!
//! `exp([[A₀Δt, I, 0], [0, 0, I], [0, 0, 0]])` (12×12) has the blocks
//! `[e^{A₀Δt}, Φ₁/Δt, Φ₂/Δt]` in its first block row. Derivation: for
//! `C = [[A, I, 0], [0, 0, I], [0, 0, 0]]`, `e^{Cs}` has first block row
//! `[e^{As}, F₁(s), F₂(s)]` with `F₁' = A F₁ + I`, `F₂' = A F₂ + s I`,
//! `F₁(0) = F₂(0) = 0`, whose solutions are `F₁ = ∫₀^s e^{Au} du` and
//! `F₂ = ∫₀^s e^{Au}(s − u) du`; with `A = A₀Δt` and s = 1 the substitution
//! u → u/Δt gives `F₁ = Φ₁/Δt`, `F₂ = Φ₂/Δt`. The exponential is nalgebra's
//! scaling-and-squaring Padé approximant (Higham 2005). Everything here
//! depends on the modal model and the spindle speed only, so it is computed
//! once per speed ([`Discretization::new`]); the cutting depth and the
//! (state-dependent) gains only enter the cheap per-step data.
//!
//! # The monodromy map
//!
//! The discrete state at grid point i is `z_i = (x_i, p_{i−1}, …, p_{i−r})`
//! (dimension 4 + 2r) with r = ⌈τ_max/Δt⌉ past displacements. One period
//! maps `z_0 ↦ z_m = Φ z_0` (Ding 2010 eq. 15); the spectral radius of Φ
//! decides stability (Floquet theory, seed 004 section 2).

use nalgebra::{DMatrix, DVector, Matrix2, Matrix4, Matrix4x2, SMatrix, Vector2, Vector4};

use crate::error::{check_positive, ChatterError};
use crate::model::{Modal2, PeriodicDde};
use crate::spectral::{spectral_radius_arnoldi, spectral_radius_dense, ArnoldiOptions};

/// Default number of sub-intervals per period (issue 4: m ≥ 40).
pub const DEFAULT_STEPS: usize = 40;

/// Iteration cap of the dense reference eigen-solve (QR sweeps).
pub const DENSE_MAX_ITERATIONS: usize = 10_000;

/// Relative tolerance within which a delay is snapped to a whole number of
/// time steps (so that τ = T is exactly m steps despite rounding).
const SNAP: f64 = 1e-9;

/// Precomputed full discretization of one modal model at one spindle
/// speed (Ding et al. 2010; see the module documentation).
#[derive(Debug, Clone)]
pub struct Discretization {
    period: f64,
    steps: usize,
    dt: f64,
    max_delay: f64,
    history: usize,
    phi0: Matrix4<f64>,
    phi1: Matrix4<f64>,
    phi2: Matrix4<f64>,
    g1: Matrix4x2<f64>,
    g2: Matrix4x2<f64>,
}

/// One delayed term compiled for the stepping loop: the interpolation
/// stencils of `p(t_i − τ)` and `p(t_{i+1} − τ)` and the two 4×2 gains.
#[derive(Debug, Clone, Copy)]
struct CompiledDelay {
    /// Buffer index of the left grid point of `t_i − τ`, and its weight on
    /// the right neighbour.
    j0: usize,
    w0: f64,
    /// Same for `t_{i+1} − τ`.
    j1: usize,
    w1: f64,
    c1: Matrix4x2<f64>,
    c2: Matrix4x2<f64>,
}

/// One sub-interval compiled for the stepping loop.
#[derive(Debug, Clone, Copy)]
struct CompiledStep {
    /// `(I + W₁)⁻¹`.
    inv_top: Matrix2<f64>,
    /// `W₂`.
    w_bottom: Matrix2<f64>,
    /// `G₁ A_i`.
    present: Matrix4x2<f64>,
    /// Range of this step's delayed terms in the flat list.
    first_delay: usize,
    end_delay: usize,
}

/// A [`PeriodicDde`] compiled against a [`Discretization`]: everything
/// needed to apply the monodromy map to a vector in m cheap steps.
#[derive(Debug, Clone)]
pub struct CompiledDde {
    steps: Vec<CompiledStep>,
    delays: Vec<CompiledDelay>,
    history: usize,
    phi0: Matrix4<f64>,
}

impl Discretization {
    /// Precomputes `Φ₀ = e^{A₀Δt}`, `Φ₁`, `Φ₂` (module documentation) for
    /// one modal model and one period.
    ///
    /// # Arguments
    /// * `modal` — the tool-tip dynamics (validated here).
    /// * `period` — the principal period T [s] (tooth-passing period).
    /// * `steps` — number m of sub-intervals per period, ≥ 2 (use ≥ 40).
    /// * `max_delay` — the largest delay any equation used with this
    ///   discretization may have [s], ≥ T/m; fixes the state dimension
    ///   `4 + 2⌈max_delay/Δt⌉`.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] for an invalid modal model,
    /// period, m < 2 or a maximum delay below one step;
    /// [`ChatterError::NonFinite`] if the exponential overflows.
    pub fn new(
        modal: &Modal2,
        period: f64,
        steps: usize,
        max_delay: f64,
    ) -> Result<Self, ChatterError> {
        modal.validate()?;
        check_positive("period [s]", period)?;
        check_positive("maximum delay [s]", max_delay)?;
        if steps < 2 {
            return Err(ChatterError::InvalidParameter {
                name: "number of sub-intervals m".to_string(),
                value: steps as f64,
                reason: "must be >= 2 (use >= 40 for milling)".to_string(),
            });
        }
        let dt = period / steps as f64;
        let q_max = snap(max_delay / dt);
        if q_max < 1.0 {
            return Err(ChatterError::InvalidParameter {
                name: "maximum delay [s]".to_string(),
                value: max_delay,
                reason: format!("must be >= one time step T/m = {dt:e} s"),
            });
        }
        if q_max > 1e6 {
            return Err(ChatterError::InvalidParameter {
                name: "maximum delay [s]".to_string(),
                value: max_delay,
                reason: "needs more than 1e6 history steps".to_string(),
            });
        }
        let history = q_max.ceil() as usize;
        let minv = modal
            .mass
            .try_inverse()
            .ok_or(ChatterError::InvalidParameter {
                name: "mass matrix [kg]".to_string(),
                value: modal.mass.determinant(),
                reason: "is singular".to_string(),
            })?;
        let a0 = state_matrix(modal, &minv);
        let (phi0, phi1, phi2) = exponential_integrals(&a0, dt)?;
        let l_map = |phi: &Matrix4<f64>| -> Matrix4x2<f64> {
            let cols: Matrix4x2<f64> = phi.fixed_view::<4, 2>(0, 2).into_owned();
            cols * minv
        };
        let g1 = l_map(&(phi1 - phi2));
        let g2 = l_map(&phi2);
        Ok(Self {
            period,
            steps,
            dt,
            max_delay,
            history,
            phi0,
            phi1,
            phi2,
            g1,
            g2,
        })
    }

    /// Principal period T [s].
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Number of sub-intervals m.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Time step Δt = T/m [s].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Largest admissible delay [s].
    pub fn max_delay(&self) -> f64 {
        self.max_delay
    }

    /// Number r of past displacements in the discrete state.
    pub fn history_len(&self) -> usize {
        self.history
    }

    /// Dimension 4 + 2r of the monodromy matrix.
    pub fn dimension(&self) -> usize {
        4 + 2 * self.history
    }

    /// `Φ₀ = e^{A₀Δt}`, the free-vibration transition over one step.
    pub fn phi0(&self) -> &Matrix4<f64> {
        &self.phi0
    }

    /// `Φ₁ = ∫₀^Δt e^{A₀u} du`.
    pub fn phi1(&self) -> &Matrix4<f64> {
        &self.phi1
    }

    /// `Φ₂ = (1/Δt) ∫₀^Δt e^{A₀u} (Δt − u) du`.
    pub fn phi2(&self) -> &Matrix4<f64> {
        &self.phi2
    }

    /// Validates `dde` against this discretization and compiles its
    /// per-step data (interpolation stencils, 2×2 implicit solves).
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] / [`ChatterError::NonFinite`] for
    /// an invalid equation; [`ChatterError::Unsupported`] if its period or
    /// number of sub-intervals differ from this discretization's, or a
    /// delay lies outside `[T/m, max_delay]`, or an implicit step is
    /// singular.
    pub fn compile(&self, dde: &PeriodicDde) -> Result<CompiledDde, ChatterError> {
        dde.validate()?;
        if (dde.period - self.period).abs() > 1e-12 * self.period {
            return Err(ChatterError::Unsupported {
                reason: format!(
                    "equation period {} s differs from the discretization's {} s",
                    dde.period, self.period
                ),
            });
        }
        if dde.steps() != self.steps {
            return Err(ChatterError::Unsupported {
                reason: format!(
                    "equation has {} sub-intervals, the discretization {}",
                    dde.steps(),
                    self.steps
                ),
            });
        }
        let r = self.history;
        let mut steps = Vec::with_capacity(self.steps);
        let mut delays = Vec::new();
        for (i, sample) in dde.samples.iter().enumerate() {
            let w = self.g2 * sample.present;
            let top: Matrix2<f64> = Matrix2::identity() + w.fixed_view::<2, 2>(0, 0);
            let inv_top = top.try_inverse().ok_or_else(|| ChatterError::Unsupported {
                reason: format!("implicit step {i} is singular (present gain too large)"),
            })?;
            let first_delay = delays.len();
            for d in &sample.delayed {
                let q = snap(d.delay / self.dt);
                if q < 1.0 || q > r as f64 {
                    return Err(ChatterError::Unsupported {
                        reason: format!(
                            "delay {} s of sub-interval {i} is outside [T/m, max_delay] = [{}, {}] s",
                            d.delay, self.dt, self.max_delay
                        ),
                    });
                }
                let (j0, w0) = stencil(i as f64 - q, r, i);
                let (j1, w1) = stencil(i as f64 + 1.0 - q, r, i);
                delays.push(CompiledDelay {
                    j0,
                    w0,
                    j1,
                    w1,
                    c1: self.g1 * d.gain,
                    c2: self.g2 * d.gain,
                });
            }
            steps.push(CompiledStep {
                inv_top,
                w_bottom: w.fixed_view::<2, 2>(2, 0).into_owned(),
                present: self.g1 * sample.present,
                first_delay,
                end_delay: delays.len(),
            });
        }
        Ok(CompiledDde {
            steps,
            delays,
            history: r,
            phi0: self.phi0,
        })
    }

    /// The monodromy matrix Φ (dense, `(4+2r)×(4+2r)`), built column by
    /// column by the stepping map (Ding 2010 eq. 15). The reference path.
    ///
    /// # Errors
    /// As [`Discretization::compile`]; [`ChatterError::NonFinite`] if the
    /// product overflows.
    ///
    /// # Performance
    /// `4+2r` applications of the m-step map (≈ 0.1 ms at m = 40).
    pub fn monodromy(&self, dde: &PeriodicDde) -> Result<DMatrix<f64>, ChatterError> {
        let compiled = self.compile(dde)?;
        compiled.dense()
    }

    /// The chatter indicator |μ|max: spectral radius of the monodromy
    /// matrix, by the matrix-free Arnoldi iteration of
    /// [`crate::spectral::spectral_radius_arnoldi`] (relative accuracy
    /// ~1e-8), falling back to the dense capped QR reference if Arnoldi hits
    /// its restart cap.
    ///
    /// # Errors
    /// As [`Discretization::compile`]; [`ChatterError::NotConverged`] if
    /// the dense fallback also hits its iteration cap;
    /// [`ChatterError::NonFinite`] on overflow.
    pub fn spectral_radius(&self, dde: &PeriodicDde) -> Result<f64, ChatterError> {
        self.compile(dde)?.spectral_radius()
    }
}

impl CompiledDde {
    /// Dimension 4 + 2r of the monodromy matrix.
    pub fn dimension(&self) -> usize {
        4 + 2 * self.history
    }

    /// Applies the monodromy map `z_0 ↦ z_m` (module documentation) to
    /// `input` (length [`CompiledDde::dimension`]), writing `output`.
    /// `buffer` is scratch space (resized as needed).
    ///
    /// # Errors
    /// [`ChatterError::Unsupported`] for wrong vector lengths.
    pub fn apply(
        &self,
        input: &[f64],
        output: &mut [f64],
        buffer: &mut Vec<Vector2<f64>>,
    ) -> Result<(), ChatterError> {
        let n = self.dimension();
        if input.len() != n || output.len() != n {
            return Err(ChatterError::Unsupported {
                reason: format!(
                    "monodromy vectors must have length {n} (got {} and {})",
                    input.len(),
                    output.len()
                ),
            });
        }
        let r = self.history;
        let m = self.steps.len();
        // buffer[j] = p at grid point j − r, j = 0 ..= r + m.
        buffer.clear();
        buffer.resize(r + m + 1, Vector2::zeros());
        for k in 1..=r {
            buffer[r - k] = Vector2::new(input[4 + 2 * (k - 1)], input[5 + 2 * (k - 1)]);
        }
        let mut x = Vector4::new(input[0], input[1], input[2], input[3]);
        buffer[r] = x.fixed_rows::<2>(0).into_owned();
        for (i, step) in self.steps.iter().enumerate() {
            let p = buffer[r + i];
            let mut rhs = self.phi0 * x - step.present * p;
            for d in &self.delays[step.first_delay..step.end_delay] {
                let pd0 = interpolate(buffer, d.j0, d.w0);
                let pd1 = interpolate(buffer, d.j1, d.w1);
                rhs += d.c1 * pd0 + d.c2 * pd1;
            }
            let p_next = step.inv_top * rhs.fixed_rows::<2>(0);
            let v_next = rhs.fixed_rows::<2>(2) - step.w_bottom * p_next;
            x = Vector4::new(p_next[0], p_next[1], v_next[0], v_next[1]);
            buffer[r + i + 1] = p_next;
        }
        output[..4].copy_from_slice(x.as_slice());
        for k in 1..=r {
            let p = buffer[r + m - k];
            output[4 + 2 * (k - 1)] = p[0];
            output[5 + 2 * (k - 1)] = p[1];
        }
        Ok(())
    }

    /// The dense monodromy matrix (one [`CompiledDde::apply`] per column).
    ///
    /// # Errors
    /// [`ChatterError::NonFinite`] if an entry is not finite.
    pub fn dense(&self) -> Result<DMatrix<f64>, ChatterError> {
        let n = self.dimension();
        let mut out = DMatrix::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut col = vec![0.0; n];
        let mut buffer = Vec::new();
        for j in 0..n {
            e.iter_mut().for_each(|v| *v = 0.0);
            e[j] = 1.0;
            self.apply(&e, &mut col, &mut buffer)?;
            out.column_mut(j)
                .copy_from(&DVector::from_column_slice(&col));
        }
        if out.iter().any(|v| !v.is_finite()) {
            return Err(ChatterError::NonFinite {
                what: "monodromy matrix".to_string(),
            });
        }
        Ok(out)
    }

    /// Spectral radius of the monodromy matrix: Arnoldi (fast path), with
    /// the dense capped QR as fallback (see
    /// [`Discretization::spectral_radius`]).
    ///
    /// # Errors
    /// As [`Discretization::spectral_radius`].
    pub fn spectral_radius(&self) -> Result<f64, ChatterError> {
        let n = self.dimension();
        let mut buffer = Vec::new();
        let fast = spectral_radius_arnoldi(
            n,
            |v, out| self.apply(v, out, &mut buffer),
            &ArnoldiOptions::default(),
        );
        match fast {
            Ok(rho) => Ok(rho),
            Err(ChatterError::NotConverged { .. }) => {
                log::debug!("Arnoldi did not converge; dense spectral radius instead");
                spectral_radius_dense(&self.dense()?, DENSE_MAX_ITERATIONS)
            }
            Err(e) => Err(e),
        }
    }
}

/// `A₀ = [0, I; −M⁻¹K, −M⁻¹C]` (module documentation).
fn state_matrix(modal: &Modal2, minv: &Matrix2<f64>) -> Matrix4<f64> {
    let mut a0 = Matrix4::zeros();
    a0.fixed_view_mut::<2, 2>(0, 2)
        .copy_from(&Matrix2::identity());
    a0.fixed_view_mut::<2, 2>(2, 0)
        .copy_from(&(-minv * modal.stiffness));
    a0.fixed_view_mut::<2, 2>(2, 2)
        .copy_from(&(-minv * modal.damping));
    a0
}

/// `(Φ₀, Φ₁, Φ₂)` of the module documentation.
pub type ExpIntegrals = (Matrix4<f64>, Matrix4<f64>, Matrix4<f64>);

/// `(e^{AΔt}, ∫₀^Δt e^{Au} du, (1/Δt)∫₀^Δt e^{Au}(Δt − u) du)` by the
/// 12×12 block exponential of the module documentation (Van Loan 1978).
///
/// # Errors
/// [`ChatterError::NonFinite`] if the exponential is not finite.
pub fn exponential_integrals(a: &Matrix4<f64>, dt: f64) -> Result<ExpIntegrals, ChatterError> {
    check_positive("time step [s]", dt)?;
    if a.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "state matrix".to_string(),
        });
    }
    let mut c = SMatrix::<f64, 12, 12>::zeros();
    c.fixed_view_mut::<4, 4>(0, 0).copy_from(&(a * dt));
    c.fixed_view_mut::<4, 4>(0, 4)
        .copy_from(&Matrix4::identity());
    c.fixed_view_mut::<4, 4>(4, 8)
        .copy_from(&Matrix4::identity());
    let e = c.exp();
    if e.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "matrix exponential of the state matrix".to_string(),
        });
    }
    let phi0 = e.fixed_view::<4, 4>(0, 0).into_owned();
    let phi1 = e.fixed_view::<4, 4>(0, 4).into_owned() * dt;
    let phi2 = e.fixed_view::<4, 4>(0, 8).into_owned() * dt;
    Ok((phi0, phi1, phi2))
}

/// Rounds `q` to the nearest integer when it is within [`SNAP`] of it.
fn snap(q: f64) -> f64 {
    let rq = q.round();
    if (q - rq).abs() <= SNAP * rq.abs().max(1.0) {
        rq
    } else {
        q
    }
}

/// Interpolation stencil of grid coordinate `s` (time `s Δt`, s ≥ −r, at
/// most `i`): buffer index of the left neighbour and weight of the right.
fn stencil(s: f64, r: usize, i: usize) -> (usize, f64) {
    let fl = s.floor();
    let w = s - fl;
    // Buffer index of grid point fl is fl + r, clamped into the valid range
    // (the caller guarantees −r ≤ s ≤ i up to the snapping tolerance).
    let j = (fl + r as f64).max(0.0) as usize;
    let j = j.min(r + i);
    if j == r + i {
        (j, 0.0)
    } else {
        (j, w)
    }
}

#[inline]
fn interpolate(buffer: &[Vector2<f64>], j: usize, w: f64) -> Vector2<f64> {
    if w == 0.0 {
        buffer[j]
    } else {
        buffer[j] * (1.0 - w) + buffer[j + 1] * w
    }
}
