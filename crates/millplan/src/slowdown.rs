//! The slowdown field c(s) ≥ 1 of the executed time law
//! ([`crate::time_law`]): the robot runs at the planned feed divided by
//! c(s). A uniform cubic B-spline in the arc length, so that c, c' and c''
//! are continuous (the joint accelerations and jerks of the time law
//! contain c' and c''), with coefficients ≥ 1, so that c ≥ 1 everywhere
//! (a B-spline lies in the convex hull of its coefficients: de Boor, *A
//! Practical Guide to Splines* (2001), ch. IX, property (ix)).

/// c(s) on [0, length] (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct SlowdownField {
    spacing: f64,
    cells: usize,
    coefficients: Vec<f64>,
}

/// The uniform cubic B-spline basis at u ∈ [0, 1] and its first two
/// derivatives in u (de Boor ch. IX; the four pieces of the cardinal cubic
/// B-spline).
fn basis(u: f64) -> [[f64; 4]; 3] {
    let w = 1.0 - u;
    let u2 = u * u;
    let u3 = u2 * u;
    [
        [
            w * w * w / 6.0,
            (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0,
            (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0,
            u3 / 6.0,
        ],
        [
            -0.5 * w * w,
            1.5 * u2 - 2.0 * u,
            -1.5 * u2 + u + 0.5,
            0.5 * u2,
        ],
        [w, 3.0 * u - 2.0, -3.0 * u + 1.0, u],
    ]
}

impl SlowdownField {
    /// c ≡ 1 on [0, `length`] with `cells` equal knot intervals.
    ///
    /// # Arguments
    /// * `length` — > 0 and finite \[m\].
    /// * `cells` — ≥ 1 knot intervals (their length is the field's
    ///   resolution).
    ///
    /// # Returns
    /// `None` for a non-positive length or zero cells.
    pub fn new(length: f64, cells: usize) -> Option<Self> {
        if !(length.is_finite() && length > 0.0) || cells == 0 {
            return None;
        }
        Some(Self {
            spacing: length / cells as f64,
            cells,
            coefficients: vec![1.0; cells + 3],
        })
    }

    fn locate(&self, s: f64) -> (usize, f64) {
        let x = (s / self.spacing).max(0.0);
        let i = (x.floor() as usize).min(self.cells - 1);
        (i, (x - i as f64).min(1.0))
    }

    /// c(s), c'(s), c''(s) (s clamped to the field's range).
    pub fn eval(&self, s: f64) -> (f64, f64, f64) {
        let (i, u) = self.locate(s);
        let local = &self.coefficients[i..i + 4];
        if local.iter().all(|c| *c == local[0]) {
            // Partition of unity, exactly (no rounding of Σ B_k = 1).
            return (local[0], 0.0, 0.0);
        }
        let b = basis(u);
        let mut out = [0.0; 3];
        for (k, row) in b.iter().enumerate() {
            out[k] = row
                .iter()
                .zip(&self.coefficients[i..i + 4])
                .map(|(bk, ck)| bk * ck)
                .sum();
        }
        (
            out[0],
            out[1] / self.spacing,
            out[2] / (self.spacing * self.spacing),
        )
    }

    /// Raises c on several spans at once: every coefficient whose basis
    /// function is non-zero on a span [`from`, `to`] or on one knot
    /// interval beyond either side is multiplied by the LARGEST `factor`
    /// (> 1) of the spans it touches (once: overlapping spans do not
    /// compound), so that c grows by at least that factor on each span.
    pub fn raise(&mut self, spans: &[(f64, f64, f64)]) {
        let mut factors = vec![1.0_f64; self.coefficients.len()];
        for &(from, to, factor) in spans {
            if !(factor.is_finite() && factor > 1.0) {
                continue;
            }
            let (a, _) = self.locate(from);
            let (b, _) = self.locate(to);
            let lo = a.saturating_sub(1);
            let hi = (b + 4).min(self.coefficients.len() - 1);
            for f in &mut factors[lo..=hi] {
                *f = f.max(factor);
            }
        }
        for (c, f) in self.coefficients.iter_mut().zip(&factors) {
            *c *= f;
        }
    }

    /// Multiplies every coefficient by `factor` (an exact uniform slowdown).
    pub fn scale(&mut self, factor: f64) {
        for c in &mut self.coefficients {
            *c *= factor;
        }
    }

    /// The largest coefficient (an upper bound of c).
    pub fn max(&self) -> f64 {
        self.coefficients.iter().copied().fold(1.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_field_and_raise() {
        let mut f = SlowdownField::new(1.0, 10).unwrap();
        for k in 0..=100 {
            let (c, d1, d2) = f.eval(k as f64 / 100.0);
            assert!((c - 1.0).abs() < 1e-14 && d1.abs() < 1e-12 && d2.abs() < 1e-10);
        }
        f.raise(&[(0.42, 0.47, 2.0), (0.45, 0.5, 1.5)]);
        for k in 0..=100 {
            let s = k as f64 / 100.0;
            let (c, _, _) = f.eval(s);
            assert!(c >= 1.0 - 1e-14);
            if (0.42..=0.47).contains(&s) {
                assert!(c >= 2.0 - 1e-12, "{s}: {c}");
            }
        }
        // Continuity of c' across a knot.
        let (_, l, _) = f.eval(0.4 - 1e-9);
        let (_, r, _) = f.eval(0.4 + 1e-9);
        assert!((l - r).abs() < 1e-6);
        assert!(SlowdownField::new(0.0, 3).is_none());
    }
}
