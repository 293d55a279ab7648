//! 8-point Gauss–Legendre quadrature, the arc length rule of every corner
//! curve. Nodes and weights: Abramowitz and Stegun, Handbook of
//! Mathematical Functions, Table 25.4, n = 8.

/// Positive nodes of the 8-point rule on [−1, 1].
const X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];

/// Their weights.
const W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// ∫ f over [u0, u1] by the 8-point rule (exact for polynomials up to
/// degree 15).
pub(crate) fn gauss_legendre_8(u0: f64, u1: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (mid, half) = (0.5 * (u0 + u1), 0.5 * (u1 - u0));
    let mut total = 0.0;
    for (x, w) in X.iter().zip(W) {
        for s in [-1.0, 1.0] {
            total += w * half * f(mid + s * x * half);
        }
    }
    total
}
