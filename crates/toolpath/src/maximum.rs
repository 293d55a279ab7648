//! The largest value of a function of one parameter on an interval, by a
//! grid and a golden-section refinement: the search behind kerf's corner
//! curvature, its jerk norm and a corner curve's largest curvature.

/// Golden-section steps of the refinement: the bracket of two grid steps
/// shrinks to 0.618²⁴ ≈ 10⁻⁵ of itself.
const GOLDEN_STEPS: usize = 24;

/// The largest value of `f` on [`lo`, `hi`]: `samples` + 1 equally spaced
/// parameters, the best refined by [`GOLDEN_STEPS`] golden-section steps on
/// its two neighbouring grid steps (clamped to the interval). A sampled
/// estimate: a peak narrower than a grid step can be missed.
///
/// # Returns
/// The largest of the grid's values and the refined one; 0 when every value
/// is ≤ 0.
///
/// # Performance
/// `samples` + 1 + 2 · [`GOLDEN_STEPS`] + 1 evaluations of `f`.
pub(crate) fn sampled_maximum(f: impl Fn(f64) -> f64, lo: f64, hi: f64, samples: usize) -> f64 {
    let n = samples.max(1);
    let h = (hi - lo) / n as f64;
    let mut best = (0.0, 0usize);
    for k in 0..=n {
        let v = f(lo + k as f64 * h);
        if v > best.0 {
            best = (v, k);
        }
    }
    let centre = lo + best.1 as f64 * h;
    let (mut a, mut b) = ((centre - h).max(lo), (centre + h).min(hi));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..GOLDEN_STEPS {
        let m1 = b - g * (b - a);
        let m2 = a + g * (b - a);
        if f(m1) < f(m2) {
            a = m1;
        } else {
            b = m2;
        }
    }
    best.0.max(f(0.5 * (a + b)))
}
