//! The cutting head as URDF collision primitives on the links of the
//! chain of seed 001 eq. 2, placed by its forward kinematics.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::PlanError;

/// A link of the cutting head that can carry collision geometry, in the
/// order the collision check visits them (nearest the workpiece first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum HeadLink {
    /// `nozzle`: frame at the CL point C, z = tool axis O (moves with q6).
    Nozzle,
    /// `a_axis`: frame at M, tilted by q5 about the C-axis-rotated y axis.
    AAxis,
    /// `c_axis`: frame at M, rotated by q4 about z.
    CAxis,
    /// `z_ram`: frame at M = (q1, q2, q3), axes parallel to the machine frame.
    ZRam,
    /// `y_carriage`: at (q1, q2, 0).
    YCarriage,
    /// `x_carriage`: at (q1, 0, 0).
    XCarriage,
}

impl HeadLink {
    /// Every head link, in check order.
    pub const ALL: [HeadLink; 6] = [
        HeadLink::Nozzle,
        HeadLink::AAxis,
        HeadLink::CAxis,
        HeadLink::ZRam,
        HeadLink::YCarriage,
        HeadLink::XCarriage,
    ];

    /// The URDF link name.
    pub fn name(self) -> &'static str {
        match self {
            HeadLink::Nozzle => "nozzle",
            HeadLink::AAxis => "a_axis",
            HeadLink::CAxis => "c_axis",
            HeadLink::ZRam => "z_ram",
            HeadLink::YCarriage => "y_carriage",
            HeadLink::XCarriage => "x_carriage",
        }
    }

    /// The head link of a URDF link name (`tool0` is the nozzle frame).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "nozzle" | "tool0" => Some(HeadLink::Nozzle),
            "a_axis" => Some(HeadLink::AAxis),
            "c_axis" => Some(HeadLink::CAxis),
            "z_ram" => Some(HeadLink::ZRam),
            "y_carriage" => Some(HeadLink::YCarriage),
            "x_carriage" => Some(HeadLink::XCarriage),
            _ => None,
        }
    }

    /// Pose of the link frame in the machine frame (`base_link`) at `q`.
    ///
    /// The specialised forward kinematics of `urdf/laser_cutter.urdf`
    /// (seed 001 eq. 2): `z_ram = Trans(q1, q2, q3)`, `c_axis = z_ram ·
    /// Rz(q4)`, `a_axis = c_axis · Ry(q5)`, `nozzle = a_axis · Trans(0, 0,
    /// q6)`; the origin of `nozzle` is C = M + q6 · O with O = (cos q4 sin
    /// q5, sin q4 sin q5, cos q5). [`HeadModel::from_urdf`] checks that the
    /// URDF has exactly this chain.
    ///
    /// # Arguments
    /// * `q` - joint vector q1..q6 (m, rad).
    pub fn pose(self, q: &[f64; 6]) -> Isometry3<f64> {
        let [q1, q2, q3, q4, q5, q6] = *q;
        let ram =
            || Isometry3::from_parts(Translation3::new(q1, q2, q3), UnitQuaternion::identity());
        let c_axis = || ram() * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), q4);
        let a_axis = || c_axis() * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), q5);
        match self {
            HeadLink::XCarriage => Isometry3::translation(q1, 0.0, 0.0),
            HeadLink::YCarriage => Isometry3::translation(q1, q2, 0.0),
            HeadLink::ZRam => ram(),
            HeadLink::CAxis => c_axis(),
            HeadLink::AAxis => a_axis(),
            HeadLink::Nozzle => a_axis() * Translation3::new(0.0, 0.0, q6),
        }
    }
}

/// A convex collision primitive of a URDF `<collision>` element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// URDF `<box size>`: half extents along the shape's x, y, z (m).
    Box {
        /// Half the URDF size (m).
        half_extents: [f64; 3],
    },
    /// URDF `<cylinder>`: along the shape's local z axis, centred.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Half the URDF length (m).
        half_length: f64,
    },
    /// URDF `<sphere>`.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
}

/// One collision primitive of the head, in its link frame.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadShape {
    /// The link carrying it.
    pub link: HeadLink,
    /// The URDF `<origin>`: shape frame in the link frame.
    pub origin: Isometry3<f64>,
    /// The primitive.
    pub primitive: Primitive,
}

/// The collision geometry of the cutting head.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadModel {
    pub(super) shapes: Vec<HeadShape>,
    /// The URDF limits `[lower, upper]` of the standoff joint q6 (m): the
    /// range [`HeadModel::lipschitz`] bounds the nozzle's reach over.
    pub(super) standoff_range: [f64; 2],
}

/// The joints the specialised kinematics of [`HeadLink::pose`] expects:
/// name, parent, child, prismatic?, axis.
const CHAIN: [(&str, &str, &str, bool, [f64; 3]); 6] = [
    ("q1", "base_link", "x_carriage", true, [1.0, 0.0, 0.0]),
    ("q2", "x_carriage", "y_carriage", true, [0.0, 1.0, 0.0]),
    ("q3", "y_carriage", "z_ram", true, [0.0, 0.0, 1.0]),
    ("q4", "z_ram", "c_axis", false, [0.0, 0.0, 1.0]),
    ("q5", "c_axis", "a_axis", false, [0.0, 1.0, 0.0]),
    ("q6", "a_axis", "nozzle", true, [0.0, 0.0, 1.0]),
];

pub(super) fn machine_err(reason: String) -> PlanError {
    PlanError::invalid("machine", reason)
}

/// The URDF `<origin xyz rpy>` as an isometry (REP 103 fixed-axis roll,
/// pitch, yaw: `R = Rz(yaw) Ry(pitch) Rx(roll)`).
fn origin_isometry(what: &str, pose: &urdf_rs::Pose) -> Result<Isometry3<f64>, PlanError> {
    let (xyz, rpy) = (pose.xyz.0, pose.rpy.0);
    if xyz.iter().chain(rpy.iter()).any(|v| !v.is_finite()) {
        return Err(machine_err(format!(
            "{what}: origin xyz {xyz:?} rpy {rpy:?} is not finite"
        )));
    }
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    ))
}

fn positive_size(what: &str, v: f64) -> Result<f64, PlanError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(machine_err(format!(
            "{what}: size {v} must be finite and > 0"
        )))
    }
}

impl HeadModel {
    /// Collects the head's collision primitives from a URDF.
    ///
    /// # Arguments
    /// * `robot` - the parsed URDF of the laser cutting machine, e.g.
    ///   `LaserMachine::default_machine()?.robot().urdf()`.
    ///
    /// # Returns
    /// The shapes of the links `x_carriage`, `y_carriage`, `z_ram`,
    /// `c_axis`, `a_axis`, `nozzle` and `tool0` (the nozzle frame; its
    /// fixed joint must be the identity). Geometry of `base_link` (the
    /// static machine bed the workpiece rests on) is ignored.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `machine`) when the joints q1..q6
    /// are not the chain of seed 001 eq. 2 with identity origins (the
    /// specialised kinematics would be wrong), when another link carries
    /// collision geometry, for mesh or capsule geometry (only box, cylinder
    /// and sphere are supported), for non-positive or non-finite sizes, for
    /// non-finite or inverted limits of q6, and when no link has collision
    /// geometry at all.
    pub fn from_urdf(robot: &urdf_rs::Robot) -> Result<Self, PlanError> {
        let mut standoff_range = [0.0; 2];
        for (name, parent, child, prismatic, axis) in CHAIN {
            let j = robot
                .joints
                .iter()
                .find(|j| j.name == name)
                .ok_or_else(|| machine_err(format!("joint {name} is missing")))?;
            let kind_ok = if prismatic {
                j.joint_type == urdf_rs::JointType::Prismatic
            } else {
                matches!(
                    j.joint_type,
                    urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous
                )
            };
            let o = origin_isometry(&format!("joint {name}"), &j.origin)?;
            let identity = o.translation.vector.norm() <= 1e-12 && o.rotation.angle() <= 1e-12;
            let a = j.axis.xyz.0;
            let axis_ok = a.iter().zip(axis).all(|(x, y)| (x - y).abs() <= 1e-12);
            if !kind_ok || j.parent.link != parent || j.child.link != child || !identity || !axis_ok
            {
                return Err(machine_err(format!(
                    "joint {name} must be {} {parent} -> {child} about/along {axis:?} with an \
                     identity origin (seed 001 eq. 2), found {:?} {} -> {} axis {a:?}",
                    if prismatic { "prismatic" } else { "revolute" },
                    j.joint_type,
                    j.parent.link,
                    j.child.link
                )));
            }
            if name == "q6" {
                let (lo, hi) = (j.limit.lower, j.limit.upper);
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(machine_err(format!(
                        "joint q6: limits [{lo}, {hi}] must be finite with lower <= upper"
                    )));
                }
                standoff_range = [lo, hi];
            }
        }
        let mut shapes = Vec::new();
        for link in &robot.links {
            if link.collision.is_empty() {
                continue;
            }
            if link.name == "base_link" {
                log::debug!("base_link collision geometry ignored (static machine bed)");
                continue;
            }
            let head_link = HeadLink::from_name(&link.name).ok_or_else(|| {
                machine_err(format!(
                    "link '{}' has collision geometry but is not on the head chain \
                     (x_carriage, y_carriage, z_ram, c_axis, a_axis, nozzle, tool0)",
                    link.name
                ))
            })?;
            let tool_offset = if link.name == "tool0" {
                let j = robot
                    .joints
                    .iter()
                    .find(|j| j.child.link == "tool0")
                    .ok_or_else(|| machine_err("link tool0 has no parent joint".into()))?;
                let o = origin_isometry("joint to tool0", &j.origin)?;
                if j.parent.link != "nozzle" || j.joint_type != urdf_rs::JointType::Fixed {
                    return Err(machine_err("tool0 must be fixed to the nozzle link".into()));
                }
                o
            } else {
                Isometry3::identity()
            };
            for (k, c) in link.collision.iter().enumerate() {
                let what = format!("link '{}' collision {k}", link.name);
                let origin = tool_offset * origin_isometry(&what, &c.origin)?;
                let primitive = match &c.geometry {
                    urdf_rs::Geometry::Box { size } => {
                        let s = size.0;
                        Primitive::Box {
                            half_extents: [
                                positive_size(&what, s[0])? / 2.0,
                                positive_size(&what, s[1])? / 2.0,
                                positive_size(&what, s[2])? / 2.0,
                            ],
                        }
                    }
                    urdf_rs::Geometry::Cylinder { radius, length } => Primitive::Cylinder {
                        radius: positive_size(&what, *radius)?,
                        half_length: positive_size(&what, *length)? / 2.0,
                    },
                    urdf_rs::Geometry::Sphere { radius } => Primitive::Sphere {
                        radius: positive_size(&what, *radius)?,
                    },
                    other => {
                        return Err(machine_err(format!(
                            "{what}: geometry {other:?} is not supported (use box, cylinder \
                             or sphere)"
                        )))
                    }
                };
                shapes.push(HeadShape {
                    link: head_link,
                    origin,
                    primitive,
                });
            }
        }
        if shapes.is_empty() {
            return Err(machine_err(
                "no head link has collision geometry: nothing to check".into(),
            ));
        }
        shapes.sort_by_key(|s| s.link);
        Ok(Self {
            shapes,
            standoff_range,
        })
    }

    /// Names of the links with collision geometry, in check order
    /// (nozzle first).
    pub fn links(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for s in &self.shapes {
            if out.last() != Some(&s.link.name()) {
                out.push(s.link.name());
            }
        }
        out
    }

    /// The collision primitives, in check order.
    pub fn shapes(&self) -> &[HeadShape] {
        &self.shapes
    }

    /// The URDF limits `[lower, upper]` of the standoff joint q6 (m).
    pub fn standoff_range(&self) -> [f64; 2] {
        self.standoff_range
    }

    /// Poses of the links with collision geometry at `q`, in the machine
    /// frame (see [`HeadLink::pose`]).
    pub fn link_poses(&self, q: &[f64; 6]) -> Vec<(&'static str, Isometry3<f64>)> {
        self.links()
            .into_iter()
            .filter_map(HeadLink::from_name)
            .map(|l| (l.name(), l.pose(q)))
            .collect()
    }
}
