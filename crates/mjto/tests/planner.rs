//! The acceptance on the committed cases (seed 001 section 3):
//! `Planner::plan` of `cases/case1.yaml` and `cases/case2.yaml`, every
//! returned sample re-checked independently (Table 2 limits, collisions
//! with a fresh `CollisionWorld`, lead/tilt, CL error, timing), MJTO
//! against the QI baseline, and bad requests through `Planner::plan`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::case;

use std::path::PathBuf;

use kerf_budget::Budget;
use kerf_executor::spline::{coefficients, Interpolation, Knot};
use kerf_mjto::baseline::{quaternion_interpolation_along, Rto};
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::error::status;
use kerf_mjto::kinematics::{forward, tool_axis};
use kerf_mjto::machine::JOINT_NAMES;
use kerf_mjto::mesh::{load, write_obj, MeshData};
use kerf_mjto::metrics::finite_differences;
use kerf_mjto::optimal_feed::FeedMode;
use kerf_mjto::orientation::PathFrames;
use kerf_mjto::planner::Planner;
use kerf_mjto::request::RtoConstraint;
use kerf_mjto::timelaw::TimeLaw;
use kerf_mjto::{CutPlan, CutRequest, LaserMachine, PlanError};

/// Largest accepted distance between the CL point of the planned joints
/// (eq. 2) and the requested polyline (m).
const CL_TOLERANCE: f64 = 2e-4;

/// Relative tolerance of the limit re-check (the planner's own gate uses
/// the same 1e-6).
const REL: f64 = 1e-6;

fn machine() -> LaserMachine {
    LaserMachine::default_machine().unwrap()
}

/// Every check of a returned plan that does not use the planner's own
/// bookkeeping.
fn check_plan(name: &str, request: &CutRequest, plan: &CutPlan) {
    let machine = machine();
    let limits = machine.limits();
    let v = request.validate().unwrap();
    let n = plan.times.len();
    assert!(n > 50, "{name}: {n} samples");
    assert_eq!(plan.positions.len(), n);
    assert_eq!(plan.velocities.len(), n);
    assert_eq!(plan.accelerations.len(), n);
    assert_eq!(plan.joint_names, JOINT_NAMES);
    assert_eq!(plan.request_id, request.request_id);
    assert!((plan.path_length - v.sigma).abs() < 1e-12);

    // The planner's verdicts.
    assert!(
        plan.metrics.within_limits,
        "{:?}",
        plan.metrics.limit_violations
    );
    assert!(plan.metrics.limit_violations.is_empty());
    assert_eq!(plan.metrics.colliding_samples, 0);

    // Times: every sample period from 0, the last at the end T of the
    // feed law, less than one period after the one before. The constant
    // feed's S-curve (its phases on the sample grid) is the fastest law under
    // the process limits alone up to that rounding, so no law is faster; a
    // plan that runs it is exactly it.
    let dt = request.sample_period;
    let law = TimeLaw::new(
        v.sigma,
        request.feedrate,
        request.feed_acceleration,
        request.feed_jerk,
    )
    .unwrap()
    .on_grid(dt)
    .unwrap();
    assert_eq!(plan.feed.constant_feed_time, law.duration());
    let total = plan.feed.cycle_time;
    let fastest = TimeLaw::new(
        v.sigma,
        request.feedrate,
        request.feed_acceleration,
        request.feed_jerk,
    )
    .unwrap()
    .duration();
    assert!(total >= fastest * (1.0 - 1e-9), "{name}: {total} s");
    let on_s_curve = total == law.duration();
    assert_eq!(plan.path_positions.len(), n);
    for (k, &t) in plan.times[..n - 1].iter().enumerate() {
        assert!((t - k as f64 * dt).abs() < 1e-9, "{name}: t[{k}] = {t}");
    }
    assert!((plan.times[n - 1] - total).abs() < 1e-12);
    let last_step = plan.times[n - 1] - plan.times[n - 2];
    assert!(
        last_step > 0.0 && last_step <= dt * (1.0 + 1e-9),
        "{last_step}"
    );

    // At rest at both ends.
    for j in 0..6 {
        assert!(
            plan.velocities[0][j].abs() < 1e-12,
            "{name}: q{} starts moving",
            j + 1
        );
        assert!(
            plan.velocities[n - 1][j].abs() < 1e-9,
            "{name}: q{} ends moving",
            j + 1
        );
    }

    // Table 2, independently: positions, velocities and accelerations as
    // returned, jerk as the finite difference of the accelerations (the
    // mean jerk over each step).
    let mut peak_fd_jerk = [0.0f64; 6];
    for k in 0..n {
        for (j, l) in limits.iter().enumerate() {
            let tol = REL * (l.max - l.min);
            let (q, qd, qdd) = (
                plan.positions[k][j],
                plan.velocities[k][j],
                plan.accelerations[k][j],
            );
            assert!(
                q >= l.min - tol && q <= l.max + tol,
                "{name}: q{} = {q} at sample {k}",
                j + 1
            );
            assert!(
                qd.abs() <= l.vel * (1.0 + REL),
                "{name}: q{} velocity {qd} at {k}",
                j + 1
            );
            assert!(
                qdd.abs() <= l.acc * (1.0 + REL),
                "{name}: q{} acceleration {qdd} at {k}",
                j + 1
            );
            if k + 1 < n {
                let h = plan.times[k + 1] - plan.times[k];
                let jerk = (plan.accelerations[k + 1][j] - qdd) / h;
                peak_fd_jerk[j] = peak_fd_jerk[j].max(jerk.abs());
                assert!(
                    jerk.abs() <= l.jerk * (1.0 + REL),
                    "{name}: q{} jerk {jerk} at {k}",
                    j + 1
                );
                // The velocities are the derivative of the positions and the
                // accelerations that of the velocities: the trapezoidal rule
                // over a step errs by at most h²/4 times the bound of the
                // next derivative.
                let dq = plan.positions[k + 1][j] - q;
                let trap = 0.5 * h * (qd + plan.velocities[k + 1][j]);
                assert!(
                    (dq - trap).abs() <= 0.25 * h * h * l.acc + 1e-12,
                    "{name}: q{} step {k}",
                    j + 1
                );
                let dv = plan.velocities[k + 1][j] - qd;
                let trap = 0.5 * h * (qdd + plan.accelerations[k + 1][j]);
                assert!(
                    (dv - trap).abs() <= 0.25 * h * h * l.jerk + 1e-12,
                    "{name}: q{} step {k}",
                    j + 1
                );
            }
        }
    }
    // What the executor commands between the samples: its quintic Hermite
    // segments (kerf_executor::spline, as JTC), whose jerk is quadratic in
    // time; every step's peak within the jerk limit.
    for (j, l) in limits.iter().enumerate() {
        for k in 0..n - 1 {
            let h = plan.times[k + 1] - plan.times[k];
            let knot = |i: usize| Knot {
                p: plan.positions[i][j],
                v: plan.velocities[i][j],
                a: plan.accelerations[i][j],
            };
            let c = coefficients(Interpolation::Quintic, knot(k), knot(k + 1), h);
            for m in 0..=16 {
                let tau = h * m as f64 / 16.0;
                let jerk = 6.0 * c[3] + 24.0 * c[4] * tau + 60.0 * c[5] * tau * tau;
                assert!(
                    jerk.abs() <= l.jerk * (1.0 + REL),
                    "{name}: q{} executed jerk {jerk} in step {k}",
                    j + 1
                );
            }
        }
    }

    // The planner's peaks are those of the returned samples.
    for j in 0..6 {
        let peak_v = plan
            .velocities
            .iter()
            .map(|s| s[j].abs())
            .fold(0.0, f64::max);
        let peak_a = plan
            .accelerations
            .iter()
            .map(|s| s[j].abs())
            .fold(0.0, f64::max);
        assert_eq!(plan.metrics.peak_velocity[j], peak_v);
        assert_eq!(plan.metrics.peak_acceleration[j], peak_a);
    }

    // Geometry at every sample, with u(t) from the feed profile (eq. 1):
    // the CL point of eq. 2 on the requested polyline, the tool axis
    // within the lead/tilt limits.
    let frames = PathFrames::new(&v.points, &v.axes, &v.u);
    let mut max_cl = 0.0f64;
    let mut previous_u = 0.0;
    for (k, (&t, q)) in plan.times.iter().zip(&plan.positions).enumerate() {
        let s = plan.path_positions[k];
        if on_s_curve {
            assert!((s - law.eval(t)[0]).abs() <= 1e-12, "{name}: s({t})");
        }
        // The feed of the executed samples: at most f on every step.
        if k + 1 < n {
            let step = plan.path_positions[k + 1] - s;
            let h = plan.times[k + 1] - t;
            assert!(
                step <= request.feedrate * h * (1.0 + 1e-6),
                "{name}: feed {} m/s over step {k}",
                step / h
            );
        }
        let u = (s / v.sigma).clamp(0.0, 1.0);
        assert!(u >= previous_u, "{name}: u decreases at {k}");
        previous_u = u;
        let (c, o) = forward(q);
        let err = (c - frames.cl_point(u)).norm();
        max_cl = max_cl.max(err);
        assert!(
            err <= CL_TOLERANCE,
            "{name}: CL error {err} m at sample {k} (u = {u})"
        );
        let (lead, tilt) = frames.lead_tilt(u, &o);
        assert!(
            lead.abs() <= request.max_lead_angle * (1.0 + 1e-9),
            "{name}: lead {lead} at {k}"
        );
        assert!(
            tilt.abs() <= request.max_tilt_angle * (1.0 + 1e-9),
            "{name}: tilt {tilt} at {k}"
        );
    }
    assert_eq!(previous_u, 1.0);
    assert!(max_cl <= plan.metrics.max_cl_error * (1.0 + 1e-9) + 1e-15);

    // Collisions, with a world built here from the request.
    let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    let mesh = load(&request.mesh).unwrap();
    let world = CollisionWorld::new(
        head,
        &mesh,
        &request.workpiece_pose.isometry().unwrap(),
        request.options.clearance,
    )
    .unwrap();
    for (k, q) in plan.positions.iter().enumerate() {
        let links = world.colliding_links(q);
        assert!(
            links.is_empty(),
            "{name}: sample {k} (t = {}) touches with {links:?}",
            plan.times[k]
        );
    }
    // The RTOs: in path order from the first CL point to the last, each a
    // free configuration at its CL point (eq. 3) within lead and tilt.
    let rtos = &plan.rtos;
    assert!(rtos.len() >= 2);
    assert_eq!(rtos[0].cl_index, 0);
    assert_eq!(rtos[rtos.len() - 1].cl_index, v.points.len() - 1);
    for pair in rtos.windows(2) {
        assert!(pair[1].cl_index > pair[0].cl_index);
    }
    for r in rtos {
        assert_eq!(r.u, v.u[r.cl_index]);
        let o = tool_axis(r.q4, r.q5);
        let m = v.points[r.cl_index] - r.q6 * o;
        let q = [m.x, m.y, m.z, r.q4, r.q5, r.q6];
        assert!(world.is_free(&q), "{name}: RTO {r:?} collides");
        let (lead, tilt) = frames.lead_tilt_at(r.cl_index, &o);
        assert!(lead.abs() <= request.max_lead_angle && tilt.abs() <= request.max_tilt_angle);
        assert!(r.q6 >= limits[5].min && r.q6 <= limits[5].max);
    }

    // MJTO against QI on the same RTOs (plan.qi_metrics): lower peak
    // accelerations and jerks on q1..q5.
    let (m, qi) = (&plan.metrics, &plan.qi_metrics);
    println!(
        "{name}: {n} samples, {} RTOs, {} iteration(s), n+1 = {}, max CL error {:.3e} m",
        rtos.len(),
        plan.iterations,
        plan.control_points,
        max_cl
    );
    println!(
        "| {name} | peak acc MJTO | peak acc QI | peak jerk MJTO | peak jerk QI | (FD jerk MJTO) |"
    );
    println!("|---|---|---|---|---|---|");
    for j in 0..6 {
        println!(
            "| {} | {:.4e} | {:.4e} | {:.4e} | {:.4e} | {:.4e} |",
            JOINT_NAMES[j],
            m.peak_acceleration[j],
            qi.peak_acceleration[j],
            m.peak_jerk[j],
            qi.peak_jerk[j],
            peak_fd_jerk[j]
        );
    }
}

/// Seed 001's claim on its cases: MJTO's peak accelerations and jerks are below QI's on q1..q5,
/// at constant feed (eq. 13). Both through the plan's RTOs on the plan's own s(t), compared on
/// the cruise at the feedrate (the feed ramps, shared by both, are kerf's addition), by finite
/// differences of the sampled positions for both.
fn check_smoother_than_qi(name: &str, request: &CutRequest, plan: &CutPlan) {
    let v = request.validate().unwrap();
    let frames = PathFrames::new(&v.points, &v.axes, &v.u);
    let rtos: Vec<Rto> = plan.rtos.iter().map(Rto::from).collect();
    let qi = quaternion_interpolation_along(
        &frames,
        &rtos,
        &plan.path_positions,
        v.sigma,
        machine().limits(),
        &Budget::unlimited(),
    )
    .unwrap();
    let (_, qi_a, qi_j) = finite_differences(&plan.times, &qi);
    let (_, m_a, m_j) = finite_differences(&plan.times, &plan.positions);
    let cruise = plan
        .feed
        .limits
        .iter()
        .find(|l| l.limited_by == "feedrate")
        .unwrap();
    let inside: Vec<usize> = (0..plan.times.len())
        .filter(|&k| {
            let s = plan.path_positions[k];
            s > cruise.s_start && s < cruise.s_end
        })
        .collect();
    assert!(
        inside.len() > plan.times.len() / 2,
        "{name}: cruise {cruise:?}"
    );
    let peak = |series: &[[f64; 6]], j: usize| {
        inside
            .iter()
            .filter_map(|&k| series.get(k))
            .map(|row| row[j].abs())
            .fold(0.0f64, f64::max)
    };
    for j in 0..5 {
        for (what, ours, theirs) in [
            ("acceleration", peak(&m_a, j), peak(&qi_a, j)),
            ("jerk", peak(&m_j, j), peak(&qi_j, j)),
        ] {
            println!(
                "{name}: q{} cruise peak {what} MJTO {ours:.4} QI {theirs:.4}",
                j + 1
            );
            assert!(ours.is_finite() && theirs.is_finite());
            assert!(
                ours <= theirs,
                "{name}: q{} peak {what} MJTO {ours} > QI {theirs}",
                j + 1
            );
            if theirs > 1e-9 {
                assert!(
                    ours < theirs,
                    "{name}: q{} peak {what} MJTO {ours} = QI {theirs}",
                    j + 1
                );
            }
        }
    }
}

#[test]
fn case1_plans_within_limits_collision_free_and_smoother_than_qi() {
    let request = case("case1");
    let mut planner = Planner::new(machine()).unwrap();
    let plan = planner.plan(&request).unwrap();
    check_plan("case1", &request, &plan);
    check_smoother_than_qi("case1", &request, &plan);
    // Seed 001 section 3.1: one iteration suffices.
    assert_eq!(plan.iterations, 1);
    assert!(plan.rtos.iter().all(|r| r.inserted_at_iteration == 0));
}

#[test]
fn case1_at_twice_its_feed_is_refused_at_constant_feed_and_planned_time_optimal() {
    // With RTOs as equalities (seed 001; boxes make q4 smooth enough for the constant feed).
    let mut request = case("case1");
    request.feedrate *= 2.0;
    request.options.rto_constraint = RtoConstraint::Equality;
    let mut planner = Planner::new(machine()).unwrap();
    // Seed 001's constant feed breaks a joint limit on its samples.
    let mut constant = request.clone();
    constant.options.feed_law = FeedMode::Constant;
    match planner.plan(&constant) {
        Err(e @ PlanError::LimitViolation { .. }) => {
            assert_eq!(e.status(), status::LIMIT_VIOLATION);
        }
        other => panic!("expected LimitViolation, got {other:?}"),
    }
    // The time-optimal law slows down where q4 needs it.
    let plan = planner.plan(&request).unwrap();
    check_plan("case1 at 40 m/min", &request, &plan);
    let feed = &plan.feed;
    assert_eq!(feed.law, FeedMode::TimeOptimal);
    // Slower than the S-curve would be, which breaks q4's jerk limit.
    let v = request.validate().unwrap();
    let s_curve = TimeLaw::new(v.sigma, request.feedrate, 8.0, 80.0)
        .unwrap()
        .duration();
    assert!(feed.cycle_time > s_curve, "{feed:?}");
    assert!(feed.peak_feed <= request.feedrate * (1.0 + 1e-9));
    assert!(feed.peak_feed > 0.95 * request.feedrate, "{feed:?}");
    let by: Vec<&str> = feed.limits.iter().map(|l| l.limited_by.as_str()).collect();
    assert!(by.contains(&"feedrate"), "{by:?}");
    assert!(by.iter().any(|b| b.starts_with("q4")), "{by:?}");
    for l in &feed.limits {
        assert!(l.s_start <= l.s_end && l.s_end <= plan.path_length, "{l:?}");
    }
    println!(
        "case1 at 40 m/min: {:.4} s time-optimal, {:.4} s at constant feed (refused); limits {by:?}",
        feed.cycle_time, feed.constant_feed_time
    );
}

#[test]
fn case2_plans_within_limits_collision_free_and_inserts_rtos() {
    let request = case("case2");
    let mut planner = Planner::new(machine()).unwrap();
    let plan = planner.plan(&request).unwrap();
    check_plan("case2", &request, &plan);
    check_smoother_than_qi("case2", &request, &plan);
    // Seed 001 section 3.2: RTOs are inserted.
    assert!(plan.iterations >= 2, "{} iterations", plan.iterations);
    let inserted: Vec<_> = plan
        .rtos
        .iter()
        .filter(|r| r.inserted_at_iteration >= 1)
        .collect();
    assert!(!inserted.is_empty());
    assert!(inserted
        .iter()
        .all(|r| r.inserted_at_iteration < plan.iterations));
}

/// A mesh file in the temporary directory, removed on drop.
struct TempMesh(PathBuf);

impl TempMesh {
    fn new(tag: &str, mesh: &MeshData) -> Self {
        let path = std::env::temp_dir().join(format!(
            "kerf_mjto_planner_test_{}_{tag}.obj",
            std::process::id()
        ));
        write_obj(&path, mesh).unwrap();
        Self(path)
    }

    fn reference(&self) -> String {
        self.0.to_string_lossy().into_owned()
    }
}

impl Drop for TempMesh {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn expect_invalid(planner: &mut Planner, request: &CutRequest, field: &str, reason: &str) {
    match planner.plan(request) {
        Err(e @ PlanError::InvalidRequest { .. }) => {
            assert_eq!(e.status(), status::INVALID_REQUEST);
            let PlanError::InvalidRequest {
                field: f,
                reason: r,
            } = &e
            else {
                unreachable!()
            };
            assert_eq!(f, field, "{e}");
            assert!(r.contains(reason), "{e}");
        }
        other => panic!("{field}: expected InvalidRequest, got {other:?}"),
    }
}

#[test]
fn bad_requests_give_the_right_error_and_the_planner_recovers() {
    let base = case("case1");
    let n = base.points.len();
    let mut planner = Planner::new(machine()).unwrap();
    let first = planner.plan(&base).unwrap();

    // Malformed requests.
    let mut r = base.clone();
    r.axes.pop();
    expect_invalid(&mut planner, &r, "axes", "axes for");
    let mut r = base.clone();
    r.axes[5] = [0.0, 0.0, 2.0];
    expect_invalid(&mut planner, &r, "axes[5]", "norm");
    let mut r = base.clone();
    r.axes[5] = [0.0, 0.1, 0.999];
    expect_invalid(&mut planner, &r, "axes[5]", "norm");
    let mut r = base.clone();
    r.axes[8] = [0.0, 0.0, 0.0];
    expect_invalid(&mut planner, &r, "axes[8]", "zero");
    let mut r = base.clone();
    r.points[7][1] = f64::NAN;
    expect_invalid(&mut planner, &r, "points[7]", "not finite");
    let mut r = base.clone();
    r.axes[3][2] = f64::NAN;
    expect_invalid(&mut planner, &r, "axes[3]", "not finite");
    let mut r = base.clone();
    r.feedrate = f64::NAN;
    expect_invalid(&mut planner, &r, "feedrate", "finite");
    for (bad, reason) in [
        (0.0, "must be > 0"),
        (-1e-4, "must be > 0"),
        (f64::NAN, "finite"),
        (f64::INFINITY, "finite"),
    ] {
        let mut r = base.clone();
        r.options.cl_tolerance = bad;
        expect_invalid(&mut planner, &r, "options.cl_tolerance", reason);
    }
    let mut r = base.clone();
    r.points[10] = r.points[9];
    expect_invalid(&mut planner, &r, "points[10]", "repeats");
    let mut r = base.clone();
    r.points.truncate(1);
    r.axes.truncate(1);
    expect_invalid(&mut planner, &r, "points", "at least 2");
    let mut r = base.clone();
    r.points.truncate(0);
    r.axes.truncate(0);
    expect_invalid(&mut planner, &r, "points", "at least 2");
    // Two to five points pass validation but cannot carry a quintic.
    let mut r = base.clone();
    r.points = vec![base.points[0], base.points[100], base.points[200]];
    r.axes = vec![base.axes[0], base.axes[100], base.axes[200]];
    r.options.rto_indices.clear();
    expect_invalid(&mut planner, &r, "points", "quintic");

    // A point outside the stroke: the workpiece 2 m further along x puts
    // q1 beyond its 1.6 m.
    let mut r = base.clone();
    r.workpiece_pose.position[0] += 2.0;
    match planner.plan(&r) {
        Err(e @ PlanError::Unreachable { .. }) => {
            assert_eq!(e.status(), status::UNREACHABLE);
            assert!(e.to_string().contains("q1"), "{e}");
        }
        other => panic!("expected Unreachable, got {other:?}"),
    }

    // Too fast: 5 m/s cannot meet the Table 2 limits of a rotary axis.
    // Seed 001's constant feed: the rotary QP refuses it with the largest
    // feedrate its constant-feed bounds allow (eq. 15).
    let mut r = base.clone();
    r.feedrate = 5.0;
    r.options.feed_law = FeedMode::Constant;
    let f_max = match planner.plan(&r) {
        Err(
            e @ PlanError::Infeasible {
                max_feasible_feedrate: Some(f),
                ..
            },
        ) => {
            assert_eq!(e.status(), status::INFEASIBLE);
            let PlanError::Infeasible { problem, .. } = &e else {
                unreachable!()
            };
            assert!(problem == "q4" || problem == "q5", "{e}");
            assert!(f > 0.0 && f < 5.0, "{f}");
            assert!(e.to_string().contains("largest feasible feedrate"), "{e}");
            f
        }
        other => panic!("expected Infeasible with a feedrate, got {other:?}"),
    };
    // Just above the reported feedrate it is still infeasible.
    r.feedrate = 1.01 * f_max;
    match planner.plan(&r) {
        Err(e @ PlanError::Infeasible { .. }) => assert_eq!(e.status(), status::INFEASIBLE),
        other => panic!("expected Infeasible at 1.01 f*, got {other:?}"),
    }
    // The time-optimal law (the default) slows down where the joints need
    // it; 5 m/s is refused only because no point of the path allows it at
    // steady state, with the largest feed some point allows and the joint
    // that limits it there.
    let mut r = base.clone();
    r.feedrate = 5.0;
    let f_max = match planner.plan(&r) {
        Err(
            e @ PlanError::Infeasible {
                max_feasible_feedrate: Some(f),
                ..
            },
        ) => {
            assert_eq!(e.status(), status::INFEASIBLE);
            let text = e.to_string();
            assert!(
                text.contains("steady state") && text.contains("limited by the q"),
                "{e}"
            );
            assert!(f > 0.0 && f < 5.0, "{f}");
            f
        }
        other => panic!("expected Infeasible with a feedrate, got {other:?}"),
    };
    // Just above it, refused again; just below it, planned within every
    // limit, reaching nearly that feed.
    r.feedrate = 1.01 * f_max;
    match planner.plan(&r) {
        Err(e @ PlanError::Infeasible { .. }) => assert_eq!(e.status(), status::INFEASIBLE),
        other => panic!("expected Infeasible at 1.01 f*, got {other:?}"),
    }
    r.feedrate = 0.99 * f_max;
    let fast = planner.plan(&r).unwrap();
    check_plan("case1 at 0.99 f*", &r, &fast);

    // An unknown mesh.
    for mesh in [
        "/nonexistent/kerf/workpiece.stl",
        "package://kerf/urdf/meshes/no_such_part.obj",
    ] {
        let mut r = base.clone();
        r.mesh = mesh.into();
        match planner.plan(&r) {
            Err(e @ PlanError::Mesh { .. }) => assert_eq!(e.status(), status::MESH_ERROR),
            other => panic!("{mesh}: expected Mesh, got {other:?}"),
        }
    }

    // Collisions no RTO can avoid: a 5 cm plate 0.7 m above the sheet,
    // where the ram (a 0.2 m box from 0.42 m to 1.42 m above M) passes
    // at every orientation. Case 1 runs along x from 0.6 m to 1.4 m
    // (workpiece frame), the sheet near z = 0.
    let bpillar = load(&base.mesh).unwrap();
    let with_plate = |x0: f64, x1: f64| {
        let mut mesh = bpillar.clone();
        mesh.append(&MeshData::cuboid([x0, -0.5, 0.7], [x1, 0.15, 0.75]))
            .unwrap();
        mesh
    };
    // Over the middle of the path only, with RTOs at the two ends: the
    // ends are free, the trajectory between them collides, and the RTO
    // inserted against it finds no free candidate.
    let middle = TempMesh::new("middle", &with_plate(0.85, 1.15));
    let mut r = base.clone();
    r.mesh = middle.reference();
    r.options.rto_indices = vec![0, n - 1];
    match planner.plan(&r) {
        Err(e @ PlanError::NoFeasibleOrientation { .. }) => {
            assert_eq!(e.status(), status::COLLISION);
            assert!(e.to_string().contains("z_ram"), "{e}");
            let PlanError::NoFeasibleOrientation { index, .. } = &e else {
                unreachable!()
            };
            let x = base.points[*index][0];
            assert!((0.75..=1.25).contains(&x), "{e}");
        }
        other => panic!("expected NoFeasibleOrientation, got {other:?}"),
    }
    // With a single iteration the dense check reports every colliding
    // sample, naming the ram.
    r.options.max_iterations = 1;
    match planner.plan(&r) {
        Err(e @ PlanError::Collision { .. }) => {
            assert_eq!(e.status(), status::COLLISION);
            assert!(e.to_string().contains("z_ram"), "{e}");
            let PlanError::Collision {
                iterations,
                collisions,
            } = &e
            else {
                unreachable!()
            };
            assert_eq!(*iterations, 1);
            assert!(collisions.len() > 10);
            for c in collisions {
                assert!(c.links.iter().any(|l| l == "z_ram"), "{c:?}");
                let x = base.points[c.cl_index][0];
                assert!((0.7..=1.3).contains(&x), "{c:?}");
            }
        }
        other => panic!("expected Collision, got {other:?}"),
    }
    // Over the whole path: not even the first RTO has a free candidate.
    let everywhere = TempMesh::new("everywhere", &with_plate(0.3, 1.7));
    let mut r = base.clone();
    r.mesh = everywhere.reference();
    match planner.plan(&r) {
        Err(e @ PlanError::NoFeasibleOrientation { .. }) => {
            assert_eq!(e.status(), status::COLLISION);
            assert!(e.to_string().contains("collide"), "{e}");
        }
        other => panic!("expected NoFeasibleOrientation, got {other:?}"),
    }

    // The same planner still plans case 1, identically.
    let again = planner.plan(&base).unwrap();
    assert_eq!(again.positions, first.positions);
    assert_eq!(again.velocities, first.velocities);
    assert_eq!(again.accelerations, first.accelerations);
    assert_eq!(again.rtos, first.rtos);
    check_plan("case1 again", &base, &again);
}
