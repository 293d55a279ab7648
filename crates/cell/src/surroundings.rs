//! [`CellSurroundings`]: a robot's collision shapes against a cell's objects by exact signed
//! distance, as the `kerf_approach::Surroundings` of a planner's approach and retract
//! (issue 27, item 1).
//!
//! The shapes, objects and contact allowances are those of the cell file the simulated cell
//! reads ([`crate::config`]), so a plan is certified against the same world the executor's
//! `hardware: sim` checks. Without a physics step: the bodies are placed by the chain's
//! forward kinematics ([`Chain::body_poses`]).
//!
//! | `process` | pairs measured |
//! |---|---|
//! | `false` | every robot shape against every object (a cutter in its stock is a collision) |
//! | `true` | the same, less the pairs of the cell file's allowances: the tool's working contact with the workpiece (engagement, standoff) |
//!
//! The tool axis ([`Surroundings::back_off`]) is the robot's own kinematics ([`ToolAxis`]; the
//! IRB 6660's in [`crate::milling_tool`]).

use std::path::Path;
use std::sync::Arc;

use kerf_approach::{ApproachError, Clearance, JointLimit, Surroundings};
use kerf_robot::RobotModel;
use nalgebra::Isometry3;
use parry3d_f64::math::Pose;
use parry3d_f64::query;

use crate::chain::Chain;
use crate::config::CellFile;
use crate::geometry::{to_pose, RobotShape, SceneObject};
use crate::motion::aabb_gap;
use crate::{Cell, CellError, CellSettings};

/// Distances are exact up to this far (m); a robot farther from every object is reported this
/// far (a lower bound: the certification stays sound). 0.25 m is more than the approach
/// clearance plus the farthest an IRB 6660 shape point moves in one 4 ms control period at
/// the velocity limits (`Σ_j L_j v_j · 0.004 s` ≈ 0.12 m, [`crate::lipschitz`]), so the
/// cut-off never shortens a conservative-advancement step.
pub const EXACT_UP_TO: f64 = 0.25;

/// How the robot's tool backs off along its axis (the robot's kinematics).
pub trait ToolAxis: Send + Sync {
    /// The configuration with the tool `distance` m further back along its axis, away from
    /// the part, same orientation ([`Surroundings::back_off`]).
    ///
    /// # Errors
    /// An [`ApproachError`] naming why: no inverse kinematics, a joint limit.
    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError>;
}

/// One robot shape against one object.
#[derive(Debug, Clone, Copy)]
struct Pair {
    shape: usize,
    object: usize,
    /// A pair of the cell file's allowances: left out with `process`.
    working: bool,
}

/// The robot's shapes and the cell's objects (module documentation). Cheap to clone (the
/// shapes are shared).
#[derive(Clone)]
pub struct CellSurroundings {
    chain: Chain,
    shapes: Vec<RobotShape>,
    objects: Vec<SceneObject>,
    pairs: Vec<Pair>,
    lipschitz: Vec<f64>,
    tool: Arc<dyn ToolAxis>,
    source: String,
}

impl std::fmt::Debug for CellSurroundings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CellSurroundings")
            .field("source", &self.source)
            .field(
                "shapes",
                &self.shapes.iter().map(|s| &s.name).collect::<Vec<_>>(),
            )
            .field("objects", &self.object_names())
            .field("lipschitz", &self.lipschitz)
            .finish()
    }
}

impl CellSurroundings {
    /// The surroundings of `model` in `cell`: its URDF collision shapes (the base's only with
    /// the cell's `contact.check_base`) and tool shapes against the cell's objects, the tool
    /// axis by `tool`.
    ///
    /// # Errors
    /// Every [`CellError`] of loading the cell ([`Cell::new`]: another robot, unknown links,
    /// a missing mesh, the mass sidecar, …), and of [`crate::lipschitz::lipschitz`].
    ///
    /// # Performance
    /// Builds the cell once (its rapier world is dropped, never stepped): milliseconds. Build
    /// it at start-up and clone it per request.
    pub fn new(
        model: RobotModel,
        cell: &CellFile,
        tool: Arc<dyn ToolAxis>,
    ) -> Result<Self, CellError> {
        let built = Cell::new(model, cell, CellSettings::default())?;
        let shapes = built.checker().shapes().to_vec();
        let objects = built.checker().objects().to_vec();
        let chain = built.chain().clone();
        let working = |s: &RobotShape, o: &SceneObject| {
            cell.contact
                .allowances
                .iter()
                .any(|a| a.shape == s.name && a.object == o.name)
        };
        let mut pairs = Vec::with_capacity(shapes.len() * objects.len());
        for (si, s) in shapes.iter().enumerate() {
            for (oi, o) in objects.iter().enumerate() {
                pairs.push(Pair {
                    shape: si,
                    object: oi,
                    working: working(s, o),
                });
            }
        }
        let lipschitz = crate::lipschitz::lipschitz(&chain, &shapes)?;
        Ok(Self {
            chain,
            shapes,
            objects,
            pairs,
            lipschitz,
            tool,
            source: cell.source.display().to_string(),
        })
    }

    /// [`CellSurroundings::new`] with the cell file read from `path`.
    ///
    /// # Errors
    /// [`CellError::FileRead`], [`CellError::Parse`] and those of [`CellSurroundings::new`].
    pub fn from_file(
        model: RobotModel,
        path: &Path,
        tool: Arc<dyn ToolAxis>,
    ) -> Result<Self, CellError> {
        Self::new(model, &CellFile::from_file(path)?, tool)
    }

    /// The cell file it was built from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The robot's bodies (forward kinematics).
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The robot shapes measured.
    pub fn shapes(&self) -> &[RobotShape] {
        &self.shapes
    }

    /// The names of the cell's objects.
    pub fn object_names(&self) -> Vec<&str> {
        self.objects.iter().map(|o| o.name.as_str()).collect()
    }

    /// The exact signed distance (m) from the robot at `q` to the nearest object, and its
    /// name: `<object> (<shape> on <link>)`, e.g. `stock (cutter on tool0)`. Negative inside
    /// an object (parry's penetration depth). Pairs whose bounding boxes are at least as far
    /// as the nearest pair found (or [`EXACT_UP_TO`]) are skipped: their box gap is a lower
    /// bound of their distance. Beyond [`EXACT_UP_TO`], that distance (a lower bound).
    ///
    /// NaN (refused by `kerf_approach`) for a `q` of the wrong length or not finite, and for
    /// a pair parry cannot measure (every pair was probed when the cell was built).
    pub fn distance(&self, q: &[f64], process: bool) -> Clearance {
        let n = self.chain.joints.len();
        if q.len() != n || q.iter().any(|v| !v.is_finite()) {
            return Clearance::new(
                f64::NAN,
                format!("no distance: q {q:?} is not {n} finite joint positions"),
            );
        }
        let mut bodies: Vec<Isometry3<f64>> = Vec::with_capacity(n);
        self.chain.body_poses(q, &mut bodies);
        let poses: Vec<Pose> = self
            .shapes
            .iter()
            .map(|s| match s.body {
                Some(b) => to_pose(&bodies[b]) * s.local,
                None => s.local,
            })
            .collect();
        let boxes: Vec<_> = self
            .shapes
            .iter()
            .zip(&poses)
            .map(|(s, p)| s.shape.compute_aabb(p))
            .collect();
        let mut best = EXACT_UP_TO;
        let mut nearest: Option<Pair> = None;
        for pair in self.pairs.iter().filter(|p| !(process && p.working)) {
            let o = &self.objects[pair.object];
            if aabb_gap(&boxes[pair.shape], &o.aabb) >= best {
                continue;
            }
            let s = &self.shapes[pair.shape];
            let Some(d) = signed_distance(&poses[pair.shape], s, o) else {
                return Clearance::new(
                    f64::NAN,
                    format!("parry cannot measure {} against {}", s.name, o.name),
                );
            };
            if d < best {
                best = d;
                nearest = Some(*pair);
            }
        }
        match nearest {
            Some(p) => {
                let s = &self.shapes[p.shape];
                Clearance::new(
                    best,
                    format!("{} ({} on {})", self.objects[p.object].name, s.name, s.link),
                )
            }
            None => Clearance::new(
                EXACT_UP_TO,
                format!(
                    "the cell's objects ({}; none within {EXACT_UP_TO} m)",
                    self.object_names().join(", ")
                ),
            ),
        }
    }
}

/// parry's distance of a robot shape at `pose` to an object; where they intersect (parry's
/// distance 0), minus the penetration depth of parry's contact query. `None` when parry
/// cannot measure the pair.
fn signed_distance(pose: &Pose, s: &RobotShape, o: &SceneObject) -> Option<f64> {
    let d = query::distance(pose, s.shape.as_ref(), &o.pose, o.shape.as_ref())
        .ok()?
        .distance;
    if d > 0.0 {
        return Some(d);
    }
    match query::contact(pose, s.shape.as_ref(), &o.pose, o.shape.as_ref(), 0.0) {
        Ok(Some(c)) => Some(c.dist.min(0.0)),
        // Touching without a contact point: distance 0.
        Ok(None) => Some(0.0),
        Err(_) => None,
    }
}

impl Surroundings for CellSurroundings {
    fn clearance(&self, q: &[f64], process: bool) -> Clearance {
        self.distance(q, process)
    }

    /// [`crate::lipschitz::lipschitz`] of the shapes measured.
    fn lipschitz(&self) -> Vec<f64> {
        self.lipschitz.clone()
    }

    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError> {
        self.tool.back_off(q, distance)
    }
}

/// The approach limits of `model`'s joints (model order): the URDF position and velocity
/// limits, the limits file's acceleration and jerk.
///
/// # Errors
/// [`CellError::InvalidValue`] naming the joint whose acceleration or jerk limit the limits
/// file does not give.
pub fn approach_limits(model: &RobotModel) -> Result<Vec<JointLimit>, CellError> {
    let missing = |joint: &str, what: &str| CellError::InvalidValue {
        field: format!("joint '{joint}' {what} limit"),
        value: f64::NAN,
        requirement: "the joint limits file must give it: approaches are jerk-limited",
    };
    model
        .joints()
        .iter()
        .map(|j| {
            Ok(JointLimit {
                name: j.name.clone(),
                min_position: j.min_position,
                max_position: j.max_position,
                max_velocity: j.max_velocity,
                max_acceleration: j
                    .max_acceleration
                    .ok_or_else(|| missing(&j.name, "acceleration"))?,
                max_jerk: j.max_jerk.ok_or_else(|| missing(&j.name, "jerk"))?,
            })
        })
        .collect()
}
