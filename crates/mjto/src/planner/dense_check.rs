//! The dense check of a trajectory (collisions and lead/tilt at every
//! sample), RTO insertion against its violations, and the geometric
//! metrics of a sampled trajectory.

use kerf_budget::Interrupt;

use super::rto_box::{jerk_proxy, INSERT_CHOICES};
use super::{Context, Iterate, RtoState, Samples, ANGLE_TOLERANCE, BUDGET_STRIDE};
use crate::collision::CollisionWorld;
use crate::error::CollisionReport;
use crate::gfd::weighted_distance;
use crate::kinematics::{forward, tool_axis};
use crate::plan::Metrics;
use crate::request::RtoConstraint;
use crate::PlanError;

impl Context<'_> {
    /// Collision and lead/tilt check of every sample, on two threads.
    ///
    /// The collision verdicts come in runs of [`BUDGET_STRIDE`] samples from
    /// [`CollisionWorld::colliding_links_along`] (conservative advancement:
    /// the same verdicts as one [`CollisionWorld::colliding_links`] per
    /// sample, with one query per head shape covering the samples it cannot
    /// reach the workpiece in).
    ///
    /// # Errors
    /// [`PlanError::Interrupted`] when the budget runs out (checked every
    /// [`super::BUDGET_STRIDE`] samples on each thread).
    pub(super) fn check(
        &self,
        world: &CollisionWorld,
        s: &Samples,
    ) -> Result<Vec<CollisionReport>, PlanError> {
        let n = s.times.len();
        let half = n / 2;
        let check_range =
            |range: std::ops::Range<usize>| -> Result<Vec<CollisionReport>, Interrupt> {
                let mut found = Vec::new();
                let mut start = range.start;
                while start < range.end {
                    self.budget.check("the dense collision check")?;
                    let end = (start + BUDGET_STRIDE).min(range.end);
                    let links = world.colliding_links_along(&s.q[start..end]);
                    for (k, links) in (start..end).zip(links) {
                        found.extend(self.check_sample(s.times[k], s.u[k], &s.q[k], &links));
                    }
                    start = end;
                }
                Ok(found)
            };
        let (first, second) = std::thread::scope(|scope| {
            let handle = scope.spawn(|| check_range(half..n));
            let first = check_range(0..half);
            // A panic in the worker is a bug; report it as a violation of
            // every sample rather than unwinding through the planner.
            let second = handle.join().unwrap_or_else(|_| {
                Ok(vec![CollisionReport {
                    u: 0.0,
                    time: 0.0,
                    cl_index: 0,
                    links: Vec::new(),
                    reason: "internal error: the collision-check thread panicked".into(),
                }])
            });
            (first, second)
        });
        let mut first = first?;
        first.extend(second?);
        Ok(first)
    }

    /// The report of one sample at `time`, path parameter `u` and joints
    /// `q`, given the head links within the clearance there (from the
    /// collision check), or `None` when it is clear and inside the
    /// lead/tilt limits.
    pub(super) fn check_sample(
        &self,
        time: f64,
        u: f64,
        q: &[f64; 6],
        colliding: &[&str],
    ) -> Option<CollisionReport> {
        let axis = tool_axis(q[3], q[4]);
        let (lead, tilt) = self.frames.lead_tilt(u, &axis);
        let r = self.request;
        let lead_bad = lead.abs() > r.max_lead_angle * (1.0 + ANGLE_TOLERANCE);
        let tilt_bad = tilt.abs() > r.max_tilt_angle * (1.0 + ANGLE_TOLERANCE);
        if colliding.is_empty() && !lead_bad && !tilt_bad {
            return None;
        }
        let links: Vec<String> = colliding.iter().map(|l| l.to_string()).collect();
        let mut reasons = Vec::new();
        if !links.is_empty() {
            reasons.push(format!(
                "head links {} touch the workpiece",
                links.join(", ")
            ));
        }
        if lead_bad {
            reasons.push(format!(
                "lead angle {:.2}° exceeds {:.2}°",
                lead.to_degrees(),
                r.max_lead_angle.to_degrees()
            ));
        }
        if tilt_bad {
            reasons.push(format!(
                "tilt angle {:.2}° exceeds {:.2}°",
                tilt.to_degrees(),
                r.max_tilt_angle.to_degrees()
            ));
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
    /// RTO. Returns how many RTOs were inserted or changed.
    ///
    /// * `options.rto_constraint: equality` (seed 001): the inserted value is
    ///   the free GFD candidate nearest (eq. 55) to the current trajectory
    ///   there.
    /// * `box` (kerf, issue 16 item 3): the free candidate nearest (eq. 55) to
    ///   the trajectory too (the least jerk to first order, see the body);
    ///   among the [`super::rto_box::INSERT_CHOICES`] nearest, those as near
    ///   are told apart by the discrete jerk against the neighbouring RTOs
    ///   ([`super::rto_box::jerk_proxy`]); its box of free samples is grown
    ///   away from the trajectory's (failing) value; and a
    ///   boxed RTO within one CL point of the run falls back to the equality
    ///   at its pick, so every round narrows the choice and the loop
    ///   terminates as the paper's does.
    pub(super) fn insert_rtos(
        &self,
        world: &CollisionWorld,
        it: &Iterate,
        violations: &[CollisionReport],
        rtos: &mut Vec<RtoState>,
        iteration: usize,
    ) -> Result<usize, PlanError> {
        let boxes = self.request.options.rto_constraint == RtoConstraint::Box;
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
            self.budget.check("RTO insertion")?;
            let mid = &violations[(a + b) / 2];
            let near = violations[a].cl_index.saturating_sub(1)..=violations[b].cl_index + 1;
            for r in rtos.iter_mut() {
                if r.bounds.is_some() && near.contains(&r.cl_index) {
                    r.bounds = None;
                    added += 1;
                }
            }
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
            // stroke end would leave no q6 span).
            let centre = [
                target[0],
                target[1],
                self.request.options.reference_standoff,
            ];
            let mut gfd = self.build_gfd(i, centre);
            let weights = &self.request.options.weights;
            let k = if boxes { INSERT_CHOICES } else { 1 };
            let mut choices = gfd.nearest_free_k(target, weights, world, &self.budget, k)?;
            if choices.is_empty() {
                // kerf: a trajectory far outside the lead/tilt cone (RTOs
                // too sparse for the turn of the nominal axis) leaves no
                // candidate in a grid centred on it; the grid centred on the
                // nominal orientation (as the initial GFDs) has them. The
                // candidate is still the one nearest (eq. 55) to the
                // trajectory.
                gfd = self.build_gfd(i, self.reference(i));
                choices = gfd.nearest_free_k(target, weights, world, &self.budget, k)?;
            }
            let pos = rtos.partition_point(|r| r.cl_index < i);
            let value = |r: &RtoState| {
                if r.inserted_at == iteration {
                    [r.q[0], r.q[1]]
                } else {
                    [it.q4.eval(r.u)[0], it.q5.eval(r.u)[0]]
                }
            };
            let before: Vec<(f64, [f64; 2])> = rtos[pos.saturating_sub(2)..pos]
                .iter()
                .map(|r| (r.u, value(r)))
                .collect();
            let after: Vec<(f64, [f64; 2])> = rtos[pos..(pos + 2).min(rtos.len())]
                .iter()
                .map(|r| (r.u, value(r)))
                .collect();
            // First order, one more point constraint at ũ_i raises each
            // rotary QP's jerk cost by (Δq)² / g_ii with g_ii the same for q4
            // and q5 (same knots, same objective): the nearest candidate
            // (eq. 55, k4 = k5) is the least-jerk one. The discrete jerk proxy
            // only breaks ties among equally near ones (measured: letting it
            // choose among all six nearest raised case 2's q5 RMS jerk from
            // 20.7 to 23.7 rad/s³).
            let nearest = choices
                .first()
                .map(|&p| weighted_distance(&gfd.candidates[p].q, &target, weights))
                .unwrap_or(f64::INFINITY);
            let tied = |p: usize| {
                weighted_distance(&gfd.candidates[p].q, &target, weights)
                    <= nearest * (1.0 + 1e-9) + 1e-12
            };
            let mut best: Option<(f64, usize)> = None;
            for &p in choices.iter().filter(|&&p| tied(p)) {
                let q = gfd.candidates[p].q;
                let score = jerk_proxy(&before, &after, u, [q[0], q[1]]);
                if best.is_none_or(|(s, _)| score < s) {
                    best = Some((score, p));
                }
            }
            let Some((_, p)) = best else {
                return Err(PlanError::NoFeasibleOrientation {
                    index: i,
                    u,
                    reason: format!(
                        "inserting an RTO against: {}; none of the {} GFD candidates around the trajectory or the nominal axis is free ({} outside the lead/tilt limits or stroke)",
                        mid.reason,
                        gfd.total,
                        gfd.total - gfd.candidates.len()
                    ),
                });
            };
            let bounds = self.rto_box(&mut gfd, p, Some(target), world)?;
            rtos.insert(
                pos,
                RtoState {
                    cl_index: i,
                    u,
                    q: gfd.candidates[p].q,
                    inserted_at: iteration,
                    bounds,
                },
            );
            added += 1;
        }
        Ok(added)
    }

    /// The CL index in [lo, hi] (widened by one on each side) nearest to
    /// `preferred` that is not an RTO yet.
    pub(super) fn free_cl_index(
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
    ///
    /// # Errors
    /// [`PlanError::Solver`] for a CL parameter outside [0, 1] (validated requests have none).
    pub(super) fn cl_error_at_points(&self, it: &Iterate) -> Result<f64, PlanError> {
        let mut worst = 0.0f64;
        for (&u, c) in self.v.u.iter().zip(&self.v.points) {
            let q = it.joints(u, 0)?.map(|d| d[0]);
            worst = worst.max((forward(&q).0 - c).norm());
        }
        Ok(worst)
    }

    /// CL error against the reference path, lead/tilt extremes and (when a
    /// world is given) the colliding samples of a sampled trajectory.
    ///
    /// # Errors
    /// [`PlanError::Interrupted`] when the budget runs out (checked every
    /// [`BUDGET_STRIDE`] samples, on each thread of the collision count).
    pub(super) fn fill_geometry(
        &self,
        m: &mut Metrics,
        u: &[f64],
        q: &[[f64; 6]],
        world: Option<&CollisionWorld>,
    ) -> Result<(), PlanError> {
        for (k, (&u, q)) in u.iter().zip(q).enumerate() {
            if k.is_multiple_of(BUDGET_STRIDE) {
                self.budget.check("the geometric metrics")?;
            }
            let (c, o) = forward(q);
            m.max_cl_error = m.max_cl_error.max((c - self.frames.cl_point(u)).norm());
            let (lead, tilt) = self.frames.lead_tilt(u, &o);
            m.max_lead_angle = m.max_lead_angle.max(lead.abs());
            m.max_tilt_angle = m.max_tilt_angle.max(tilt.abs());
        }
        if let Some(w) = world {
            // Two threads, as the dense check of the plan itself.
            let half = q.len() / 2;
            // Conservative advancement, as the dense check of the plan: the
            // same count as one query per sample.
            let count = |part: &[[f64; 6]]| -> Result<usize, Interrupt> {
                let mut n = 0;
                for chunk in part.chunks(BUDGET_STRIDE) {
                    self.budget.check("the QI baseline's collision count")?;
                    n += w
                        .colliding_links_along(chunk)
                        .iter()
                        .filter(|links| !links.is_empty())
                        .count();
                }
                Ok(n)
            };
            let (first, second) = std::thread::scope(|scope| {
                let second = scope.spawn(|| count(&q[half..]));
                let first = count(&q[..half]);
                // A panicking check thread counts every sample of its half.
                (first, second.join().unwrap_or(Ok(q.len() - half)))
            });
            m.colliding_samples = first? + second?;
        }
        Ok(())
    }
}
