//! LU factorisation with partial pivoting of a square banded matrix
//! (LAPACK `dgbtrf`/`dgbtrs` layout and algorithm, Golub & Van Loan,
//! *Matrix Computations*, 4th ed., algorithm 4.3.5 with pivoting).
//!
//! Used for the KKT systems of the equality-constrained QPs ("polish"
//! steps, see `qp::kkt`), whose saddle-point matrices become banded once
//! each constraint row is placed beside the last variable it touches.

/// A factorised banded matrix `P A = L U`.
#[derive(Debug, Clone)]
pub(crate) struct BandLu {
    n: usize,
    /// Lower bandwidth of A.
    kl: usize,
    /// Upper bandwidth of A.
    ku: usize,
    /// Column-major band storage with `ldab = 2 kl + ku + 1` rows:
    /// `ab[(kl + ku + i − j) + j·ldab] = A(i, j)`; the top `kl` rows hold
    /// the fill-in of U.
    ab: Vec<f64>,
    /// Row interchanges: at step j rows j and `ipiv[j]` were swapped.
    ipiv: Vec<usize>,
}

/// Why a factorisation failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum BandLuError {
    /// An entry lies outside the declared band or the matrix.
    OutOfBand {
        /// Row.
        i: usize,
        /// Column.
        j: usize,
    },
    /// A non-finite entry.
    NotFinite,
    /// A zero (or below `tol`) pivot at this column: numerically singular.
    Singular {
        /// Column of the pivot.
        column: usize,
    },
}

impl BandLu {
    /// Factorises the `n × n` matrix with the given `(row, col, value)`
    /// entries (duplicates are summed) and bandwidths.
    ///
    /// A pivot whose magnitude is below `pivot_tol` (absolute) is reported
    /// as [`BandLuError::Singular`].
    ///
    /// # Performance
    /// O(n · kl · (kl + ku)) time, O(n · (2 kl + ku)) memory.
    pub fn factor(
        n: usize,
        kl: usize,
        ku: usize,
        entries: impl IntoIterator<Item = (usize, usize, f64)>,
        pivot_tol: f64,
    ) -> Result<Self, BandLuError> {
        let ldab = 2 * kl + ku + 1;
        let mut ab = vec![0.0; ldab * n];
        for (i, j, v) in entries {
            if i >= n || j >= n || i + ku < j || j + kl < i {
                return Err(BandLuError::OutOfBand { i, j });
            }
            if !v.is_finite() {
                return Err(BandLuError::NotFinite);
            }
            ab[kl + ku + i - j + j * ldab] += v;
        }
        let mut lu = Self {
            n,
            kl,
            ku,
            ab,
            ipiv: vec![0; n],
        };
        lu.factor_in_place(pivot_tol)?;
        Ok(lu)
    }

    fn idx(&self, i: usize, j: usize) -> usize {
        let ldab = 2 * self.kl + self.ku + 1;
        self.kl + self.ku + i - j + j * ldab
    }

    fn factor_in_place(&mut self, pivot_tol: f64) -> Result<(), BandLuError> {
        let (n, kl, ku) = (self.n, self.kl, self.ku);
        let ldab = 2 * kl + ku + 1;
        let mut l = vec![0.0; kl];
        for j in 0..n {
            // Pivot search in column j, rows j ..= min(n − 1, j + kl); the
            // column is contiguous in the band storage.
            let last = (j + kl).min(n - 1);
            let len = last - j;
            let diag = self.idx(j, j);
            let mut p = j;
            let mut best = self.ab[diag].abs();
            for (t, v) in self.ab[diag + 1..=diag + len].iter().enumerate() {
                if v.abs() > best {
                    best = v.abs();
                    p = j + 1 + t;
                }
            }
            if best.is_nan() || best <= pivot_tol {
                return Err(BandLuError::Singular { column: j });
            }
            self.ipiv[j] = p;
            // Columns that row j of U can reach after interchanges.
            let ucol = (j + kl + ku).min(n - 1);
            if p != j {
                for c in j..=ucol {
                    let (a, b) = (self.idx(j, c), self.idx(p, c));
                    self.ab.swap(a, b);
                }
            }
            let pivot = self.ab[diag];
            for (lt, a) in l.iter_mut().zip(&mut self.ab[diag + 1..=diag + len]) {
                *a /= pivot;
                *lt = *a;
            }
            // Rank-one update of the trailing columns, one contiguous
            // column segment (rows j + 1 ..= last) at a time.
            for c in j + 1..=ucol {
                let u = self.ab[self.idx(j, c)];
                if u != 0.0 {
                    let start = kl + ku + j + 1 - c + c * ldab;
                    for (a, lt) in self.ab[start..start + len].iter_mut().zip(&l) {
                        *a -= lt * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place.
    ///
    /// # Performance
    /// O(n · (2 kl + ku)).
    pub fn solve(&self, b: &mut [f64]) {
        let (n, kl, ku) = (self.n, self.kl, self.ku);
        if b.len() != n {
            b.iter_mut().for_each(|v| *v = f64::NAN);
            return;
        }
        let ldab = 2 * kl + ku + 1;
        // L y = P b: column j of L holds rows j + 1 ..= j + kl contiguously.
        for j in 0..n {
            let p = self.ipiv[j];
            if p != j {
                b.swap(j, p);
            }
            let bj = b[j];
            let len = (j + kl).min(n - 1) - j;
            if bj != 0.0 && len > 0 {
                let col = self.idx(j, j) + 1;
                for (bi, l) in b[j + 1..=j + len].iter_mut().zip(&self.ab[col..col + len]) {
                    *bi -= l * bj;
                }
            }
        }
        // U x = y: column j of U holds rows j − kl − ku ..= j contiguously.
        for j in (0..n).rev() {
            b[j] /= self.ab[self.idx(j, j)];
            let xj = b[j];
            let first = j.saturating_sub(kl + ku);
            if xj != 0.0 && first < j {
                let col = kl + ku + first - j + j * ldab;
                for (bi, u) in b[first..j].iter_mut().zip(&self.ab[col..col + (j - first)]) {
                    *bi -= u * xj;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A banded matrix that needs pivoting (zero diagonal entries, as in a
    /// KKT matrix), checked against nalgebra's dense LU.
    #[test]
    fn matches_dense_lu_with_pivoting() {
        let n = 40;
        let (kl, ku) = (3, 2);
        let mut entries = Vec::new();
        let mut dense = DMatrix::zeros(n, n);
        for i in 0..n {
            for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                let v = if i == j && i % 3 == 0 {
                    0.0
                } else {
                    ((i * 7 + j * 13) % 11) as f64 - 5.0 + 0.1 * i as f64
                };
                entries.push((i, j, v));
                dense[(i, j)] = v;
            }
        }
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let lu = BandLu::factor(n, kl, ku, entries, 1e-300).unwrap();
        let mut x = b.clone();
        lu.solve(&mut x);
        let expect = dense
            .clone()
            .lu()
            .solve(&DVector::from_vec(b.clone()))
            .unwrap();
        for (a, e) in x.iter().zip(expect.iter()) {
            assert!((a - e).abs() < 1e-9 * e.abs().max(1.0), "{a} vs {e}");
        }
        let r = &dense * DVector::from_vec(x) - DVector::from_vec(b);
        assert!(r.amax() < 1e-10);
    }

    #[test]
    fn reports_singular_and_out_of_band() {
        let singular = [(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 4.0)];
        assert_eq!(
            BandLu::factor(2, 1, 1, singular, 1e-12).unwrap_err(),
            BandLuError::Singular { column: 1 }
        );
        assert_eq!(
            BandLu::factor(3, 0, 0, [(0, 2, 1.0)], 1e-12).unwrap_err(),
            BandLuError::OutOfBand { i: 0, j: 2 }
        );
        assert_eq!(
            BandLu::factor(1, 0, 0, [(0, 0, f64::NAN)], 1e-12).unwrap_err(),
            BandLuError::NotFinite
        );
    }
}
