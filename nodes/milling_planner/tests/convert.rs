//! Messages ⇄ planner types: the `has_*` groups of `MillRequest`, the "empty = default"
//! fields, the `policy_file` rule, and real plans of the default request (naive, ddpg with the
//! shipped policy, dp) converted to a `MillPlan` whose trajectory, segments and totals are the
//! planner's AS EXECUTED: the trajectory time-scaled to the joint limits, from rest to rest,
//! and the plan at the feeds it runs.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::sync::OnceLock;

use kerf_executor::JointLimits;
use kerf_milling_planner::{convert, text};
use kerf_millplan::{
    request::{RequestInitial, RequestLimits, RequestProcess, RequestStepBounds},
    MillPlanError, MillPlanOutput, MillPlanner, MillRequest,
};
use kerf_msgs::{geometry_msgs::Point, msg};
use kerf_ros::planner::check_trajectory_msg;

fn point(x: f64, y: f64, z: f64) -> Point {
    Point { x, y, z }
}

fn message() -> msg::MillRequest {
    msg::MillRequest {
        request_id: "m1".into(),
        points: vec![point(1.4, -0.3, 1.7), point(2.1, 0.3, 1.7)],
        ..msg::MillRequest::default()
    }
}

#[test]
fn flags_off_means_the_cell_and_empty_means_the_default() {
    let r = convert::request_from_msg(&message()).unwrap();
    assert_eq!(
        r,
        MillRequest {
            request_id: "m1".into(),
            points: vec![[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]],
            segments: None,
            process: None,
            limits: None,
            initial: None,
            planner: "best".into(),
            allow_chatter: false,
            entry: None,
            policy_file: None,
            time_budget: None,
            tolerances: None,
            // No start given: the robot's state when the node has one (issue 27).
            start: kerf_approach::StartSpec::Default,
        }
    );
    // allow_chatter and entry are passed on (issue 28).
    let mut m = message();
    m.allow_chatter = true;
    m.entry = "in_material".into();
    let r = convert::request_from_msg(&m).unwrap();
    assert!(r.allow_chatter);
    assert_eq!(r.entry().unwrap(), kerf_millplan::timing::Entry::InMaterial);
    let mut m = message();
    m.time_budget = 4.0;
    assert_eq!(
        convert::request_from_msg(&m).unwrap().time_budget,
        Some(4.0)
    );
    // Tolerances: taken whole when flagged (then 0 is refused as a path tolerance).
    let mut m = message();
    m.path_tolerance = 2e-5;
    assert_eq!(convert::request_from_msg(&m).unwrap().tolerances, None);
    m.has_tolerances = true;
    let r = convert::request_from_msg(&m).unwrap();
    assert_eq!(
        r.tolerances,
        Some(kerf_millplan::request::RequestTolerances {
            path_tolerance: Some(2e-5),
            min_condition_indicator: Some(0.0),
        })
    );
    assert_eq!(r.min_condition_indicator(), None);
    r.validate().unwrap();
    m.path_tolerance = 0.0;
    let e = convert::request_from_msg(&m)
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(e.to_string().contains("tolerances.path_tolerance"), "{e}");
    // Values of a group whose flag is false are ignored by the conversion, even NaN (the
    // number check before it, kerf_msgs::numbers, refuses a NaN anywhere).
    let mut m = message();
    m.teeth = 7;
    m.feed_min = f64::NAN;
    m.initial_g = 9.0;
    let r = convert::request_from_msg(&m).unwrap();
    assert_eq!((r.process, r.limits, r.initial), (None, None, None));
    r.validate().unwrap();
}

#[test]
fn flagged_groups_are_taken_whole() {
    let m = msg::MillRequest {
        segments: 40,
        has_process: true,
        teeth: 3,
        tool_radius: 0.03,
        axial_depth: 0.002,
        kt: 6e8,
        kn: 2e8,
        entry_angle: 2.0,
        exit_angle: 3.0,
        has_limits: true,
        spindle_min_rpm: 2100.0,
        spindle_max_rpm: 3900.0,
        feed_min: 0.01,
        feed_max: 0.05,
        g_min: -1.0,
        g_max: 1.5,
        max_spindle_step_rpm: 15.0,
        max_feed_step: 5e-4,
        max_g_step: 0.1,
        has_initial_state: true,
        initial_spindle_rpm: 2500.0,
        initial_feed: 0.02,
        initial_g: 0.5,
        planner: "fixed_g".into(),
        policy_file: "/p/fixed.safetensors".into(),
        ..message()
    };
    let r = convert::request_from_msg(&m).unwrap();
    assert_eq!(r.segments, Some(40));
    assert_eq!(
        r.process,
        Some(RequestProcess {
            teeth: 3,
            tool_radius: 0.03,
            axial_depth: 0.002,
            kt: 6e8,
            kn: 2e8,
            entry_angle: 2.0,
            exit_angle: 3.0,
        })
    );
    assert_eq!(
        r.limits,
        Some(RequestLimits {
            spindle_rpm: Some([2100.0, 3900.0]),
            feed: Some([0.01, 0.05]),
            redundancy_angle: Some([-1.0, 1.5]),
            step_bounds: Some(RequestStepBounds {
                spindle_rpm: Some(15.0),
                feed: Some(5e-4),
                redundancy_angle: Some(0.1),
            }),
        })
    );
    assert_eq!(
        r.initial,
        Some(RequestInitial {
            spindle_rpm: Some(2500.0),
            feed: Some(0.02),
            g: Some(0.5),
        })
    );
    assert_eq!(r.initial_state(), [2500.0, 0.02, 0.5]);
    assert_eq!(r.planner, "fixed_g");
    assert_eq!(r.policy_file.as_deref(), Some("/p/fixed.safetensors"));
    r.validate().unwrap();
}

#[test]
fn bad_values_reach_validation_and_are_named() {
    // NaN in a point.
    let mut m = message();
    m.points[1].y = f64::NAN;
    let e = convert::request_from_msg(&m)
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(e.to_string().contains("points[1][1] [m]"), "{e}");
    assert_eq!(kerf_millplan::status_of(&e), msg::MillPlan::INVALID_REQUEST);
    // Limits with min > max (flag on).
    let m = msg::MillRequest {
        has_limits: true,
        spindle_min_rpm: 2000.0,
        spindle_max_rpm: 4000.0,
        feed_min: 0.05,
        feed_max: 0.01,
        g_min: -1.0,
        g_max: 1.0,
        max_spindle_step_rpm: 20.0,
        max_feed_step: 1e-3,
        max_g_step: 0.2,
        ..message()
    };
    let e = convert::request_from_msg(&m)
        .unwrap()
        .validate()
        .unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("limits.feed [m/s][0]") && text.contains("min > max"),
        "{text}"
    );
    // One point; an unknown planner.
    let mut m = message();
    m.points.pop();
    let e = convert::request_from_msg(&m)
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(e.to_string().contains("at least 2 points"), "{e}");
    let mut m = message();
    m.planner = "fastest".into();
    let e = convert::request_from_msg(&m)
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(e.to_string().contains("unknown planner `fastest`"), "{e}");
}

#[test]
fn policy_file_for_dp_or_naive_is_refused() {
    for planner in ["dp", "naive"] {
        let mut m = message();
        m.planner = planner.into();
        m.policy_file = "/p/a.safetensors".into();
        let e = convert::request_from_msg(&m).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("policy_file") && text.contains(planner) && text.contains("no policy"),
            "{text}"
        );
        let answer = convert::error_to_msg(&m.request_id, &m.planner, &e);
        assert_eq!(answer.status, msg::MillPlan::INVALID_REQUEST);
        assert_eq!(
            (answer.request_id.as_str(), answer.planner.as_str()),
            ("m1", planner)
        );
        // Without the file it converts.
        m.policy_file.clear();
        assert_eq!(convert::request_from_msg(&m).unwrap().policy_file, None);
    }
}

#[test]
fn errors_carry_their_status_and_the_planner_name() {
    let policy = MillPlanError::Policy {
        path: "/p/x.safetensors".into(),
        reason: "missing".into(),
    };
    let m = convert::error_to_msg("e1", "", &policy);
    assert_eq!(m.status, msg::MillPlan::POLICY_ERROR);
    assert_eq!(m.planner, "best");
    assert_eq!(m.message, "policy /p/x.safetensors: missing");
    assert!(m.trajectory.points.is_empty() && m.segments.is_empty());
    let bad = MillPlanError::InvalidParameter {
        name: "x".into(),
        value: f64::NAN,
        reason: "must be finite".into(),
    };
    let m = convert::error_to_msg("e2", "fastest", &bad);
    assert_eq!(m.status, msg::MillPlan::INVALID_REQUEST);
    assert_eq!(m.planner, "");
    assert_eq!(convert::answer_planner("fixed_g"), "fixed_g");
    assert_eq!(convert::QUEUE_FULL, 5);
}

/// The plan of the default request by `planner` (its shipped policy for `ddpg`).
fn plan_default(planner: &str) -> MillPlanOutput {
    let p = MillPlanner::with_default_cell().expect("planner");
    let request = MillRequest {
        request_id: format!("{planner}-convert"),
        planner: planner.into(),
        ..MillRequest::default()
    };
    p.plan(&request).unwrap_or_else(|e| {
        panic!(
            "{planner} plan of the default request failed ({e}); if the indicator cache is \
             being rebuilt, retry in a few minutes"
        )
    })
}

fn naive_output() -> &'static MillPlanOutput {
    static OUT: OnceLock<MillPlanOutput> = OnceLock::new();
    OUT.get_or_init(|| plan_default("naive"))
}

fn ddpg_output() -> &'static MillPlanOutput {
    static OUT: OnceLock<MillPlanOutput> = OnceLock::new();
    OUT.get_or_init(|| plan_default("ddpg"))
}

/// The only dp plan of this test binary (seconds even in release).
fn dp_output() -> &'static MillPlanOutput {
    static OUT: OnceLock<MillPlanOutput> = OnceLock::new();
    OUT.get_or_init(|| plan_default("dp"))
}

/// The planner's PLANNED trajectory as a message, as it is (not from rest, timed by the
/// planned feeds): what the node published before the planner time-scaled it.
fn planned_msg(out: &MillPlanOutput) -> kerf_msgs::trajectory_msgs::JointTrajectory {
    use kerf_msgs::{builtin_interfaces::Duration, trajectory_msgs};
    trajectory_msgs::JointTrajectory {
        joint_names: out.trajectory.joint_names().to_vec(),
        points: out
            .trajectory
            .points()
            .iter()
            .map(|p| trajectory_msgs::JointTrajectoryPoint {
                positions: p.positions.clone(),
                velocities: p.velocities.clone(),
                time_from_start: Duration::from_secs_f64(p.time_from_start).unwrap(),
                ..trajectory_msgs::JointTrajectoryPoint::default()
            })
            .collect(),
        ..trajectory_msgs::JointTrajectory::default()
    }
}

/// `m` is the SUCCESS answer of `out` as executed: the executed trajectory as it is (positions
/// and velocities exact, times to the nanosecond of a Duration), from rest to rest, within
/// the robot's limits; the segments and totals of the executed plan, consistent with the
/// trajectory (machining time = its duration); the text form is the same message.
fn assert_published_as_executed(m: &msg::MillPlan, out: &MillPlanOutput) {
    assert_eq!(m.status, msg::MillPlan::SUCCESS, "{}", m.message);
    assert_eq!(m.request_id, out.request_id);
    assert_eq!(m.planner, out.planner.name());
    let executed = &out.executed.scaling.trajectory;
    let t = &m.trajectory;
    assert_eq!(
        t.joint_names,
        ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"]
    );
    assert_eq!(t.joint_names, executed.joint_names());
    assert!(t.header.stamp.sec == 0 && t.header.stamp.nanosec == 0);
    let n = out.plan.segments.len();
    assert!(t.points.len() > n + 2, "dense samples");
    assert_eq!(t.points.len(), executed.points().len());
    for (k, (a, b)) in t.points.iter().zip(executed.points()).enumerate() {
        assert_eq!(a.positions, b.positions, "point {k}");
        assert_eq!(a.velocities, b.velocities, "point {k}");
        assert_eq!(a.accelerations, b.accelerations, "point {k}");
        assert_eq!(a.accelerations.len(), 6);
        assert!(a.effort.is_empty());
        let dt = a.time_from_start.as_secs_f64() - b.time_from_start;
        assert!(dt.abs() <= 1e-9, "point {k}: {dt} s off");
    }
    // The plan's joints at every segment midpoint, among the samples.
    for (i, seg) in out.plan.segments.iter().enumerate() {
        assert!(
            t.points.iter().any(|p| p
                .positions
                .iter()
                .zip(&seg.joints)
                .all(|(a, b)| (a - b).abs() < 1e-9)),
            "segment {i}'s midpoint joints not among the samples"
        );
    }
    // From rest to rest.
    let last = t.points.len() - 1;
    for k in [0, last] {
        assert_eq!(t.points[k].velocities, vec![0.0; 6], "point {k}");
        assert_eq!(t.points[k].accelerations, vec![0.0; 6], "point {k}");
    }
    // Never faster than planned at a segment midpoint.
    for (x, p) in out.executed.plan.segments.iter().zip(&out.plan.segments) {
        assert!(x.feed <= p.feed, "segment {}", p.segment);
    }
    // The executed tool path and the conditioning along the trajectory.
    let d = &out.executed.scaling.deviation;
    assert_eq!(
        (m.max_path_deviation, m.max_plane_deviation),
        (d.max_off_path, d.max_off_plane)
    );
    assert_eq!(m.path_tolerance, out.executed.settings.path_tolerance);
    assert!(m.max_path_deviation <= m.path_tolerance && m.max_plane_deviation <= m.path_tolerance);
    assert_eq!(
        (m.min_condition_indicator_path, m.min_condition_arc_length),
        out.executed.scaling.min_condition_indicator
    );
    // Within the robot's limits, as the executor interpolates it.
    let limits = robot_limits();
    assert_eq!(check_trajectory_msg(&limits, t), Ok(()));
    // Segments and totals: the executed plan's.
    let x = &out.executed.plan;
    assert_eq!(m.segments.len(), n);
    let mut time = 0.0;
    for (s, q) in m.segments.iter().zip(&x.segments) {
        assert_eq!(s.index as usize, q.segment);
        assert_eq!(
            (s.spindle_rpm, s.feed, s.redundancy_angle),
            (q.rpm, q.feed, q.g)
        );
        assert_eq!(
            (s.mu_max, s.condition_indicator, s.time, s.reward),
            (
                q.spectral_radius,
                q.condition_indicator,
                q.time,
                q.reward.total
            )
        );
        assert_eq!(s.joint_positions, q.joints.to_vec());
        time += s.time;
    }
    assert!((time - m.machining_time).abs() < 1e-9);
    assert_eq!(m.machining_time, x.total_time);
    // The trajectory runs the run-in, the path and the run-out (issue 28): its duration is
    // `trajectory_duration`; the machining time is the part in the material.
    let end = t.points[last].time_from_start.as_secs_f64();
    assert!(
        (end - m.trajectory_duration).abs() <= 1e-9 * end.max(1.0),
        "trajectory {end} s, duration {} s",
        m.trajectory_duration
    );
    let (enter, leave) = out.executed.scaling.material_times();
    assert!((m.machining_time - (leave - enter)).abs() <= 1e-9 * end);
    assert!(m.machining_time < end && m.run_in > 0.0 && m.run_out > 0.0);
    assert!(m.machining_time > out.plan.total_time, "ramps at least");
    assert_eq!(m.chatter_free, x.chatter_free);
    // max_mu is the largest of the segments' values and of the judge's samples (issue 28).
    let max_mu = m.segments.iter().map(|s| s.mu_max).fold(0.0, f64::max);
    assert_eq!(
        m.max_mu,
        max_mu.max(out.executed.chatter.max_spectral_radius)
    );
    assert_eq!(m.max_mu, x.max_spectral_radius);
    let min_ci = m
        .segments
        .iter()
        .map(|s| s.condition_indicator)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(m.min_condition_indicator, min_ci);
    assert_eq!(m.min_condition_indicator, x.min_condition_indicator);
    assert_eq!(m.total_reward, x.total_reward);
    // The message: both the executed and the planned totals.
    let sc = &out.executed.scaling;
    for needle in [
        format!("planned {n} segments with {}", out.planner.name()),
        format!(
            "machining time {:.3} s as executed from rest to rest",
            x.total_time
        ),
        format!("({:.3} s at the planned feeds;", out.plan.total_time),
        format!("{} of {n} segments slowed", sc.slowed_segments()),
        format!(
            "{} trajectory points, tool tip within {:.4} mm of the path",
            sc.trajectory.points().len(),
            out.executed.scaling.deviation.max_off_path * 1e3
        ),
        format!(
            "max |mu| {:.4} as executed ({:.4} as planned)",
            x.max_spectral_radius, out.plan.max_spectral_radius
        ),
        format!("total reward {:.3} as executed", x.total_reward),
        "planning took".to_string(),
    ] {
        assert!(
            m.message.contains(&needle),
            "{needle:?} not in {}",
            m.message
        );
    }
    assert_eq!(
        m.message.contains("CHATTER"),
        !x.chatter_free,
        "{}",
        m.message
    );
    assert_eq!(
        m.message
            .contains("chatter-free at its planned feeds but NOT as executed"),
        out.plan.chatter_free && !x.chatter_free,
        "{}",
        m.message
    );
    assert_eq!(
        m.message.contains("segments from the indicator cache"),
        !out.executed.cached_segments.is_empty(),
        "{}",
        m.message
    );
    // The text form is the same message.
    let back: msg::MillPlan = serde_yaml_ng::from_str(&text::plan_text(m)).unwrap();
    assert_eq!(&back, m);
    println!("{}", m.message);
}

#[test]
fn a_real_plan_becomes_its_mill_plan() {
    let out = naive_output();
    let m = convert::output_to_msg(out);
    assert_eq!(m.request_id, "naive-convert");
    assert!(m.message.contains("cache used"), "{}", m.message);
    assert_published_as_executed(&m, out);
    assert_eq!(m.segments.len(), 100);
    assert_eq!(
        m.trajectory.points.len(),
        out.executed.scaling.trajectory.points().len()
    );
    assert!(m.trajectory.points.len() > 102, "dense samples");
    println!(
        "naive: {} rpm, {} m/s, machining time {:.3} s as executed ({:.3} s planned), max |mu| \
         {:.4}",
        m.segments[0].spindle_rpm,
        m.segments[0].feed,
        m.machining_time,
        out.plan.total_time,
        m.max_mu
    );
}

/// The ddpg and dp plans of the default request are published as executed: the joint limits
/// slowed them, so some segments run below their planned feed, with the |μ|max of that feed.
#[test]
fn ddpg_and_dp_plans_are_published_as_executed() {
    for out in [ddpg_output(), dp_output()] {
        let name = out.planner.name();
        assert!(
            out.executed.scaling.slowed_segments() > 0,
            "{name}: nothing slowed"
        );
        let m = convert::output_to_msg(out);
        assert_published_as_executed(&m, out);
        let pairs = || m.segments.iter().zip(&out.plan.segments);
        assert!(pairs().any(|(s, p)| s.feed < p.feed), "{name}");
        assert!(pairs().all(|(s, p)| s.feed <= p.feed), "{name}");
        // A slowed segment carries the |μ|max of its executed feed, not the planned one.
        assert!(
            pairs().any(|(s, p)| s.feed < p.feed && s.mu_max != p.spectral_radius),
            "{name}"
        );
        assert_eq!(m.max_mu, out.executed.plan.max_spectral_radius, "{name}");
        println!(
            "{name}: machining time {:.3} s as executed ({:.3} s planned), max |mu| {:.4} \
             ({:.4} planned), {} of {} segments slowed",
            m.machining_time,
            out.plan.total_time,
            m.max_mu,
            out.plan.max_spectral_radius,
            out.executed.scaling.slowed_segments(),
            out.executed.scaling.segment_slowdown.len()
        );
    }
}

/// A plan chatter-free as planned but not as executed is said so, with a WARNING; one that
/// chatters in both says CHATTER without it.
/// Issue 28: a plan that chatters as executed is never SUCCESS. Refused, it is CHATTER with
/// the segment, its |μ|max and the lowest |μ|max any planner reached; allowed
/// (`allow_chatter`), it is CHATTER with its trajectory and the message says kerf does not send
/// it. Planner `best` names the planner it chose and lists every candidate.
#[test]
fn a_plan_that_chatters_as_executed_is_chatter_not_success() {
    let p = MillPlanner::with_default_cell().expect("planner");
    let request = MillRequest {
        request_id: "chatter".into(),
        planner: "fixed_g".into(),
        ..MillRequest::default()
    };
    let e = p
        .plan(&request)
        .expect_err("fixed_g chatters on the default path");
    let m = convert::error_to_msg("chatter", "fixed_g", &e);
    assert_eq!(m.status, msg::MillPlan::CHATTER, "{}", m.message);
    assert_eq!(msg::MillPlan::status_name(m.status), Some("CHATTER"));
    assert!(m.trajectory.points.is_empty());
    for needle in [
        "fixed_g: the plan chatters as executed: |μ|max 1.0",
        "at segment",
        "the lowest |μ|max any planner reached on this path is 0.9",
    ] {
        assert!(
            m.message.contains(needle),
            "{needle:?} not in {}",
            m.message
        );
    }
    let allowed = p
        .plan(&MillRequest {
            allow_chatter: true,
            ..request
        })
        .expect("allowed");
    let m = convert::output_to_msg(&allowed);
    assert_eq!(m.status, msg::MillPlan::CHATTER, "{}", m.message);
    assert!(!m.chatter_free && m.max_mu >= 1.0);
    assert!(!m.trajectory.points.is_empty());
    assert!(
        m.message.contains("CHATTERS as executed from segment")
            && m.message
                .contains("kerf does not send this trajectory to the robot"),
        "{}",
        m.message
    );
    assert!(m.judged_samples > 1000 && m.judge_evaluations > 0);
    assert!(m.run_in > 0.0 && m.run_out > 0.0);
    assert!(m.trajectory_duration > m.machining_time);
    // best: the planner that produced the answer and every candidate.
    let best = p
        .plan(&MillRequest {
            request_id: "best".into(),
            ..MillRequest::default()
        })
        .expect("best");
    let m = convert::output_to_msg(&best);
    assert_eq!(m.status, msg::MillPlan::SUCCESS, "{}", m.message);
    assert_eq!(m.planner, best.planner.name());
    assert_ne!(m.planner, "best");
    // greedy is chatter-free on the default path: greedy_best_g is not run.
    let names: Vec<&str> = m.candidates.iter().map(|c| c.planner.as_str()).collect();
    assert_eq!(names, ["ddpg", "fixed_g", "naive", "greedy"]);
    let fixed_g = &m.candidates[1];
    assert_eq!(fixed_g.status, msg::MillPlan::CHATTER);
    assert!(!fixed_g.chatter_free && fixed_g.max_mu >= 1.0);
    assert!(
        m.message.contains("best of 4 candidates: ")
            && m.message.contains("ddpg ")
            && m.message
                .contains("greedy_best_g not run (greedy is chatter-free)"),
        "{}",
        m.message
    );
}

/// Executed |μ|max values taken from the indicator cache are counted in the message.
#[test]
fn cached_executed_values_are_said() {
    let mut out = naive_output().clone();
    out.executed.cached_segments = vec![3, 4, 90];
    let m = convert::output_to_msg(&out);
    assert!(
        m.message
            .contains("; as executed, |mu|max of 3 of 100 segments from the indicator cache;"),
        "{}",
        m.message
    );
}

#[test]
fn a_defective_trajectory_is_an_internal_error_not_a_plan() {
    let good = naive_output();
    type Defect = (&'static str, fn(&mut MillPlanOutput));
    let defects: [Defect; 6] = [
        ("is NaN", |o| {
            o.executed.scaling.trajectory.request.points[5].velocities[2] = f64::NAN
        }),
        ("times do not increase at point 3", |o| {
            let p = &mut o.executed.scaling.trajectory.request.points;
            p[3].time_from_start = p[2].time_from_start
        }),
        ("5 joint names", |o| {
            o.executed.scaling.trajectory.request.joint_names.pop();
        }),
        ("not at time 0", |o| {
            o.executed.scaling.trajectory.request.points[0].time_from_start = 0.1
        }),
        (
            "the first point (t = 0 s) is not at rest: velocity of joint_2",
            |o| o.executed.scaling.trajectory.request.points[0].velocities[1] = 1e-3,
        ),
        ("the last point", |o| {
            let p = o
                .executed
                .scaling
                .trajectory
                .request
                .points
                .last_mut()
                .unwrap();
            p.velocities[5] = -0.2
        }),
    ];
    for (needle, corrupt) in defects {
        let mut out = good.clone();
        corrupt(&mut out);
        let m = convert::output_to_msg(&out);
        assert_eq!(m.status, msg::MillPlan::INTERNAL_ERROR, "{needle}");
        assert!(
            m.message.contains("unusable trajectory") && m.message.contains(needle),
            "{needle:?} not in {}",
            m.message
        );
        assert!(m.trajectory.points.is_empty() && m.segments.is_empty());
        assert_eq!(m.request_id, "naive-convert");
    }
}

/// The robot's limits as the executor (and the node's executability check) takes them.
fn robot_limits() -> Vec<JointLimits> {
    let planner = MillPlanner::with_default_cell().expect("planner");
    planner
        .cell()
        .robot()
        .executor_limits()
        .expect("acceleration limits")
}

#[test]
fn limit_excess_of_the_interpolated_trajectory() {
    use kerf_msgs::{
        builtin_interfaces::Duration,
        trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    };
    // Rest to rest, 1 rad in 2 s (cubic): peak acceleration 6Δ/T² = 1.5 rad/s² at both ends,
    // peak velocity 1.5Δ/T = 0.75 rad/s at the middle.
    let point = |q: f64, sec: i32| JointTrajectoryPoint {
        positions: vec![q, 0.0],
        velocities: vec![0.0, 0.0],
        time_from_start: Duration { sec, nanosec: 0 },
        ..JointTrajectoryPoint::default()
    };
    let t = JointTrajectory {
        joint_names: vec!["a".into(), "b".into()],
        points: vec![point(0.0, 0), point(1.0, 2)],
        ..JointTrajectory::default()
    };
    let limit = |v: f64, a: f64| {
        ["a", "b"]
            .map(|name| JointLimits {
                name: name.into(),
                min_position: -10.0,
                max_position: 10.0,
                max_velocity: v,
                max_acceleration: a,
            })
            .to_vec()
    };
    assert_eq!(check_trajectory_msg(&limit(0.76, 1.51), &t), Ok(()));
    let e = check_trajectory_msg(&limit(0.76, 1.49), &t).unwrap_err();
    assert!(
        e.contains("joint 'a'") && e.contains("acceleration 1.5") && e.contains("t = 0 s"),
        "{e}"
    );
    let e = check_trajectory_msg(&limit(0.74, 1.51), &t).unwrap_err();
    assert!(
        e.contains("velocity 0.75") && e.contains("t = 1 s") && e.contains("limit 0.74"),
        "{e}"
    );
}

/// Every published plan of the default request (naive, ddpg, dp) stays within the robot's
/// limits; the ddpg and dp plans' PLANNED timing (what the node published before the planner
/// time-scaled it) does not, so the guard does fire on a trajectory that asks too much.
#[test]
fn plans_of_the_default_request_are_within_the_robot_limits() {
    let limits = robot_limits();
    let names: Vec<&str> = limits.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"]
    );
    // urdf/irb6660_limits.yaml: joint_5 4 rad/s², URDF 120 deg/s.
    assert_eq!(limits[4].max_acceleration, 4.0);
    assert!((limits[4].max_velocity - 120f64.to_radians()).abs() < 1e-3);
    for out in [naive_output(), ddpg_output(), dp_output()] {
        let name = out.planner.name();
        let m = convert::output_to_msg(out);
        assert_eq!(m.status, msg::MillPlan::SUCCESS, "{name}: {}", m.message);
        assert_eq!(
            check_trajectory_msg(&limits, &m.trajectory),
            Ok(()),
            "{name}"
        );
        if name != "naive" {
            // The planned timing does not end at rest (the executor's first refusal); brought
            // to rest at its last point, the interpolated curve exceeds a joint limit.
            let mut planned = planned_msg(out);
            if let Some(last) = planned.points.last_mut() {
                last.velocities.iter_mut().for_each(|v| *v = 0.0);
            }
            let excess = check_trajectory_msg(&limits, &planned);
            println!("{name} as planned: {excess:?}");
            assert!(
                excess
                    .as_ref()
                    .is_err_and(|e| e.contains("exceeds the limit")),
                "{name}: the planned timing was expected to exceed a joint limit"
            );
        }
    }
}
