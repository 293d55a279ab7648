//! Inverse dynamics of the robot's bodies: the recursive Newton-Euler algorithm.
//!
//! Luh, Walker, Paul, "On-line computational scheme for mechanical manipulators", ASME J.
//! Dyn. Sys. Meas. Control 102(2):69-76, 1980; written in the base frame as in Craig,
//! *Introduction to Robotics*, 3rd ed., eq. 6.45-6.53 (outward: velocities and accelerations;
//! inward: forces and moments). Gravity enters as an upward base acceleration (Craig,
//! section 6.5). Used for the acceleration and gravity feed-forward of the dynamic mode, with
//! the same bodies (masses, centres, tensors) that the rapier multibody integrates, so the
//! feed-forward matches the simulated robot up to the integrator's error.

use nalgebra::{Isometry3, Vector3};

use kerf_robot::JointKind;

use crate::chain::Chain;

/// Scratch buffers of [`inverse_dynamics`], kept between calls (no allocation per call).
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    poses: Vec<Isometry3<f64>>,
    omega: Vec<Vector3<f64>>,
    omega_dot: Vec<Vector3<f64>>,
    acc: Vec<Vector3<f64>>,
    force: Vec<Vector3<f64>>,
    moment: Vec<Vector3<f64>>,
}

/// Joint efforts `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)` of the rigid bodies (without armature or
/// friction), in N or N m.
///
/// # Arguments
/// * `chain` - the bodies.
/// * `q`, `qd`, `qdd` - joint positions, velocities, accelerations (model order).
/// * `gravity` - gravity in the base frame (m/s²), e.g. `(0, 0, -9.81)`.
/// * `ws` - scratch buffers.
/// * `tau` - output, one effort per joint.
///
/// # Performance
/// O(joints), no allocation once `ws` has grown.
pub fn inverse_dynamics(
    chain: &Chain,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: &Vector3<f64>,
    ws: &mut Workspace,
    tau: &mut [f64],
) {
    let n = chain.joints.len();
    chain.body_poses(q, &mut ws.poses);
    ws.omega.clear();
    ws.omega_dot.clear();
    ws.acc.clear();
    // Outward recursion: angular velocity and acceleration of each body, linear acceleration
    // of its frame origin (Craig eq. 6.45-6.47 and 6.48-6.50 for prismatic joints).
    for (j, joint) in chain.joints.iter().enumerate() {
        let (w0, wd0, a0, p0) = match joint.parent {
            Some(p) => (
                ws.omega[p],
                ws.omega_dot[p],
                ws.acc[p],
                ws.poses[p].translation.vector,
            ),
            None => (
                Vector3::zeros(),
                Vector3::zeros(),
                -gravity,
                Vector3::zeros(),
            ),
        };
        let pose = &ws.poses[j];
        let axis = pose.rotation * joint.axis.into_inner();
        let r = pose.translation.vector - p0;
        let mut a = a0 + wd0.cross(&r) + w0.cross(&w0.cross(&r));
        let (w, wd) = match joint.kind {
            JointKind::Revolute => (
                w0 + axis * qd[j],
                wd0 + axis * qdd[j] + w0.cross(&(axis * qd[j])),
            ),
            JointKind::Prismatic => {
                a += axis * qdd[j] + 2.0 * w0.cross(&(axis * qd[j]));
                (w0, wd0)
            }
        };
        ws.omega.push(w);
        ws.omega_dot.push(wd);
        ws.acc.push(a);
    }
    // Body forces at the centres of mass (Newton and Euler, Craig eq. 6.51-6.52), moments
    // about the body frame origin.
    ws.force.clear();
    ws.moment.clear();
    for (j, joint) in chain.joints.iter().enumerate() {
        let pose = &ws.poses[j];
        let m = &joint.mass;
        let rc = pose.rotation * m.com;
        let (w, wd) = (ws.omega[j], ws.omega_dot[j]);
        let ac = ws.acc[j] + wd.cross(&rc) + w.cross(&w.cross(&rc));
        let r = pose.rotation.to_rotation_matrix();
        let inertia = r * m.inertia * r.transpose();
        let f = ac * m.mass;
        let nc = inertia * wd + w.cross(&(inertia * w));
        ws.force.push(f);
        ws.moment.push(nc + rc.cross(&f));
    }
    // Inward recursion (Craig eq. 6.53): children's forces and moments into their parents.
    for j in (0..n).rev() {
        let joint = &chain.joints[j];
        let axis = ws.poses[j].rotation * joint.axis.into_inner();
        tau[j] = match joint.kind {
            JointKind::Revolute => axis.dot(&ws.moment[j]),
            JointKind::Prismatic => axis.dot(&ws.force[j]),
        };
        if let Some(p) = joint.parent {
            let f = ws.force[j];
            let arm = ws.poses[j].translation.vector - ws.poses[p].translation.vector;
            let m = ws.moment[j] + arm.cross(&f);
            ws.force[p] += f;
            ws.moment[p] += m;
        }
    }
}

/// Diagonal of the joint-space mass matrix `M(q)` of the rigid bodies (without armature), in
/// kg or kg m².
///
/// From the kinetic energy, `M(q) = Σ_b (m_b J_v,bᵀ J_v,b + J_ω,bᵀ I_b J_ω,b)` (Siciliano,
/// Sciavicco, Villani, Oriolo, *Robotics: Modelling, Planning and Control*, 2009, eq. 7.32),
/// with the geometric Jacobian columns of joint `j` at body `b`'s centre of mass
/// (ibid., eq. 3.30): `J_v = a_j × (c_b − o_j)`, `J_ω = a_j` for a revolute joint and
/// `J_v = a_j`, `J_ω = 0` for a prismatic one, for every body `b` that joint `j` moves. The
/// diagonal entry is `Σ_b m_b |J_v|² + J_ωᵀ I_b J_ω`: the same numbers as
/// [`inverse_dynamics`] with a unit acceleration of joint `j` and no velocity or gravity
/// (Walker and Orin's method 1), in one pass instead of one per joint.
///
/// # Arguments
/// * `chain` - the bodies.
/// * `q` - joint positions (model order).
/// * `ws` - scratch buffers.
/// * `out` - output, one entry per joint.
///
/// # Performance
/// O(joints × depth), no allocation once `ws` has grown.
pub fn mass_diagonal(chain: &Chain, q: &[f64], ws: &mut Workspace, out: &mut [f64]) {
    chain.body_poses(q, &mut ws.poses);
    out.iter_mut().for_each(|m| *m = 0.0);
    for (b, body) in chain.joints.iter().enumerate() {
        let pose = &ws.poses[b];
        let m = &body.mass;
        let centre = pose * nalgebra::Point3::from(m.com);
        let r = pose.rotation.to_rotation_matrix();
        let inertia = r * m.inertia * r.transpose();
        let mut j = Some(b);
        while let Some(k) = j {
            let joint = &chain.joints[k];
            let frame = &ws.poses[k];
            let axis = frame.rotation * joint.axis.into_inner();
            out[k] += match joint.kind {
                JointKind::Revolute => {
                    let v = axis.cross(&(centre.coords - frame.translation.vector));
                    m.mass * v.norm_squared() + axis.dot(&(inertia * axis))
                }
                JointKind::Prismatic => m.mass * axis.norm_squared(),
            };
            j = joint.parent;
        }
    }
}
