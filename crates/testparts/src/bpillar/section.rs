//! The hat cross-section of the part: its dimensions, checks and outer
//! profile with fillets.

use super::MIN_PIECE;
use crate::TestPartError;

/// One hat cross-section, in the section plane (y across, z towards the
/// head side; the flanges lie on z = 0, the hat is symmetric about y = 0).
///
/// Dimensions are of the outer (head-side) surface, measured at the
/// virtual sharp corners where the straight pieces would meet without
/// fillets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HatSection {
    /// Half width of the top between the virtual wall-top corners (m).
    pub top_half_width: f64,
    /// Height of the top above the flanges (m).
    pub depth: f64,
    /// Angle between each wall and the flange plane (rad), in (0, π/2].
    pub wall_angle: f64,
    /// Radius of the concave fillet between flange and wall (m).
    pub flange_fillet_radius: f64,
    /// Radius of the convex fillet between wall and top (m).
    pub top_fillet_radius: f64,
    /// Flange width from the virtual flange-wall corner to the free edge (m).
    pub flange_width: f64,
}

impl HatSection {
    /// Tangent length of the flange fillet: distance from the virtual
    /// flange-wall corner to each tangent point, `r tan(β/2)` for a fillet
    /// of radius r between two lines meeting at a deflection β.
    pub fn flange_fillet_tangent(&self) -> f64 {
        self.flange_fillet_radius * (self.wall_angle / 2.0).tan()
    }

    /// Tangent length of the top fillet, `r tan(β/2)`.
    pub fn top_fillet_tangent(&self) -> f64 {
        self.top_fillet_radius * (self.wall_angle / 2.0).tan()
    }

    /// y of the left virtual flange-wall corner, `-(b + h cot β)` (m).
    pub fn flange_corner_y(&self) -> f64 {
        -(self.top_half_width + self.depth / self.wall_angle.tan())
    }

    /// y of the left flange's free edge (m).
    pub fn flange_edge_y(&self) -> f64 {
        self.flange_corner_y() - self.flange_width
    }

    /// y where the left flange ends and its fillet starts (m).
    pub fn flange_tangent_y(&self) -> f64 {
        self.flange_corner_y() - self.flange_fillet_tangent()
    }

    /// Length of the straight part of each wall between its two fillets
    /// (m): `h / sin β` minus both tangent lengths.
    pub fn wall_straight_length(&self) -> f64 {
        self.depth / self.wall_angle.sin()
            - self.flange_fillet_tangent()
            - self.top_fillet_tangent()
    }

    /// Checks that the section is finite and its pieces fit.
    ///
    /// # Arguments
    /// * `field` - name used in errors (e.g. `bpillar.foot`).
    /// * `thickness` - sheet thickness (m); every fillet radius must exceed
    ///   it so the inner surface does not fold.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] naming the field when a value is not
    /// finite or positive, the wall angle is outside (0, π/2], a radius is
    /// not larger than the thickness, or the flange, wall or top is too
    /// short for its fillets (straight piece < 1 mm).
    pub fn validate(&self, field: &str, thickness: f64) -> Result<(), TestPartError> {
        for (name, v) in [
            ("top_half_width", self.top_half_width),
            ("depth", self.depth),
            ("wall_angle", self.wall_angle),
            ("flange_fillet_radius", self.flange_fillet_radius),
            ("top_fillet_radius", self.top_fillet_radius),
            ("flange_width", self.flange_width),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(TestPartError::invalid(
                    format!("{field}.{name}"),
                    format!("{v} must be finite and > 0"),
                ));
            }
        }
        if self.wall_angle > std::f64::consts::FRAC_PI_2 {
            return Err(TestPartError::invalid(
                format!("{field}.wall_angle"),
                format!("{} rad must be in (0, π/2]", self.wall_angle),
            ));
        }
        for (name, r) in [
            ("flange_fillet_radius", self.flange_fillet_radius),
            ("top_fillet_radius", self.top_fillet_radius),
        ] {
            if r <= thickness {
                return Err(TestPartError::invalid(
                    format!("{field}.{name}"),
                    format!("{r} m must exceed the sheet thickness {thickness} m"),
                ));
            }
        }
        let pieces = [
            (
                "flange_width",
                self.flange_width - self.flange_fillet_tangent(),
            ),
            ("depth", self.wall_straight_length()),
            (
                "top_half_width",
                self.top_half_width - self.top_fillet_tangent(),
            ),
        ];
        for (name, len) in pieces {
            if len.is_nan() || len < MIN_PIECE {
                return Err(TestPartError::invalid(
                    format!("{field}.{name}"),
                    format!(
                        "leaves a straight piece of {len:.6} m beside the fillets (at least \
                         {MIN_PIECE} m needed)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Blend `a (1 - w) + b w` of every dimension (exactly `a` at w = 0
    /// and `b` at w = 1).
    pub(super) fn blend(a: &HatSection, b: &HatSection, w: f64) -> HatSection {
        let l = |x: f64, y: f64| x * (1.0 - w) + y * w;
        HatSection {
            top_half_width: l(a.top_half_width, b.top_half_width),
            depth: l(a.depth, b.depth),
            wall_angle: l(a.wall_angle, b.wall_angle),
            flange_fillet_radius: l(a.flange_fillet_radius, b.flange_fillet_radius),
            top_fillet_radius: l(a.top_fillet_radius, b.top_fillet_radius),
            flange_width: l(a.flange_width, b.flange_width),
        }
    }

    /// The outer profile from the left flange edge to the right flange
    /// edge: `2 (n1 + n2 + 3)` vertices with their unit head-side normals.
    ///
    /// Left half: flange edge; the concave flange fillet, centre
    /// `c1 = (y_c - r1 tan(β/2), r1)`, points `c1 + r1 (sin φ, -cos φ)`,
    /// normal `(-sin φ, cos φ)`, φ = 0 → β; the convex top fillet, centre
    /// `c2 = (-b + r2 tan(β/2), h - r2)`, points `c2 + r2 (-sin φ, cos φ)`,
    /// same normal, φ = β → 0. The right half is the mirror image. (Fillet
    /// construction: a circle tangent to both lines, its tangent points at
    /// `r tan(β/2)` from the corner.)
    pub(super) fn profile(&self, n1: usize, n2: usize) -> Vec<ProfileVertex> {
        let beta = self.wall_angle;
        let (r1, r2) = (self.flange_fillet_radius, self.top_fillet_radius);
        let mut left = Vec::with_capacity(n1 + n2 + 3);
        left.push(ProfileVertex {
            y: self.flange_edge_y(),
            z: 0.0,
            ny: 0.0,
            nz: 1.0,
        });
        let c1 = (self.flange_tangent_y(), r1);
        for k in 0..=n1 {
            let phi = beta * k as f64 / n1 as f64;
            let (s, c) = phi.sin_cos();
            left.push(ProfileVertex {
                y: c1.0 + r1 * s,
                z: c1.1 - r1 * c,
                ny: -s,
                nz: c,
            });
        }
        let c2 = (
            -self.top_half_width + self.top_fillet_tangent(),
            self.depth - r2,
        );
        for k in 0..=n2 {
            let phi = beta * (n2 - k) as f64 / n2 as f64;
            let (s, c) = phi.sin_cos();
            left.push(ProfileVertex {
                y: c2.0 - r2 * s,
                z: c2.1 + r2 * c,
                ny: -s,
                nz: c,
            });
        }
        let right: Vec<ProfileVertex> = left
            .iter()
            .rev()
            .map(|v| ProfileVertex {
                y: -v.y,
                z: v.z,
                ny: -v.ny,
                nz: v.nz,
            })
            .collect();
        left.extend(right);
        left
    }
}

/// A vertex of a section profile: position (y, z) and unit head-side
/// normal (ny, nz).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ProfileVertex {
    pub(super) y: f64,
    pub(super) z: f64,
    pub(super) ny: f64,
    pub(super) nz: f64,
}

/// Index of the first vertex of the left flange fillet in a profile.
pub(super) const LEFT_FLANGE_FILLET_START: usize = 1;
