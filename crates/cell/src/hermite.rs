//! Cubic Hermite interpolation between two samples of position and velocity: the cell's
//! reference within a control period, and its tests' and bench's commands between the samples
//! of a plan.

/// The cubic Hermite basis and its derivative at a fraction `s` ∈ [0, 1] of an interval
/// (e.g. Bartels, Beatty, Barsky, *An Introduction to Splines for Use in Computer Graphics*,
/// 1987, section 3.6): p(s) = h00 p0 + h10 h v0 + h01 p1 + h11 h v1 over an interval of length
/// h, and p′ = (d00 p0 + d10 h v0 + d01 p1 + d11 h v1) / h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hermite {
    h00: f64,
    h10: f64,
    h01: f64,
    h11: f64,
    d00: f64,
    d10: f64,
    d01: f64,
    d11: f64,
}

impl Hermite {
    /// The basis at fraction `s` of the interval.
    pub fn at(s: f64) -> Self {
        let (s2, s3) = (s * s, s * s * s);
        Self {
            h00: 2.0 * s3 - 3.0 * s2 + 1.0,
            h10: s3 - 2.0 * s2 + s,
            h01: -2.0 * s3 + 3.0 * s2,
            h11: s3 - s2,
            d00: 6.0 * s2 - 6.0 * s,
            d10: 3.0 * s2 - 4.0 * s + 1.0,
            d01: -6.0 * s2 + 6.0 * s,
            d11: 3.0 * s2 - 2.0 * s,
        }
    }

    /// The position between (`p0`, `v0`) and (`p1`, `v1`) over an interval of length `h`.
    pub fn position(&self, p0: f64, v0: f64, p1: f64, v1: f64, h: f64) -> f64 {
        self.h00 * p0 + self.h10 * h * v0 + self.h01 * p1 + self.h11 * h * v1
    }

    /// The velocity (the position's derivative in time) at the same point.
    pub fn velocity(&self, p0: f64, v0: f64, p1: f64, v1: f64, h: f64) -> f64 {
        (self.d00 * p0 + self.d10 * h * v0 + self.d01 * p1 + self.d11 * h * v1) / h
    }
}
