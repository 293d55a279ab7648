//! Row-banded sparse matrices: each row stores one contiguous run of
//! columns (collocation matrices, derivative operators, eq. 35-38).

use crate::error::BsplineError;
use nalgebra::DMatrix;

/// One row of a [`BandRows`] matrix: the values of columns
/// `start .. start + values.len()`; every other column is zero.
#[derive(Debug, Clone, PartialEq)]
pub struct BandRow {
    /// First stored column.
    pub start: usize,
    /// Values of columns `start ..`.
    pub values: Vec<f64>,
}

impl BandRow {
    /// One past the last stored column.
    pub fn end(&self) -> usize {
        self.start + self.values.len()
    }

    /// The value at column `col` (0 outside the stored run).
    pub fn get(&self, col: usize) -> f64 {
        col.checked_sub(self.start)
            .and_then(|c| self.values.get(c))
            .copied()
            .unwrap_or(0.0)
    }

    /// Dot product with a dense vector.
    ///
    /// Returns NaN when the row reaches past the end of `x`, so that a
    /// dimension error cannot go unnoticed.
    pub fn dot(&self, x: &[f64]) -> f64 {
        match x.get(self.start..self.end()) {
            Some(xs) => xs.iter().zip(&self.values).map(|(a, b)| a * b).sum(),
            None => f64::NAN,
        }
    }
}

/// A sparse matrix stored as rows of contiguous nonzeros (banded
/// structure): row i holds the values of columns `start_i .. start_i + len`.
///
/// Invariant (checked by [`BandRows::new`], kept by every constructor of
/// this crate): `start + values.len() <= ncols` for every row.
#[derive(Debug, Clone, PartialEq)]
pub struct BandRows {
    /// Number of columns.
    pub ncols: usize,
    /// The rows, in order.
    pub rows: Vec<BandRow>,
}

impl BandRows {
    /// Build a matrix after checking the invariant and finiteness.
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] when a row reaches past `ncols`,
    /// [`BsplineError::NotFinite`] for a NaN/infinite value.
    pub fn new(ncols: usize, rows: Vec<BandRow>) -> Result<Self, BsplineError> {
        for (i, r) in rows.iter().enumerate() {
            if r.end() > ncols {
                return Err(BsplineError::LengthMismatch {
                    what: format!("columns of band row {i}"),
                    expected: ncols,
                    got: r.end(),
                });
            }
            crate::error::check_finite(&format!("band row {i}"), &r.values)?;
        }
        Ok(Self { ncols, rows })
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.rows.len()
    }

    fn well_formed(&self) -> bool {
        self.rows.iter().all(|r| r.end() <= self.ncols)
    }

    /// A x.
    ///
    /// # Returns
    /// A vector of length `nrows()`; all NaN when `x.len() != ncols` or the
    /// matrix breaks its invariant (use [`BandRows::try_mul_vec`] for an
    /// error instead).
    ///
    /// # Performance
    /// O(number of stored values).
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        if x.len() != self.ncols || !self.well_formed() {
            return vec![f64::NAN; self.nrows()];
        }
        self.rows.iter().map(|r| r.dot(x)).collect()
    }

    /// A x, with a dimension check.
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] when `x.len() != ncols`.
    pub fn try_mul_vec(&self, x: &[f64]) -> Result<Vec<f64>, BsplineError> {
        if x.len() != self.ncols {
            return Err(BsplineError::LengthMismatch {
                what: "vector multiplied by a band matrix".into(),
                expected: self.ncols,
                got: x.len(),
            });
        }
        Ok(self.mul_vec(x))
    }

    /// A^T y.
    ///
    /// # Returns
    /// A vector of length `ncols`; all NaN when `y.len() != nrows()` or the
    /// matrix breaks its invariant (use [`BandRows::try_tr_mul_vec`]).
    pub fn tr_mul_vec(&self, y: &[f64]) -> Vec<f64> {
        if y.len() != self.nrows() || !self.well_formed() {
            return vec![f64::NAN; self.ncols];
        }
        let mut out = vec![0.0; self.ncols];
        for (r, &yi) in self.rows.iter().zip(y) {
            if let Some(dst) = out.get_mut(r.start..r.end()) {
                for (o, v) in dst.iter_mut().zip(&r.values) {
                    *o += v * yi;
                }
            }
        }
        out
    }

    /// A^T y, with a dimension check.
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] when `y.len() != nrows()`.
    pub fn try_tr_mul_vec(&self, y: &[f64]) -> Result<Vec<f64>, BsplineError> {
        if y.len() != self.nrows() {
            return Err(BsplineError::LengthMismatch {
                what: "vector multiplied by a transposed band matrix".into(),
                expected: self.nrows(),
                got: y.len(),
            });
        }
        Ok(self.tr_mul_vec(y))
    }

    /// Dense copy (entries past `ncols`, which no constructor of this crate
    /// produces, are dropped).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.nrows(), self.ncols);
        for (i, c, v) in self.triplets() {
            m[(i, c)] = v;
        }
        m
    }

    /// `(row, col, value)` of every nonzero stored value, row by row.
    pub fn triplets(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        let ncols = self.ncols;
        self.rows.iter().enumerate().flat_map(move |(i, r)| {
            r.values
                .iter()
                .enumerate()
                .map(move |(c, &v)| (i, r.start + c, v))
                .filter(move |&(_, c, v)| v != 0.0 && c < ncols)
        })
    }

    /// The matrix multiplied by `s`.
    pub fn scaled(&self, s: f64) -> BandRows {
        BandRows {
            ncols: self.ncols,
            rows: self
                .rows
                .iter()
                .map(|r| BandRow {
                    start: r.start,
                    values: r.values.iter().map(|v| v * s).collect(),
                })
                .collect(),
        }
    }

    /// The product `self * other` of two band matrices (e.g. a collocation
    /// row times a derivative operator).
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] when `self.ncols != other.nrows()`.
    pub fn mul(&self, other: &BandRows) -> Result<BandRows, BsplineError> {
        if self.ncols != other.nrows() {
            return Err(BsplineError::LengthMismatch {
                what: "inner dimension of a band matrix product".into(),
                expected: other.nrows(),
                got: self.ncols,
            });
        }
        let rows = self
            .rows
            .iter()
            .map(|r| {
                let mut lo = usize::MAX;
                let mut hi = 0;
                for j in r.start..r.end() {
                    if let Some(o) = other.rows.get(j) {
                        if !o.values.is_empty() {
                            lo = lo.min(o.start);
                            hi = hi.max(o.end());
                        }
                    }
                }
                if lo >= hi {
                    return BandRow {
                        start: 0,
                        values: Vec::new(),
                    };
                }
                let mut values = vec![0.0; hi - lo];
                for (j, &a) in (r.start..r.end()).zip(&r.values) {
                    if let Some(o) = other.rows.get(j) {
                        for (c, &b) in (o.start..o.end()).zip(&o.values) {
                            if let Some(dst) = values.get_mut(c - lo) {
                                *dst += a * b;
                            }
                        }
                    }
                }
                BandRow { start: lo, values }
            })
            .collect();
        Ok(BandRows {
            ncols: other.ncols,
            rows,
        })
    }
}
