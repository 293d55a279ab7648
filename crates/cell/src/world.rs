//! The rapier world of the robot: one dynamic rigid body per movable joint, joined by rapier
//! multibody (reduced-coordinate) joints to a fixed base body.
//!
//! The bodies carry no colliders: contacts are decided by [`crate::contact`] from distance
//! queries, and the robot is not pushed back by the scene (a contact is a fault to report,
//! not a collision to resolve). Mass properties come from [`crate::chain`]; viscous friction
//! is rapier's implicit per-DoF damping, Coulomb friction its per-DoF `frictions`
//! (MuJoCo's `frictionloss`), and the armature its per-DoF `armature`.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Matrix, Pose, Vector};
use rapier3d_f64::dynamics::{
    GenericJointBuilder, JointAxesMask, JointAxis, MultibodyIndex, RigidBodyBuilder,
    RigidBodyHandle,
};
use rapier3d_f64::pipeline::PhysicsWorld;

use kerf_robot::JointKind;

use crate::chain::{BodyJoint, Chain};
use crate::geometry::{to_isometry, to_pose};
use crate::CellError;

/// The rotation that takes the x axis onto `axis` (rapier's joints move along/about their
/// frame's x axis).
fn x_to_axis(axis: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&Vector3::x(), axis).unwrap_or_else(|| {
        // axis = -x: half a turn about z.
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
    })
}

/// The robot in rapier.
pub struct World {
    /// The rapier sets and pipeline.
    pub physics: PhysicsWorld,
    /// Body of each movable joint.
    pub handles: Vec<RigidBodyHandle>,
    /// The base (fixed) body.
    pub base: RigidBodyHandle,
    /// The multibody.
    pub multibody: MultibodyIndex,
    /// Multibody link id of each joint's body.
    pub link_ids: Vec<usize>,
    /// Generalized-coordinate index of each joint.
    pub dofs: Vec<usize>,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("bodies", &self.handles.len())
            .field("dofs", &self.dofs)
            .finish()
    }
}

fn mass_properties(j: &BodyJoint) -> MassProperties {
    let m = &j.mass;
    let i = m.inertia;
    MassProperties::with_inertia_matrix(
        Vector::new(m.com.x, m.com.y, m.com.z),
        m.mass,
        Matrix::from_cols_array(&[
            i[(0, 0)],
            i[(1, 0)],
            i[(2, 0)],
            i[(0, 1)],
            i[(1, 1)],
            i[(2, 1)],
            i[(0, 2)],
            i[(1, 2)],
            i[(2, 2)],
        ]),
    )
}

impl World {
    /// Builds the multibody at joint positions `q0`.
    ///
    /// # Arguments
    /// * `chain` - the bodies.
    /// * `q0` - initial joint positions.
    /// * `gravity` - base-frame gravity (m/s²).
    /// * `dt` - physics step (s).
    ///
    /// # Errors
    /// [`CellError::Robot`] if rapier refuses a joint (a loop in the tree).
    pub fn new(
        chain: &Chain,
        q0: &[f64],
        gravity: &Vector3<f64>,
        dt: f64,
    ) -> Result<Self, CellError> {
        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::new(gravity.x, gravity.y, gravity.z);
        physics.integration_parameters.dt = dt;
        // rapier's solver iterations are substeps: each one updates the multibody's mass
        // matrix and integrates (TGS). The cell already steps at the physics rate, so one
        // substep per step; its constraints (the joint limits and each DoF's dry friction,
        // no contacts: the bodies have no colliders) get 4 PGS iterations instead. This cuts
        // a 1 kHz step of the laser cutter from 36 us to about 11 us (median,
        // examples/step_cost.rs), with the holding and tracking tests' bounds unchanged.
        physics.integration_parameters.num_solver_iterations = 1;
        physics.integration_parameters.num_internal_pgs_iterations = 4;
        let base = physics.bodies.insert(RigidBodyBuilder::fixed().build());
        let mut poses = Vec::new();
        chain.body_poses(q0, &mut poses);
        let mut handles = Vec::with_capacity(chain.joints.len());
        for (j, joint) in chain.joints.iter().enumerate() {
            let rb = RigidBodyBuilder::dynamic()
                .pose(to_pose(&poses[j]))
                .additional_mass_properties(mass_properties(joint))
                .can_sleep(false)
                .build();
            let h = physics.bodies.insert(rb);
            let parent = joint.parent.map_or(base, |p| handles[p]);
            let ra = x_to_axis(&joint.axis.into_inner());
            let frame1 = joint.origin * Isometry3::from_parts(Default::default(), ra);
            let frame2 = Isometry3::from_parts(Default::default(), ra);
            let (mask, axis) = match joint.kind {
                JointKind::Revolute => (JointAxesMask::LOCKED_REVOLUTE_AXES, JointAxis::AngX),
                JointKind::Prismatic => (JointAxesMask::LOCKED_PRISMATIC_AXES, JointAxis::LinX),
            };
            let mut builder = GenericJointBuilder::new(mask)
                .local_frame1(to_pose(&frame1))
                .local_frame2(to_pose(&frame2))
                .contacts_enabled(false);
            if joint.limits.iter().all(|l| l.is_finite()) {
                builder = builder.limits(axis, joint.limits);
            }
            physics
                .multibody_joints
                .insert(parent, h, builder.build(), true)
                .ok_or_else(|| CellError::Robot {
                    reason: format!("rapier refused the multibody joint '{}'", joint.name),
                })?;
            handles.push(h);
        }
        let first = handles.first().ok_or_else(|| CellError::Robot {
            reason: "the robot has no movable joint".into(),
        })?;
        let link = physics
            .multibody_joints
            .rigid_body_link(*first)
            .copied()
            .ok_or_else(|| CellError::Robot {
                reason: "rapier lost the multibody".into(),
            })?;
        let multibody = link.multibody;
        let mut link_ids = Vec::new();
        for h in &handles {
            let l = physics
                .multibody_joints
                .rigid_body_link(*h)
                .ok_or_else(|| CellError::Robot {
                    reason: "rapier lost a multibody link".into(),
                })?;
            link_ids.push(l.id);
        }
        let mb = physics
            .multibody_joints
            .get_multibody_mut(multibody)
            .ok_or_else(|| CellError::Robot {
                reason: "rapier lost the multibody".into(),
            })?;
        // The root starts as a free joint (6 DoFs) until rapier sees that its body is fixed:
        // settle that before reading the DoF indices.
        mb.forward_kinematics(&physics.bodies, false);
        let mut dofs = Vec::new();
        for &id in &link_ids {
            let l = mb.link(id).ok_or_else(|| CellError::Robot {
                reason: "rapier lost a multibody link".into(),
            })?;
            dofs.push(l.assembly_id());
        }
        for (j, joint) in chain.joints.iter().enumerate() {
            // Replaces rapier's default damping of 0.1 on angular DoFs by the joint's viscous
            // friction.
            mb.damping_mut()[dofs[j]] = joint.drive.viscous;
            mb.armature_mut()[dofs[j]] = joint.drive.armature;
            mb.frictions_mut()[dofs[j]] = joint.drive.coulomb;
        }
        let mut world = Self {
            physics,
            handles,
            base,
            multibody,
            link_ids,
            dofs,
        };
        world.set_state(chain, q0, &vec![0.0; q0.len()]);
        Ok(world)
    }

    /// Joint positions of the multibody (model order).
    pub fn positions(&self, chain: &Chain, out: &mut [f64]) {
        if let Some(mb) = self.physics.multibody_joints.get_multibody(self.multibody) {
            for (j, joint) in chain.joints.iter().enumerate() {
                if let Some(l) = mb.link(self.link_ids[j]) {
                    let c = l.joint().coords();
                    out[j] = match joint.kind {
                        JointKind::Prismatic => c[0],
                        JointKind::Revolute => c[3],
                    };
                }
            }
        }
    }

    /// Joint velocities of the multibody (model order).
    pub fn velocities(&self, out: &mut [f64]) {
        if let Some(mb) = self.physics.multibody_joints.get_multibody(self.multibody) {
            let v = mb.generalized_velocity();
            for (j, &d) in self.dofs.iter().enumerate() {
                out[j] = v[d];
            }
        }
    }

    /// Sets joint positions and velocities exactly (kinematic mode, and the initial state),
    /// then places the bodies by forward kinematics.
    pub fn set_state(&mut self, chain: &Chain, q: &[f64], qd: &[f64]) {
        let mut current = vec![0.0; q.len()];
        self.positions(chain, &mut current);
        let World {
            physics,
            multibody,
            dofs,
            ..
        } = self;
        let Some(mb) = physics.multibody_joints.get_multibody_mut(*multibody) else {
            return;
        };
        let mut disp = vec![0.0; mb.ndofs()];
        for (j, &d) in dofs.iter().enumerate() {
            disp[d] = q[j] - current[j];
        }
        mb.apply_displacements(&disp);
        {
            let mut v = mb.generalized_velocity_mut();
            for (j, &d) in dofs.iter().enumerate() {
                v[d] = qd[j];
            }
        }
        mb.forward_kinematics(&physics.bodies, false);
        mb.update_rigid_bodies(&mut physics.bodies, false);
    }

    /// Body poses in the base frame (parry convention), as rapier holds them.
    pub fn body_poses(&self, out: &mut Vec<Pose>) {
        out.clear();
        for h in &self.handles {
            out.push(*self.physics.bodies[*h].position());
        }
    }

    /// Applies joint efforts for the next step: a torque couple (revolute) or a force pair at
    /// the joint origin (prismatic) on the child and parent bodies, so that only the joint's
    /// own generalized force is `tau` (the pair cancels in every other joint).
    pub fn apply_efforts(&mut self, chain: &Chain, tau: &[f64]) {
        let bodies = &mut self.physics.bodies;
        for h in self.handles.iter().chain(std::iter::once(&self.base)) {
            if let Some(b) = bodies.get_mut(*h) {
                b.reset_forces(false);
                b.reset_torques(false);
            }
        }
        for (j, joint) in chain.joints.iter().enumerate() {
            let child = self.handles[j];
            let parent = joint.parent.map(|p| self.handles[p]);
            let pose = to_isometry(bodies[child].position());
            let axis = pose.rotation * joint.axis.into_inner();
            let a = Vector::new(axis.x, axis.y, axis.z) * tau[j];
            match joint.kind {
                JointKind::Revolute => {
                    bodies[child].add_torque(a, false);
                    if let Some(p) = parent {
                        bodies[p].add_torque(-a, false);
                    }
                }
                JointKind::Prismatic => {
                    let t = pose.translation.vector;
                    let at = Vector::new(t.x, t.y, t.z);
                    bodies[child].add_force_at_point(a, at, false);
                    if let Some(p) = parent {
                        bodies[p].add_force_at_point(-a, at, false);
                    }
                }
            }
        }
    }

    /// One physics step.
    pub fn step(&mut self) {
        self.physics.step();
    }
}
