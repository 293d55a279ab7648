//! The robot as rigid bodies: every movable joint's child link, merged with the links fixed
//! to it, is one body with its mass properties and collision shapes.
//!
//! This is the small URDF converter of the cell (`rapier3d-urdf` builds f32 worlds only): it
//! reads the tree of [`kerf_robot::RobotModel`] (which has checked the URDF) and the mass
//! sidecar, and yields plain nalgebra data that [`crate::world`] turns into rapier multibody
//! joints and [`crate::dynamics`] uses for the inverse dynamics.

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use kerf_robot::{JointKind, RobotModel};

use crate::inertia::{InertiaFile, JointDrive, LinkInertia};
use crate::CellError;

/// Mass properties of a body in its own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProps {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, body-frame axes (kg m²).
    pub inertia: Matrix3<f64>,
}

impl MassProps {
    /// No mass.
    pub fn zero() -> Self {
        Self {
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }

    /// `other` (given in a frame placed at `pose` in this body) added to `self`.
    ///
    /// Parallel-axis theorem (Steiner): `I_c = Σ R I_i Rᵀ + m_i (|d_i|² E − d_i d_iᵀ)` with
    /// `d_i` the offset of part i's centre from the combined centre (e.g. Craig, *Introduction
    /// to Robotics*, 3rd ed., eq. 6.25).
    pub fn add(&self, other: &MassProps, pose: &Isometry3<f64>) -> MassProps {
        let m = self.mass + other.mass;
        if m <= 0.0 {
            return *self;
        }
        let c_other = pose * nalgebra::Point3::from(other.com);
        let com = (self.com * self.mass + c_other.coords * other.mass) / m;
        let r = pose.rotation.to_rotation_matrix();
        let steiner = |mass: f64, d: Vector3<f64>| {
            mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose())
        };
        let inertia = self.inertia
            + steiner(self.mass, self.com - com)
            + r * other.inertia * r.transpose()
            + steiner(other.mass, c_other.coords - com);
        MassProps {
            mass: m,
            com,
            inertia,
        }
    }
}

impl From<&LinkInertia> for MassProps {
    fn from(l: &LinkInertia) -> Self {
        Self {
            mass: l.mass,
            com: l.com(),
            inertia: l.tensor(),
        }
    }
}

/// One movable joint and the body it moves.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyJoint {
    /// Joint name.
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// The parent body (index into [`Chain::joints`]), `None` for the fixed base.
    pub parent: Option<usize>,
    /// Joint frame at zero position in the parent body frame (URDF origin, moved by the fixed
    /// joints between the parent body's link and the joint's parent link).
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint (= child body) frame.
    pub axis: Unit<Vector3<f64>>,
    /// The child link (the body's frame).
    pub link: String,
    /// Mass properties of the body (the child link and every link fixed to it).
    pub mass: MassProps,
    /// URDF effort limit (N or N m), > 0.
    pub max_effort: f64,
    /// Position limits (m or rad).
    pub limits: [f64; 2],
    /// Armature and friction.
    pub drive: JointDrive,
}

/// The robot's bodies and where every URDF link sits on them.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// Movable joints in the model's order (root to tip); joint `j` moves body `j`.
    pub joints: Vec<BodyJoint>,
    /// For every URDF link: its body (`None` = fixed base) and its frame in the body frame.
    pub links: Vec<(String, Option<usize>, Isometry3<f64>)>,
}

/// The URDF `<origin>` as an isometry (REP 103: `R = Rz(yaw) Ry(pitch) Rx(roll)`).
pub(crate) fn urdf_origin(pose: &urdf_rs::Pose) -> Isometry3<f64> {
    let (xyz, rpy) = (pose.xyz.0, pose.rpy.0);
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

impl Chain {
    /// Builds the bodies of `model` with the masses of `inertia`.
    ///
    /// # Errors
    /// [`CellError::EffortLimit`] for an effort limit ≤ 0 or not finite;
    /// [`CellError::Inertia`] when a moving body has no mass (none of its links is in the
    /// sidecar) or the sidecar names a link the URDF does not have;
    /// [`CellError::JointMismatch`] when the sidecar names a joint that is not a movable
    /// joint of the URDF. Links on the fixed base may have a mass (it is not simulated).
    pub fn build(model: &RobotModel, inertia: &InertiaFile) -> Result<Self, CellError> {
        let urdf = model.urdf();
        for spec in model.joints() {
            if !(spec.max_effort.is_finite() && spec.max_effort > 0.0) {
                return Err(CellError::EffortLimit {
                    joint: spec.name.clone(),
                    effort: spec.max_effort,
                });
            }
        }
        for name in inertia.links.keys() {
            if !urdf.links.iter().any(|l| &l.name == name) {
                return Err(CellError::Inertia {
                    link: name.clone(),
                    reason: "named in the inertia file but not a link of the URDF".into(),
                });
            }
        }
        for name in inertia.joints.keys() {
            if model.joint_index(name).is_none() {
                return Err(CellError::JointMismatch {
                    what: "inertia file joints",
                    reason: format!("'{name}' is not a movable joint of the URDF"),
                    expected: model.joint_names().join(", "),
                });
            }
        }
        // Place every link on its body, parents first (the tree is small: repeat passes).
        let root = model.root_link().to_string();
        let mut links: Vec<(String, Option<usize>, Isometry3<f64>)> =
            vec![(root, None, Isometry3::identity())];
        let mut joint_origin: Vec<Option<(Option<usize>, Isometry3<f64>)>> =
            vec![None; model.dof()];
        let mut pending: Vec<&urdf_rs::Joint> = urdf.joints.iter().collect();
        while !pending.is_empty() {
            let before = pending.len();
            pending.retain(|j| {
                let Some(&(_, body, off)) =
                    links.iter().find(|(name, _, _)| *name == j.parent.link)
                else {
                    return true;
                };
                let origin = off * urdf_origin(&j.origin);
                match model.joint_index(&j.name) {
                    Some(k) => {
                        joint_origin[k] = Some((body, origin));
                        links.push((j.child.link.clone(), Some(k), Isometry3::identity()));
                    }
                    None => links.push((j.child.link.clone(), body, origin)),
                }
                false
            });
            if pending.len() == before {
                // kerf_robot has checked the tree; links off the root's tree cannot occur.
                return Err(CellError::Robot {
                    reason: format!(
                        "joints {:?} are not connected to the root link",
                        pending.iter().map(|j| &j.name).collect::<Vec<_>>()
                    ),
                });
            }
        }
        let mut joints = Vec::with_capacity(model.dof());
        for (k, spec) in model.joints().iter().enumerate() {
            let (parent, origin) = joint_origin[k].ok_or_else(|| CellError::Robot {
                reason: format!("joint '{}' not reached from the root", spec.name),
            })?;
            let mut mass = MassProps::zero();
            for (name, body, off) in &links {
                if *body == Some(k) {
                    if let Some(l) = inertia.links.get(name) {
                        mass = mass.add(&MassProps::from(l), off);
                    }
                }
            }
            if mass.mass <= 0.0 {
                return Err(CellError::Inertia {
                    link: spec.child_link.clone(),
                    reason: format!(
                        "moved by joint '{}' but neither it nor a link fixed to it has a mass \
                         in the inertia file",
                        spec.name
                    ),
                });
            }
            joints.push(BodyJoint {
                name: spec.name.clone(),
                kind: spec.kind,
                parent,
                origin,
                axis: spec.axis,
                link: spec.child_link.clone(),
                mass,
                max_effort: spec.max_effort,
                limits: [spec.min_position, spec.max_position],
                drive: inertia.joints.get(&spec.name).copied().unwrap_or_default(),
            });
        }
        for (name, body, _) in &links {
            if body.is_none() && inertia.links.contains_key(name) {
                log::debug!("link '{name}' is on the fixed base: its mass is not simulated");
            }
        }
        Ok(Self { joints, links })
    }

    /// The body and the pose in the body frame of URDF link `name`.
    pub fn link(&self, name: &str) -> Option<(Option<usize>, Isometry3<f64>)> {
        self.links
            .iter()
            .find(|(n, _, _)| n == name)
            .map(|&(_, b, off)| (b, off))
    }

    /// Adds a mass (a tool) to the body carrying `link`.
    ///
    /// # Errors
    /// [`CellError::Inertia`] when `link` is on the fixed base or unknown.
    pub fn add_mass(
        &mut self,
        link: &str,
        props: &MassProps,
        pose: &Isometry3<f64>,
    ) -> Result<(), CellError> {
        match self.link(link) {
            Some((Some(b), off)) => {
                self.joints[b].mass = self.joints[b].mass.add(props, &(off * pose));
                Ok(())
            }
            _ => Err(CellError::Inertia {
                link: link.to_string(),
                reason: "a tool mass must be on a link that moves".into(),
            }),
        }
    }

    /// Body poses in the base frame at joint positions `q` (forward kinematics:
    /// `T_j = T_parent · origin_j · motion_j(q_j)`, URDF specification).
    pub fn body_poses(&self, q: &[f64], out: &mut Vec<Isometry3<f64>>) {
        out.clear();
        for (j, joint) in self.joints.iter().enumerate() {
            let parent = joint.parent.map_or(Isometry3::identity(), |p| out[p]);
            out.push(parent * joint.origin * motion(joint, q[j]));
        }
    }
}

/// The joint motion in the joint frame: rotation by `q` about the axis, or translation by
/// `q · axis` (URDF specification, ROS wiki `urdf/XML/joint`).
pub(crate) fn motion(joint: &BodyJoint, q: f64) -> Isometry3<f64> {
    match joint.kind {
        JointKind::Revolute => Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&joint.axis, q),
        ),
        JointKind::Prismatic => Isometry3::from_parts(
            Translation3::from(joint.axis.into_inner() * q),
            UnitQuaternion::identity(),
        ),
    }
}
