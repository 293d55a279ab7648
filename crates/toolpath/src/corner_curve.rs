//! [`CornerCurve`]: the curve of a corner transition, kerf's quintic
//! Bézier or a baseline's rational cubic B-spline, behind one interface
//! (parameter u ∈ [0, 1] from the incoming segment to the outgoing one).

use crate::bezier::QuinticBezier;
use crate::maximum::sampled_maximum;
use crate::spline::CubicSpline;

/// The curve of a corner transition.
#[derive(Debug, Clone, Copy, PartialEq)]
// A spline is 400 bytes, a quintic 144: boxing would cost an allocation per
// corner and the pieces' Copy, for one value per corner.
#[allow(clippy::large_enum_variant)]
pub enum CornerCurve {
    /// kerf's symmetric quintic ([`crate::corner`]).
    Quintic(QuinticBezier),
    /// A baseline's spline ([`crate::baseline`]).
    Spline(CubicSpline),
}

impl From<QuinticBezier> for CornerCurve {
    fn from(c: QuinticBezier) -> Self {
        CornerCurve::Quintic(c)
    }
}

impl From<CubicSpline> for CornerCurve {
    fn from(c: CubicSpline) -> Self {
        CornerCurve::Spline(c)
    }
}

impl CornerCurve {
    /// The point at u ∈ [0, 1].
    pub fn point(&self, u: f64) -> [f64; 3] {
        match self {
            CornerCurve::Quintic(c) => c.point(u),
            CornerCurve::Spline(c) => c.point(u),
        }
    }

    /// The first derivative in u.
    pub fn d1(&self, u: f64) -> [f64; 3] {
        match self {
            CornerCurve::Quintic(c) => c.d1(u),
            CornerCurve::Spline(c) => c.d1(u),
        }
    }

    /// The second derivative in u.
    pub fn d2(&self, u: f64) -> [f64; 3] {
        match self {
            CornerCurve::Quintic(c) => c.d2(u),
            CornerCurve::Spline(c) => c.d2(u),
        }
    }

    /// The curvature at u \[1/m\]; 0 where the first derivative is 0.
    pub fn curvature(&self, u: f64) -> f64 {
        match self {
            CornerCurve::Quintic(c) => c.curvature(u),
            CornerCurve::Spline(c) => c.curvature(u),
        }
    }

    /// The arc length between the parameters `u0` and `u1` \[m\] (8-point
    /// Gauss–Legendre quadrature; on a spline, per knot span).
    pub fn length_between(&self, u0: f64, u1: f64) -> f64 {
        match self {
            CornerCurve::Quintic(c) => c.length_between(u0, u1),
            CornerCurve::Spline(c) => c.length_between(u0, u1),
        }
    }

    /// The arc length by quadrature on each of `pieces` equal parameter
    /// intervals \[m\].
    pub fn length(&self, pieces: usize) -> f64 {
        match self {
            CornerCurve::Quintic(c) => c.length(pieces),
            CornerCurve::Spline(c) => {
                let pieces = pieces.max(1);
                let h = 1.0 / pieces as f64;
                (0..pieces)
                    .map(|k| c.length_between(k as f64 * h, (k + 1) as f64 * h))
                    .sum()
            }
        }
    }

    /// The first point (u = 0), exactly the first control point.
    pub fn start(&self) -> [f64; 3] {
        match self {
            CornerCurve::Quintic(c) => c.control[0],
            CornerCurve::Spline(c) => c.start(),
        }
    }

    /// The last point (u = 1), exactly the last control point.
    pub fn end(&self) -> [f64; 3] {
        match self {
            CornerCurve::Quintic(c) => c.control[5],
            CornerCurve::Spline(c) => c.end(),
        }
    }

    /// The largest curvature on [u0, u1] \[1/m\]: `samples` + 1 equally
    /// spaced parameters, the best refined by 24 golden-section steps on its
    /// neighbouring interval (a sampled estimate, as kerf's corner's).
    pub fn max_curvature_on(&self, u0: f64, u1: f64, samples: usize) -> f64 {
        sampled_maximum(|u| self.curvature(u), u0, u1, samples)
    }
}
