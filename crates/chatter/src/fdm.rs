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
//! # The discretization (Ding, Zhu, Zhang & Ding 2010, IJMTM 50:502, eq. 5–15, with a cubic delayed-state interpolation)
//!
//! The period is cut into m sub-intervals `[t_i, t_{i+1}]`, `t_i = i Δt`,
//! `Δt = T/m`. The variation-of-constants formula over one sub-interval is
//! (Ding 2010 eq. 6)
//!
//! ```text
//! x_{i+1} = Φ₀ x_i + ∫₀^Δt e^{A₀(Δt−s)} L f(t_i + s) ds,   Φ₀ = e^{A₀Δt}.
//! ```
//!
//! Full discretization keeps `A₀` exact and approximates the forcing `f`
//! by polynomials in `u = s/Δt ∈ [0, 1]`, so that only the moments
//!
//! ```text
//! Ψ_n = ∫₀^Δt e^{A₀(Δt−s)} (s/Δt)ⁿ ds,   n = 0 … 3
//! ```
//!
//! are needed (`Ψ₀ = Φ₁`, `Ψ₁ = Φ₂` in Ding's notation); they depend on the
//! modal model and Δt only. The gains are the sub-interval averages carried
//! by the [`DdeSample`](crate::model::DdeSample)s (as in first-order semi-discretization, Insperger &
//! Stépán 2004 IJNME 61:117 §3, which keeps interrupted cutting accurate).
//!
//! * Present term `−A_i p(t)`: linear interpolation between `p_i` and
//!   `p_{i+1}` (Ding 2010 eq. 8), weights `Ψ₀ − Ψ₁` and `Ψ₁`. (A quadratic
//!   interpolation through `p_{i−1}, p_i, p_{i+1}` as in the second-order
//!   FDM of Ding et al. 2010, IJMTM 50:926, was tried: for the textbook
//!   oscillator at ω_n Δt ≈ 0.9 it made |μ| worse, 5 % instead of 0.2 %
//!   (presumably a parasitic root of the multistep formula), so it is not
//!   used.)
//! * Delayed terms `B_k p(t − τ_k)`: `t_i + s − τ` is grid coordinate
//!   `σ = i − q + u` (`q = τ/Δt`, any positive real ≥ 1, not only m).
//!   `p` is interpolated by the cubic Lagrange polynomial through the four
//!   consecutive past grid points `n₀ … n₀+3` around `[i − q, i + 1 − q]`
//!   (`n₀ = ⌊i − q⌋ − 1`, moved back if `n₀ + 3 > i` so that only known
//!   values are used). Writing each Lagrange basis polynomial in monomials,
//!   `ℓ_k(u) = Σ_n a_{kn} uⁿ`, its weight matrix is `Σ_n a_{kn} Ψ_n`.
//!   This generalizes the linear interpolation of first-order SDM
//!   (Insperger & Stépán 2004 eq. 19) and of Ding 2010 eq. 9; with linear
//!   interpolation the delayed term dominated the error (2 % in |μ| at
//!   ω_n Δt ≈ 0.9, against 0.2 % for the present term).
//!
//! With `L Ψ = Ψ[:, 2..4] M⁻¹` the step is
//!
//! ```text
//! x_{i+1} = Φ₀ x_i − L(Ψ₀ − Ψ₁) A_i p_i − LΨ₁ A_i p_{i+1}
//!           + Σ_k Σ_{l=0}^{3} LΨ_{(k,l)} B_{k,i} p_{n₀+l}.
//! ```
//!
//! `p_{i+1}` appears on both sides (Ding 2010 eq. 13, the `(I − F₀,₁)⁻¹`
//! factor). Because it only enters through the displacement, the implicit
//! part reduces to a 2×2 solve: writing `W = LΨ₁ A_i = [W₁; W₂]` (two
//! 2×2 blocks), `p_{i+1} = (I + W₁)⁻¹ r_p` and `ṗ_{i+1} = r_v − W₂ p_{i+1}`
//! where `(r_p, r_v)` is the explicit right-hand side.
//!
//! # The moments by one matrix exponential (Van Loan 1978)
//!
//! For the 20×20 block matrix `C = [[A₀Δt, I, 0, 0, 0], [0, 0, I, 0, 0],
//! [0, 0, 0, I, 0], [0, 0, 0, 0, I], 0]`, `e^{C}` has the first block row
//! `[e^{A₀Δt}, G₁, G₂, G₃, G₄]` with `G_{n+1} = ∫₀¹ e^{A₀Δtσ} (1 − σ)ⁿ/n! dσ`.
//! Derivation: `(e^{Cs})' = e^{Cs} C`, so the first block row
//! `[E, F₁, …, F₄](s)` satisfies `E' = E A`, `F₁' = E`, `F_{n+1}' = F_n`
//! with zero initial values: `F₁(s) = ∫₀^s e^{Av} dv` and, by Cauchy's
//! repeated-integration formula, `F_{n+1}(s) = ∫₀^s e^{Av} (s − v)ⁿ/n! dv`;
//! s = 1 with `A = A₀Δt` gives `G_{n+1}`. Substituting `s = Δt(1 − σ)` in
//! `Ψ_n` gives `Ψ_n = Δt · n! · G_{n+1}`. The exponential is nalgebra's
//! scaling-and-squaring Padé approximant (Higham 2005). Everything here
//! depends on the modal model and the spindle speed only, so it is computed
//! once per speed ([`Discretization::new`]); the cutting depth and the
//! (state-dependent) gains only enter the cheap per-step data.
//!
//! # The monodromy map
//!
//! The discrete state at grid point i is `z_i = (x_i, p_{i−1}, …, p_{i−r})`
//! (dimension 4 + 2r) with `r = max(⌈τ_max/Δt⌉ + 1, 3)` past displacements
//! (one more than the delay needs, for the cubic stencil). One period maps
//! `z_0 ↦ z_m = Φ z_0` (Ding 2010 eq. 15); the spectral radius of Φ decides
//! stability (Floquet theory, seed 004 section 2).

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

/// Number of interpolation nodes of a delayed term (cubic).
const NODES: usize = 4;

/// `[Φ₀, Ψ₀, Ψ₁, Ψ₂, Ψ₃]` of the module documentation.
pub type ExpMoments = [Matrix4<f64>; 5];

/// Precomputed full discretization of one modal model at one spindle
/// speed (Ding et al. 2010; see the module documentation).
#[derive(Debug, Clone)]
pub struct Discretization {
    period: f64,
    steps: usize,
    dt: f64,
    max_delay: f64,
    history: usize,
    moments: ExpMoments,
    /// `LΨ_n = Ψ_n[:, 2..4] M⁻¹`, n = 0 … 3.
    l_psi: [Matrix4x2<f64>; 4],
}

/// One delayed term compiled for the stepping loop: buffer index of its
/// first interpolation node and the four node gains `LΨ_(k,l) B`.
#[derive(Debug, Clone, Copy)]
struct CompiledDelay {
    first_node: usize,
    gains: [Matrix4x2<f64>; NODES],
}

/// One sub-interval compiled for the stepping loop.
#[derive(Debug, Clone, Copy)]
struct CompiledStep {
    /// `(I + W₁)⁻¹`.
    inv_top: Matrix2<f64>,
    /// `W₂`.
    w_bottom: Matrix2<f64>,
    /// `LΨ_(0) A_i` (weight of `p_i`).
    present_now: Matrix4x2<f64>,
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
    /// Precomputes `Φ₀ = e^{A₀Δt}` and the moments `Ψ₀ … Ψ₃` (module
    /// documentation) for one modal model and one period.
    ///
    /// # Arguments
    /// * `modal` — the tool-tip dynamics (validated here).
    /// * `period` — the principal period T [s] (tooth-passing period).
    /// * `steps` — number m of sub-intervals per period, ≥ 2 (use ≥ 40).
    /// * `max_delay` — the largest delay any equation used with this
    ///   discretization may have [s], ≥ T/m; fixes the state dimension
    ///   `4 + 2 max(⌈max_delay/Δt⌉ + 1, 3)`.
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
        let history = (q_max.ceil() as usize + 1).max(3);
        let minv = modal.mass_inverse()?;
        let a0 = state_matrix(modal, &minv);
        let moments = exponential_moments(&a0, dt)?;
        let l_map = |psi: &Matrix4<f64>| -> Matrix4x2<f64> {
            let cols: Matrix4x2<f64> = psi.fixed_view::<4, 2>(0, 2).into_owned();
            cols * minv
        };
        let l_psi = [
            l_map(&moments[1]),
            l_map(&moments[2]),
            l_map(&moments[3]),
            l_map(&moments[4]),
        ];
        Ok(Self {
            period,
            steps,
            dt,
            max_delay,
            history,
            moments,
            l_psi,
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
        &self.moments[0]
    }

    /// `Φ₁ = Ψ₀ = ∫₀^Δt e^{A₀u} du`.
    pub fn phi1(&self) -> &Matrix4<f64> {
        &self.moments[1]
    }

    /// `Φ₂ = Ψ₁ = (1/Δt) ∫₀^Δt e^{A₀u} (Δt − u) du`.
    pub fn phi2(&self) -> &Matrix4<f64> {
        &self.moments[2]
    }

    /// The moment `Ψ_n = ∫₀^Δt e^{A₀(Δt−s)} (s/Δt)ⁿ ds`, n = 0 … 3 (`None`
    /// for larger n).
    pub fn moment(&self, n: usize) -> Option<&Matrix4<f64>> {
        if n < 4 {
            self.moments.get(n + 1)
        } else {
            None
        }
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
        let [lp0, lp1, _, _] = self.l_psi;
        // Linear present-term weights (module documentation).
        let w_now = lp0 - lp1;
        let w_next = lp1;
        let q_limit = snap(self.max_delay / self.dt);
        let mut steps = Vec::with_capacity(self.steps);
        let mut delays = Vec::new();
        for (i, sample) in dde.samples.iter().enumerate() {
            let w = w_next * sample.present;
            let top: Matrix2<f64> = Matrix2::identity() + w.fixed_view::<2, 2>(0, 0);
            let inv_top = top.try_inverse().ok_or_else(|| ChatterError::Unsupported {
                reason: format!("implicit step {i} is singular (present gain too large)"),
            })?;
            let first_delay = delays.len();
            for d in &sample.delayed {
                let q = snap(d.delay / self.dt);
                if q < 1.0 || q > q_limit {
                    return Err(ChatterError::Unsupported {
                        reason: format!(
                            "delay {} s of sub-interval {i} is outside [T/m, max_delay] = [{}, {}] s",
                            d.delay, self.dt, self.max_delay
                        ),
                    });
                }
                let (first_node, weights) = self.delay_stencil(i, q);
                delays.push(CompiledDelay {
                    first_node,
                    gains: weights.map(|w| w * d.gain),
                });
            }
            steps.push(CompiledStep {
                inv_top,
                w_bottom: w.fixed_view::<2, 2>(2, 0).into_owned(),
                present_now: w_now * sample.present,
                first_delay,
                end_delay: delays.len(),
            });
        }
        Ok(CompiledDde {
            steps,
            delays,
            history: r,
            phi0: self.moments[0],
        })
    }

    /// Cubic interpolation stencil of `p(t_i + s − τ)`, `τ = q Δt`: buffer
    /// index of the first of four consecutive nodes, and the four weights
    /// `Σ_n a_{kn} LΨ_n` (module documentation).
    fn delay_stencil(&self, i: usize, q: f64) -> (usize, [Matrix4x2<f64>; NODES]) {
        let r = self.history as f64;
        let s0 = i as f64 - q; // grid coordinate of u = 0
        let n0 = (s0.floor() - 1.0).min(i as f64 - 3.0).max(-r);
        let nodes: [f64; NODES] = [0.0, 1.0, 2.0, 3.0].map(|k| n0 + k - s0);
        let mut weights = [Matrix4x2::zeros(); NODES];
        for (k, weight) in weights.iter_mut().enumerate() {
            // Monomial coefficients of ℓ_k(u) = Π_{l≠k} (u − u_l)/(u_k − u_l).
            let mut poly = [1.0, 0.0, 0.0, 0.0];
            let mut denom = 1.0;
            for (l, &ul) in nodes.iter().enumerate() {
                if l == k {
                    continue;
                }
                let mut next = [0.0; 4];
                for deg in 0..3 {
                    next[deg + 1] += poly[deg];
                    next[deg] -= ul * poly[deg];
                }
                poly = next;
                denom *= nodes[k] - ul;
            }
            *weight = poly
                .iter()
                .zip(&self.l_psi)
                .fold(Matrix4x2::zeros(), |acc, (a, lp)| acc + lp * (a / denom));
        }
        ((n0 + r) as usize, weights)
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
    ///
    /// # Performance
    /// ≈ 0.09–0.11 ms at m = 40 (release build; see `benches/indicator.rs`),
    /// mostly the two Ritz-value checks (real Schur form of the 12×12 and
    /// 16×16 Hessenberg matrices) and the Gram–Schmidt products.
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
            let mut rhs = self.phi0 * x - step.present_now * buffer[r + i];
            for d in &self.delays[step.first_delay..step.end_delay] {
                let nodes = &buffer[d.first_node..d.first_node + NODES];
                for (g, p) in d.gains.iter().zip(nodes) {
                    rhs += g * p;
                }
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

/// `[e^{AΔt}, Ψ₀, Ψ₁, Ψ₂, Ψ₃]` with `Ψ_n = ∫₀^Δt e^{A(Δt−s)} (s/Δt)ⁿ ds`,
/// by the 20×20 block exponential of the module documentation (Van Loan
/// 1978): `Ψ_n = Δt n! G_{n+1}`.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for a bad Δt,
/// [`ChatterError::NonFinite`] if `a` or the exponential is not finite.
pub fn exponential_moments(a: &Matrix4<f64>, dt: f64) -> Result<ExpMoments, ChatterError> {
    check_positive("time step [s]", dt)?;
    if a.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "state matrix".to_string(),
        });
    }
    let mut c = SMatrix::<f64, 20, 20>::zeros();
    c.fixed_view_mut::<4, 4>(0, 0).copy_from(&(a * dt));
    for b in 0..4 {
        c.fixed_view_mut::<4, 4>(4 * b, 4 * (b + 1))
            .copy_from(&Matrix4::identity());
    }
    let e = c.exp();
    if e.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "matrix exponential of the state matrix".to_string(),
        });
    }
    let block = |b: usize| -> Matrix4<f64> { e.fixed_view::<4, 4>(0, 4 * b).into_owned() };
    Ok([
        block(0),
        block(1) * dt,
        block(2) * dt,
        block(3) * (2.0 * dt),
        block(4) * (6.0 * dt),
    ])
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
