//! Conservative bounds for skipping distance queries: how far any point of a shape can have
//! moved between two poses, and the gap between two bounding boxes.
//!
//! A pair whose distance was at least `d` at pose `P0` is at least `d − δ(P0, P1)` apart at
//! `P1` (the scene objects are static), so while `d − δ ≥ threshold` it cannot be a contact
//! and its query can be skipped without changing any result. This is the bound of
//! conservative advancement (Mirtich, "Impulse-based dynamic simulation of rigid body
//! systems", PhD thesis, UC Berkeley, 1996, section 2.3.2; Zhang, Lee, Kim, "Continuous
//! collision detection for articulated models using Taylor models and temporal culling",
//! ACM TOG 26(3), 2007, eq. 1: `|Δp| ≤ |Δc| + |Δθ| r`), here with the chord `2 sin(θ/2)`
//! instead of the arc `θ` because only the end poses matter, not the path between them.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::Shape;

/// A shape's bounding sphere in its own frame: the data of [`ShapeBound::displacement`].
#[derive(Debug, Clone, Copy)]
pub struct ShapeBound {
    center: Vector,
    radius: f64,
}

impl ShapeBound {
    /// The bound of `shape` (its local bounding sphere).
    pub fn new(shape: &dyn Shape) -> Self {
        let sphere = shape.compute_local_bounding_sphere();
        Self {
            center: sphere.center(),
            radius: sphere.radius(),
        }
    }

    /// Largest distance any point of the shape moves from pose `from` to pose `to`:
    /// `δ = |P1 c − P0 c| + 2 sin(θ/2) R`, with `c`, `R` the local bounding sphere and `θ` the
    /// angle of the relative rotation `R1 R0ᵀ` (for a point `x = c + y`, `|y| ≤ R`:
    /// `P1 x − P0 x = (P1 c − P0 c) + (R1 R0ᵀ − I) R0 y`, and `|(Q − I) v| ≤ 2 sin(θ/2) |v|`
    /// for a rotation `Q` by `θ`). `sin(θ/2)` is the norm of the relative quaternion's vector
    /// part, so no trigonometry is needed.
    ///
    /// # Performance
    /// Two point transforms and one quaternion product.
    pub fn displacement(&self, from: &Pose, to: &Pose) -> f64 {
        let moved = (to * self.center - from * self.center).length();
        let relative = to.rotation * from.rotation.conjugate();
        let half_sine = Vector::new(relative.x, relative.y, relative.z).length();
        moved + 2.0 * half_sine.min(1.0) * self.radius
    }
}

/// Euclidean distance between two axis-aligned boxes (0 when they overlap): a lower bound on
/// the distance of any two shapes they contain.
pub fn aabb_gap(a: &Aabb, b: &Aabb) -> f64 {
    let below = b.mins - a.maxs;
    let above = a.mins - b.maxs;
    below.max(above).max(Vector::ZERO).length()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use parry3d_f64::math::Rotation;
    use parry3d_f64::shape::{Cone, Cuboid};

    /// Largest displacement of the shape's vertices (a box's corners bound its points).
    fn corner_displacement(half: Vector, from: &Pose, to: &Pose) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 0..8 {
            let p = Vector::new(
                if i & 1 == 0 { -half.x } else { half.x },
                if i & 2 == 0 { -half.y } else { half.y },
                if i & 4 == 0 { -half.z } else { half.z },
            );
            worst = worst.max((to * p - from * p).length());
        }
        worst
    }

    #[test]
    fn displacement_bounds_every_corner_and_is_tight_for_a_translation() {
        let half = Vector::new(0.3, 0.05, 0.1);
        let bound = ShapeBound::new(&Cuboid::new(half));
        let from = Pose::from_parts(Vector::new(0.1, 0.2, 0.3), Rotation::from_rotation_x(0.4));
        let moved = Pose::from_parts(Vector::new(0.1, 0.2, 0.301), from.rotation);
        assert!((bound.displacement(&from, &moved) - 0.001).abs() < 1e-12);
        let mut tight: f64 = 1.0;
        for k in 1..50 {
            let a = k as f64 * 0.03;
            let to = Pose::from_parts(
                Vector::new(0.1 + 0.002 * a, 0.2, 0.3 - 0.001 * a),
                Rotation::from_rotation_x(0.4)
                    * Rotation::from_axis_angle(Vector::new(0.6, 0.0, 0.8), a),
            );
            let exact = corner_displacement(half, &from, &to);
            let b = bound.displacement(&from, &to);
            assert!(
                b >= exact - 1e-12,
                "bound {b} below a corner's move {exact}"
            );
            tight = tight.min(exact / b);
        }
        // The sphere around the box is the only slack: the bound is within a factor of 2.
        assert!(tight > 0.5, "bound looser than expected: {tight}");
    }

    #[test]
    fn displacement_of_a_half_turn_is_the_sphere_diameter() {
        let cone = Cone::new(0.05, 0.02);
        let bound = ShapeBound::new(&cone);
        let sphere = cone.compute_local_bounding_sphere();
        let from = Pose::IDENTITY;
        let to = Pose::from_parts(
            Vector::ZERO,
            Rotation::from_axis_angle(Vector::X, std::f64::consts::PI),
        );
        let d = bound.displacement(&from, &to);
        let c = sphere.center().length();
        assert!(d <= 2.0 * (sphere.radius() + c) + 1e-12 && d >= 2.0 * sphere.radius() - 1e-12);
    }

    #[test]
    fn aabb_gap_is_the_box_distance() {
        let a = Aabb::new(Vector::ZERO, Vector::ONE);
        let b = Aabb::new(Vector::new(4.0, 5.0, 0.5), Vector::new(6.0, 6.0, 2.0));
        assert!((aabb_gap(&a, &b) - 5.0).abs() < 1e-12);
        assert!((aabb_gap(&b, &a) - 5.0).abs() < 1e-12);
        let c = Aabb::new(Vector::splat(0.5), Vector::splat(2.0));
        assert_eq!(aabb_gap(&a, &c), 0.0);
    }
}
