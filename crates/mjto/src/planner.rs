//! The MJTO loop of seed 001, Figure 6.
//!
//! ```text
//! validate ─► GFDs at the initial RTOs ─► RTO selection (eq. 56)
//!               ▲                               │
//!               │                               ▼
//!   insert RTOs from their GFDs ◄── dense check ◄── rotary QPs (eq. 61) + M-path QP (eq. 62)
//!   (eq. 55, nearest free)        (every Δt sample: collision + lead/tilt)
//! ```
//!
//! Differences from the paper, each because a real cell needs it:
//! * the whole trajectory is checked at every controller sample Δt, not
//!   only at the RTOs, and the check includes the lead/tilt tolerance
//!   (Table 1) besides collisions: between RTOs the splines are free, and a
//!   cut outside its orientation tolerance is scrap;
//! * the trajectory is timed by a jerk-limited feed profile that starts and
//!   ends at rest ([`crate::timelaw`]); the QP bounds use the constant
//!   feedrate f of eq. 13-15 (an upper bound of ṡ), and the final plan is
//!   checked analytically (eq. 7) against every Table 2 limit on the dense
//!   samples; a violation is an error, never clamped;
//! * an inserted RTO is the free GFD candidate nearest (eq. 55) to the
//!   current trajectory at that CL point (the GFD is centred there, or on
//!   the nominal axis when none is free there), so the smooth solution is
//!   perturbed as little as possible;
//! * with `options.rto_constraint: box` (the default; issue 16 item 3) an
//!   RTO is a box of free, lead/tilt-feasible GFD samples around its pick
//!   and the QPs choose inside it (`planner/rto_box.rs`); `equality` is the
//!   paper's.
//! * with `options.orientation_corridor: allowance` (the default; issue 16
//!   item 3) the q5 QP also keeps q5 inside the lead/tilt allowance at every
//!   CL point between the RTOs (with the q4 just chosen), so it minimizes the
//!   jerk over the feasible orientations of the whole cut, not only at the
//!   RTOs; and with the time-optimal feed, a rotary QP that is infeasible at
//!   the requested feedrate with eq. 45's zero end slopes is solved with free
//!   end slopes (a closed cut that starts where the tool axis passes the
//!   vertical; the feed ramps then adapt to the joint jerk, item 2)
//!   (`planner/corridor.rs`). `none` is the paper's. Measured on saddle r/R
//!   0.4 at 10 m/min: 8.95 → 9.98 m/min peak, 1.111 → 0.966 s (BENCHMARKS.md).

use kerf_budget::Budget;
use kerf_executor::{check_executable, ExecutorConfig};
use std::time::Instant;

use kerf_bspline::{BSpline, KnotVector};

use crate::collision::{CollisionWorld, HeadModel};
use crate::mesh::MeshCache;
use crate::orientation::PathFrames;
use crate::plan::StageTimes;
use crate::request::ValidatedRequest;
use crate::rotary::JerkFactor;
use crate::timelaw::TimeLaw;
use crate::{CutPlan, CutRequest, LaserMachine, PlanError};

mod corridor;
mod dense_check;
mod feed;
mod iteration;
mod rto_box;
mod setup;

/// Degree of the B-splines: quintic, C³ (seed 001 section 2.1).
pub const DEGREE: usize = 5;

/// Relative tolerance of the lead/tilt check on the dense samples.
const ANGLE_TOLERANCE: f64 = 1e-9;

/// Trajectory samples (sampled or collision-checked) between two checks of the time budget.
pub const BUDGET_STRIDE: usize = 256;

/// Relative tolerance of the analytic limit check of the final plan.
const LIMIT_TOLERANCE: f64 = 1e-6;

/// A planner bound to one machine; keeps a cache of workpiece meshes and the collision world
/// of its last plan.
pub struct Planner {
    machine: LaserMachine,
    head: HeadModel,
    meshes: MeshCache,
    /// The last plan's collision world and what it was built from: the mesh (the cache's
    /// `Arc`, new when the file changes), the pose and the clearance. The BVH build is ~1.6 ms
    /// of a case-1 plan; a cell plans many cuts on one part.
    world: Option<WorldKey>,
}

/// A collision world and what it was built from.
struct WorldKey {
    mesh: std::sync::Arc<crate::mesh::MeshData>,
    pose: [u64; 7],
    clearance: u64,
    world: CollisionWorld,
}

/// The exact bits of a pose, for comparing keys.
fn pose_bits(p: &nalgebra::Isometry3<f64>) -> [u64; 7] {
    let t = p.translation.vector;
    let q = p.rotation.coords;
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(f64::to_bits)
}

/// One RTO while the loop runs.
#[derive(Debug, Clone, Copy)]
struct RtoState {
    cl_index: usize,
    u: f64,
    q: [f64; 3],
    inserted_at: usize,
    /// The box of free, feasible GFD samples around `q` the QPs may choose
    /// in (`options.rto_constraint: box`); `None`: equality at `q`.
    bounds: Option<crate::gfd::GridBox>,
}

/// The splines of one iteration and their dense samples.
struct Iterate {
    q4: BSpline,
    q5: BSpline,
    m: [BSpline; 3],
    q6: BSpline,
    /// w_i of the M-path QP (q6 at the CL points).
    w: Vec<f64>,
}

impl Iterate {
    /// `[q, q_u, q_uu, q_uuu]` of the six joint splines at `u`, in joint order (q1..q3 the
    /// M path, q4, q5, q6), derivatives above `nderiv` left 0: one basis evaluation for all six
    /// (they share the knot vector), the same arithmetic as six [`BSpline::eval`]s.
    ///
    /// # Errors
    /// [`PlanError::Solver`] for u outside [0, 1] or not finite.
    ///
    /// # Performance
    /// One basis evaluation instead of six: six separate evaluations were 16 % of a case-2
    /// plan's instructions (BENCHMARKS.md).
    fn joints(&self, u: f64, nderiv: usize) -> Result<[[f64; 4]; 6], PlanError> {
        let [m0, m1, m2] = &self.m;
        self.q4
            .eval_shared(
                [
                    m0.coeffs(),
                    m1.coeffs(),
                    m2.coeffs(),
                    self.q4.coeffs(),
                    self.q5.coeffs(),
                    self.q6.coeffs(),
                ],
                u,
                nderiv,
            )
            .map_err(bspline_error)
    }
}

/// Dense samples of a trajectory: time, u, and q, q̇, q̈, q⃛ per joint.
struct Samples {
    times: Vec<f64>,
    u: Vec<f64>,
    /// ṡ (m/s) of the feed law.
    sd: Vec<f64>,
    q: Vec<[f64; 6]>,
    qd: Vec<[f64; 6]>,
    qdd: Vec<[f64; 6]>,
    qddd: Vec<[f64; 6]>,
}

impl Planner {
    /// A planner for `machine`.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `machine`) if the head geometry
    /// of the URDF cannot be used for collision checking.
    pub fn new(machine: LaserMachine) -> Result<Self, PlanError> {
        let head = HeadModel::from_urdf(machine.robot().urdf())?;
        Ok(Self {
            machine,
            head,
            meshes: MeshCache::new(),
            world: None,
        })
    }

    /// The workpiece mesh `reference` names, from the planner's cache (loaded on first use):
    /// what a plan of a request naming it will use, without reading the file again.
    ///
    /// # Errors
    /// [`PlanError::Mesh`] for a mesh that does not load.
    pub fn mesh(
        &mut self,
        reference: &str,
    ) -> Result<std::sync::Arc<crate::mesh::MeshData>, PlanError> {
        self.meshes.get(reference)
    }

    /// The machine this planner plans for.
    pub fn machine(&self) -> &LaserMachine {
        &self.machine
    }

    /// Plans one cut request (seed 001 Figure 6).
    ///
    /// # Returns
    /// The collision-free trajectory sampled at Δt with its RTOs, metrics
    /// beside the QI baseline, and stage timings.
    ///
    /// # Errors
    /// Every [`PlanError`] variant; see their documentation. The last check is the trajectory
    /// executor's own validation of [`CutPlan::joint_trajectory`]
    /// (`kerf_executor::check_executable`, the one executability check of kerf):
    /// [`PlanError::NotExecutable`].
    ///
    /// # Performance
    /// Dominated by the dense collision checks (one query per sample per
    /// iteration) and the two QPs; see BENCHMARKS.md.
    pub fn plan(&mut self, request: &CutRequest) -> Result<CutPlan, PlanError> {
        self.plan_within(request, &Budget::unlimited())
    }

    /// [`Self::plan`] under a time budget and a cancellation token (issue 11, item 3).
    ///
    /// # Arguments
    /// * `request` — the cut request; its own `time_budget` (if any) tightens `budget`.
    /// * `budget` — checked between units of work: each GFD candidate's collision query, each
    ///   DP layer of the RTO selection, each QP (the q4 and q5 QPs together, on two threads;
    ///   each bounded to 200 interior-point iterations), every [`BUDGET_STRIDE`] trajectory
    ///   samples, each stage of the evaluation.
    ///
    /// # Errors
    /// As [`Self::plan`], and [`PlanError::Interrupted`] when the budget runs out (status
    /// TIMEOUT) or is cancelled.
    pub fn plan_within(
        &mut self,
        request: &CutRequest,
        budget: &Budget,
    ) -> Result<CutPlan, PlanError> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let v = request.validate()?;
        let budget = budget.tightened(v.time_budget);
        budget.check("validation")?;
        if v.points.len() < DEGREE + 1 {
            return Err(PlanError::invalid(
                "points",
                format!(
                    "{} CL points: the quintic B-spline needs at least {} (sample the path at the controller period)",
                    v.points.len(),
                    DEGREE + 1
                ),
            ));
        }
        let mesh = self.meshes.get(&request.mesh)?;
        budget.check("mesh loading")?;
        let (pose, clearance) = (
            pose_bits(&v.workpiece_pose),
            request.options.clearance.to_bits(),
        );
        let cached = self.world.as_ref().is_some_and(|k| {
            std::sync::Arc::ptr_eq(&k.mesh, &mesh) && k.pose == pose && k.clearance == clearance
        });
        if !cached {
            self.world = None;
            let world = CollisionWorld::new(
                self.head.clone(),
                &mesh,
                &v.workpiece_pose,
                request.options.clearance,
            )?;
            self.world = Some(WorldKey {
                mesh,
                pose,
                clearance,
                world,
            });
        }
        let world = &self
            .world
            .as_ref()
            .ok_or_else(|| internal("collision world missing"))?
            .world;
        world.reset_queries();
        let ctx = Context::new(&self.machine, request, &v, budget)?;
        times.setup = start.elapsed().as_secs_f64();

        let automatic = request.options.control_points == 0;
        let mut n_coeffs = match request.options.control_points {
            0 => automatic_control_points(v.sigma, v.points.len()),
            c => c,
        };
        let tolerance = request.options.cl_tolerance;
        let plan = loop {
            let t = Instant::now();
            let knots =
                KnotVector::for_parameters(DEGREE, n_coeffs, &v.u).map_err(bspline_error)?;
            ctx.budget.check("the jerk Hessian")?;
            let factor = JerkFactor::new(&knots)?;
            times.hessian += t.elapsed().as_secs_f64();
            let plan = ctx.run(world, &knots, &factor, times.clone(), start)?;
            let error = plan.metrics.max_cl_error;
            let more = (2 * n_coeffs)
                .min(MAX_AUTO_CONTROL_POINTS)
                .min(v.points.len());
            if error <= tolerance {
                break plan;
            }
            // The path error is the M-path fit's (eq. 62): more coefficients follow tighter
            // turns. Only the automatic choice is refined; a request's own count is kept.
            if !automatic || more <= n_coeffs {
                // The sample farthest from the path, for the message (the CL points between
                // samples can be farther; `error` is the largest of both).
                let time = plan
                    .positions
                    .iter()
                    .zip(&plan.path_positions)
                    .zip(&plan.times)
                    .map(|((q, &s), &t)| {
                        let c = crate::kinematics::forward(q).0;
                        ((c - ctx.frames.cl_point(s / v.sigma)).norm(), t)
                    })
                    .max_by(|a, b| a.0.total_cmp(&b.0))
                    .map_or(0.0, |w| w.1);
                return Err(PlanError::LimitViolation {
                    violations: vec![crate::error::LimitViolation {
                        joint: "tool tip".into(),
                        quantity: "distance from the CL path (m)",
                        value: error,
                        limit: tolerance,
                        time,
                    }],
                });
            }
            log::debug!(
                "CL error {error:.3e} m > {tolerance:.3e} m with {n_coeffs} coefficients: {more}"
            );
            times = plan.times_per_stage.clone();
            n_coeffs = more;
        };
        ctx.budget.check("the executability check")?;
        // Judged by what the executor runs: its own validation, from rest at the first point.
        let not_executable = |reason: String| PlanError::NotExecutable { reason };
        let model = self
            .machine
            .robot()
            .executor_limits()
            .map_err(|e| not_executable(e.to_string()))?;
        check_executable(&model, &ExecutorConfig::default(), &plan.joint_trajectory())
            .map_err(|e| not_executable(e.to_string()))?;
        // The whole plan, the executability check included (it is ~6 % of a case-1 plan; the
        // benches' planning times are this).
        let mut plan = plan;
        plan.times_per_stage.total = start.elapsed().as_secs_f64();
        Ok(plan)
    }
}

/// Most control coefficients the automatic choice refines to for the CL tolerance
/// (`options.cl_tolerance`).
pub const MAX_AUTO_CONTROL_POINTS: usize = 400;

/// Path length per control coefficient of the automatic choice (m).
pub const AUTO_SPACING: f64 = 0.01;

/// The automatic number of control coefficients: one per
/// [`AUTO_SPACING`] of path, at least 12 and at most 100 (and never more
/// than the CL points).
///
/// Seed 001 uses one coefficient per CL point (n + 1 = 628 in its case 2;
/// `options.control_points` = the CL count reproduces that). Its cost grows
/// with n² in the M-path problem while the CL error it buys is small: on
/// the committed cases 1 cm per coefficient reproduces the CL points
/// to 0.02-0.1 mm (BENCHMARKS.md).
pub fn automatic_control_points(sigma: f64, n_points: usize) -> usize {
    let n = (sigma / AUTO_SPACING).ceil();
    let n = if n.is_finite() {
        n.clamp(12.0, 100.0) as usize
    } else {
        12
    };
    n.min(n_points)
}

fn bspline_error(e: kerf_bspline::BsplineError) -> PlanError {
    PlanError::Solver {
        problem: "B-spline".into(),
        detail: e.to_string(),
    }
}

/// Everything one plan needs, borrowed from the request and the machine.
struct Context<'a> {
    machine: &'a LaserMachine,
    request: &'a CutRequest,
    v: &'a ValidatedRequest,
    frames: PathFrames,
    law: TimeLaw,
    /// Controller sample times 0, Δt, 2Δt, ..., T.
    sample_times: Vec<f64>,
    /// Nominal (q4, q5) per CL point by IKT (eq. 3) with q4 continuity.
    nominal: Vec<(f64, f64)>,
    /// The plan's time budget and cancellation.
    budget: Budget,
}

fn internal(detail: &str) -> PlanError {
    PlanError::Solver {
        problem: "planner".into(),
        detail: detail.into(),
    }
}
