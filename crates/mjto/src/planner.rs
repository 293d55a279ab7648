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
//!   current trajectory at that CL point (the GFD is centred there), so the
//!   smooth solution is perturbed as little as possible.

use std::time::Instant;

use kerf_bspline::{BSpline, KnotVector};
use nalgebra::Vector3;

use crate::baseline::{quaternion_interpolation, Rto};
use crate::collision::{CollisionWorld, HeadModel};
use crate::error::CollisionReport;
use crate::gfd::Gfd;
use crate::kinematics::{forward, rotary_ikt, tool_axis};
use crate::machine::JOINT_NAMES;
use crate::mesh::MeshCache;
use crate::metrics::{finite_differences, kinematic_metrics, limit_violations};
use crate::orientation::PathFrames;
use crate::plan::{Metrics, RtoRecord, StageTimes};
use crate::request::ValidatedRequest;
use crate::rotary::{JerkFactor, RotaryQp};
use crate::selection::select_rtos;
use crate::standoff::{solve_standoff, MPathProblem};
use crate::timelaw::{chain_rule, TimeLaw, MAX_SAMPLES};
use crate::{CutPlan, CutRequest, LaserMachine, PlanError};

/// Degree of the B-splines: quintic, C³ (seed 001 section 2.1).
pub const DEGREE: usize = 5;

/// Relative tolerance of the lead/tilt check on the dense samples.
const ANGLE_TOLERANCE: f64 = 1e-9;

/// Relative tolerance of the analytic limit check of the final plan.
const LIMIT_TOLERANCE: f64 = 1e-6;

/// A planner bound to one machine; keeps a cache of workpiece meshes.
pub struct Planner {
    machine: LaserMachine,
    head: HeadModel,
    meshes: MeshCache,
}

/// One RTO while the loop runs.
#[derive(Debug, Clone, Copy)]
struct RtoState {
    cl_index: usize,
    u: f64,
    q: [f64; 3],
    inserted_at: usize,
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

/// Dense samples of a trajectory: time, u, and q, q̇, q̈, q⃛ per joint.
struct Samples {
    times: Vec<f64>,
    u: Vec<f64>,
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
        })
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
    /// Every [`PlanError`] variant; see their documentation.
    ///
    /// # Performance
    /// Dominated by the dense collision checks (one query per sample per
    /// iteration) and the two QPs; see BENCHMARKS.md.
    pub fn plan(&mut self, request: &CutRequest) -> Result<CutPlan, PlanError> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let v = request.validate()?;
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
        let world = CollisionWorld::new(
            self.head.clone(),
            &mesh,
            &v.workpiece_pose,
            request.options.clearance,
        )?;
        let ctx = Context::new(&self.machine, request, &v)?;
        times.setup = start.elapsed().as_secs_f64();

        let t = Instant::now();
        let n_coeffs = match request.options.control_points {
            0 => automatic_control_points(v.sigma, v.points.len()),
            c => c,
        };
        let knots = KnotVector::for_parameters(DEGREE, n_coeffs, &v.u).map_err(bspline_error)?;
        let factor = JerkFactor::new(&knots)?;
        times.hessian = t.elapsed().as_secs_f64();

        ctx.run(&world, &knots, &factor, times, start)
    }
}

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
}

impl<'a> Context<'a> {
    fn new(
        machine: &'a LaserMachine,
        request: &'a CutRequest,
        v: &'a ValidatedRequest,
    ) -> Result<Self, PlanError> {
        let frames = PathFrames::new(&v.points, &v.axes, &v.u);
        let law = TimeLaw::new(
            v.sigma,
            request.feedrate,
            request.feed_acceleration,
            request.feed_jerk,
        )?;
        let sample_times = law.checked_sample_times(request.sample_period, MAX_SAMPLES)?;
        let limits = machine.limits();
        let standoff = request.options.reference_standoff;
        if standoff < limits[5].min || standoff > limits[5].max {
            return Err(PlanError::invalid(
                "options.reference_standoff",
                format!(
                    "{standoff} m is outside the q6 stroke [{}, {}] m",
                    limits[5].min, limits[5].max
                ),
            ));
        }
        let mut nominal = Vec::with_capacity(v.points.len());
        let mut previous = None;
        for (i, (c, o)) in v.points.iter().zip(&v.axes).enumerate() {
            let (q4, q5) = rotary_ikt(
                o,
                previous,
                (limits[3].min, limits[3].max),
                (limits[4].min, limits[4].max),
            )
            .map_err(|e| PlanError::Unreachable {
                index: i,
                reason: e.to_string(),
            })?;
            previous = Some(q4);
            // The M point of the nominal orientation at the reference
            // standoff must be inside the stroke of q1..q3 (eq. 3).
            let m = c - standoff * o;
            for (a, joint) in limits.iter().take(3).enumerate() {
                let x = m[a];
                if x < joint.min || x > joint.max {
                    let by = if x < joint.min {
                        joint.min - x
                    } else {
                        x - joint.max
                    };
                    return Err(PlanError::Unreachable {
                        index: i,
                        reason: format!(
                            "{} = {x:.4} m is outside [{}, {}] m by {by:.4} m (nominal axis, standoff {standoff} m)",
                            JOINT_NAMES[a], joint.min, joint.max
                        ),
                    });
                }
            }
            nominal.push((q4, q5));
        }
        Ok(Self {
            machine,
            request,
            v,
            frames,
            law,
            sample_times,
            nominal,
        })
    }

    fn limits(&self) -> &[crate::AxisLimits; 6] {
        self.machine.limits()
    }

    /// Initial RTO indices: the request's, or automatic ones.
    ///
    /// Automatic: the first and last CL point, plus a point wherever the
    /// path length since the previous RTO reaches `rto_spacing` or the
    /// nominal axis has turned by `rto_angle` since it.
    fn initial_rto_indices(&self) -> Vec<usize> {
        let o = &self.request.options;
        if !o.rto_indices.is_empty() {
            return o.rto_indices.clone();
        }
        let n = self.v.points.len();
        let mut idx = vec![0];
        for i in 1..n - 1 {
            let last = idx[idx.len() - 1];
            let ds = self.v.arc_length[i] - self.v.arc_length[last];
            let angle = self.v.axes[i].angle(&self.v.axes[last]);
            if ds >= o.rto_spacing || angle >= o.rto_angle {
                idx.push(i);
            }
        }
        // Do not crowd the end: a last automatic RTO closer than a quarter
        // spacing to the end is replaced by the end point.
        if idx.len() > 1 {
            let last = idx[idx.len() - 1];
            if self.v.arc_length[n - 1] - self.v.arc_length[last] < 0.25 * o.rto_spacing {
                idx.pop();
            }
        }
        idx.push(n - 1);
        idx
    }

    fn reference(&self, i: usize) -> [f64; 3] {
        let (q4, q5) = self.nominal[i];
        [q4, q5, self.request.options.reference_standoff]
    }

    fn build_gfd(&self, i: usize, reference: [f64; 3]) -> Gfd {
        let r = self.request;
        let frames = &self.frames;
        Gfd::build(
            i,
            self.v.u[i],
            &self.v.points[i],
            reference,
            &r.options.gfd,
            &r.options.weights,
            r.max_lead_angle,
            r.max_tilt_angle,
            &|o: &Vector3<f64>| frames.lead_tilt_at(i, o),
            self.limits(),
        )
    }

    fn run(
        &self,
        world: &CollisionWorld,
        knots: &KnotVector,
        factor: &JerkFactor,
        mut times: StageTimes,
        start: Instant,
    ) -> Result<CutPlan, PlanError> {
        let o = &self.request.options;
        // 1. GFDs of the initial RTOs and their selection (eq. 55-56).
        let t = Instant::now();
        let indices = self.initial_rto_indices();
        let mut gfds: Vec<Gfd> = indices
            .iter()
            .map(|&i| self.build_gfd(i, self.reference(i)))
            .collect();
        times.gfd += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let lengths: Vec<f64> = indices
            .windows(2)
            .map(|w| self.v.arc_length[w[1]] - self.v.arc_length[w[0]])
            .collect();
        let chosen = select_rtos(&mut gfds, &lengths, &o.weights, world)?;
        times.selection += t.elapsed().as_secs_f64();
        let mut rtos: Vec<RtoState> = gfds
            .iter()
            .zip(&chosen)
            .map(|(g, &p)| RtoState {
                cl_index: g.cl_index,
                u: g.u,
                q: g.candidates[p].q,
                inserted_at: 0,
            })
            .collect();

        // 2. The loop of Figure 6.
        let mut iteration = 0;
        let (iterate, samples) = loop {
            iteration += 1;
            let iterate = self.solve(knots, factor, &rtos, &mut times)?;
            let samples = self.sample(&iterate);
            let t = Instant::now();
            let violations = self.check(world, &samples);
            times.collision += t.elapsed().as_secs_f64();
            if violations.is_empty() {
                break (iterate, samples);
            }
            if iteration >= o.max_iterations {
                return Err(PlanError::Collision {
                    iterations: iteration,
                    collisions: violations,
                });
            }
            let t = Instant::now();
            let added = self.insert_rtos(world, &iterate, &violations, &mut rtos, iteration)?;
            times.gfd += t.elapsed().as_secs_f64();
            if added == 0 {
                let mut collisions = violations;
                for c in &mut collisions {
                    c.reason
                        .push_str("; no CL point left to insert an RTO next to it");
                }
                return Err(PlanError::Collision {
                    iterations: iteration,
                    collisions,
                });
            }
        };

        // 3. Limits (analytic, eq. 7), metrics, QI baseline.
        let t = Instant::now();
        let limits = self.limits();
        let violations = limit_violations(
            &samples.times,
            &samples.q,
            &samples.qd,
            &samples.qdd,
            &samples.qddd,
            limits,
            LIMIT_TOLERANCE,
        );
        if !violations.is_empty() {
            return Err(PlanError::LimitViolation { violations });
        }
        let mut metrics = kinematic_metrics(
            &samples.times,
            &samples.q,
            &samples.qd,
            &samples.qdd,
            &samples.qddd,
            limits,
        );
        self.fill_geometry(&mut metrics, &samples.u, &samples.q, None);
        metrics.max_cl_error = metrics.max_cl_error.max(self.cl_error_at_points(&iterate));

        let qi_rtos: Vec<Rto> = rtos
            .iter()
            .map(|r| Rto {
                u: r.u,
                q4: r.q[0],
                q5: r.q[1],
                q6: r.q[2],
            })
            .collect();
        let dt = self.request.sample_period;
        let (qi_times, qi_q) =
            quaternion_interpolation(&self.frames, &qi_rtos, &self.law, self.v.sigma, dt, limits)?;
        let (qi_v, qi_a, qi_j) = finite_differences(&qi_times, &qi_q);
        let mut qi_metrics = kinematic_metrics(&qi_times, &qi_q, &qi_v, &qi_a, &qi_j, limits);
        let qi_u: Vec<f64> = qi_times.iter().map(|&t| self.u_at(t)).collect();
        self.fill_geometry(&mut qi_metrics, &qi_u, &qi_q, Some(world));
        times.evaluation += t.elapsed().as_secs_f64();
        times.total = start.elapsed().as_secs_f64();

        Ok(CutPlan {
            request_id: self.request.request_id.clone(),
            joint_names: JOINT_NAMES.iter().map(|s| s.to_string()).collect(),
            times: samples.times,
            positions: samples.q,
            velocities: samples.qd,
            accelerations: samples.qdd,
            rtos: rtos
                .iter()
                .map(|r| RtoRecord {
                    u: r.u,
                    cl_index: r.cl_index,
                    q4: r.q[0],
                    q5: r.q[1],
                    q6: r.q[2],
                    inserted_at_iteration: r.inserted_at,
                })
                .collect(),
            metrics,
            qi_metrics,
            iterations: iteration,
            collision_queries: world.queries(),
            control_points: knots.n_coeffs(),
            path_length: self.v.sigma,
            times_per_stage: times,
        })
    }

    /// Both QPs for the current RTOs (eq. 61, then eq. 62 with the
    /// optimized orientation).
    fn solve(
        &self,
        knots: &KnotVector,
        factor: &JerkFactor,
        rtos: &[RtoState],
        times: &mut StageTimes,
    ) -> Result<Iterate, PlanError> {
        let limits = self.limits();
        let t = Instant::now();
        let mut rotary = Vec::with_capacity(2);
        for (k, name) in [(3usize, "q4"), (4usize, "q5")] {
            let via: Vec<(f64, f64)> = rtos.iter().map(|r| (r.u, r.q[k - 3])).collect();
            let problem = RotaryQp {
                axis_name: name,
                knots,
                factor,
                limits: limits[k],
                sigma: self.v.sigma,
                feedrate: self.request.feedrate,
                boundary: [0.0; 4],
                via: &via,
            };
            let (coeffs, _) = problem.solve()?;
            rotary.push(BSpline::new(knots.clone(), coeffs).map_err(bspline_error)?);
        }
        times.rotary_qp += t.elapsed().as_secs_f64();
        let q5 = rotary
            .pop()
            .ok_or_else(|| internal("rotary QP result missing"))?;
        let q4 = rotary
            .pop()
            .ok_or_else(|| internal("rotary QP result missing"))?;

        let t = Instant::now();
        let axes: Vec<Vector3<f64>> = self
            .v
            .u
            .iter()
            .map(|&u| tool_axis(q4.eval(u)[0], q5.eval(u)[0]))
            .collect();
        let via: Vec<(usize, f64)> = rtos.iter().map(|r| (r.cl_index, r.q[2])).collect();
        let problem = MPathProblem {
            knots,
            factor,
            params: &self.v.u,
            points: &self.v.points,
            axes: &axes,
            stroke: (limits[5].min, limits[5].max),
            via: &via,
            reference: self.request.options.reference_standoff,
        };
        let sol = solve_standoff(&problem)?;
        let [px, py, pz] = sol.control_points;
        let m = [
            BSpline::new(knots.clone(), px).map_err(bspline_error)?,
            BSpline::new(knots.clone(), py).map_err(bspline_error)?,
            BSpline::new(knots.clone(), pz).map_err(bspline_error)?,
        ];
        let q6 = BSpline::new(knots.clone(), sol.standoff_coeffs).map_err(bspline_error)?;
        times.mpath_qp += t.elapsed().as_secs_f64();
        Ok(Iterate {
            q4,
            q5,
            m,
            q6,
            w: sol.w,
        })
    }

    /// u at time t of the feed profile (eq. 1).
    fn u_at(&self, t: f64) -> f64 {
        (self.law.eval(t)[0] / self.v.sigma).clamp(0.0, 1.0)
    }

    /// Samples every Δt: q1..q3 from the M path (eq. 47: M = (q1, q2, q3)),
    /// q4, q5 from eq. 5, q6 from its spline; derivatives by eq. 7.
    fn sample(&self, it: &Iterate) -> Samples {
        let times = self.sample_times.clone();
        let n = times.len();
        let mut s = Samples {
            u: Vec::with_capacity(n),
            q: Vec::with_capacity(n),
            qd: Vec::with_capacity(n),
            qdd: Vec::with_capacity(n),
            qddd: Vec::with_capacity(n),
            times,
        };
        let splines = [&it.m[0], &it.m[1], &it.m[2], &it.q4, &it.q5, &it.q6];
        for &t in &s.times {
            let law = self.law.eval(t);
            let u = (law[0] / self.v.sigma).clamp(0.0, 1.0);
            let mut row = [[0.0; 6]; 4];
            for (j, spline) in splines.iter().enumerate() {
                let d = chain_rule(spline.eval(u), law, self.v.sigma);
                for (r, value) in d.iter().enumerate() {
                    row[r][j] = *value;
                }
            }
            s.u.push(u);
            s.q.push(row[0]);
            s.qd.push(row[1]);
            s.qdd.push(row[2]);
            s.qddd.push(row[3]);
        }
        s
    }

    /// Collision and lead/tilt check of every sample, on two threads.
    fn check(&self, world: &CollisionWorld, s: &Samples) -> Vec<CollisionReport> {
        let n = s.times.len();
        let half = n / 2;
        let check_range = |range: std::ops::Range<usize>| -> Vec<CollisionReport> {
            range
                .filter_map(|k| self.check_sample(world, s.times[k], s.u[k], &s.q[k]))
                .collect()
        };
        let (mut first, second) = std::thread::scope(|scope| {
            let handle = scope.spawn(|| check_range(half..n));
            let first = check_range(0..half);
            // A panic in the worker is a bug; report it as a violation of
            // every sample rather than unwinding through the planner.
            let second = handle.join().unwrap_or_else(|_| {
                vec![CollisionReport {
                    u: 0.0,
                    time: 0.0,
                    cl_index: 0,
                    links: Vec::new(),
                    reason: "internal error: the collision-check thread panicked".into(),
                }]
            });
            (first, second)
        });
        first.extend(second);
        first
    }

    fn check_sample(
        &self,
        world: &CollisionWorld,
        time: f64,
        u: f64,
        q: &[f64; 6],
    ) -> Option<CollisionReport> {
        let links: Vec<String> = world
            .colliding_links(q)
            .into_iter()
            .map(|l| l.to_string())
            .collect();
        let axis = tool_axis(q[3], q[4]);
        let (lead, tilt) = self.frames.lead_tilt(u, &axis);
        let r = self.request;
        let mut reasons = Vec::new();
        if !links.is_empty() {
            reasons.push(format!(
                "head links {} touch the workpiece",
                links.join(", ")
            ));
        }
        if lead.abs() > r.max_lead_angle * (1.0 + ANGLE_TOLERANCE) {
            reasons.push(format!(
                "lead angle {:.2}° exceeds {:.2}°",
                lead.to_degrees(),
                r.max_lead_angle.to_degrees()
            ));
        }
        if tilt.abs() > r.max_tilt_angle * (1.0 + ANGLE_TOLERANCE) {
            reasons.push(format!(
                "tilt angle {:.2}° exceeds {:.2}°",
                tilt.to_degrees(),
                r.max_tilt_angle.to_degrees()
            ));
        }
        if reasons.is_empty() {
            return None;
        }
        Some(CollisionReport {
            u,
            time,
            cl_index: self.frames.nearest_index(u),
            links,
            reason: reasons.join("; "),
        })
    }

    /// Inserts one RTO per run of consecutive violating samples, at the CL
    /// point nearest to the run's worst (middle) sample that is not yet an
    /// RTO; its value is the free GFD candidate nearest (eq. 55) to the
    /// current trajectory there. Returns how many were inserted.
    fn insert_rtos(
        &self,
        world: &CollisionWorld,
        it: &Iterate,
        violations: &[CollisionReport],
        rtos: &mut Vec<RtoState>,
        iteration: usize,
    ) -> Result<usize, PlanError> {
        let mut runs: Vec<(usize, usize)> = Vec::new();
        let mut start = 0;
        for k in 1..=violations.len() {
            let split =
                k == violations.len() || violations[k].cl_index > violations[k - 1].cl_index + 1;
            if split {
                runs.push((start, k - 1));
                start = k;
            }
        }
        let mut added = 0;
        for (a, b) in runs {
            let mid = &violations[(a + b) / 2];
            let Some(i) = self.free_cl_index(
                mid.cl_index,
                violations[a].cl_index,
                violations[b].cl_index,
                rtos,
            ) else {
                continue;
            };
            let u = self.v.u[i];
            let target = [it.q4.eval(u)[0], it.q5.eval(u)[0], it.w[i]];
            // The grid is centred on the trajectory's orientation and spans
            // the usual q6 range around the preferred standoff (a q6 at a
            // stroke end would leave no q6 span); the candidate taken is the
            // free one nearest (eq. 55) to the trajectory's (q4, q5, q6).
            let centre = [
                target[0],
                target[1],
                self.request.options.reference_standoff,
            ];
            let mut gfd = self.build_gfd(i, centre);
            let weights = &self.request.options.weights;
            let Some(p) = gfd.nearest_free(target, weights, world) else {
                return Err(PlanError::NoFeasibleOrientation {
                    index: i,
                    u,
                    reason: format!(
                        "inserting an RTO against: {}; none of the {} GFD candidates around the trajectory is free ({} outside the lead/tilt limits or stroke)",
                        mid.reason,
                        gfd.total,
                        gfd.total - gfd.candidates.len()
                    ),
                });
            };
            let pos = rtos.partition_point(|r| r.cl_index < i);
            rtos.insert(
                pos,
                RtoState {
                    cl_index: i,
                    u,
                    q: gfd.candidates[p].q,
                    inserted_at: iteration,
                },
            );
            added += 1;
        }
        Ok(added)
    }

    /// The CL index in [lo, hi] (widened by one on each side) nearest to
    /// `preferred` that is not an RTO yet.
    fn free_cl_index(
        &self,
        preferred: usize,
        lo: usize,
        hi: usize,
        rtos: &[RtoState],
    ) -> Option<usize> {
        let n = self.v.points.len();
        let lo = lo.saturating_sub(1);
        let hi = (hi + 1).min(n - 1);
        let taken = |i: usize| rtos.iter().any(|r| r.cl_index == i);
        (0..=(hi - lo))
            .flat_map(|d| [preferred.checked_sub(d), preferred.checked_add(d)])
            .flatten()
            .find(|&i| i >= lo && i <= hi && !taken(i))
    }

    /// Largest distance between FK (eq. 2) of the splines at the CL
    /// parameters u_i and the CL points C_i.
    fn cl_error_at_points(&self, it: &Iterate) -> f64 {
        self.v
            .u
            .iter()
            .zip(&self.v.points)
            .map(|(&u, c)| {
                let q = [
                    it.m[0].eval(u)[0],
                    it.m[1].eval(u)[0],
                    it.m[2].eval(u)[0],
                    it.q4.eval(u)[0],
                    it.q5.eval(u)[0],
                    it.q6.eval(u)[0],
                ];
                (forward(&q).0 - c).norm()
            })
            .fold(0.0, f64::max)
    }

    /// CL error against the reference path, lead/tilt extremes and (when a
    /// world is given) the colliding samples of a sampled trajectory.
    fn fill_geometry(
        &self,
        m: &mut Metrics,
        u: &[f64],
        q: &[[f64; 6]],
        world: Option<&CollisionWorld>,
    ) {
        for (&u, q) in u.iter().zip(q) {
            let (c, o) = forward(q);
            m.max_cl_error = m.max_cl_error.max((c - self.frames.cl_point(u)).norm());
            let (lead, tilt) = self.frames.lead_tilt(u, &o);
            m.max_lead_angle = m.max_lead_angle.max(lead.abs());
            m.max_tilt_angle = m.max_tilt_angle.max(tilt.abs());
        }
        if let Some(w) = world {
            // Two threads, as the dense check of the plan itself.
            let half = q.len() / 2;
            let count = |part: &[[f64; 6]]| part.iter().filter(|q| !w.is_free(q)).count();
            m.colliding_samples = std::thread::scope(|scope| {
                let second = scope.spawn(|| count(&q[half..]));
                let first = count(&q[..half]);
                // A panicking check thread counts every sample of its half.
                first + second.join().unwrap_or(q.len() - half)
            });
        }
    }
}

fn internal(detail: &str) -> PlanError {
    PlanError::Solver {
        problem: "planner".into(),
        detail: detail.into(),
    }
}
