//! The kinematic robot model: URDF tree, movable joints, merged limits.

use std::path::Path;

use nalgebra::Isometry3;

use crate::chain::{self, Chain, Motion};
use crate::{limits, JointSpec, RobotError};

/// A serial kinematic chain loaded from a URDF plus an optional MoveIt
/// `joint_limits.yaml`.
///
/// The chain runs from the URDF root link to a tip link (by default
/// `tool0`, else the unique leaf link). Fixed links may branch off the
/// chain anywhere; movable joints must all lie on it. Joint vectors `q`
/// are ordered root to tip, like [`RobotModel::joints`], in SI units (m
/// for prismatic, rad for revolute joints).
#[derive(Debug, Clone)]
pub struct RobotModel {
    urdf: urdf_rs::Robot,
    chain: Chain,
}

impl RobotModel {
    /// Loads a URDF file and, optionally, its `joint_limits.yaml`.
    ///
    /// # Arguments
    /// * `urdf` - path of the URDF file (plain URDF, not xacro).
    /// * `limits_yaml` - path of the MoveIt joint limits file, if any.
    ///
    /// # Returns
    /// The model with tip `tool0` (or the unique leaf link), or
    /// [`RobotError::FileRead`] or any validation error of
    /// [`RobotModel::from_urdf`].
    pub fn from_files(urdf: &Path, limits_yaml: Option<&Path>) -> Result<Self, RobotError> {
        let read = |path: &Path| {
            std::fs::read_to_string(path).map_err(|source| RobotError::FileRead {
                path: path.to_path_buf(),
                source,
            })
        };
        let urdf_xml = read(urdf)?;
        let limits = limits_yaml.map(read).transpose()?;
        Self::from_strings(&urdf_xml, limits.as_deref())
    }

    /// Loads a model from URDF XML text and optional limits YAML text.
    ///
    /// # Arguments
    /// * `urdf_xml` - the URDF document.
    /// * `limits_yaml` - the MoveIt joint limits document, if any.
    ///
    /// # Returns
    /// The model with tip `tool0` (or the unique leaf link), or an error
    /// as for [`RobotModel::from_urdf`].
    pub fn from_strings(urdf_xml: &str, limits_yaml: Option<&str>) -> Result<Self, RobotError> {
        let urdf = parse_urdf(urdf_xml)?;
        Self::from_urdf(urdf, limits_yaml, None)
    }

    /// Like [`RobotModel::from_strings`] with an explicit tip link.
    ///
    /// # Arguments
    /// * `urdf_xml` - the URDF document.
    /// * `limits_yaml` - the MoveIt joint limits document, if any.
    /// * `tip` - name of the link at the end of the chain.
    ///
    /// # Returns
    /// The model, or an error as for [`RobotModel::from_urdf`].
    pub fn from_strings_with_tip(
        urdf_xml: &str,
        limits_yaml: Option<&str>,
        tip: &str,
    ) -> Result<Self, RobotError> {
        let urdf = parse_urdf(urdf_xml)?;
        Self::from_urdf(urdf, limits_yaml, Some(tip))
    }

    /// Builds a model from an already parsed URDF.
    ///
    /// # Arguments
    /// * `urdf` - the parsed URDF.
    /// * `limits_yaml` - the MoveIt joint limits document, if any; without
    ///   it every joint has `max_acceleration` and `max_jerk` `None`.
    /// * `tip` - tip link; `None` means `tool0` if present, else the unique
    ///   leaf link.
    ///
    /// # Returns
    /// The model, or the first problem found: a malformed tree
    /// ([`RobotError::DuplicateLink`], [`RobotError::UnknownLink`],
    /// [`RobotError::RootNotUnique`], ...), an unsupported joint
    /// ([`RobotError::UnsupportedJointType`], [`RobotError::MimicJoint`],
    /// [`RobotError::MovableJointOffChain`]), an invalid URDF limit or
    /// axis, or a YAML problem ([`RobotError::LimitsParse`],
    /// [`RobotError::UnknownJoint`], [`RobotError::LimitWidened`], ...).
    pub fn from_urdf(
        urdf: urdf_rs::Robot,
        limits_yaml: Option<&str>,
        tip: Option<&str>,
    ) -> Result<Self, RobotError> {
        let mut chain = chain::build(&urdf, tip)?;
        if let Some(yaml) = limits_yaml {
            let fixed: Vec<&str> = urdf
                .joints
                .iter()
                .filter(|j| j.joint_type == urdf_rs::JointType::Fixed)
                .map(|j| j.name.as_str())
                .collect();
            limits::apply(&mut chain.joints, &fixed, yaml)?;
        }
        Ok(Self { urdf, chain })
    }

    /// The robot name from the URDF `<robot name>`.
    pub fn name(&self) -> &str {
        &self.urdf.name
    }

    /// The movable joints, root to tip.
    pub fn joints(&self) -> &[JointSpec] {
        &self.chain.joints
    }

    /// The movable joint names, root to tip.
    pub fn joint_names(&self) -> Vec<&str> {
        self.chain.joints.iter().map(|j| j.name.as_str()).collect()
    }

    /// Index of the movable joint `name` in [`RobotModel::joints`], or
    /// `None` if there is no such movable joint.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.chain.joints.iter().position(|j| j.name == name)
    }

    /// Number of movable joints (degrees of freedom).
    pub fn dof(&self) -> usize {
        self.chain.joints.len()
    }

    /// Name of the root link (the base frame of all poses).
    pub fn root_link(&self) -> &str {
        &self.chain.root
    }

    /// Name of the tip link (the frame returned by
    /// [`RobotModel::forward_kinematics`]).
    pub fn tip_link(&self) -> &str {
        &self.chain.tip
    }

    /// The parsed URDF, e.g. for visual and collision geometry.
    pub fn urdf(&self) -> &urdf_rs::Robot {
        &self.urdf
    }

    /// Pose of the tip link in the root link frame.
    ///
    /// The product of the joint transforms `origin_i * motion_i(q_i)`
    /// (and fixed origins) from root to tip, as defined by the URDF
    /// specification (ROS wiki `urdf/XML/joint`).
    ///
    /// # Arguments
    /// * `q` - joint positions, root to tip (m or rad). Must have length
    ///   [`RobotModel::dof`] and be finite; position limits are *not*
    ///   checked (use [`RobotModel::check_positions`]).
    ///
    /// # Returns
    /// `T_root_tip`, or [`RobotError::WrongLength`] / [`RobotError::NonFinite`].
    ///
    /// # Performance
    /// O(chain length), no allocation.
    pub fn forward_kinematics(&self, q: &[f64]) -> Result<Isometry3<f64>, RobotError> {
        self.check_finite(q)?;
        Ok(self
            .chain
            .path
            .iter()
            .fold(Isometry3::identity(), |pose, &f| {
                pose * self.local_transform(f, q)
            }))
    }

    /// Poses of every link of the tree in the root link frame, including
    /// links attached by fixed joints on or off the chain.
    ///
    /// # Arguments
    /// * `q` - joint positions as for [`RobotModel::forward_kinematics`].
    ///
    /// # Returns
    /// `(link name, T_root_link)` for every link, root first and every
    /// parent before its children, or [`RobotError::WrongLength`] /
    /// [`RobotError::NonFinite`].
    ///
    /// # Performance
    /// O(links); allocates the result vector and one name per link.
    pub fn link_poses(&self, q: &[f64]) -> Result<Vec<(String, Isometry3<f64>)>, RobotError> {
        self.check_finite(q)?;
        let mut poses: Vec<Isometry3<f64>> = Vec::with_capacity(self.chain.frames.len());
        for (f, frame) in self.chain.frames.iter().enumerate() {
            let pose = match frame.motion {
                Motion::Root => Isometry3::identity(),
                _ => poses[frame.parent] * self.local_transform(f, q),
            };
            poses.push(pose);
        }
        Ok(self
            .chain
            .frames
            .iter()
            .zip(poses)
            .map(|(frame, pose)| (frame.link.clone(), pose))
            .collect())
    }

    /// Checks a joint position vector: right length, finite, and every
    /// value within its joint's `[min_position, max_position]` (bounds
    /// included).
    ///
    /// # Arguments
    /// * `q` - joint positions, root to tip (m or rad).
    ///
    /// # Returns
    /// `Ok(())`, or the first problem: [`RobotError::WrongLength`],
    /// [`RobotError::NonFinite`] or [`RobotError::OutOfRange`].
    ///
    /// # Performance
    /// O(dof), no allocation.
    pub fn check_positions(&self, q: &[f64]) -> Result<(), RobotError> {
        self.check_finite(q)?;
        for (joint, &value) in self.chain.joints.iter().zip(q) {
            if !joint.contains(value) {
                return Err(RobotError::OutOfRange {
                    joint: joint.name.clone(),
                    value,
                    min: joint.min_position,
                    max: joint.max_position,
                });
            }
        }
        Ok(())
    }

    /// Length and finiteness check shared by all evaluations.
    fn check_finite(&self, q: &[f64]) -> Result<(), RobotError> {
        if q.len() != self.dof() {
            return Err(RobotError::WrongLength {
                expected: self.dof(),
                got: q.len(),
            });
        }
        for (joint, &value) in self.chain.joints.iter().zip(q) {
            if !value.is_finite() {
                return Err(RobotError::NonFinite {
                    joint: joint.name.clone(),
                    value,
                });
            }
        }
        Ok(())
    }

    /// Parent-to-child transform of frame `f`; `q` has been checked.
    fn local_transform(&self, f: usize, q: &[f64]) -> Isometry3<f64> {
        match &self.chain.frames[f].motion {
            Motion::Root => Isometry3::identity(),
            Motion::Fixed(origin) => *origin,
            Motion::Movable(j) => self.chain.joints[*j].transform(q[*j]),
        }
    }
}

/// Parses URDF XML text.
fn parse_urdf(urdf_xml: &str) -> Result<urdf_rs::Robot, RobotError> {
    urdf_rs::read_from_string(urdf_xml).map_err(|source| RobotError::UrdfParse { source })
}
