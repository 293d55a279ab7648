//! The robotic milling cell file `urdf/irb6660_milling.yaml`: robot, TCP,
//! path, characteristic length, tool-tip dynamics and the milling process
//! of seed 004 Table 1 in one validated description.
//!
//! File paths inside the YAML (`robot.urdf`, `robot.limits`) are relative to
//! the YAML file's directory. Every field is validated on load; an error
//! names the field (e.g. `process.spindle_rpm[1]`), the value and the
//! reason.

use std::path::{Path, PathBuf};

use kerf_chatter::indicator::IndicatorSettings;
use kerf_chatter::{MillingProcess, Modal2};
use kerf_robot::RobotModel;
use nalgebra::{Isometry3, Vector3};

use crate::dynamics::{ComplianceModel, ToolTipDynamics};
use crate::error::{check_finite, check_positive, MillError};
use crate::ik::Kinematics;
use crate::jacobian::condition_number;
use crate::path::{MillingPath, PathSpec};

mod file;
mod limits;
mod sections;

pub use limits::StateLimits;

use file::CellFile;
use sections::{indicator_from, process_from, tcp_from_axes};

/// The shipped cell file, relative to the kerf data root.
const DEFAULT_CELL: &str = "urdf/irb6660_milling.yaml";

/// What the cell gives for one (segment, g).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellState {
    /// Joint vector \[rad\] (nearest valid IK solution to the reference).
    pub joints: [f64; 6],
    /// The normalized condition number K of seed 004 eq. 14 (≥ 1, ∞ at a
    /// singularity).
    pub condition_number: f64,
    /// The singularity indicator 1/K ∈ [0, 1].
    pub condition_indicator: f64,
    /// The 2-DOF tool-tip dynamics in the segment's cutting frame.
    pub modal: Modal2,
}

/// The robotic milling cell (module documentation).
#[derive(Debug, Clone)]
pub struct MillCell {
    robot: RobotModel,
    kinematics: Kinematics,
    path: MillingPath,
    characteristic_length: f64,
    dynamics: ToolTipDynamics,
    process: MillingProcess,
    limits: StateLimits,
    indicator: IndicatorSettings,
    reference: [f64; 6],
    jump_threshold: f64,
}

impl MillCell {
    /// The default cell file, `urdf/irb6660_milling.yaml` below the kerf data root
    /// ([`kerf_robot::data`]: `KERF_DATA_DIR`, the share directory beside the binary, the
    /// source tree).
    ///
    /// # Returns
    /// The path; when the data search fails, below the place it failed at
    /// ([`kerf_robot::data::default_path`]), and [`MillCell::default_cell`] reports why.
    pub fn default_path() -> PathBuf {
        kerf_robot::data::default_path(DEFAULT_CELL)
    }

    /// Loads [`MillCell::default_path`] (with `urdf/irb6660.urdf` and
    /// `urdf/irb6660_limits.yaml`).
    ///
    /// # Errors
    /// [`MillError::Robot`] when no kerf data root is found (the message names every place
    /// searched); else as [`MillCell::load`].
    pub fn default_cell() -> Result<Self, MillError> {
        Self::load(&kerf_robot::data::path(DEFAULT_CELL)?)
    }

    /// Loads and validates a cell file.
    ///
    /// # Errors
    /// [`MillError::FileRead`], [`MillError::Yaml`] (syntax, unknown or
    /// missing field), [`MillError::Robot`], and every validation error of
    /// [`MillCell::from_yaml_str`].
    pub fn load(path: &Path) -> Result<Self, MillError> {
        let text = std::fs::read_to_string(path).map_err(|e| MillError::FileRead {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Self::from_yaml_str(&text, dir, path)
    }

    /// Parses and validates cell YAML text.
    ///
    /// # Arguments
    /// * `yaml` - the document;
    /// * `base_dir` - directory the robot file paths are relative to;
    /// * `name` - the file name used in error messages.
    ///
    /// # Errors
    /// [`MillError::Yaml`], [`MillError::Robot`], [`MillError::InvalidParameter`]
    /// / [`MillError::InvalidConfig`] naming the field,
    /// [`MillError::NotCoplanar`], [`MillError::Chatter`].
    pub fn from_yaml_str(yaml: &str, base_dir: &Path, name: &Path) -> Result<Self, MillError> {
        let file: CellFile = serde_yaml_ng::from_str(yaml).map_err(|e| MillError::Yaml {
            path: name.to_path_buf(),
            message: e.to_string(),
        })?;
        let urdf = base_dir.join(&file.robot.urdf);
        let limits = file.robot.limits.as_ref().map(|l| base_dir.join(l));
        let robot = RobotModel::from_files(&urdf, limits.as_deref())?;
        let tcp = match &file.tcp {
            None => Isometry3::identity(),
            Some(t) => tcp_from_axes(t)?,
        };
        let kinematics = Kinematics::from_robot(&robot, tcp, file.robot.joint_weights)?;
        for (i, v) in file.robot.reference_joints.iter().enumerate() {
            check_finite(&format!("robot.reference_joints[{i}] [rad]"), *v)?;
        }
        let jump_threshold = check_positive(
            "robot.branch_jump_threshold [rad]",
            file.robot.branch_jump_threshold,
        )?;
        let path = MillingPath::new(&PathSpec {
            points: file.path.points.clone(),
            segments: file.path.segments,
            approach_from_above: file.path.approach_from_above,
            up: file.path.up,
        })?;
        let characteristic_length = check_positive(
            "condition.characteristic_length [m]",
            file.condition.characteristic_length,
        )?;
        let compliance = ComplianceModel {
            joint_stiffness: file.dynamics.joint_stiffness,
            modal_mass: file.dynamics.modal_mass,
            damping_ratio: file.dynamics.damping_ratio,
        };
        compliance.validate()?;
        let dynamics = match (file.dynamics.model.as_str(), &file.dynamics.measured) {
            ("compliance", _) => ToolTipDynamics::Compliance(compliance),
            ("measured", Some(m)) => ToolTipDynamics::Measured { x: m.x, y: m.y },
            ("measured", None) => {
                return Err(MillError::InvalidConfig {
                    name: "dynamics.measured".to_string(),
                    reason: "model is `measured` but no measured modes are given".to_string(),
                })
            }
            (other, _) => {
                return Err(MillError::InvalidConfig {
                    name: "dynamics.model".to_string(),
                    reason: format!("`{other}`: must be `compliance` or `measured`"),
                })
            }
        };
        dynamics.validate()?;
        let (process, limits) = process_from(&file.process)?;
        let indicator = indicator_from(file.chatter.as_ref())?;
        Ok(Self {
            robot,
            kinematics,
            path,
            characteristic_length,
            dynamics,
            process,
            limits,
            indicator,
            reference: file.robot.reference_joints,
            jump_threshold,
        })
    }

    /// The robot model (URDF + limits).
    pub fn robot(&self) -> &RobotModel {
        &self.robot
    }

    /// The kinematics (with the TCP offset).
    pub fn kinematics(&self) -> &Kinematics {
        &self.kinematics
    }

    /// The milling path.
    pub fn path(&self) -> &MillingPath {
        &self.path
    }

    /// The characteristic length L of eq. 14 \[m\].
    pub fn characteristic_length(&self) -> f64 {
        self.characteristic_length
    }

    /// The tool-tip dynamics model.
    pub fn dynamics(&self) -> &ToolTipDynamics {
        &self.dynamics
    }

    /// The milling process (seed 004 Table 1), for `kerf_chatter`.
    pub fn milling_process(&self) -> MillingProcess {
        self.process
    }

    /// How the chatter indicator is evaluated for this cell (the YAML's
    /// `chatter` section: delay model, m, force law, wall term).
    pub fn indicator_settings(&self) -> &IndicatorSettings {
        &self.indicator
    }

    /// State ranges and step bounds.
    pub fn state_limits(&self) -> &StateLimits {
        &self.limits
    }

    /// The reference joint vector of the YAML (`robot.reference_joints`).
    pub fn reference_joints(&self) -> &[f64; 6] {
        &self.reference
    }

    /// The branch-jump threshold \[rad\].
    pub fn branch_jump_threshold(&self) -> f64 {
        self.jump_threshold
    }

    /// Joint vector, condition number/indicator and 2-DOF dynamics at
    /// segment `segment` and redundancy angle `g`.
    ///
    /// The tool tip is at the segment's arc-length midpoint with the
    /// orientation `R0 · RotZ(g)` of [`MillingPath::tool_pose`]; the joint
    /// vector is the valid IK solution nearest to `reference` (the previous
    /// state's joints, for branch continuity), or to the YAML's
    /// `robot.reference_joints` when `None`.
    ///
    /// # Errors
    /// [`MillError::Unreachable`] / [`MillError::JointLimit`] with the segment
    /// and g; [`MillError::InvalidParameter`] for a bad index or g outside
    /// the configured range; the errors of the dynamics model.
    ///
    /// # Performance
    /// One IK (≤ 8 solutions), one Jacobian, one 6×6 eigen-decomposition:
    /// a few µs.
    pub fn evaluate(
        &self,
        segment: usize,
        g: f64,
        reference: Option<&[f64; 6]>,
    ) -> Result<CellState, MillError> {
        let [lo, hi] = self.limits.redundancy_angle;
        if !(g >= lo - 1e-12 && g <= hi + 1e-12) {
            return Err(MillError::InvalidParameter {
                name: "redundancy angle g [rad]".to_string(),
                value: g,
                reason: format!("must be in [{lo}, {hi}]"),
            });
        }
        let pose = self.path.tool_pose(segment, g)?;
        let reference = reference.unwrap_or(&self.reference);
        let joints = self
            .kinematics
            .ik_nearest(&pose, reference)
            .map_err(|e| e.with_context(Some(segment), Some(g)))?;
        let j = self.kinematics.jacobian(&joints)?;
        let k = condition_number(&j, self.characteristic_length)?;
        let frame = self.path.segment(segment)?.cutting_frame;
        let modal = self.dynamics.modal2(&j, &frame)?;
        Ok(CellState {
            joints,
            condition_number: k,
            condition_indicator: 1.0 / k,
            modal,
        })
    }
}

/// Derived cells: the same robot, TCP, dynamics model, characteristic
/// length, reference joints and chatter settings with another path,
/// process or state limits (a planner request that overrides part of the
/// cell file).
impl MillCell {
    /// This cell with another milling path.
    ///
    /// The characteristic length L of eq. 14 stays this cell's: L is a
    /// normalization constant of the Jacobian (Angeles' choice minimizes
    /// the mean K over the cell file's task); for another path it still
    /// gives a valid, comparable condition number, though no longer the
    /// minimizing one — recompute it with [`crate::characteristic_length`]
    /// and a new cell file when that matters.
    ///
    /// # Errors
    /// Those of [`MillingPath::new`]: too few, non-finite or repeated
    /// points, N = 0, [`MillError::NotCoplanar`] with the worst point and
    /// its distance, a non-converged arc length.
    ///
    /// # Performance
    /// One spline fit and the arc-length table (about a millisecond), plus
    /// a clone of the cell.
    pub fn with_path(&self, spec: &PathSpec) -> Result<MillCell, MillError> {
        let path = MillingPath::new(spec)?;
        Ok(Self {
            path,
            ..self.clone()
        })
    }

    /// This cell with another milling process (tool, cutting coefficients,
    /// engagement).
    ///
    /// # Errors
    /// [`MillError::Chatter`] when [`MillingProcess::validate`] refuses it.
    pub fn with_process(&self, process: MillingProcess) -> Result<MillCell, MillError> {
        process.validate()?;
        Ok(Self {
            process,
            ..self.clone()
        })
    }

    /// This cell with other state ranges and step bounds, validated by
    /// [`StateLimits::validate`] (the rules of the cell YAML).
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] naming the field.
    pub fn with_state_limits(&self, limits: StateLimits) -> Result<MillCell, MillError> {
        limits.validate()?;
        Ok(Self {
            limits,
            ..self.clone()
        })
    }

    /// The tool-tip pose at arc length `s` along the path and redundancy
    /// angle `g`: `[R0 · RotZ(g), P(u(s))]` with the tangent of
    /// [`MillingPath::tool_pose`] taken at u(s) (the derivative P'(u)
    /// projected on the path plane). At a segment's arc-length midpoint it
    /// is that segment's [`MillingPath::tool_pose`].
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] for s outside [0, total length] or a
    /// non-finite g; [`MillError::NotConverged`] from the arc-length
    /// inversion; [`MillError::Singular`] for a zero tangent.
    pub fn tool_pose_at(&self, s: f64, g: f64) -> Result<Isometry3<f64>, MillError> {
        let g = check_finite("redundancy angle g [rad]", g)?;
        self.tool_pose_at_parameter(self.path.parameter_at(s)?, g)
    }

    /// [`MillCell::tool_pose_at`] at the path's spline parameter `u` instead of the arc
    /// length (for a caller that already has u: the arc-length inversion is the costly part).
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] for a non-finite g; [`MillError::Bspline`] for u
    /// outside [0, 1]; [`MillError::Singular`] for a zero tangent.
    pub fn tool_pose_at_parameter(&self, u: f64, g: f64) -> Result<Isometry3<f64>, MillError> {
        let g = check_finite("redundancy angle g [rad]", g)?;
        let (p, tangent) = self.point_and_plane_tangent(u)?;
        Ok(crate::path::tool_pose(
            &p,
            &tangent,
            &self.path.approach(),
            g,
        ))
    }

    /// The path point P(u) and the unit tangent of the path frame there: P'(u) projected on
    /// the path plane and normalized (the tangent of [`MillCell::tool_pose_at_parameter`] and
    /// of the extensions of [`MillCell::tool_pose_on_extension`]).
    ///
    /// # Errors
    /// [`MillError::Bspline`] for u outside [0, 1]; [`MillError::Singular`] for a zero
    /// tangent.
    pub fn point_and_plane_tangent(
        &self,
        u: f64,
    ) -> Result<(Vector3<f64>, Vector3<f64>), MillError> {
        let (p, d) = self.path.point_and_derivative(u)?;
        let n = self.path.normal();
        let d = d - d.dot(&n) * n;
        let norm = d.norm();
        if norm.is_nan() || norm <= 0.0 {
            return Err(MillError::Singular {
                what: format!("path tangent at spline parameter {u} (zero speed)"),
            });
        }
        Ok((p, d / norm))
    }

    /// The tool-tip pose at an arc length `s` of the path extended by straight lines along
    /// its end tangents: [`MillCell::tool_pose_at_parameter`] inside [0, L]; before the
    /// start, the start pose moved by `s` along the start tangent (s < 0); after the end,
    /// the end pose moved by `s − L` along the end tangent. The orientation on an extension
    /// is the end's (the path frame's tangent is constant on a line), so the pose is
    /// continuous at both ends. The extensions are the straight run-in and run-out a cut
    /// enters and leaves the material on ([`MillCell::path`] is the cut in the material).
    ///
    /// # Errors
    /// As [`MillCell::tool_pose_at`], and [`MillError::InvalidParameter`] for a non-finite s.
    pub fn tool_pose_on_extension(&self, s: f64, g: f64) -> Result<Isometry3<f64>, MillError> {
        let s = check_finite("extended arc length s [m]", s)?;
        let total = self.path.total_length();
        let (u, beyond) = if s < 0.0 {
            (0.0, s)
        } else if s > total {
            (1.0, s - total)
        } else {
            return self.tool_pose_at(s, g);
        };
        let mut pose = self.tool_pose_at_parameter(u, g)?;
        let (_, tangent) = self.point_and_plane_tangent(u)?;
        pose.translation.vector += beyond * tangent;
        Ok(pose)
    }

    /// The joint vector at an extended arc length ([`MillCell::tool_pose_on_extension`]):
    /// the valid IK solution nearest `reference`, as [`MillCell::joints_at`].
    ///
    /// # Errors
    /// As [`MillCell::joints_at`].
    pub fn joints_on_extension(
        &self,
        s: f64,
        g: f64,
        reference: Option<&[f64; 6]>,
    ) -> Result<[f64; 6], MillError> {
        self.check_g(g)?;
        self.joints_at_pose(&self.tool_pose_on_extension(s, g)?, g, reference)
    }

    /// The joint vector at arc length `s` and redundancy angle `g`: the
    /// valid IK solution of [`MillCell::tool_pose_at`] nearest `reference`
    /// (the YAML's reference joints for `None`), as [`MillCell::evaluate`]
    /// does at segment midpoints.
    ///
    /// # Errors
    /// As [`MillCell::tool_pose_at`]; [`MillError::InvalidParameter`] for g
    /// outside the configured range; [`MillError::Unreachable`] /
    /// [`MillError::JointLimit`] with g (no segment).
    pub fn joints_at(
        &self,
        s: f64,
        g: f64,
        reference: Option<&[f64; 6]>,
    ) -> Result<[f64; 6], MillError> {
        self.check_g(g)?;
        self.joints_at_parameter(self.path.parameter_at(s)?, g, reference)
    }

    /// [`MillCell::joints_at`] at the path's spline parameter `u` instead of the arc length.
    ///
    /// # Errors
    /// As [`MillCell::tool_pose_at_parameter`]; [`MillError::InvalidParameter`] for g outside
    /// the configured range; [`MillError::Unreachable`] / [`MillError::JointLimit`] with g.
    pub fn joints_at_parameter(
        &self,
        u: f64,
        g: f64,
        reference: Option<&[f64; 6]>,
    ) -> Result<[f64; 6], MillError> {
        self.check_g(g)?;
        self.joints_at_pose(&self.tool_pose_at_parameter(u, g)?, g, reference)
    }

    /// The valid IK solution of the tool-tip `pose` nearest `reference` (the YAML's reference
    /// joints for `None`); an IK error carries `g` as its context.
    fn joints_at_pose(
        &self,
        pose: &Isometry3<f64>,
        g: f64,
        reference: Option<&[f64; 6]>,
    ) -> Result<[f64; 6], MillError> {
        self.kinematics
            .ik_nearest(pose, reference.unwrap_or(&self.reference))
            .map_err(|e| e.with_context(None, Some(g)))
    }

    /// g inside the configured range (1e-12 slack).
    fn check_g(&self, g: f64) -> Result<(), MillError> {
        let [lo, hi] = self.limits.redundancy_angle;
        if !(g >= lo - 1e-12 && g <= hi + 1e-12) {
            return Err(MillError::InvalidParameter {
                name: "redundancy angle g [rad]".to_string(),
                value: g,
                reason: format!("must be in [{lo}, {hi}]"),
            });
        }
        Ok(())
    }
}
