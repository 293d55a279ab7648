//! Symmetric banded matrices (jerk Hessian eq. 18, normal matrices eq. 52)
//! and their Cholesky solve.

use crate::error::BsplineError;
use nalgebra::DMatrix;

/// Relative pivot tolerance of [`BandedSym::solve_spd`]: a Cholesky pivot
/// below `PIVOT_TOLERANCE · A_ii` means `cond_2(A) > 1 / PIVOT_TOLERANCE`.
pub const PIVOT_TOLERANCE: f64 = 1e-10;

/// Symmetric n × n matrix with `A(i, j) = 0` for `|i - j| > bandwidth`;
/// only the lower triangle of the band is stored.
#[derive(Debug, Clone, PartialEq)]
pub struct BandedSym {
    n: usize,
    bandwidth: usize,
    /// `data[i * (bandwidth + 1) + d] = A(i, i - d)` for `d = 0..=bandwidth`
    /// (entries with `d > i` are unused zeros).
    data: Vec<f64>,
}

impl BandedSym {
    /// The zero matrix of size n with the given bandwidth (capped at
    /// n - 1, beyond which a band holds nothing more).
    pub fn zeros(n: usize, bandwidth: usize) -> Self {
        let bandwidth = bandwidth.min(n.saturating_sub(1));
        Self {
            n,
            bandwidth,
            data: vec![0.0; n * (bandwidth + 1)],
        }
    }

    /// Banded copy of the lower triangle of a dense matrix.
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] for a non-square matrix,
    /// [`BsplineError::NotFinite`] for a NaN/infinite entry in the band.
    pub fn from_dense_lower(m: &DMatrix<f64>, bandwidth: usize) -> Result<Self, BsplineError> {
        if m.nrows() != m.ncols() {
            return Err(BsplineError::LengthMismatch {
                what: "columns of a symmetric matrix".into(),
                expected: m.nrows(),
                got: m.ncols(),
            });
        }
        let mut s = Self::zeros(m.nrows(), bandwidth);
        for i in 0..m.nrows() {
            for j in i.saturating_sub(bandwidth)..=i {
                let v = m[(i, j)];
                if !v.is_finite() {
                    return Err(BsplineError::NotFinite {
                        what: format!("matrix entry ({i}, {j})"),
                    });
                }
                s.add(i, j, v);
            }
        }
        Ok(s)
    }

    fn index(&self, i: usize, j: usize) -> Option<usize> {
        let (hi, lo) = if i >= j { (i, j) } else { (j, i) };
        let d = hi - lo;
        if hi >= self.n || d > self.bandwidth {
            None
        } else {
            Some(hi * (self.bandwidth + 1) + d)
        }
    }

    /// Add `v` to `A(i, j)` (and so to `A(j, i)`).
    ///
    /// # Returns
    /// `false` (and no change) when `(i, j)` is outside the matrix or band.
    pub fn add(&mut self, i: usize, j: usize, v: f64) -> bool {
        match self.index(i, j).and_then(|ix| self.data.get_mut(ix)) {
            Some(x) => {
                *x += v;
                true
            }
            None => false,
        }
    }

    /// The size n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The bandwidth b (`A(i, j) = 0` for `|i - j| > b`).
    pub fn bandwidth(&self) -> usize {
        self.bandwidth
    }

    /// `A(i, j)`; 0 outside the band or the matrix.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.index(i, j)
            .and_then(|ix| self.data.get(ix))
            .copied()
            .unwrap_or(0.0)
    }

    /// A x.
    ///
    /// # Returns
    /// A vector of length n; all NaN when `x.len() != n`.
    ///
    /// # Performance
    /// O(n b).
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        if x.len() != self.n {
            return vec![f64::NAN; self.n];
        }
        let mut y = vec![0.0; self.n];
        for i in 0..self.n {
            let (xi, lo) = (x[i], i.saturating_sub(self.bandwidth));
            let mut acc = 0.0;
            for j in lo..i {
                let a = self.get(i, j);
                acc += a * x[j];
                y[j] += a * xi;
            }
            y[i] += acc + self.get(i, i) * xi;
        }
        y
    }

    /// `(i, j, value)` with `i <= j` for every nonzero of the upper
    /// triangle (the form Clarabel and OSQP take for P), ordered by
    /// column j, then row i.
    pub fn upper_triplets(&self) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::with_capacity(self.data.len());
        for j in 0..self.n {
            for i in j.saturating_sub(self.bandwidth)..=j {
                let v = self.get(j, i);
                if v != 0.0 {
                    out.push((i, j, v));
                }
            }
        }
        out
    }

    /// Dense symmetric copy.
    pub fn to_dense(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }

    /// Largest absolute entry (0 for an empty matrix; NaN if any is NaN).
    pub fn max_abs(&self) -> f64 {
        self.data.iter().fold(0.0, |m: f64, v| {
            if v.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(v.abs())
            }
        })
    }

    /// The matrix multiplied by `s`.
    pub fn scaled(&self, s: f64) -> BandedSym {
        BandedSym {
            n: self.n,
            bandwidth: self.bandwidth,
            data: self.data.iter().map(|v| v * s).collect(),
        }
    }

    /// Solve A x = b by banded Cholesky A = L L^T (A symmetric positive
    /// definite).
    ///
    /// The i-th pivot s_i (the diagonal of the Schur complement, equal to
    /// `1 / (A^{-1})_ii`) satisfies `s_i / A_ii >= 1 / cond_2(A)`; a pivot
    /// below [`PIVOT_TOLERANCE`]` · A_ii` (or NaN, or a non-positive
    /// diagonal) therefore certifies `cond_2(A) > 1e10` and is reported as
    /// singular: the solution would be dominated by rounding.
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] when `b.len() != n`,
    /// [`BsplineError::NotFinite`] for a NaN/infinite `b`,
    /// [`BsplineError::Singular`] naming the failing pivot when A is not
    /// (numerically) positive definite.
    ///
    /// # Performance
    /// O(n b^2) time, O(n b) memory.
    pub fn solve_spd(&self, b: &[f64]) -> Result<Vec<f64>, BsplineError> {
        let n = self.n;
        if b.len() != n {
            return Err(BsplineError::LengthMismatch {
                what: "right-hand side of a banded solve".into(),
                expected: n,
                got: b.len(),
            });
        }
        crate::error::check_finite("right-hand side", b)?;
        let bw = self.bandwidth;
        let w = bw + 1;
        // l[i * w + d] = L(i, i - d).
        let mut l = vec![0.0; n * w];
        for i in 0..n {
            let lo = i.saturating_sub(bw);
            for j in lo..=i {
                let mut s = self.get(i, j);
                // Σ_{p = lo}^{j-1} L(i, p) L(j, p); L(j, p) = 0 for p < j - bw.
                for p in lo.max(j.saturating_sub(bw))..j {
                    s -= l[i * w + (i - p)] * l[j * w + (j - p)];
                }
                if i == j {
                    let a_ii = self.get(i, i);
                    let tol = PIVOT_TOLERANCE * a_ii;
                    if s.is_nan() || a_ii.is_nan() || a_ii <= 0.0 || s <= tol {
                        return Err(BsplineError::Singular {
                            detail: format!(
                                "Cholesky pivot {i} of {n} is {s:e} for a diagonal entry {a_ii:e}: \
                                 the matrix is not (numerically) positive definite"
                            ),
                        });
                    }
                    l[i * w] = s.sqrt();
                } else {
                    l[i * w + (i - j)] = s / l[j * w];
                }
            }
        }
        // Forward: L y = b.
        let mut y = b.to_vec();
        for i in 0..n {
            let mut s = y[i];
            for p in i.saturating_sub(bw)..i {
                s -= l[i * w + (i - p)] * y[p];
            }
            y[i] = s / l[i * w];
        }
        // Backward: L^T x = y.
        for i in (0..n).rev() {
            let mut s = y[i];
            for p in i + 1..n.min(i + bw + 1) {
                s -= l[p * w + (p - i)] * y[p];
            }
            y[i] = s / l[i * w];
        }
        crate::error::check_finite("solution of a banded solve", &y)?;
        Ok(y)
    }
}
