//! The chatter indicator |μ|max: the spectral radius of the monodromy
//! matrix (Floquet theory; seed 004 section 2 — the milling DDE is
//! asymptotically stable iff every characteristic multiplier μ satisfies
//! |μ| < 1).
//!
//! Two solvers, both capped in iterations:
//!
//! * [`spectral_radius_dense`] — the reference: real Schur form by
//!   nalgebra's shifted QR (`Schur::try_new`), which reports
//!   non-convergence instead of looping.
//! * [`spectral_radius_arnoldi`] — the fast path, matrix-free: the
//!   monodromy matrix is only applied to vectors (m cheap steps each, see
//!   [`crate::fdm`]). Arnoldi's method (Saad, *Numerical Methods for Large
//!   Eigenvalue Problems*, 2nd ed. 2011, Alg. 6.1 with re-orthogonalized
//!   modified Gram–Schmidt) builds a Krylov basis `V_k` and the Hessenberg
//!   matrix `H_k = V_kᵀ Φ V_k`; the Ritz values (eigenvalues of `H_k`)
//!   converge to the outermost eigenvalues first. The residual of a Ritz
//!   pair (θ, V_k y) is `|h_{k+1,k}| |e_kᵀ y| / ‖y‖` (Saad 2011 Prop. 6.8),
//!   which is the stopping test. Dominant multipliers may be a complex pair
//!   (Hopf), real negative (flip) or real positive, which is why a plain
//!   power iteration is not used: the Ritz values resolve all three. If the
//!   basis reaches its maximum size first, the iteration restarts
//!   explicitly (Saad 2011 §7.1) from the sum of the real and imaginary
//!   parts of the leading Ritz vectors; the number of restarts is capped.

use nalgebra::{Complex, DMatrix};

use crate::error::ChatterError;

/// Spectral radius of a dense square matrix by the real Schur form
/// (shifted QR), the reference solver.
///
/// # Arguments
/// * `m` — square matrix with finite entries.
/// * `max_iterations` — cap on QR iterations (nalgebra's `max_niter`; 0 is
///   refused because nalgebra reads it as "no cap").
///
/// # Returns
/// `max |λ_i(m)|`.
///
/// # Errors
/// [`ChatterError::Unsupported`] for a non-square or empty matrix,
/// [`ChatterError::NonFinite`] for non-finite entries,
/// [`ChatterError::InvalidParameter`] for a zero cap,
/// [`ChatterError::NotConverged`] when QR hits the cap.
pub fn spectral_radius_dense(m: &DMatrix<f64>, max_iterations: usize) -> Result<f64, ChatterError> {
    let lambda = eigenvalues_dense(m, max_iterations)?;
    let rho = lambda.iter().map(|z| z.norm()).fold(0.0, f64::max);
    if rho.is_finite() {
        Ok(rho)
    } else {
        Err(ChatterError::NonFinite {
            what: "spectral radius (dense)".to_string(),
        })
    }
}

/// All eigenvalues of a dense square matrix by the capped real Schur form
/// (see [`spectral_radius_dense`] for arguments and errors).
///
/// # Errors
/// As [`spectral_radius_dense`].
pub fn eigenvalues_dense(
    m: &DMatrix<f64>,
    max_iterations: usize,
) -> Result<Vec<Complex<f64>>, ChatterError> {
    if m.nrows() != m.ncols() || m.nrows() == 0 {
        return Err(ChatterError::Unsupported {
            reason: format!(
                "eigenvalues need a non-empty square matrix (got {}x{})",
                m.nrows(),
                m.ncols()
            ),
        });
    }
    if max_iterations == 0 {
        return Err(ChatterError::InvalidParameter {
            name: "QR iteration cap".to_string(),
            value: 0.0,
            reason: "must be >= 1".to_string(),
        });
    }
    if m.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "matrix given to the eigen-solver".to_string(),
        });
    }
    let schur = nalgebra::Schur::try_new(m.clone(), f64::EPSILON, max_iterations).ok_or(
        ChatterError::NotConverged {
            what: "real Schur form (shifted QR)".to_string(),
            iterations: max_iterations,
            residual: f64::NAN,
        },
    )?;
    let lambda: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().collect();
    if lambda
        .iter()
        .any(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        return Err(ChatterError::NonFinite {
            what: "eigenvalues (dense)".to_string(),
        });
    }
    Ok(lambda)
}

/// Settings of [`spectral_radius_arnoldi`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArnoldiOptions {
    /// Maximum Krylov dimension per cycle (clamped to the matrix size).
    pub max_dimension: usize,
    /// First convergence check at this dimension, then every
    /// `check_every` vectors.
    pub first_check: usize,
    /// Vectors between convergence checks.
    pub check_every: usize,
    /// Cap on explicit restarts; reaching it returns
    /// [`ChatterError::NotConverged`].
    pub max_restarts: usize,
    /// Relative residual `‖Φv − θv‖ / |θ|` at which the dominant Ritz
    /// value is accepted.
    pub tolerance: f64,
    /// Seed of the pseudo-random start vector.
    pub seed: u64,
}

impl Default for ArnoldiOptions {
    fn default() -> Self {
        Self {
            max_dimension: 60,
            first_check: 12,
            check_every: 4,
            max_restarts: 20,
            tolerance: 1e-10,
            seed: 0x9e37_79b9_7f4a_7c15,
        }
    }
}

/// Spectral radius of the linear map `apply` (dimension `n`) by restarted
/// Arnoldi (module documentation), never forming its matrix.
///
/// # Arguments
/// * `n` — dimension of the map.
/// * `apply` — writes `Φ v` into its second argument.
/// * `opts` — caps and tolerance.
///
/// # Returns
/// `max |μ|` to ~`tolerance` relative accuracy (well-conditioned dominant
/// multipliers; the residual bounds the error of a non-normal matrix's
/// eigenvalue only up to its condition number).
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for n = 0 or bad options;
/// errors of `apply`; [`ChatterError::NonFinite`] if a product is not
/// finite; [`ChatterError::NotConverged`] after `max_restarts` restarts.
pub fn spectral_radius_arnoldi<F>(
    n: usize,
    mut apply: F,
    opts: &ArnoldiOptions,
) -> Result<f64, ChatterError>
where
    F: FnMut(&[f64], &mut [f64]) -> Result<(), ChatterError>,
{
    if n == 0 {
        return Err(ChatterError::InvalidParameter {
            name: "matrix dimension".to_string(),
            value: 0.0,
            reason: "must be >= 1".to_string(),
        });
    }
    if opts.max_dimension < 2
        || opts.check_every == 0
        || opts.tolerance.is_nan()
        || opts.tolerance <= 0.0
    {
        return Err(ChatterError::InvalidParameter {
            name: "Arnoldi options".to_string(),
            value: opts.max_dimension as f64,
            reason: "need max_dimension >= 2, check_every >= 1, tolerance > 0".to_string(),
        });
    }
    let kmax = opts.max_dimension.min(n);
    // Krylov basis, column-major: v_j = basis[j*n .. (j+1)*n].
    let mut basis = vec![0.0; n * (kmax + 1)];
    let mut h = DMatrix::<f64>::zeros(kmax + 1, kmax);
    let mut w = vec![0.0; n];
    let mut start = pseudo_random(n, opts.seed);
    let mut last_residual = f64::NAN;
    let mut previous_rho = f64::NAN;

    for _restart in 0..=opts.max_restarts {
        let norm = norm2(&start);
        if !(norm > 0.0 && norm.is_finite()) {
            return Err(ChatterError::NonFinite {
                what: "Arnoldi start vector".to_string(),
            });
        }
        for (b, s) in basis[..n].iter_mut().zip(&start) {
            *b = s / norm;
        }
        h.fill(0.0);
        let mut k = 0;
        while k < kmax {
            let (done, rest) = basis.split_at_mut((k + 1) * n);
            let vk = &done[k * n..];
            apply(vk, &mut w)?;
            if w.iter().any(|v| !v.is_finite()) {
                return Err(ChatterError::NonFinite {
                    what: "monodromy-vector product".to_string(),
                });
            }
            let wnorm0 = norm2(&w);
            // Modified Gram–Schmidt, twice (re-orthogonalization).
            for _pass in 0..2 {
                for j in 0..=k {
                    let vj = &done[j * n..(j + 1) * n];
                    let c = dot(vj, &w);
                    h[(j, k)] += c;
                    w.iter_mut().zip(vj).for_each(|(wi, vi)| *wi -= c * vi);
                }
            }
            let beta = norm2(&w);
            h[(k + 1, k)] = beta;
            k += 1;
            let breakdown = beta <= 1e-13 * wnorm0.max(f64::MIN_POSITIVE) || beta == 0.0;
            let check = breakdown
                || k == kmax
                || (k >= opts.first_check
                    && (k - opts.first_check).is_multiple_of(opts.check_every));
            if !breakdown {
                let vnext = &mut rest[..n];
                vnext.iter_mut().zip(&w).for_each(|(v, wi)| *v = wi / beta);
            }
            if !check {
                continue;
            }
            let hk = h.view((0, 0), (k, k)).into_owned();
            let ritz = eigenvalues_dense(&hk, 100 * k.max(10))?;
            let (imax, theta) = ritz
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.norm().total_cmp(&b.1.norm()))
                .map(|(i, z)| (i, *z))
                .ok_or_else(|| ChatterError::NonFinite {
                    what: "Ritz values".to_string(),
                })?;
            let rho = theta.norm();
            if breakdown {
                // Invariant subspace: the Ritz values are exact eigenvalues.
                return Ok(rho);
            }
            let stable = (rho - previous_rho).abs() <= 1e-6 * rho;
            previous_rho = rho;
            if !stable && k < kmax {
                // Not accepted whatever the residual, and no restart: the
                // Ritz vector is not needed (a restart cycle always ends
                // with a check at k = kmax, which computes it).
                continue;
            }
            let y = hessenberg_eigenvector(&hk, theta)?;
            let ynorm = y.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
            let last = y.last().map(|z| z.norm()).unwrap_or(f64::NAN);
            let residual = beta * last / ynorm;
            last_residual = residual / rho.max(f64::MIN_POSITIVE);
            let scale = rho.max(1e-12 * hk.norm());
            if residual <= opts.tolerance * scale && stable {
                return Ok(rho);
            }
            if k == kmax {
                if kmax == n {
                    // Full basis (h_{n+1,n} ≈ 0 up to rounding): exact.
                    return Ok(rho);
                }
                // Explicit restart from the leading Ritz vectors.
                start = restart_vector(&basis, n, k, &hk, &ritz, imax)?;
            }
        }
    }
    Err(ChatterError::NotConverged {
        what: "spectral radius (restarted Arnoldi)".to_string(),
        iterations: opts.max_restarts,
        residual: last_residual,
    })
}

/// Restart vector: Σ over the (up to 4) largest-modulus Ritz pairs of
/// `Re(V y) + Im(V y)`, which spans the real invariant subspace of a
/// complex pair as well as a real eigenvector.
fn restart_vector(
    basis: &[f64],
    n: usize,
    k: usize,
    hk: &DMatrix<f64>,
    ritz: &[Complex<f64>],
    imax: usize,
) -> Result<Vec<f64>, ChatterError> {
    let mut order: Vec<usize> = (0..ritz.len()).collect();
    order.sort_by(|a, b| ritz[*b].norm().total_cmp(&ritz[*a].norm()));
    let mut out = vec![0.0; n];
    let mut taken = 0;
    for &i in std::iter::once(&imax).chain(order.iter()) {
        if taken >= 4 {
            break;
        }
        if i == imax && taken > 0 {
            continue;
        }
        // Skip the conjugate twin of a pair already taken.
        if ritz[i].im < 0.0 {
            continue;
        }
        let y = hessenberg_eigenvector(hk, ritz[i])?;
        let ynorm = y.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        for (j, yj) in y.iter().enumerate().take(k) {
            let c = (yj.re + yj.im) / ynorm;
            let vj = &basis[j * n..(j + 1) * n];
            out.iter_mut().zip(vj).for_each(|(o, v)| *o += c * v);
        }
        taken += 1;
    }
    Ok(out)
}

/// Eigenvector of the small matrix `hk` for the eigenvalue estimate
/// `theta`, by two steps of complex inverse iteration with a slightly
/// shifted `theta` (so that the solve is never exactly singular).
fn hessenberg_eigenvector(
    hk: &DMatrix<f64>,
    theta: Complex<f64>,
) -> Result<Vec<Complex<f64>>, ChatterError> {
    let k = hk.nrows();
    let scale = hk.norm().max(f64::MIN_POSITIVE);
    let shift = theta + Complex::new(1e-10 * scale, 1e-10 * scale);
    let a = DMatrix::<Complex<f64>>::from_fn(k, k, |i, j| {
        let v = Complex::new(hk[(i, j)], 0.0);
        if i == j {
            v - shift
        } else {
            v
        }
    });
    let lu = a.lu();
    let mut y = nalgebra::DVector::<Complex<f64>>::from_element(k, Complex::new(1.0, 0.0));
    for _ in 0..2 {
        y = lu.solve(&y).ok_or_else(|| ChatterError::NonFinite {
            what: "Ritz vector (singular inverse iteration)".to_string(),
        })?;
        let nrm = y.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        if !(nrm.is_finite() && nrm > 0.0) {
            return Err(ChatterError::NonFinite {
                what: "Ritz vector".to_string(),
            });
        }
        y /= Complex::new(nrm, 0.0);
    }
    Ok(y.iter().copied().collect())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm2(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Deterministic pseudo-random vector in (−1, 1)ⁿ (xorshift64*).
fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed | 1;
    (0..n)
        .map(|_| {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            let u = s.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            2.0 * (u as f64 / (1u64 << 53) as f64) - 1.0
        })
        .collect()
}
