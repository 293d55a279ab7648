//! Per-joint Lipschitz bounds of the robot's collision shapes: how far any point of any shape
//! can move per unit of each joint, for the conservative advancement of `kerf_approach`
//! (issue 27).
//!
//! # The bound and its proof
//! Let joint j carry body j (the chain of [`crate::chain::Chain`]: body `j`'s frame is
//! `T_parent · origin_j · motion_j(q_j)`). A point x of a shape on a body b moved by j (b is j
//! or a descendant of it) moves, per unit of q_j, at
//!
//! * `|∂x/∂q_j| = |a_j| = 1` for a prismatic joint (the prismatic column of the geometric
//!   Jacobian, Siciliano, Sciavicco, Villani, Oriolo, *Robotics: Modelling, Planning and
//!   Control*, Springer 2009, section 3.1);
//! * `|∂x/∂q_j| = |a_j × (x − o_j)| ≤ |x − o_j|` for a revolute joint about the unit axis
//!   `a_j` through `o_j`, the origin of body j's frame (the revolute column of the same
//!   Jacobian).
//!
//! Walk from body j to body b through the bodies k between them: `x − o_j = R_j (t_{k1} +
//! R_{k1} (t_{k2} + … + R_b y))` with `t_k` the translation of joint k's origin in its parent
//! body (plus `q_k · axis_k` for a prismatic k), `R` rotations and `y` the point in body b's
//! frame. Rotations keep lengths, so by the triangle inequality
//!
//! ```text
//! |x − o_j| ≤ Σ_k (|t_k| + max |q_k| for prismatic k) + |y|,
//! ```
//!
//! for every configuration: the link lengths of the URDF between the joints plus the shape's
//! reach in its body, `|y| ≤ |c| + r` for the shape's bounding sphere (centre c, radius r, in
//! the body frame; parry's `compute_bounding_sphere`, exact for boxes and cylinders: the
//! half-diagonal). `L_j` is the maximum of that over every shape j moves (0 when it moves
//! none). A monotone joint motion from `a` to `b` thus moves no shape point by more than
//! `Σ_j L_j |b_j − a_j|`, the sweep `kerf_approach::ClearanceCheck` needs.
//!
//! For the IRB 6660 with the spindle of `urdf/cells/irb6660_plate.yaml`: `L_1` = 0.30 + 1.28 +
//! 0.28 + 1.5055 + 0.20 m (the joint origins 2..6 of `urdf/irb6660.urdf`) + 0.365 m (the
//! cutter's reach in `tool0`) ≈ 3.93 m/rad.

use crate::chain::Chain;
use crate::geometry::RobotShape;
use crate::CellError;
use kerf_robot::JointKind;

/// Per-joint Lipschitz bounds `L_j` (m per rad or m per m) of `shapes` on `chain` (module
/// documentation).
///
/// # Errors
/// [`CellError::InvalidValue`] naming the joint when a bound is not finite (a prismatic joint
/// without finite limits between it and a shape).
pub fn lipschitz(chain: &Chain, shapes: &[RobotShape]) -> Result<Vec<f64>, CellError> {
    let joints = &chain.joints;
    let mut out = vec![0.0; joints.len()];
    for s in shapes {
        let Some(b) = s.body else {
            // On the fixed base: no joint moves it.
            continue;
        };
        let sphere = s.shape.compute_bounding_sphere(&s.local);
        let reach = sphere.center.length() + sphere.radius;
        // Walk from body b to the root: `offset` is the bound on |x − o_k| for the joint k
        // reached, the link lengths between k and b plus the shape's reach.
        let mut offset = reach;
        let mut k = Some(b);
        let mut steps = 0;
        while let Some(j) = k {
            // The tree is acyclic (Chain::build); the step count guards a malformed chain.
            steps += 1;
            if steps > joints.len() {
                return Err(CellError::InvalidValue {
                    field: "robot chain".into(),
                    value: steps as f64,
                    requirement: "must be a tree (a body is its own ancestor)",
                });
            }
            let joint = &joints[j];
            let bound = match joint.kind {
                JointKind::Prismatic => 1.0,
                JointKind::Revolute => offset,
            };
            out[j] = f64::max(out[j], bound);
            offset += joint.origin.translation.vector.norm();
            if joint.kind == JointKind::Prismatic {
                offset += joint.limits[0].abs().max(joint.limits[1].abs());
            }
            k = joint.parent;
        }
    }
    for (l, joint) in out.iter().zip(joints) {
        if !l.is_finite() {
            return Err(CellError::InvalidValue {
                field: format!("Lipschitz bound of joint '{}'", joint.name),
                value: *l,
                requirement: "must be finite (prismatic joints need finite limits)",
            });
        }
    }
    Ok(out)
}
