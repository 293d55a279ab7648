//! The path through N-dimensional reference points: a natural cubic spline
//! per axis over the chord-length parameter, with exact bounds of its
//! first three derivatives.
//!
//! Natural cubic spline (de Boor, "A Practical Guide to Splines", 1978,
//! ch. IV, eq. (IV.11)–(IV.13)): on `[s_k, s_{k+1}]`, `h = s_{k+1} − s_k`,
//!
//! ```text
//! x(s) = M_k (s_{k+1}−s)³/(6h) + M_{k+1} (s−s_k)³/(6h)
//!      + (x_k/h − M_k h/6)(s_{k+1}−s) + (x_{k+1}/h − M_{k+1} h/6)(s−s_k)
//! ```
//!
//! with the second derivatives `M` from the tridiagonal continuity system
//! and `M_0 = M_L = 0`. Knots are cumulative chord lengths, so points on a
//! line give the line itself (`x(s) = x_0 + s·d`), and one-axis points that
//! increase give `x(s) = x_0 + s`: the paper's single axis exactly.

use crate::error::StepError;

/// A natural cubic spline per axis through points, over chord length.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    /// Knots: cumulative chord lengths, `knots[0] = 0`.
    pub knots: Vec<f64>,
    /// The points, one `Vec` per point (all the same length).
    pub points: Vec<Vec<f64>>,
    /// Second derivatives at the knots, per point then per axis.
    second: Vec<Vec<f64>>,
}

/// Largest number of axes (a 6-joint robot, or x y z and three angles).
pub const MAX_AXES: usize = 6;

/// Bounds of |x'|, |x''|, |x'''| per axis over the whole spline.
#[derive(Debug, Clone, PartialEq)]
pub struct DerivativeBounds {
    /// max |x_i'| per axis.
    pub first: Vec<f64>,
    /// max |x_i''| per axis.
    pub second: Vec<f64>,
    /// max |x_i'''| per axis.
    pub third: Vec<f64>,
    /// max ‖x'‖₂ bound: √Σ first².
    pub speed: f64,
}

impl Spline {
    /// The spline through `points`.
    ///
    /// # Errors
    /// [`StepError::InvalidPoint`] for fewer than two points, a point with
    /// no coordinate, more than [`MAX_AXES`], or another count than the
    /// first, a NaN or infinite coordinate, or a point within
    /// `2·min_gap`… of its predecessor (`min_gap` = the precision: the two
    /// would be one point).
    pub fn new(points: Vec<Vec<f64>>, min_gap: f64) -> Result<Self, StepError> {
        let dim = points.first().map_or(0, Vec::len);
        if points.len() < 2 {
            return Err(StepError::InvalidPoint {
                index: points.len(),
                reason: "a path needs a start and at least one point to pass".to_string(),
            });
        }
        for (i, p) in points.iter().enumerate() {
            if p.is_empty() || p.len() > MAX_AXES || p.len() != dim {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!(
                        "{} coordinates (the first point has {dim}; 1 to {MAX_AXES} allowed)",
                        p.len()
                    ),
                });
            }
            if let Some(c) = p.iter().find(|c| !c.is_finite()) {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!("coordinate {c} is not finite"),
                });
            }
        }
        let mut knots = vec![0.0];
        for i in 1..points.len() {
            let chord = distance(&points[i], &points[i - 1]);
            if chord <= 2.0 * min_gap {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!(
                        "{chord} from point {}: points must be more than twice the precision \
                         {min_gap} apart (a repeated point)",
                        i - 1
                    ),
                });
            }
            knots.push(knots[i - 1] + chord);
        }
        let second = natural_second_derivatives(&knots, &points, dim);
        Ok(Self {
            knots,
            points,
            second,
        })
    }

    /// Number of axes.
    pub fn axes(&self) -> usize {
        self.points[0].len()
    }

    /// Total chord length (the parameter's end).
    pub fn length(&self) -> f64 {
        self.knots.last().copied().unwrap_or(0.0)
    }

    /// Segment index and local coordinates of `s` (clamped to the ends).
    fn segment(&self, s: f64) -> usize {
        let n = self.knots.len() - 1;
        match self
            .knots
            .binary_search_by(|k| k.partial_cmp(&s).unwrap_or(std::cmp::Ordering::Less))
        {
            Ok(i) => i.min(n - 1),
            Err(i) => i.saturating_sub(1).min(n - 1),
        }
    }

    /// Value and first three derivatives of every axis at `s`, written into
    /// `out[d][axis]` for d = 0..4.
    pub fn eval(&self, s: f64, out: &mut [Vec<f64>; 4]) {
        self.eval_in(self.segment(s), s, out);
    }

    /// An evaluation buffer for [`Spline::eval`].
    pub fn buffer(&self) -> [Vec<f64>; 4] {
        std::array::from_fn(|_| vec![0.0; self.axes()])
    }

    /// Exact bounds of the derivatives per segment (x' is quadratic, x''
    /// linear, x''' constant on each), maximized over the spline.
    pub fn bounds(&self) -> DerivativeBounds {
        let dim = self.axes();
        let mut first = vec![0.0f64; dim];
        let mut second = vec![0.0f64; dim];
        let mut third = vec![0.0f64; dim];
        let mut buf = self.buffer();
        for k in 0..self.knots.len() - 1 {
            let (s0, s1) = (self.knots[k], self.knots[k + 1]);
            for axis in 0..dim {
                let (m0, m1) = (self.second[k][axis], self.second[k + 1][axis]);
                second[axis] = second[axis].max(m0.abs()).max(m1.abs());
                third[axis] = third[axis].max((m1 - m0).abs() / (s1 - s0));
            }
            // |x'| at both ends and where x'' = 0 inside.
            let mut candidates = vec![s0, s1];
            for axis in 0..dim {
                let (m0, m1) = (self.second[k][axis], self.second[k + 1][axis]);
                if m0 * m1 < 0.0 {
                    candidates.push(s0 + (s1 - s0) * m0 / (m0 - m1));
                }
            }
            for s in candidates {
                // Evaluate inside the segment (the ends belong to it).
                let s = s.clamp(s0, s1);
                self.eval_in(k, s, &mut buf);
                for axis in 0..dim {
                    first[axis] = first[axis].max(buf[1][axis].abs());
                }
            }
        }
        let speed = first.iter().map(|d| d * d).sum::<f64>().sqrt();
        DerivativeBounds {
            first,
            second,
            third,
            speed,
        }
    }

    /// [`Spline::eval`] on segment `k`.
    fn eval_in(&self, k: usize, s: f64, out: &mut [Vec<f64>; 4]) {
        let (s0, s1) = (self.knots[k], self.knots[k + 1]);
        let h = s1 - s0;
        let (l, r) = (s1 - s, s - s0);
        let ends = self.second[k].iter().zip(&self.second[k + 1]);
        let values = self.points[k].iter().zip(&self.points[k + 1]);
        for (axis, ((m0, m1), (x0, x1))) in ends.zip(values).enumerate() {
            let c0 = x0 / h - m0 * h / 6.0;
            let c1 = x1 / h - m1 * h / 6.0;
            out[0][axis] =
                m0 * l.powi(3) / (6.0 * h) + m1 * r.powi(3) / (6.0 * h) + c0 * l + c1 * r;
            out[1][axis] = -m0 * l * l / (2.0 * h) + m1 * r * r / (2.0 * h) - c0 + c1;
            out[2][axis] = (m0 * l + m1 * r) / h;
            out[3][axis] = (m1 - m0) / h;
        }
    }
}

/// Euclidean distance.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// `M` of the natural spline (de Boor ch. IV): the tridiagonal system
/// `h_{k−1} M_{k−1} + 2(h_{k−1}+h_k) M_k + h_k M_{k+1} = 6(Δ_k − Δ_{k−1})`,
/// `Δ_k = (x_{k+1} − x_k)/h_k`, `M_0 = M_L = 0`, solved by the Thomas
/// algorithm (diagonally dominant, so stable without pivoting).
fn natural_second_derivatives(knots: &[f64], points: &[Vec<f64>], dim: usize) -> Vec<Vec<f64>> {
    let n = knots.len();
    let mut m = vec![vec![0.0; dim]; n];
    if n < 3 {
        return m;
    }
    let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
    for axis in 0..dim {
        let inner = n - 2;
        let mut diag = vec![0.0; inner];
        let mut upper = vec![0.0; inner];
        let mut rhs = vec![0.0; inner];
        for j in 0..inner {
            let k = j + 1;
            diag[j] = 2.0 * (h[k - 1] + h[k]);
            upper[j] = h[k];
            let d1 = (points[k + 1][axis] - points[k][axis]) / h[k];
            let d0 = (points[k][axis] - points[k - 1][axis]) / h[k - 1];
            rhs[j] = 6.0 * (d1 - d0);
        }
        for j in 1..inner {
            let w = h[j] / diag[j - 1];
            diag[j] -= w * upper[j - 1];
            rhs[j] -= w * rhs[j - 1];
        }
        let mut x = vec![0.0; inner];
        for j in (0..inner).rev() {
            let next = if j + 1 < inner {
                upper[j] * x[j + 1]
            } else {
                0.0
            };
            x[j] = (rhs[j] - next) / diag[j];
        }
        for j in 0..inner {
            m[j + 1][axis] = x[j];
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn increasing_points_on_one_axis_are_the_identity() {
        let s = Spline::new(vec![vec![0.0], vec![0.3], vec![1.0], vec![1.1]], 1e-5).unwrap();
        let mut b = s.buffer();
        for t in [0.0, 0.1, 0.5, 0.99, 1.1] {
            s.eval(t, &mut b);
            assert!((b[0][0] - t).abs() < 1e-12 && (b[1][0] - 1.0).abs() < 1e-12);
        }
        let d = s.bounds();
        assert!((d.first[0] - 1.0).abs() < 1e-12 && d.second[0] < 1e-12);
    }

    #[test]
    fn the_spline_interpolates_and_its_derivatives_match_differences() {
        let pts = vec![
            vec![0.0, 0.0],
            vec![1.0, 0.5],
            vec![2.0, -0.3],
            vec![2.5, 1.0],
        ];
        let s = Spline::new(pts.clone(), 1e-5).unwrap();
        let mut b = s.buffer();
        for (k, p) in pts.iter().enumerate() {
            s.eval(s.knots[k], &mut b);
            assert!(distance(&b[0], p) < 1e-12);
        }
        let bounds = s.bounds();
        let (mut c, mut l, mut r) = (s.buffer(), s.buffer(), s.buffer());
        let e = 1e-6;
        let mut t = 0.01;
        while t < s.length() - 0.01 {
            s.eval(t, &mut c);
            s.eval(t - e, &mut l);
            s.eval(t + e, &mut r);
            for a in 0..2 {
                assert!(((r[0][a] - l[0][a]) / (2.0 * e) - c[1][a]).abs() < 1e-6);
                assert!(((r[1][a] - l[1][a]) / (2.0 * e) - c[2][a]).abs() < 1e-5);
                assert!(c[1][a].abs() <= bounds.first[a] + 1e-12);
                assert!(c[2][a].abs() <= bounds.second[a] + 1e-12);
            }
            t += 0.013;
        }
    }

    #[test]
    fn bad_points_are_refused() {
        assert!(Spline::new(vec![vec![0.0]], 1e-5).is_err());
        assert!(Spline::new(vec![vec![0.0], vec![f64::NAN]], 1e-5).is_err());
        assert!(Spline::new(vec![vec![0.0, 1.0], vec![1.0]], 1e-5).is_err());
        assert!(Spline::new(vec![vec![0.0], vec![1e-5]], 1e-5).is_err());
        assert!(Spline::new(vec![vec![0.0; 7], vec![1.0; 7]], 1e-5).is_err());
    }
}
