//! Per-joint Lipschitz bounds of the head geometry: how fast any point of
//! any head shape can move per unit of each joint, for conservative
//! advancement between configurations (`kerf_approach`'s clearance check).

use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};

use super::head::{HeadLink, HeadModel, HeadShape, Primitive};

/// Sides of the regular polygon that stands in for each end disc of a
/// cylinder in [`HeadModel::lipschitz`]: its circumradius is `r / cos(π/32)`,
/// 0.48 % above the cylinder's radius.
pub const RIM_SIDES: usize = 32;

/// Finite points of the shape's link frame whose convex hull, grown by a
/// ball of the returned radius, contains the shape.
///
/// * box: its 8 corners, radius 0 (the box is their hull);
/// * cylinder (radius r, half length h, along the shape's z): the vertices
///   of the two regular [`RIM_SIDES`]-gons of circumradius `r / cos(π/n)` at
///   `z = ±h`, radius 0. Such a polygon has apothem (inradius)
///   `r / cos(π/n) · cos(π/n) = r`, so it contains the disc of radius r,
///   and the prism over it contains the cylinder;
/// * sphere: its centre, radius r.
fn hull(s: &HeadShape) -> (Vec<Vector3<f64>>, f64) {
    let at = |x: f64, y: f64, z: f64| (s.origin * Point3::new(x, y, z)).coords;
    match s.primitive {
        Primitive::Box { half_extents: h } => {
            let mut v = Vec::with_capacity(8);
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    for sz in [-1.0, 1.0] {
                        v.push(at(sx * h[0], sy * h[1], sz * h[2]));
                    }
                }
            }
            (v, 0.0)
        }
        Primitive::Cylinder {
            radius,
            half_length,
        } => {
            let n = RIM_SIDES as f64;
            let r = radius / (PI / n).cos();
            let mut v = Vec::with_capacity(2 * RIM_SIDES);
            for k in 0..RIM_SIDES {
                let a = 2.0 * PI * k as f64 / n;
                for z in [-half_length, half_length] {
                    v.push(at(r * a.cos(), r * a.sin(), z));
                }
            }
            (v, 0.0)
        }
        Primitive::Sphere { radius } => (vec![at(0.0, 0.0, 0.0)], radius),
    }
}

impl HeadModel {
    /// Per-joint Lipschitz bounds of the head geometry over the URDF range
    /// of the standoff joint q6 ([`HeadModel::standoff_range`]); see
    /// [`HeadModel::lipschitz_within`].
    pub fn lipschitz(&self) -> [f64; 6] {
        self.lipschitz_within(self.standoff_range)
    }

    /// Per-joint Lipschitz bounds `L_j` (m per m or per rad): for every
    /// joint j, every configuration with q6 in `standoff` and every point x
    /// of every head shape (not inflated by any clearance),
    /// `|∂x/∂q_j| ≤ L_j`. So a monotone joint motion from `a` to `b` moves
    /// no head point by more than `Σ_j L_j |b_j − a_j|`, the sweep of
    /// conservative advancement (`kerf_approach`'s `ClearanceCheck`).
    ///
    /// # Arguments
    /// * `standoff` - the range `[lower, upper]` of q6 (m) the bound must
    ///   hold over (either order).
    ///
    /// # Returns
    /// `[1, 1, 1, L4, L5, 1]`:
    /// * q1, q2, q3, q6 are prismatic: a point they carry moves along the
    ///   unit joint axis, `∂x/∂q_j = z_j` (the prismatic column of the
    ///   geometric Jacobian, Siciliano, Sciavicco, Villani, Oriolo,
    ///   *Robotics: Modelling, Planning and Control*, Springer 2009,
    ///   section 3.1), and a point they do not carry does not move: 1.
    /// * q4 (C axis, about the vertical z through M, carrying `c_axis`,
    ///   `a_axis`, `nozzle`) and q5 (A axis, about the y axis of `c_axis`
    ///   through M, carrying `a_axis`, `nozzle`) are revolute: the revolute
    ///   column of the same Jacobian gives `∂x/∂q_j = a_j × (x − M)` with
    ///   the unit axis `a_j` through M, so `|∂x/∂q_j| = |P_j (x − M)|`, the
    ///   distance from x to the axis (`P_j = I − a_j a_jᵀ`). `L_j` is an
    ///   upper bound of that distance over the shapes the joint carries and
    ///   the motion of the joints after it; infinite when `standoff` is not
    ///   finite and the nozzle has shapes; 0 when the joint carries none.
    ///
    /// # The bound and its proof
    /// Write a point of the joint's child frame (origin M, every joint
    /// origin of the chain is the identity, seed 001 eq. 2) as `x_F`.
    /// * q5, frame `a_axis`, axis y: an `a_axis` point is fixed, `x_F = p`;
    ///   a `nozzle` point is `x_F = p + q6 e_z`. Take `N(x) = |P_y x|`.
    /// * q4, frame `c_axis`, axis z: a `c_axis` point is fixed, `x_F = p`
    ///   with `N(x) = |P_z x|`; an `a_axis` point is `x_F = Ry(q5) p` and a
    ///   `nozzle` point `x_F = Ry(q5)(p + q6 e_z)`, and for them
    ///   `|P_z x_F| ≤ |x_F| = |p + t e_z|` (a rotation about an axis through
    ///   M keeps the distance from M): take `N(x) = |x|`.
    ///
    /// Each shape S is inside `conv(V) ⊕ B(ρ)` for the finite set V and
    /// radius ρ of `hull` (corners of a box; the prisms over the regular
    /// [`RIM_SIDES`]-gons circumscribing a cylinder's end discs; the centre
    /// and radius of a sphere). For `x = v + w` with `v ∈ conv(V)`,
    /// `|w| ≤ ρ`, and `t` = q6 in the range (or 0 for a link q6 does not
    /// carry), the seminorm's triangle inequality and `N(w) ≤ |w|` give
    /// `N(x + t e_z) ≤ N(v + t e_z) + ρ`. The map `(v, t) ↦ N(v + t e_z)`
    /// is convex (a seminorm of an affine map) on the polytope
    /// `conv(V) × [lower, upper] = conv(V × {lower, upper})`, so its maximum
    /// is reached at a point of `V × {lower, upper}` (a convex function
    /// attains its maximum over a polytope at a vertex; R. T. Rockafellar,
    /// *Convex Analysis*, 1970, section 32). Hence
    ///
    /// ```text
    /// L_j = max over carried shapes S, v ∈ V(S), t ∈ T(S) of N_j(v + t e_z) + ρ(S)
    /// ```
    ///
    /// with `T = {lower, upper}` for `nozzle` shapes and `{0}` otherwise
    /// bounds `|∂x/∂q_j|` at every configuration with q6 in the range. ∎
    ///
    /// For the shipped head (`urdf/laser_cutter.urdf`, q6 in
    /// [−0.1, 0.02]): `L4` ≈ 0.1254 m/rad (a corner of a fork arm, exact),
    /// `L5` ≈ 0.09903 m/rad (the nozzle tip's rim at q6 = −0.1; 0.3 µm
    /// above the exact value, from the polygon standing in for the rim).
    /// The bound is void for q6 outside `standoff`: each metre beyond it adds
    /// up to a metre to `L4` and `L5`.
    ///
    /// # Performance
    /// O(shapes · [`RIM_SIDES`]); a few microseconds. Compute it once per
    /// head.
    pub fn lipschitz_within(&self, standoff: [f64; 2]) -> [f64; 6] {
        let finite = standoff.iter().all(|t| t.is_finite());
        let ez = Vector3::z();
        // max over the link's shapes of max_{v, t} N(v + t e_z) + ρ.
        let reach = |link: HeadLink, norm: &dyn Fn(Vector3<f64>) -> f64, ts: &[f64]| -> f64 {
            let mut best: f64 = 0.0;
            for s in self.shapes.iter().filter(|s| s.link == link) {
                if !finite && ts.len() > 1 {
                    return f64::INFINITY;
                }
                let (points, rho) = hull(s);
                for v in &points {
                    for &t in ts {
                        best = best.max(norm(v + t * ez) + rho);
                    }
                }
            }
            best
        };
        let about = |a: Vector3<f64>| move |x: Vector3<f64>| (x - a * a.dot(&x)).norm();
        let about_z = about(Vector3::z());
        let about_y = about(Vector3::y());
        let radius = |x: Vector3<f64>| x.norm();
        let nozzle = [standoff[0], standoff[1]];
        let l4 = reach(HeadLink::CAxis, &about_z, &[0.0])
            .max(reach(HeadLink::AAxis, &radius, &[0.0]))
            .max(reach(HeadLink::Nozzle, &radius, &nozzle));
        let l5 = reach(HeadLink::AAxis, &about_y, &[0.0]).max(reach(
            HeadLink::Nozzle,
            &about_y,
            &nozzle,
        ));
        [1.0, 1.0, 1.0, l4, l5, 1.0]
    }
}
