//! Topology of a URDF: the link tree and the root-to-tip kinematic chain.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Unit, Vector3};

use crate::pose::isometry_from_origin;
use crate::{JointKind, JointSpec, RobotError};

/// How a link frame moves relative to its parent link frame.
#[derive(Debug, Clone)]
pub(crate) enum Motion {
    /// The link is the tree root: its frame is the model's base frame.
    Root,
    /// Fixed joint with the given parent-to-child transform.
    Fixed(Isometry3<f64>),
    /// Movable joint: index into [`Chain::joints`].
    Movable(usize),
}

/// One link frame of the tree.
#[derive(Debug, Clone)]
pub(crate) struct Frame {
    /// Link name.
    pub link: String,
    /// Index of the parent frame in [`Chain::frames`] (`0` for the root itself).
    pub parent: usize,
    /// Motion of this link relative to its parent.
    pub motion: Motion,
}

/// The validated topology of a robot.
#[derive(Debug, Clone)]
pub(crate) struct Chain {
    /// All link frames, root first, every parent before its children.
    pub frames: Vec<Frame>,
    /// Indices into `frames` of the links from the root's first child to the tip.
    pub path: Vec<usize>,
    /// Movable joints in root-to-tip order, limits from the URDF only.
    pub joints: Vec<JointSpec>,
    /// Root link name.
    pub root: String,
    /// Tip link name.
    pub tip: String,
}

/// Builds and validates the tree and the root-to-tip chain of `robot`.
///
/// Rules: link and joint names are unique; joints refer to existing links;
/// every link has at most one parent joint; there is exactly one root and
/// every link is reachable from it; joint types are revolute, prismatic or
/// fixed and no joint mimics another; every movable joint lies on the
/// root-to-tip path (fixed subtrees may branch off anywhere).
///
/// The tip is `tip` if given, else the link `tool0` if present, else the
/// unique leaf link.
///
/// # Returns
/// The chain, or the first violated rule as a [`RobotError`].
///
/// # Performance
/// O(links + joints) expected time.
pub(crate) fn build(robot: &urdf_rs::Robot, tip: Option<&str>) -> Result<Chain, RobotError> {
    let mut link_index: HashMap<&str, usize> = HashMap::with_capacity(robot.links.len());
    for (i, link) in robot.links.iter().enumerate() {
        if link_index.insert(link.name.as_str(), i).is_some() {
            return Err(RobotError::DuplicateLink {
                name: link.name.clone(),
            });
        }
    }
    let mut joint_names: HashSet<&str> = HashSet::with_capacity(robot.joints.len());
    // parent_joint[link] = index of the joint whose child is that link.
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    // children[link] = indices of the joints whose parent is that link.
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (j, joint) in robot.joints.iter().enumerate() {
        if !joint_names.insert(joint.name.as_str()) {
            return Err(RobotError::DuplicateJoint {
                name: joint.name.clone(),
            });
        }
        check_joint_type(joint)?;
        let lookup = |link: &str| {
            link_index
                .get(link)
                .copied()
                .ok_or_else(|| RobotError::UnknownLink {
                    joint: joint.name.clone(),
                    link: link.to_owned(),
                })
        };
        let parent = lookup(&joint.parent.link)?;
        let child = lookup(&joint.child.link)?;
        if let Some(first) = parent_joint[child] {
            return Err(RobotError::MultipleParents {
                link: joint.child.link.clone(),
                first_joint: robot.joints[first].name.clone(),
                second_joint: joint.name.clone(),
            });
        }
        parent_joint[child] = Some(j);
        children[parent].push(j);
    }

    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&l| parent_joint[l].is_none())
        .collect();
    let root = match roots.as_slice() {
        [only] => *only,
        _ => {
            return Err(RobotError::RootNotUnique {
                roots: roots.iter().map(|&l| robot.links[l].name.clone()).collect(),
            })
        }
    };

    // Depth-first traversal from the root: parents precede children. Once
    // every movable joint is known to lie on the root-to-tip path (checked
    // below), `joints` is in root-to-tip order.
    let mut frames = vec![Frame {
        link: robot.links[root].name.clone(),
        parent: 0,
        motion: Motion::Root,
    }];
    let mut frame_of_link: Vec<Option<usize>> = vec![None; robot.links.len()];
    frame_of_link[root] = Some(0);
    let mut joints = Vec::new();
    let mut stack: Vec<(usize, usize)> = children[root].iter().rev().map(|&j| (j, 0)).collect();
    while let Some((j, parent_frame)) = stack.pop() {
        let joint = &robot.joints[j];
        let origin = isometry_from_origin(&joint.name, &joint.origin)?;
        let motion = match joint.joint_type {
            urdf_rs::JointType::Fixed => Motion::Fixed(origin),
            _ => {
                joints.push(joint_spec(joint, origin)?);
                Motion::Movable(joints.len() - 1)
            }
        };
        let child = link_index[joint.child.link.as_str()];
        frame_of_link[child] = Some(frames.len());
        frames.push(Frame {
            link: joint.child.link.clone(),
            parent: parent_frame,
            motion,
        });
        let this_frame = frames.len() - 1;
        stack.extend(children[child].iter().rev().map(|&c| (c, this_frame)));
    }
    if let Some(l) = frame_of_link.iter().position(Option::is_none) {
        return Err(RobotError::Unreachable {
            link: robot.links[l].name.clone(),
            root: robot.links[root].name.clone(),
        });
    }

    let tip = choose_tip(robot, &link_index, &children, tip)?;
    let mut path = Vec::new();
    let mut frame = frame_of_link[tip].unwrap_or(0);
    while frame != 0 {
        path.push(frame);
        frame = frames[frame].parent;
    }
    path.reverse();
    let on_path: HashSet<usize> = path.iter().copied().collect();
    for (f, frame) in frames.iter().enumerate() {
        if let Motion::Movable(j) = frame.motion {
            if !on_path.contains(&f) {
                return Err(RobotError::MovableJointOffChain {
                    joint: joints[j].name.clone(),
                    root: robot.links[root].name.clone(),
                    tip: robot.links[tip].name.clone(),
                });
            }
        }
    }

    Ok(Chain {
        frames,
        path,
        joints,
        root: robot.links[root].name.clone(),
        tip: robot.links[tip].name.clone(),
    })
}

/// Rejects joint types and features the model does not support.
fn check_joint_type(joint: &urdf_rs::Joint) -> Result<(), RobotError> {
    use urdf_rs::JointType as T;
    let unsupported = match joint.joint_type {
        T::Revolute | T::Prismatic | T::Fixed => None,
        T::Continuous => Some("continuous"),
        T::Floating => Some("floating"),
        T::Planar => Some("planar"),
        T::Spherical => Some("spherical"),
    };
    if let Some(kind) = unsupported {
        return Err(RobotError::UnsupportedJointType {
            joint: joint.name.clone(),
            kind: kind.to_owned(),
        });
    }
    if let Some(mimic) = &joint.mimic {
        return Err(RobotError::MimicJoint {
            joint: joint.name.clone(),
            leader: mimic.joint.clone(),
        });
    }
    Ok(())
}

/// Picks the tip link index: explicit, else `tool0`, else the unique leaf.
fn choose_tip(
    robot: &urdf_rs::Robot,
    link_index: &HashMap<&str, usize>,
    children: &[Vec<usize>],
    tip: Option<&str>,
) -> Result<usize, RobotError> {
    if let Some(name) = tip {
        return link_index
            .get(name)
            .copied()
            .ok_or_else(|| RobotError::UnknownTip {
                tip: name.to_owned(),
            });
    }
    if let Some(&tool0) = link_index.get("tool0") {
        return Ok(tool0);
    }
    let leaves: Vec<usize> = (0..robot.links.len())
        .filter(|&l| children[l].is_empty())
        .collect();
    match leaves.as_slice() {
        [only] => Ok(*only),
        _ => Err(RobotError::AmbiguousTip {
            leaves: leaves
                .iter()
                .map(|&l| robot.links[l].name.clone())
                .collect(),
        }),
    }
}

/// Builds the [`JointSpec`] of a movable joint from its URDF limits.
fn joint_spec(joint: &urdf_rs::Joint, origin: Isometry3<f64>) -> Result<JointSpec, RobotError> {
    let kind = match joint.joint_type {
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        _ => JointKind::Revolute,
    };
    let raw = joint.axis.xyz.0;
    let axis_vec = Vector3::new(raw[0], raw[1], raw[2]);
    let norm = axis_vec.norm();
    if !norm.is_finite() || norm <= f64::EPSILON {
        return Err(RobotError::InvalidAxis {
            joint: joint.name.clone(),
            axis: raw,
        });
    }
    let limit = &joint.limit;
    let finite = |field: &'static str, value: f64| {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(RobotError::InvalidLimit {
                joint: joint.name.clone(),
                field,
                value,
                requirement: "finite",
            })
        }
    };
    let positive = |field: &'static str, value: f64| {
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(RobotError::InvalidLimit {
                joint: joint.name.clone(),
                field,
                value,
                requirement: "finite and > 0 (is the <limit> element missing?)",
            })
        }
    };
    let max_velocity = positive("URDF <limit velocity>", limit.velocity)?;
    let max_effort = positive("URDF <limit effort>", limit.effort)?;
    let min_position = finite("URDF <limit lower>", limit.lower)?;
    let max_position = finite("URDF <limit upper>", limit.upper)?;
    if min_position >= max_position {
        return Err(RobotError::EmptyRange {
            joint: joint.name.clone(),
            min: min_position,
            max: max_position,
        });
    }
    Ok(JointSpec {
        name: joint.name.clone(),
        kind,
        parent_link: joint.parent.link.clone(),
        child_link: joint.child.link.clone(),
        origin,
        axis: Unit::new_normalize(axis_vec),
        min_position,
        max_position,
        max_velocity,
        max_effort,
        max_acceleration: None,
        max_jerk: None,
    })
}
