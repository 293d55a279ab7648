//! Clamped B-splines on the normalized arc length u in [0, 1], after
//! seed 001 (Ding, Indri, Rizzo, *Machines* 13(5):339, 2025) eq. 5-26, for
//! the MJTO planner (`kerf_mjto`).
//!
//! A joint trajectory is `q(u) = Σ_{j=0}^{n} Θ_j N_{j,k}(u)` (eq. 5) with
//! clamped knots; the planner uses quintics (k = 5). This crate gives the
//! pieces its jerk-minimizing QPs are built from:
//!
//! | item | seed 001 |
//! |---|---|
//! | [`KnotVector`]: clamped knots, spans, basis functions and derivatives (NURBS Book A2.1, A2.3) | eq. 5, 8-10 |
//! | [`collocation()`], [`basis_row`]: rows `N^{(r)}_{j,k}(u)` as [`BandRows`] | eq. 35, 45, 49, 59 |
//! | [`derivative_operator`], [`derivative_knots`]: Θ ↦ Θ^{r} and the knots of the derivative curve | eq. 11-12, 21-26, 36-38 |
//! | [`jerk_hessian`]: exact `∫ N'''_i N'''_j du`, banded ([`BandedSym`]) | eq. 17-19 |
//! | [`fit()`], [`normal_matrix`]: least-squares and interpolating fits | eq. 49-52 |
//! | [`BSpline`]: a scalar spline, value and derivatives | eq. 5, 8-10 |
//!
//! [`derivative_operator`] implements the exact derivative recursion, which
//! differs from the paper's eq. 12 and eq. 22-26 on the first and last k
//! spans of a clamped knot vector (the paper's forms assume uniform knot
//! spacing); see its documentation.
//!
//! All functions taking a parameter u reject NaN, infinities and u outside
//! [0, 1] (beyond 1e-12) with a [`BsplineError`]; the few infallible
//! evaluators ([`KnotVector::basis_derivs`], [`BSpline::eval`]) clamp u and
//! propagate NaN into their output. Nothing panics on user input.
//!
//! # Example
//!
//! Fit a quintic to samples of a cubic (reproduced exactly), then check its
//! derivatives, its derivative coefficients and its jerk cost.
//!
//! ```
//! use kerf_bspline::{derivative_knots, derivative_operator, fit, jerk_hessian, BSpline, KnotVector};
//!
//! # fn main() -> Result<(), kerf_bspline::BsplineError> {
//! let kv = KnotVector::clamped_uniform(5, 12)?;
//! let params: Vec<f64> = (0..40).map(|i| i as f64 / 39.0).collect();
//! let q = |u: f64| 2.0 * u * u * u - u + 0.5; // q''' = 12
//! let values: Vec<f64> = params.iter().map(|&u| q(u)).collect();
//! let spline = BSpline::new(kv.clone(), fit(&kv, &params, &values)?)?;
//!
//! let [v, d1, d2, d3] = spline.eval(0.3);
//! assert!((v - q(0.3)).abs() < 1e-12);
//! assert!((d1 - (6.0 * 0.09 - 1.0)).abs() < 1e-10);
//! assert!((d2 - 6.0 * 2.0 * 0.3).abs() < 1e-9);
//! assert!((d3 - 12.0).abs() < 1e-7);
//!
//! // Third-derivative coefficients Θ^{3} = D_3 Θ: a constant jerk curve.
//! let theta3 = derivative_operator(&kv, 3)?.mul_vec(spline.coeffs());
//! let jerk = BSpline::new(derivative_knots(&kv, 3)?, theta3)?;
//! assert!((jerk.eval(0.7)[0] - 12.0).abs() < 1e-7);
//!
//! // Θ^T H Θ = ∫_0^1 q'''(u)^2 du = 144.
//! let h = jerk_hessian(&kv)?;
//! let hx = h.mul_vec(spline.coeffs());
//! let cost: f64 = hx.iter().zip(spline.coeffs()).map(|(a, b)| a * b).sum();
//! assert!((cost - 144.0).abs() < 1e-6);
//! # Ok(())
//! # }
//! ```

pub mod band;
pub mod banded_sym;
pub mod collocation;
pub mod derivative;
pub mod error;
pub mod fit;
pub mod hessian;
pub mod knots;
pub mod spline;

pub use band::{BandRow, BandRows};
pub use banded_sym::BandedSym;
pub use collocation::{basis_row, collocation};
pub use derivative::{derivative_knots, derivative_operator};
pub use error::BsplineError;
pub use fit::{fit, normal_matrix, normal_rhs};
pub use hessian::{derivative_gram, gauss_legendre, jerk_hessian};
pub use knots::KnotVector;
pub use spline::BSpline;
