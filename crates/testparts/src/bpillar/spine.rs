//! The spine of the part: straight pieces and circular arcs in the
//! workpiece x-z plane, and the frame it carries along its arc length.

use nalgebra::Vector3;

use super::params::BPillarParams;

/// One piece of the spine, a plane curve in the workpiece x-z plane:
/// straight (`curvature` 0) or a circular arc bending away from the head
/// side (the spine angle α decreases with s).
#[derive(Debug, Clone, Copy)]
struct SpineSegment {
    s0: f64,
    curvature: f64,
    x0: f64,
    z0: f64,
    alpha0: f64,
}

/// A point of the spine: position, angle α of the tangent
/// `t = (cos α, 0, sin α)` and curvature.
#[derive(Debug, Clone, Copy)]
pub(super) struct SpinePoint {
    pub(super) pos: Vector3<f64>,
    pub(super) alpha: f64,
    pub(super) curvature: f64,
}

impl SpinePoint {
    /// Unit tangent `(cos α, 0, sin α)`.
    pub(super) fn tangent(&self) -> Vector3<f64> {
        Vector3::new(self.alpha.cos(), 0.0, self.alpha.sin())
    }

    /// Unit normal of the flange plane, `u = (-sin α, 0, cos α)`; with
    /// ŷ and the tangent t, (t, ŷ, u) is right-handed.
    pub(super) fn up(&self) -> Vector3<f64> {
        Vector3::new(-self.alpha.sin(), 0.0, self.alpha.cos())
    }

    /// The surface point of profile coordinates (y, z): `S + y ŷ + z u`.
    pub(super) fn map(&self, y: f64, z: f64) -> Vector3<f64> {
        self.pos + Vector3::new(0.0, y, 0.0) + self.up() * z
    }

    /// A profile direction (dy, dz) in 3D: `dy ŷ + dz u`.
    pub(super) fn map_dir(&self, dy: f64, dz: f64) -> Vector3<f64> {
        Vector3::new(0.0, dy, 0.0) + self.up() * dz
    }
}

impl SpineSegment {
    /// The point at arc length `s` (extrapolated outside the segment).
    ///
    /// Arc: α(s) = α0 - κ (s - s0); integrating t = (cos α, sin α) gives
    /// x = x0 - (sin α - sin α0) / κ, z = z0 + (cos α - cos α0) / κ.
    fn eval(&self, s: f64) -> SpinePoint {
        let d = s - self.s0;
        if self.curvature == 0.0 {
            SpinePoint {
                pos: Vector3::new(
                    self.x0 + d * self.alpha0.cos(),
                    0.0,
                    self.z0 + d * self.alpha0.sin(),
                ),
                alpha: self.alpha0,
                curvature: 0.0,
            }
        } else {
            let k = self.curvature;
            let alpha = self.alpha0 - k * d;
            SpinePoint {
                pos: Vector3::new(
                    self.x0 - (alpha.sin() - self.alpha0.sin()) / k,
                    0.0,
                    self.z0 + (alpha.cos() - self.alpha0.cos()) / k,
                ),
                alpha,
                curvature: k,
            }
        }
    }
}

/// The spine: consecutive segments from s = 0.
#[derive(Debug, Clone)]
pub(super) struct Spine {
    segments: Vec<SpineSegment>,
}

impl Spine {
    pub(super) fn new(p: &BPillarParams) -> Self {
        let pieces = [
            (p.foot_length + p.transition_length, 0.0),
            (p.curved_length, 1.0 / p.spine_radius),
            (p.kink_radius * p.kink_angle, 1.0 / p.kink_radius),
            (p.head_length, 0.0),
        ];
        let mut segments = Vec::with_capacity(pieces.len());
        let (mut s0, mut x0, mut z0, mut alpha0) = (0.0, 0.0, 0.0, 0.0);
        for (length, curvature) in pieces {
            let seg = SpineSegment {
                s0,
                curvature,
                x0,
                z0,
                alpha0,
            };
            let end = seg.eval(s0 + length);
            segments.push(seg);
            s0 += length;
            x0 = end.pos.x;
            z0 = end.pos.z;
            alpha0 = end.alpha;
        }
        Self { segments }
    }

    /// The point at arc length `s` (the last segment that starts at or
    /// before `s`; the first segment before 0).
    pub(super) fn eval(&self, s: f64) -> SpinePoint {
        let seg = self
            .segments
            .iter()
            .rev()
            .find(|g| g.s0 <= s)
            .or(self.segments.first());
        match seg {
            Some(g) => g.eval(s),
            None => SpinePoint {
                pos: Vector3::zeros(),
                alpha: 0.0,
                curvature: 0.0,
            },
        }
    }
}
