//! Searches for the largest value of a function of one parameter on an
//! interval: a grid and a golden-section refinement (kerf's corner
//! curvature, its jerk norm, a corner curve's largest curvature), and the
//! golden section alone on a unimodal function (the adaptive sampler's
//! features, eq. 17's critical radius).

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

/// Where a unimodal `f` is largest on [`lo`, `hi`], by `steps` steps of golden section, each
/// reusing one of the previous step's two evaluations; the middle of the last bracket, whose
/// width is 0.618^`steps` of the interval's.
///
/// # Performance
/// `steps` + 2 evaluations of `f`.
pub(crate) fn golden_argmax(mut lo: f64, mut hi: f64, steps: usize, f: impl Fn(f64) -> f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut m1 = hi - g * (hi - lo);
    let mut m2 = lo + g * (hi - lo);
    let (mut f1, mut f2) = (f(m1), f(m2));
    for _ in 0..steps {
        if f1 < f2 {
            lo = m1;
            m1 = m2;
            f1 = f2;
            m2 = lo + g * (hi - lo);
            f2 = f(m2);
        } else {
            hi = m2;
            m2 = m1;
            f2 = f1;
            m1 = hi - g * (hi - lo);
            f1 = f(m1);
        }
    }
    0.5 * (lo + hi)
}
