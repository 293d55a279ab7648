//! Sparse linear constraints of the MJTO QPs, grouped by
//! [`ConstraintFamily`], and their assembly into Clarabel's conic form.
//!
//! Clarabel solves `min ½ xᵀPx + qᵀx  s.t.  A x + s = b, s ∈ K`. An equality
//! `aᵀx = v` becomes a row of the zero cone (`s = v − aᵀx = 0`); a range
//! `lo ≤ aᵀx ≤ hi` becomes up to two rows of the nonnegative cone,
//! `aᵀx ≤ hi` and `−aᵀx ≤ −lo` (the `A_ineq Θ ≤ b_ineq` stacking of seed 001
//! eq. 44). Infinite sides are left out.
//!
//! Every assembled row is divided by its largest |coefficient|. This is an
//! equivalent constraint (same feasible set) and equalises rows whose raw
//! scales differ by many orders of magnitude: for 628 quintic coefficients
//! a third-derivative row (eq. 23, 26) has entries ≈ 10⁸ while a position row
//! has entries 1.

use clarabel::algebra::CscMatrix;
use clarabel::solver::SupportedConeT;
use kerf_bspline::BandRow;

use crate::error::ConstraintFamily;
use crate::PlanError;

/// Absolute floor of the post-check tolerance (SI: m, rad, or their
/// u-derivatives), far below any physical resolution of the machine.
pub(crate) const ABS_FLOOR: f64 = 1e-12;

/// The right-hand side of one constraint row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Bound {
    /// `aᵀx = v`.
    Eq(f64),
    /// `lo ≤ aᵀx ≤ hi` (either side may be infinite).
    Range {
        /// Lower side.
        lo: f64,
        /// Upper side.
        hi: f64,
    },
}

/// One sparse constraint row with its family.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    /// Which family it belongs to (for diagnosis and error messages);
    /// `None` for the structural equalities of a lifted formulation, which
    /// define auxiliary variables and are never dropped.
    pub family: Option<ConstraintFamily>,
    /// `(column, coefficient)` pairs; columns are distinct.
    pub entries: Vec<(usize, f64)>,
    /// Its right-hand side.
    pub bound: Bound,
    /// Reference magnitude of the post-check (see
    /// [`ConstraintSet::first_violation`]).
    pub scale: f64,
}

/// The first constraint a candidate solution violates (see
/// [`ConstraintSet::first_violation`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Violation {
    /// The family of the violated row (`None`: a structural row).
    pub family: Option<ConstraintFamily>,
    /// Index of the row within its family (in insertion order).
    pub index: usize,
    /// `aᵀx`.
    pub value: f64,
    /// The bound it misses (the equality value or the violated side).
    pub bound: f64,
    /// The tolerance it was checked with.
    pub tolerance: f64,
}

/// A constraint matrix in Clarabel form.
pub(crate) struct Assembled {
    /// `A` (rows scaled to unit max |coefficient|).
    pub a: CscMatrix<f64>,
    /// `b`, scaled like `A`.
    pub b: Vec<f64>,
    /// Zero cone (equalities) first, then the nonnegative cone.
    pub cones: Vec<SupportedConeT<f64>>,
}

/// Row-scaled triplets of `A` and the matching `b`.
#[derive(Default)]
struct Triplets {
    ii: Vec<usize>,
    jj: Vec<usize>,
    vv: Vec<f64>,
    b: Vec<f64>,
}

impl Triplets {
    /// Appends `sign·aᵀx ≤/= sign·rhs`, divided by max |a_j|.
    fn push_row(&mut self, entries: &[(usize, f64)], sign: f64, rhs: f64) {
        let scale = entries.iter().fold(0.0_f64, |m, &(_, v)| m.max(v.abs()));
        let scale = if scale > 0.0 { scale } else { 1.0 };
        let r = self.b.len();
        for &(c, v) in entries {
            self.ii.push(r);
            self.jj.push(c);
            self.vv.push(sign * v / scale);
        }
        self.b.push(sign * rhs / scale);
    }
}

/// All the linear constraints of one QP over `ncols` variables.
#[derive(Debug, Clone)]
pub(crate) struct ConstraintSet {
    ncols: usize,
    rows: Vec<Row>,
}

impl ConstraintSet {
    /// An empty set over `ncols` variables.
    pub fn new(ncols: usize) -> Self {
        Self {
            ncols,
            rows: Vec::new(),
        }
    }

    /// Number of variables.
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    /// Adds a row. `scale` is the magnitude the post-check measures a
    /// violation against, besides the bound itself: e.g. the velocity bound
    /// for a boundary-velocity equality whose target is 0.
    ///
    /// # Errors
    /// [`PlanError::Solver`] (an internal error, never user input) if a
    /// column is out of range, a coefficient or an equality value is not
    /// finite, a range side is NaN or `lo > hi`.
    pub fn push(
        &mut self,
        family: Option<ConstraintFamily>,
        entries: Vec<(usize, f64)>,
        bound: Bound,
        scale: f64,
    ) -> Result<(), PlanError> {
        let family_name = family.map_or("structural".to_string(), |f| f.to_string());
        let internal = |detail: String| PlanError::Solver {
            problem: "constraint assembly".into(),
            detail,
        };
        if let Some(&(c, v)) = entries
            .iter()
            .find(|&&(c, v)| c >= self.ncols || !v.is_finite())
        {
            return Err(internal(format!(
                "{family_name} row: column {c} (of {}) coefficient {v}",
                self.ncols
            )));
        }
        match bound {
            Bound::Eq(v) if !v.is_finite() => {
                return Err(internal(format!("{family_name} row: equality value {v}")));
            }
            Bound::Range { lo, hi } if lo.is_nan() || hi.is_nan() || lo > hi => {
                return Err(internal(format!("{family_name} row: range [{lo}, {hi}]")));
            }
            _ => {}
        }
        self.rows.push(Row {
            family,
            entries,
            bound,
            scale: if scale.is_finite() { scale.abs() } else { 0.0 },
        });
        Ok(())
    }

    /// Adds a banded B-spline row: `row.values[i]` at column
    /// `offset + row.start + i`.
    ///
    /// # Errors
    /// As [`ConstraintSet::push`].
    pub fn push_band(
        &mut self,
        family: Option<ConstraintFamily>,
        offset: usize,
        row: &BandRow,
        bound: Bound,
        scale: f64,
    ) -> Result<(), PlanError> {
        let entries = row
            .values
            .iter()
            .enumerate()
            .map(|(i, &v)| (offset + row.start + i, v))
            .collect();
        self.push(family, entries, bound, scale)
    }

    /// Assembles `A x + s = b` for the rows whose family passes `keep`.
    ///
    /// # Performance
    /// O(nnz log nnz) (one sort of the triplets inside Clarabel).
    pub fn assemble(&self, keep: &dyn Fn(ConstraintFamily) -> bool) -> Assembled {
        let mut t = Triplets::default();
        let kept = || self.rows.iter().filter(|r| r.family.is_none_or(keep));
        for row in kept() {
            if let Bound::Eq(v) = row.bound {
                t.push_row(&row.entries, 1.0, v);
            }
        }
        let n_eq = t.b.len();
        for row in kept() {
            if let Bound::Range { lo, hi } = row.bound {
                if hi.is_finite() {
                    t.push_row(&row.entries, 1.0, hi);
                }
                if lo.is_finite() {
                    t.push_row(&row.entries, -1.0, lo);
                }
            }
        }
        let m = t.b.len();
        let mut cones = Vec::with_capacity(2);
        if n_eq > 0 {
            cones.push(SupportedConeT::ZeroConeT(n_eq));
        }
        if m > n_eq {
            cones.push(SupportedConeT::NonnegativeConeT(m - n_eq));
        }
        // Columns were checked in `push`, so the triplets are in range.
        let a = CscMatrix::new_from_triplets(m, self.ncols, t.ii, t.jj, t.vv);
        let b = t.b;
        Assembled { a, b, cones }
    }

    /// The first row (in insertion order) among those whose family passes
    /// `keep` (structural rows always) that `x` violates by more than its
    /// tolerance, or `None`.
    ///
    /// The tolerance of a row is `rel_tol · max(|bound|, scale) +`
    /// [`ABS_FLOOR`]: relative to the bound it misses, or to the row's
    /// reference magnitude when the bound is smaller (a zero boundary
    /// velocity is checked relative to the velocity bound). A NaN value is
    /// always a violation.
    pub fn first_violation(
        &self,
        x: &[f64],
        rel_tol: f64,
        keep: &dyn Fn(ConstraintFamily) -> bool,
    ) -> Option<Violation> {
        let mut counts: Vec<(Option<ConstraintFamily>, usize)> = Vec::new();
        for row in self.rows.iter().filter(|r| r.family.is_none_or(keep)) {
            let index = match counts.iter_mut().find(|(f, _)| *f == row.family) {
                Some((_, n)) => {
                    *n += 1;
                    *n - 1
                }
                None => {
                    counts.push((row.family, 1));
                    0
                }
            };
            let value: f64 = row
                .entries
                .iter()
                .map(|&(c, a)| a * x.get(c).copied().unwrap_or(f64::NAN))
                .sum();
            let check = |bound: f64, excess: f64| {
                let tolerance = rel_tol * bound.abs().max(row.scale) + ABS_FLOOR;
                (excess.is_nan() || excess > tolerance).then_some(Violation {
                    family: row.family,
                    index,
                    value,
                    bound,
                    tolerance,
                })
            };
            let found = match row.bound {
                Bound::Eq(v) => check(v, (value - v).abs()),
                Bound::Range { lo, hi } => {
                    let upper = if hi.is_finite() {
                        check(hi, value - hi)
                    } else {
                        None
                    };
                    let lower = if lo.is_finite() {
                        check(lo, lo - value)
                    } else {
                        None
                    };
                    upper.or(lower).or_else(|| {
                        value.is_nan().then_some(Violation {
                            family: row.family,
                            index,
                            value,
                            bound: f64::NAN,
                            tolerance: 0.0,
                        })
                    })
                }
            };
            if found.is_some() {
                return found;
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ConstraintFamily::*;

    #[test]
    fn assembly_orders_equalities_first_and_scales_rows() {
        let mut set = ConstraintSet::new(2);
        let range = |lo, hi| Bound::Range { lo, hi };
        set.push(
            Some(Velocity),
            vec![(0, 4.0), (1, -2.0)],
            range(-8.0, 4.0),
            0.0,
        )
        .unwrap();
        set.push(Some(Rto), vec![(1, 0.5)], Bound::Eq(3.0), 1.0)
            .unwrap();
        set.push(
            Some(Position),
            vec![(0, 1.0)],
            range(f64::NEG_INFINITY, 1.0),
            0.0,
        )
        .unwrap();
        set.push(None, vec![(0, 2.0)], Bound::Eq(1.0), 1.0).unwrap();
        let asm = set.assemble(&|_| true);
        assert_eq!(asm.b, vec![6.0, 0.5, 1.0, 2.0, 1.0]);
        assert_eq!(
            asm.cones,
            vec![
                SupportedConeT::ZeroConeT(2),
                SupportedConeT::NonnegativeConeT(3)
            ]
        );
        let dense = |r: usize, c: usize| {
            (asm.a.colptr[c]..asm.a.colptr[c + 1])
                .find(|&k| asm.a.rowval[k] == r)
                .map(|k| asm.a.nzval[k])
                .unwrap_or(0.0)
        };
        assert_eq!([dense(0, 0), dense(0, 1)], [0.0, 1.0]);
        assert_eq!([dense(1, 0), dense(1, 1)], [1.0, 0.0]);
        assert_eq!([dense(2, 0), dense(2, 1)], [1.0, -0.5]);
        assert_eq!([dense(3, 0), dense(3, 1)], [-1.0, 0.5]);
        assert_eq!([dense(4, 0), dense(4, 1)], [1.0, 0.0]);
        // Dropping every family keeps the structural row.
        let none = set.assemble(&|_| false);
        assert_eq!(none.b, vec![0.5]);
        let no_rto = set.assemble(&|f| f != Rto);
        assert_eq!(no_rto.b.len(), 4);
    }

    #[test]
    fn violations_are_relative_and_catch_nan() {
        let mut set = ConstraintSet::new(2);
        let range = |lo, hi| Bound::Range { lo, hi };
        set.push(Some(Jerk), vec![(0, 1.0), (1, -1.0)], range(-1e3, 1e3), 0.0)
            .unwrap();
        set.push(Some(Boundary), vec![(0, 1.0)], Bound::Eq(0.0), 10.0)
            .unwrap();
        let all = |_| true;
        assert_eq!(set.first_violation(&[0.0, 0.0], 1e-6, &all), None);
        // 1e3 + 5e-4 is within 1e-6 relative to 1e3.
        assert_eq!(set.first_violation(&[0.0, -1e3 - 5e-4], 1e-6, &all), None);
        let v = set
            .first_violation(&[0.0, -1e3 - 2e-3], 1e-6, &all)
            .unwrap();
        assert_eq!((v.family, v.index, v.bound), (Some(Jerk), 0, 1e3));
        // Zero target, scale 10: 5e-6 passes, 2e-5 does not.
        assert_eq!(set.first_violation(&[5e-6, 5e-6], 1e-6, &all), None);
        let v = set.first_violation(&[2e-5, 2e-5], 1e-6, &all).unwrap();
        assert_eq!(v.family, Some(Boundary));
        assert_eq!(
            set.first_violation(&[2e-5, 2e-5], 1e-6, &|f| f != Boundary),
            None
        );
        let v = set.first_violation(&[f64::NAN, 0.0], 1e-6, &all).unwrap();
        assert_eq!(v.family, Some(Jerk));
        assert!(set
            .push(Some(Rto), vec![(2, 1.0)], Bound::Eq(0.0), 1.0)
            .is_err());
        assert!(set
            .push(Some(Rto), vec![(0, 1.0)], range(1.0, 0.0), 1.0)
            .is_err());
        assert!(set
            .push(Some(Rto), vec![(0, f64::NAN)], Bound::Eq(0.0), 1.0)
            .is_err());
    }
}
