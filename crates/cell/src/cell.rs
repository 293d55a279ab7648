//! [`Cell`]: the robot, its scene and the lock-step of control and physics.

use std::path::Path;

use kerf_executor::JointSample;
use kerf_robot::RobotModel;
use nalgebra::{Isometry3, Matrix3, Vector3};
use parry3d_f64::math::Pose;

use crate::chain::{urdf_origin, Chain, MassProps};
use crate::config::{CellFile, GeometrySpec};
use crate::contact::{Contact, ContactChecker};
use crate::dynamics::{inverse_dynamics, mass_diagonal, Workspace};
use crate::geometry::{primitive, to_pose, urdf_shape, RobotShape, SceneObject};
use crate::hermite::Hermite;
use crate::inertia::InertiaFile;
use crate::settings::{CellSettings, Mode};
use crate::world::World;
use crate::CellError;

/// The state of the cell after a control period.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CellState {
    /// Simulated time since start (s).
    pub time: f64,
    /// Joint positions (m or rad), model order.
    pub positions: Vec<f64>,
    /// Joint velocities (m/s or rad/s).
    pub velocities: Vec<f64>,
    /// Joint accelerations (m/s² or rad/s²): backward difference over the last physics step
    /// (dynamic), the command's (kinematic).
    pub accelerations: Vec<f64>,
    /// Drive efforts (N or N m): applied in the last physics step (dynamic), required by the
    /// commanded motion by inverse dynamics (kinematic).
    pub efforts: Vec<f64>,
    /// Command minus state position at the end of the period (zero in kinematic mode).
    pub tracking_error: Vec<f64>,
    /// Per joint: the effort hit its URDF limit in some physics step of the period (dynamic:
    /// the drive was limited; kinematic: the commanded motion needs more than the limit).
    pub saturated: Vec<bool>,
    /// Contacts in this period: per (robot shape, object) pair the nearest over the physics
    /// sub-steps.
    pub contacts: Vec<Contact>,
}

impl CellState {
    /// Positions, velocities and accelerations as the executor's measured state.
    pub fn joint_sample(&self) -> JointSample {
        JointSample {
            positions: self.positions.clone(),
            velocities: self.velocities.clone(),
            accelerations: self.accelerations.clone(),
        }
    }
}

/// Reference of one physics sub-step: cubic Hermite positions and velocities between the
/// previous and the current command, accelerations linear between them.
struct Reference {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
}

/// A simulated robot cell on rapier3d-f64: a drop-in for `kerf_executor::MockHardware` that
/// also checks contacts with the scene and, in dynamic mode, simulates the drives.
///
/// The executor's control loop calls [`Cell::step`] once per control period with its
/// command; the cell runs `physics_rate / control_rate` physics steps in lock-step and
/// returns the state at the end of the period.
pub struct Cell {
    model: RobotModel,
    chain: Chain,
    world: World,
    checker: ContactChecker,
    settings: CellSettings,
    substeps: usize,
    dt_control: f64,
    dt_physics: f64,
    gravity: Vector3<f64>,
    state: CellState,
    previous: JointSample,
    ws: Workspace,
    poses: Vec<Pose>,
    reference: Reference,
    scratch: Vec<f64>,
    /// Joint positions of the multibody at the start of a physics step (dynamic mode).
    state_q: Vec<f64>,
    /// Feed-forward efforts of a physics step (dynamic mode).
    tau_ff: Vec<f64>,
    kp: Vec<f64>,
    kd: Vec<f64>,
}

impl std::fmt::Debug for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cell")
            .field("robot", &self.model.name())
            .field("settings", &self.settings)
            .field("substeps", &self.substeps)
            .field("checker", &self.checker)
            .field("time", &self.state.time)
            .finish()
    }
}

/// Parses a URDF into the robot model, checking first that every movable joint has an
/// effort limit > 0 (the drives of the dynamic mode are limited by it).
///
/// # Errors
/// [`CellError::EffortLimit`] naming the first joint whose `<limit effort>` is not finite
/// and > 0; [`CellError::Robot`] for every other problem `kerf_robot` finds.
pub fn load_robot(urdf_xml: &str) -> Result<RobotModel, CellError> {
    let robot = urdf_rs::read_from_string(urdf_xml).map_err(|e| CellError::Robot {
        reason: e.to_string(),
    })?;
    for j in &robot.joints {
        let movable = matches!(
            j.joint_type,
            urdf_rs::JointType::Revolute
                | urdf_rs::JointType::Prismatic
                | urdf_rs::JointType::Continuous
        );
        if movable && !(j.limit.effort.is_finite() && j.limit.effort > 0.0) {
            return Err(CellError::EffortLimit {
                joint: j.name.clone(),
                effort: j.limit.effort,
            });
        }
    }
    RobotModel::from_urdf(robot, None, None).map_err(|e| CellError::Robot {
        reason: e.to_string(),
    })
}

/// Analytic mass properties of a uniform solid box or z-cylinder of mass `m` (Craig,
/// *Introduction to Robotics*, 3rd ed., section 6.3, examples of inertia tensors).
fn solid(m: f64, g: &GeometrySpec) -> MassProps {
    let inertia = match *g {
        GeometrySpec::Box { size: [a, b, c] } => Matrix3::from_diagonal(&Vector3::new(
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
        )),
        GeometrySpec::Cylinder {
            radius: r,
            length: l,
        } => {
            let t = m * (3.0 * r * r + l * l) / 12.0;
            Matrix3::from_diagonal(&Vector3::new(t, t, m * r * r / 2.0))
        }
        GeometrySpec::Mesh { .. } => Matrix3::zeros(),
    };
    MassProps {
        mass: m,
        com: Vector3::zeros(),
        inertia,
    }
}

impl Cell {
    /// Loads a cell: the robot's URDF, a cell file (scene, mass sidecar, contact rules).
    ///
    /// # Arguments
    /// * `urdf` - the robot description the executor uses.
    /// * `cell_file` - the cell file (e.g. `urdf/cells/laser_bpillar.yaml`).
    /// * `settings` - mode, rates, gains.
    ///
    /// # Errors
    /// Every [`CellError`] of loading, see [`Cell::new`].
    pub fn from_files(
        urdf: &Path,
        cell_file: &Path,
        settings: CellSettings,
    ) -> Result<Self, CellError> {
        let text = std::fs::read_to_string(urdf).map_err(|e| CellError::FileRead {
            path: urdf.to_path_buf(),
            reason: e.to_string(),
        })?;
        let model = load_robot(&text)?;
        let cell = CellFile::from_file(cell_file)?;
        Self::new(model, &cell, settings)
    }

    /// Builds a cell from a loaded robot model and a parsed cell file.
    ///
    /// # Errors
    /// [`CellError::RateRatio`] and [`CellError::InvalidValue`] for bad settings;
    /// [`CellError::CellFile`] when the cell file names another robot, an unknown link, or
    /// duplicate names; [`CellError::JointMismatch`] for initial positions of the wrong
    /// length; [`CellError::EffortLimit`], [`CellError::Inertia`] from the mass sidecar;
    /// [`CellError::MissingMesh`] / [`CellError::BadMesh`] for scene meshes.
    pub fn new(
        model: RobotModel,
        cell: &CellFile,
        settings: CellSettings,
    ) -> Result<Self, CellError> {
        let substeps = settings.substeps()?;
        if cell.robot.name != model.name() {
            return Err(cell.error(format!(
                "robot.name is '{}' but the URDF is '{}'",
                cell.robot.name,
                model.name()
            )));
        }
        let inertia = InertiaFile::from_file(&cell.resolve(&cell.robot.inertia))?;
        let mut chain = Chain::build(&model, &inertia)?;
        let names = model.joint_names().join(", ");
        let q0 = cell.robot.initial_positions.clone();
        if q0.len() != model.dof() {
            return Err(CellError::JointMismatch {
                what: "robot.initial_positions",
                reason: format!("{} values for {} joints", q0.len(), model.dof()),
                expected: names,
            });
        }
        if let Err(e) = model.check_positions(&q0) {
            return Err(cell.error(format!("robot.initial_positions: {e}")));
        }
        // Robot shapes: URDF collision elements, then tool shapes.
        let mut shapes = Vec::new();
        for link in &model.urdf().links {
            let (body, off) = chain
                .link(&link.name)
                .ok_or_else(|| cell.error(format!("link '{}' not on the robot tree", link.name)))?;
            if body.is_none() && !cell.contact.check_base {
                continue;
            }
            for (k, c) in link.collision.iter().enumerate() {
                let name = format!("{}/{k}", link.name);
                let (shape, fix) = urdf_shape(&name, &c.geometry)?;
                shapes.push(RobotShape {
                    name,
                    link: link.name.clone(),
                    body,
                    local: to_pose(&(off * urdf_origin(&c.origin) * fix)),
                    shape,
                });
            }
        }
        for t in &cell.tool {
            if shapes.iter().any(|s: &RobotShape| s.name == t.name) {
                return Err(cell.error(format!("tool shape name '{}' is used twice", t.name)));
            }
            let (body, off) = chain.link(&t.link).ok_or_else(|| {
                cell.error(format!("tool '{}': unknown link '{}'", t.name, t.link))
            })?;
            let origin = t.origin.isometry(&format!("tool.{}.origin", t.name))?;
            let (shape, fix) = primitive(&format!("tool.{}.geometry", t.name), &t.geometry)?;
            if !(t.mass.is_finite() && t.mass >= 0.0) {
                return Err(CellError::InvalidValue {
                    field: format!("tool.{}.mass", t.name),
                    value: t.mass,
                    requirement: "must be finite and >= 0",
                });
            }
            if t.mass > 0.0 {
                chain.add_mass(&t.link, &solid(t.mass, &t.geometry), &origin)?;
            }
            shapes.push(RobotShape {
                name: t.name.clone(),
                link: t.link.clone(),
                body,
                local: to_pose(&(off * origin * fix)),
                shape,
            });
        }
        let mut objects: Vec<SceneObject> = Vec::new();
        for o in &cell.objects {
            if objects.iter().any(|k| k.name == o.name) {
                return Err(cell.error(format!("scene object name '{}' is used twice", o.name)));
            }
            let pose = o.pose.isometry(&format!("objects.{}.pose", o.name))?;
            objects.push(SceneObject::build(
                &o.name,
                o.kind,
                &o.geometry,
                &pose,
                &cell.base_dir,
            )?);
        }
        let checker = ContactChecker::new(cell, shapes, objects)?;
        checker.probe()?;
        let gravity = Vector3::from(settings.gravity);
        let dt_physics = 1.0 / settings.physics_rate_hz;
        let world = World::new(&chain, &q0, &gravity, dt_physics)?;
        let n = model.dof();
        let mut cell = Self {
            model,
            chain,
            world,
            checker,
            settings,
            substeps,
            dt_control: 1.0 / settings.control_rate_hz,
            dt_physics,
            gravity,
            state: CellState::default(),
            previous: JointSample::at_rest(q0.clone()),
            ws: Workspace::default(),
            poses: Vec::new(),
            reference: Reference {
                q: vec![0.0; n],
                qd: vec![0.0; n],
                qdd: vec![0.0; n],
            },
            scratch: vec![0.0; n],
            state_q: vec![0.0; n],
            tau_ff: vec![0.0; n],
            kp: vec![0.0; n],
            kd: vec![0.0; n],
        };
        cell.reset(&q0)?;
        Ok(cell)
    }

    /// Puts the robot at rest at `q` (time kept), checks contacts there and makes that the
    /// state. Used at start and by tests placing the robot.
    ///
    /// # Errors
    /// [`CellError::JointMismatch`] or [`CellError::NonFinite`] for a bad `q`.
    pub fn reset(&mut self, q: &[f64]) -> Result<&CellState, CellError> {
        self.check_values("positions", q)?;
        let n = q.len();
        let zeros = vec![0.0; n];
        self.world.set_state(&self.chain, q, &zeros);
        self.previous = JointSample::at_rest(q.to_vec());
        let mut tau = vec![0.0; n];
        inverse_dynamics(
            &self.chain,
            q,
            &zeros,
            &zeros,
            &self.gravity,
            &mut self.ws,
            &mut tau,
        );
        self.world.body_poses(&mut self.poses);
        let mut contacts = Vec::new();
        self.checker
            .check(&self.poses, self.state.time, &mut contacts);
        self.state = CellState {
            time: self.state.time,
            positions: q.to_vec(),
            velocities: zeros.clone(),
            accelerations: zeros.clone(),
            saturated: self.saturation(&tau),
            efforts: tau,
            tracking_error: zeros,
            contacts,
        };
        Ok(&self.state)
    }

    /// The robot model (URDF).
    pub fn model(&self) -> &RobotModel {
        &self.model
    }

    /// The rigid bodies (masses as simulated).
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The contact checker (robot shapes, scene objects, threshold).
    pub fn checker(&self) -> &ContactChecker {
        &self.checker
    }

    /// The settings.
    pub fn settings(&self) -> &CellSettings {
        &self.settings
    }

    /// Physics steps per control period.
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    /// The state after the last step.
    pub fn state(&self) -> &CellState {
        &self.state
    }

    /// The movable joint names, model order.
    pub fn joint_names(&self) -> Vec<&str> {
        self.model.joint_names()
    }

    /// Checks that `names` are exactly the robot's joints in model order (the executor's
    /// joint list against the cell's URDF).
    ///
    /// # Errors
    /// [`CellError::JointMismatch`] naming the first difference.
    pub fn check_joint_names<S: AsRef<str>>(&self, names: &[S]) -> Result<(), CellError> {
        let ours = self.model.joint_names();
        let err = |reason: String| CellError::JointMismatch {
            what: "joint names",
            reason,
            expected: ours.join(", "),
        };
        if names.len() != ours.len() {
            return Err(err(format!(
                "{} names for {} joints",
                names.len(),
                ours.len()
            )));
        }
        for (i, (a, b)) in names.iter().zip(&ours).enumerate() {
            if a.as_ref() != *b {
                return Err(err(format!(
                    "joint {i} is '{}', expected '{b}'",
                    a.as_ref()
                )));
            }
        }
        Ok(())
    }

    /// Signed distances of the robot shapes to the scene objects at the current state (pairs
    /// engaged by an allowance excluded).
    pub fn distances(&self) -> Vec<(String, String, Option<f64>)> {
        self.checker.distances(&self.poses)
    }

    /// Body poses in the base frame at the current state (rapier's bodies).
    pub fn body_poses(&self) -> Vec<Isometry3<f64>> {
        self.poses
            .iter()
            .map(crate::geometry::to_isometry)
            .collect()
    }

    fn check_values(&self, what: &'static str, v: &[f64]) -> Result<(), CellError> {
        let names = self.model.joint_names();
        if v.len() != names.len() {
            return Err(CellError::JointMismatch {
                what: match what {
                    "positions" => "command positions",
                    "velocities" => "command velocities",
                    _ => "command accelerations",
                },
                reason: format!("{} values for {} joints", v.len(), names.len()),
                expected: names.join(", "),
            });
        }
        if let Some((j, &x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(CellError::NonFinite {
                what: match what {
                    "positions" => "command positions",
                    "velocities" => "command velocities",
                    _ => "command accelerations",
                },
                joint: names[j].to_string(),
                value: x,
            });
        }
        Ok(())
    }

    fn saturation(&self, tau: &[f64]) -> Vec<bool> {
        tau.iter()
            .zip(&self.chain.joints)
            .map(|(t, j)| t.abs() > j.max_effort)
            .collect()
    }

    /// Runs one control period: `physics_rate / control_rate` physics sub-steps towards
    /// `command`, checking contacts at every sub-step.
    ///
    /// # Arguments
    /// * `command` - the reference at the end of the period (model order): positions, and
    ///   velocities and accelerations (each empty or one per joint). Between the previous
    ///   command and this one the reference is the cubic Hermite of positions and
    ///   velocities (with empty velocities: the secant velocity), accelerations linear
    ///   between the two (empty: zero).
    /// * `dt` - the control period (s), equal to `1 / control_rate_hz`.
    ///
    /// # Returns
    /// The state at the end of the period.
    ///
    /// # Errors
    /// [`CellError::ControlPeriod`], [`CellError::JointMismatch`], [`CellError::NonFinite`];
    /// the cell is then unchanged.
    ///
    /// # Performance
    /// Kinematic: per sub-step a forward kinematics and the contact checks (a displacement
    /// bound per pair; queries only for pairs near the scene). Dynamic: per sub-step one
    /// inverse dynamics (O(joints)), one rapier step (most of the cost) and the contact checks;
    /// per period one mass-matrix diagonal for the gains. BENCHMARKS.md, "Simulated cell
    /// (issue 15)".
    pub fn step(&mut self, command: &JointSample, dt: f64) -> Result<&CellState, CellError> {
        if !(dt.is_finite() && (dt - self.dt_control).abs() <= 1e-9 * self.dt_control) {
            return Err(CellError::ControlPeriod {
                dt,
                expected: self.dt_control,
            });
        }
        self.check_values("positions", &command.positions)?;
        if !command.velocities.is_empty() {
            self.check_values("velocities", &command.velocities)?;
        }
        if !command.accelerations.is_empty() {
            self.check_values("accelerations", &command.accelerations)?;
        }
        let n = command.positions.len();
        let mut end = JointSample {
            positions: command.positions.clone(),
            velocities: command.velocities.clone(),
            accelerations: command.accelerations.clone(),
        };
        if end.velocities.is_empty() {
            end.velocities = (0..n)
                .map(|j| (end.positions[j] - self.previous.positions[j]) / dt)
                .collect();
        }
        if end.accelerations.is_empty() {
            end.accelerations = vec![0.0; n];
        }
        let mut contacts = Vec::new();
        let mut saturated = vec![false; n];
        let mut efforts = vec![0.0; n];
        let mut v_before = vec![0.0; n];
        if self.settings.mode == Mode::Dynamic {
            self.update_gains(&end.positions);
        }
        let t0 = self.state.time;
        for k in 1..=self.substeps {
            let s = k as f64 / self.substeps as f64;
            let time = t0 + k as f64 * self.dt_physics;
            match self.settings.mode {
                Mode::Kinematic => {
                    self.interpolate(&end, s, dt);
                    self.world
                        .set_state(&self.chain, &self.reference.q, &self.reference.qd);
                }
                Mode::Dynamic => {
                    // rapier integrates semi-implicit Euler (v⁺ = v + a dt, q⁺ = q + v⁺ dt):
                    // the servo compares the state with the reference at the start of the
                    // step, and the feed-forward acceleration is the one that takes the
                    // reference velocity from the start to the end of the step.
                    self.interpolate(&end, s, dt);
                    self.scratch.clone_from(&self.reference.qd);
                    let s0 = (k - 1) as f64 / self.substeps as f64;
                    self.interpolate(&end, s0, dt);
                    for j in 0..n {
                        self.reference.qdd[j] =
                            (self.scratch[j] - self.reference.qd[j]) / self.dt_physics;
                    }
                    self.drive(&mut efforts, &mut saturated, &mut v_before);
                    self.world.step();
                }
            }
            self.world.body_poses(&mut self.poses);
            self.checker.check(&self.poses, time, &mut contacts);
        }
        let mut state = CellState {
            time: t0 + self.substeps as f64 * self.dt_physics,
            positions: vec![0.0; n],
            velocities: vec![0.0; n],
            accelerations: vec![0.0; n],
            efforts,
            tracking_error: vec![0.0; n],
            saturated,
            contacts,
        };
        match self.settings.mode {
            Mode::Kinematic => {
                state.positions.clone_from(&end.positions);
                state.velocities.clone_from(&end.velocities);
                state.accelerations.clone_from(&end.accelerations);
                inverse_dynamics(
                    &self.chain,
                    &end.positions,
                    &end.velocities,
                    &end.accelerations,
                    &self.gravity,
                    &mut self.ws,
                    &mut state.efforts,
                );
                for (j, joint) in self.chain.joints.iter().enumerate() {
                    state.efforts[j] += drive_terms(joint, end.velocities[j], end.accelerations[j]);
                }
                state.saturated = self.saturation(&state.efforts);
            }
            Mode::Dynamic => {
                self.world.positions(&self.chain, &mut state.positions);
                self.world.velocities(&mut state.velocities);
                for (j, v0) in v_before.iter().enumerate() {
                    state.accelerations[j] = (state.velocities[j] - v0) / self.dt_physics;
                    state.tracking_error[j] = end.positions[j] - state.positions[j];
                }
            }
        }
        self.previous = end;
        self.state = state;
        Ok(&self.state)
    }

    /// The reference at fraction `s` of the period ([`Hermite`]; e.g. Bartels, Beatty,
    /// Barsky, *An Introduction to Splines for Use in Computer Graphics*, 1987, section 3.6).
    fn interpolate(&mut self, end: &JointSample, s: f64, dt: f64) {
        let basis = Hermite::at(s);
        let p = &self.previous;
        for j in 0..end.positions.len() {
            let (p0, v0, p1, v1) = (
                p.positions[j],
                p.velocities[j],
                end.positions[j],
                end.velocities[j],
            );
            self.reference.q[j] = basis.position(p0, v0, p1, v1, dt);
            self.reference.qd[j] = basis.velocity(p0, v0, p1, v1, dt);
            let a0 = p.accelerations[j];
            self.reference.qdd[j] = a0 + s * (end.accelerations[j] - a0);
        }
    }

    /// Servo gains at `q`: `Kp = M_jj ω²`, `Kd = 2 ζ M_jj ω` (a critically damped second
    /// order loop per joint when ζ = 1; e.g. Siciliano et al., *Robotics: Modelling,
    /// Planning and Control*, 2009, section 8.5.2, independent joint control), `M_jj` the
    /// mass-matrix diagonal ([`crate::dynamics::mass_diagonal`]) plus the armature.
    fn update_gains(&mut self, q: &[f64]) {
        let w = 2.0 * std::f64::consts::PI * self.settings.bandwidth_hz;
        mass_diagonal(&self.chain, q, &mut self.ws, &mut self.scratch);
        for (j, joint) in self.chain.joints.iter().enumerate() {
            let m = self.scratch[j] + joint.drive.armature;
            self.kp[j] = m * w * w;
            self.kd[j] = 2.0 * self.settings.damping_ratio * m * w;
        }
    }

    /// Computes and applies the drive efforts of one physics step (dynamic mode).
    fn drive(&mut self, efforts: &mut [f64], saturated: &mut [bool], v_before: &mut [f64]) {
        let Reference {
            q: qr,
            qd: qdr,
            qdd: qddr,
        } = &self.reference;
        let (q, tau_ff) = (&mut self.state_q, &mut self.tau_ff);
        self.world.positions(&self.chain, q);
        self.world.velocities(v_before);
        inverse_dynamics(
            &self.chain,
            qr,
            qdr,
            qddr,
            &self.gravity,
            &mut self.ws,
            tau_ff,
        );
        for (j, joint) in self.chain.joints.iter().enumerate() {
            // Viscous friction is rapier's implicit damping on the end-of-step velocity.
            let qd_end = qdr[j] + qddr[j] * self.dt_physics;
            let ff = tau_ff[j] + drive_terms(joint, qd_end, qddr[j]);
            let fb = self.kp[j] * (qr[j] - q[j]) + self.kd[j] * (qdr[j] - v_before[j]);
            let tau = ff + fb;
            let limit = joint.max_effort;
            efforts[j] = if tau.abs() > limit {
                saturated[j] = true;
                limit.copysign(tau)
            } else {
                tau
            };
        }
        self.world.apply_efforts(&self.chain, efforts);
    }
}

/// Armature, viscous and Coulomb friction efforts of a joint moving at `qd`, `qdd`: what the
/// drive must add to the rigid-body inverse dynamics. Coulomb friction is taken as
/// `coulomb · sign(qd)` for `|qd| > 1e-9`, zero at rest (where static friction needs no
/// drive effort).
pub(crate) fn drive_terms(joint: &crate::chain::BodyJoint, qd: f64, qdd: f64) -> f64 {
    let d = &joint.drive;
    let coulomb = if qd.abs() > 1e-9 {
        d.coulomb.copysign(qd)
    } else {
        0.0
    };
    d.armature * qdd + d.viscous * qd + coulomb
}
