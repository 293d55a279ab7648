//! The loop of seed 001 Figure 6: RTO selection, both QPs, the dense
//! samples and the check of the final plan against every limit.

use std::time::Instant;

use kerf_bspline::{BSpline, KnotVector};
use nalgebra::Vector3;

use super::{bspline_error, Context, Iterate, RtoState, Samples};
use crate::baseline::{quaternion_interpolation_along, Rto};
use crate::collision::CollisionWorld;
use crate::gfd::Gfd;
use crate::kinematics::tool_axis;
use crate::machine::JOINT_NAMES;
use crate::metrics::{finite_differences, kinematic_metrics};
use crate::plan::{RtoRecord, StageTimes};
use crate::rotary::{JerkFactor, RotaryQp};
use crate::selection::select_rtos;
use crate::standoff::{solve_standoff, MPathProblem};
use crate::timelaw::chain_rule;
use crate::{CutPlan, PlanError};

impl Context<'_> {
    pub(super) fn run(
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
        let mut gfds: Vec<Gfd> = Vec::with_capacity(indices.len());
        for &i in &indices {
            self.budget.check("GFD construction")?;
            gfds.push(self.build_gfd(i, self.reference(i)));
        }
        times.gfd += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let lengths: Vec<f64> = indices
            .windows(2)
            .map(|w| self.v.arc_length[w[1]] - self.v.arc_length[w[0]])
            .collect();
        let chosen = select_rtos(&mut gfds, &lengths, &o.weights, world, &self.budget)?;
        times.selection += t.elapsed().as_secs_f64();
        let mut rtos: Vec<RtoState> = gfds
            .iter()
            .zip(&chosen)
            .map(|(g, &p)| RtoState {
                cl_index: g.cl_index,
                u: g.u,
                q: g.candidates[p].q,
                inserted_at: 0,
                bounds: None,
            })
            .collect();
        let t = Instant::now();
        self.initial_boxes(&mut gfds, &chosen, &mut rtos, world)?;
        times.selection += t.elapsed().as_secs_f64();

        // 2. The loop of Figure 6.
        let mut iteration = 0;
        let (iterate, samples, feed) = loop {
            iteration += 1;
            let iterate = self.solve(knots, factor, &rtos, &mut times)?;
            // The geometry first, on the constant feed's samples (u every f·Δt at most);
            // the time law only for a collision-free iterate, then its own samples again.
            let constant = self.constant_samples(&iterate, &mut times)?;
            let t = Instant::now();
            let mut violations = self.check(world, &constant)?;
            times.collision += t.elapsed().as_secs_f64();
            if violations.is_empty() {
                let timed = self.timed(&iterate, constant, &mut times)?;
                if timed.resampled {
                    let t = Instant::now();
                    violations = self.check(world, &timed.samples)?;
                    times.collision += t.elapsed().as_secs_f64();
                }
                if violations.is_empty() {
                    break (iterate, timed.samples, timed.feed);
                }
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

        // 3. Limits (analytic, eq. 7, and the executor's segments between the samples),
        // metrics, QI baseline.
        let t = Instant::now();
        self.budget.check("the limit check")?;
        let limits = self.limits();
        let violations = self.violations(&samples);
        if !violations.is_empty() {
            return Err(PlanError::LimitViolation { violations });
        }
        self.budget.check("the metrics")?;
        let mut metrics = kinematic_metrics(
            &samples.times,
            &samples.q,
            &samples.qd,
            &samples.qdd,
            &samples.qddd,
            limits,
        );
        self.fill_geometry(&mut metrics, &samples.u, &samples.q, None)?;
        metrics.max_cl_error = metrics.max_cl_error.max(self.cl_error_at_points(&iterate)?);

        let qi_rtos: Vec<Rto> = rtos
            .iter()
            .map(|r| Rto {
                u: r.u,
                q4: r.q[0],
                q5: r.q[1],
                q6: r.q[2],
            })
            .collect();
        self.budget.check("the QI baseline")?;
        // QI on the plan's own time law s(t): the same samples, the same feed.
        let qi_path: Vec<f64> = samples.u.iter().map(|u| u * self.v.sigma).collect();
        let qi_q = quaternion_interpolation_along(
            &self.frames,
            &qi_rtos,
            &qi_path,
            self.v.sigma,
            limits,
            &self.budget,
        )?;
        let qi_times = samples.times.clone();
        self.budget.check("the QI baseline")?;
        let (qi_v, qi_a, qi_j) = finite_differences(&qi_times, &qi_q);
        let mut qi_metrics = kinematic_metrics(&qi_times, &qi_q, &qi_v, &qi_a, &qi_j, limits);
        let qi_u = samples.u.clone();
        self.budget.check("the QI baseline's geometry")?;
        self.fill_geometry(&mut qi_metrics, &qi_u, &qi_q, Some(world))?;
        times.evaluation += t.elapsed().as_secs_f64();
        times.total = start.elapsed().as_secs_f64();

        Ok(CutPlan {
            request_id: self.request.request_id.clone(),
            joint_names: JOINT_NAMES.iter().map(|s| s.to_string()).collect(),
            path_positions: samples.u.iter().map(|u| u * self.v.sigma).collect(),
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
            feed,
            times_per_stage: times,
        })
    }

    /// Both QPs for the current RTOs (eq. 61, then eq. 62 with the
    /// optimized orientation). An RTO with a box (kerf,
    /// `options.rto_constraint: box`) gives each QP the interval
    /// `lo ≤ q(ũ_i) ≤ hi` of its axis instead of the equality of eq. 57-60
    /// and 62-64.
    pub(super) fn solve(
        &self,
        knots: &KnotVector,
        factor: &JerkFactor,
        rtos: &[RtoState],
        times: &mut StageTimes,
    ) -> Result<Iterate, PlanError> {
        let limits = self.limits();
        let t = Instant::now();
        self.budget.check("the rotary-axis QPs")?;
        // Per axis: the RTO equalities (u, q) and boxes (u, lo, hi).
        type Vias = (Vec<(f64, f64)>, Vec<(f64, f64, f64)>);
        let vias: [Vias; 2] = [0, 1].map(|a| {
            let via = rtos
                .iter()
                .filter(|r| r.bounds.is_none())
                .map(|r| (r.u, r.q[a]))
                .collect();
            let via_box = rtos
                .iter()
                .filter_map(|r| r.bounds.map(|b| (r.u, b.lo[a], b.hi[a])))
                .collect();
            (via, via_box)
        });
        let problems = [(3usize, "q4"), (4usize, "q5")].map(|(k, name)| RotaryQp {
            axis_name: name,
            knots,
            factor,
            limits: limits[k],
            sigma: self.v.sigma,
            feedrate: self.request.feedrate,
            boundary: [0.0; 4],
            via: &vias[k - 3].0,
            via_box: &vias[k - 3].1,
            corridor: &[],
            free_end_slopes: false,
        });
        // q4 and q5's first solves side by side; q5's corridor then follows the q4 chosen
        // (kerf, planner/corridor.rs).
        let first = Self::rotary_first(self.corridor_on(), self.request.options.feed_law);
        let [c4, c5] = super::feed::rotary_pair(&problems, &first)?;
        let q4 = BSpline::new(knots.clone(), c4).map_err(bspline_error)?;
        self.budget.check("the rotary-axis QPs")?;
        let c5 = self.q5_in_allowance(&problems[1], c5, &q4, rtos)?;
        let q5 = BSpline::new(knots.clone(), c5).map_err(bspline_error)?;
        times.rotary_qp += t.elapsed().as_secs_f64();

        let t = Instant::now();
        let axes: Vec<Vector3<f64>> = self
            .v
            .u
            .iter()
            .map(|&u| {
                let [a, b] = q4
                    .eval_shared([q4.coeffs(), q5.coeffs()], u, 0)
                    .map_err(bspline_error)?;
                Ok(tool_axis(a[0], b[0]))
            })
            .collect::<Result<_, PlanError>>()?;
        let via: Vec<(usize, f64)> = rtos
            .iter()
            .filter(|r| r.bounds.is_none())
            .map(|r| (r.cl_index, r.q[2]))
            .collect();
        let via_box: Vec<(usize, f64, f64)> = rtos
            .iter()
            .filter_map(|r| r.bounds.map(|b| (r.cl_index, b.lo[2], b.hi[2])))
            .collect();
        self.budget.check("the M-path QP")?;
        let problem = MPathProblem {
            knots,
            factor,
            params: &self.v.u,
            points: &self.v.points,
            axes: &axes,
            stroke: (limits[5].min, limits[5].max),
            via: &via,
            via_box: &via_box,
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

    /// Samples at `times` with the feed `states` (`[s, ṡ, s̈, s⃛]` per time): q1..q3 from the
    /// M path (eq. 47: M = (q1, q2, q3)), q4, q5 from eq. 5, q6 from its spline; derivatives by
    /// eq. 7.
    ///
    /// # Errors
    /// [`PlanError::Interrupted`] when the budget runs out (checked every
    /// [`super::BUDGET_STRIDE`] samples).
    pub(super) fn sample(
        &self,
        it: &Iterate,
        times: Vec<f64>,
        states: &[[f64; 4]],
    ) -> Result<Samples, PlanError> {
        let n = times.len();
        let mut s = Samples {
            u: Vec::with_capacity(n),
            sd: Vec::with_capacity(n),
            q: Vec::with_capacity(n),
            qd: Vec::with_capacity(n),
            qdd: Vec::with_capacity(n),
            qddd: Vec::with_capacity(n),
            times,
        };
        for (k, &law) in states.iter().enumerate() {
            if k.is_multiple_of(super::BUDGET_STRIDE) {
                self.budget.check("trajectory sampling")?;
            }
            let u = (law[0] / self.v.sigma).clamp(0.0, 1.0);
            let mut row = [[0.0; 6]; 4];
            for (j, e) in it.joints(u, 3)?.into_iter().enumerate() {
                let d = chain_rule(e, law, self.v.sigma);
                for (r, value) in d.iter().enumerate() {
                    row[r][j] = *value;
                }
            }
            s.u.push(u);
            s.sd.push(law[1]);
            s.q.push(row[0]);
            s.qd.push(row[1]);
            s.qdd.push(row[2]);
            s.qddd.push(row[3]);
        }
        Ok(s)
    }
}
