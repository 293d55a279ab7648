//! Real roots of a low-degree polynomial on an interval.
//!
//! Used to find the exact extrema of the interpolation polynomials (degree ≤ 5, so the
//! derivatives whose roots are needed have degree ≤ 4). Coefficients are in ascending
//! powers: `c[0] + c[1] x + c[2] x² + …`.
//!
//! Method: recursive isolation by the roots of the derivative (Rolle): between consecutive
//! roots of `p'` the polynomial `p` is monotone, so each such piece holds at most one root,
//! found by bisection when `p` changes sign across it. This needs no closed forms (whose
//! cancellation problems for near-degenerate cubics/quartics are well known) and no starting
//! guesses.

/// Maximum number of bisection steps per root. Each halves the bracket; 200 reach the
/// resolution of `f64` for any bracket inside the finite range that occurs here.
const MAX_BISECTIONS: usize = 200;

/// Evaluates `c[0] + c[1] x + … + c[n] xⁿ` by Horner's rule.
///
/// # Performance
/// `n` multiply-adds, no allocation.
#[inline]
pub fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * x + ci)
}

/// Coefficients of the derivative `p'` (one fewer than `c`; empty for a constant).
pub fn derivative(c: &[f64]) -> Vec<f64> {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(i, &ci)| i as f64 * ci)
        .collect()
}

/// All real roots of the polynomial `c` in the closed interval `[lo, hi]`, ascending.
///
/// Roots of odd multiplicity (sign changes) are always found. Roots of even multiplicity
/// (the polynomial touches zero without crossing) are reported only where the polynomial
/// evaluates to exactly 0 — at a critical point or an interval end. For extremum searches
/// this is sufficient: an even-multiplicity root of `p'` is not an extremum of `p`.
///
/// # Arguments
/// * `c` — coefficients in ascending powers, any degree; trailing zeros are ignored.
/// * `lo`, `hi` — the interval; an empty result when either is not finite or `lo > hi`.
///
/// # Returns
/// The roots, sorted ascending, without duplicates. An identically zero polynomial has no
/// isolated roots and yields an empty vector.
///
/// # Performance
/// O(d²) bisection searches of at most 200 steps for degree `d`; a few µs for d ≤ 4.
pub fn real_roots_in(c: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return out;
    }
    let Some(deg) = c.iter().rposition(|&ci| ci != 0.0) else {
        return out;
    };
    let c = &c[..=deg];
    match deg {
        0 => {}
        1 => {
            let x = -c[0] / c[1];
            if x.is_finite() && lo <= x && x <= hi {
                out.push(x);
            }
        }
        _ => {
            let critical = real_roots_in(&derivative(c), lo, hi);
            let mut knots = Vec::with_capacity(critical.len() + 2);
            knots.push(lo);
            knots.extend(critical.into_iter().filter(|&x| lo < x && x < hi));
            knots.push(hi);
            let push = |x: f64, out: &mut Vec<f64>| {
                if out.last() != Some(&x) {
                    out.push(x);
                }
            };
            for w in knots.windows(2) {
                let (a, b) = (w[0], w[1]);
                let (fa, fb) = (eval(c, a), eval(c, b));
                if fa == 0.0 {
                    push(a, &mut out);
                } else if fb != 0.0 && (fa < 0.0) != (fb < 0.0) {
                    push(bisect(c, a, b, fa < 0.0), &mut out);
                }
            }
            if eval(c, hi) == 0.0 {
                push(hi, &mut out);
            }
        }
    }
    out
}

/// Bisection on a bracket `[a, b]` where `p(a) < 0` iff `a_negative` and `p(b)` has the
/// other sign. Stops at an exact zero or when the bracket no longer shrinks.
fn bisect(c: &[f64], mut a: f64, mut b: f64, a_negative: bool) -> f64 {
    for _ in 0..MAX_BISECTIONS {
        let m = a + 0.5 * (b - a);
        if m <= a || m >= b {
            break;
        }
        let fm = eval(c, m);
        if fm == 0.0 {
            return m;
        }
        if (fm < 0.0) == a_negative {
            a = m;
        } else {
            b = m;
        }
    }
    a + 0.5 * (b - a)
}

/// Smallest and largest value of the polynomial `c` on `[lo, hi]`, with their abscissae.
///
/// # Returns
/// `((x_min, p_min), (x_max, p_max))`; candidates are the interval ends and the real roots of
/// `p'` inside it.
pub fn extrema(c: &[f64], lo: f64, hi: f64) -> ((f64, f64), (f64, f64)) {
    let d = derivative(c);
    let mut min = (lo, eval(c, lo));
    let mut max = min;
    let candidates = real_roots_in(&d, lo, hi);
    for x in candidates.into_iter().chain(std::iter::once(hi)) {
        let v = eval(c, x);
        if v < min.1 {
            min = (x, v);
        }
        if v > max.1 {
            max = (x, v);
        }
    }
    (min, max)
}
