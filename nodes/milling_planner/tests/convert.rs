//! Messages ⇄ planner types: the `has_*` groups of `MillRequest`, the "empty = default"
//! fields, the `policy_file` rule, and a real plan (naive, default request) converted to a
//! `MillPlan` whose trajectory, segments and totals are the planner's.

use std::sync::OnceLock;

use kerf_milling_planner::{convert, text};
use kerf_millplan::{
    request::{RequestInitial, RequestLimits, RequestProcess, RequestStepBounds},
    MillPlanError, MillPlanOutput, MillPlanner, MillRequest,
};
use kerf_msgs::{geometry_msgs::Point, msg};

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
            planner: "ddpg".into(),
            policy_file: None,
        }
    );
    // Values of a group whose flag is false are ignored, even NaN.
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
    m.planner = "greedy".into();
    let e = convert::request_from_msg(&m)
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(e.to_string().contains("unknown planner `greedy`"), "{e}");
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
    assert_eq!(m.planner, "ddpg");
    assert_eq!(m.message, "policy /p/x.safetensors: missing");
    assert!(m.trajectory.points.is_empty() && m.segments.is_empty());
    let bad = MillPlanError::InvalidParameter {
        name: "x".into(),
        value: f64::NAN,
        reason: "must be finite".into(),
    };
    let m = convert::error_to_msg("e2", "greedy", &bad);
    assert_eq!(m.status, msg::MillPlan::INVALID_REQUEST);
    assert_eq!(m.planner, "");
    assert_eq!(convert::answer_planner("fixed_g"), "fixed_g");
    assert_eq!(convert::QUEUE_FULL, 5);
}

fn naive_output() -> &'static MillPlanOutput {
    static OUT: OnceLock<MillPlanOutput> = OnceLock::new();
    OUT.get_or_init(|| {
        let planner = MillPlanner::with_default_cell().expect("planner");
        let request = MillRequest {
            request_id: "naive-convert".into(),
            planner: "naive".into(),
            ..MillRequest::default()
        };
        planner.plan(&request).unwrap_or_else(|e| {
            panic!(
                "naive plan of the default request failed ({e}); if the indicator cache is \
                 being rebuilt, retry in a few minutes"
            )
        })
    })
}

#[test]
fn a_real_plan_becomes_its_mill_plan() {
    let out = naive_output();
    let m = convert::output_to_msg(out);
    assert_eq!(m.status, msg::MillPlan::SUCCESS, "{}", m.message);
    assert_eq!(m.request_id, "naive-convert");
    assert_eq!(m.planner, "naive");
    for needle in [
        "planned 100 segments with naive",
        "machining time",
        "from rest to rest",
        "cache used",
    ] {
        assert!(
            m.message.contains(needle),
            "{needle:?} not in {}",
            m.message
        );
    }
    // Trajectory: the planner's points exactly, from rest to rest (times to the nanosecond of
    // a Duration).
    let t = &m.trajectory;
    assert_eq!(
        t.joint_names,
        ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"]
    );
    assert_eq!(t.points.len(), out.trajectory.points.len());
    assert_eq!(t.points.len(), 102);
    assert!(t.header.stamp.sec == 0 && t.header.stamp.nanosec == 0);
    let last = t.points.len() - 1;
    let planned: Vec<f64> = out
        .trajectory
        .points
        .iter()
        .map(|p| p.time_from_start)
        .collect();
    let times = convert::ramped_times(&planned);
    for (k, (a, b)) in t.points.iter().zip(&out.trajectory.points).enumerate() {
        assert_eq!(a.positions, b.positions.to_vec());
        if k == 0 || k == last {
            // From rest and to rest (the planner's one-sided differences are not zero).
            assert_eq!(a.velocities, vec![0.0; 6]);
            assert!(
                b.velocities.iter().any(|v| v.abs() > 1e-3),
                "{k}: {:?}",
                b.velocities
            );
        } else {
            assert_eq!(a.velocities, b.velocities.to_vec());
        }
        assert!(a.accelerations.is_empty() && a.effort.is_empty());
        assert!((a.time_from_start.as_secs_f64() - times[k]).abs() <= 1e-9);
    }
    // The ramps: the midpoints T0 later than planned, the end T0 + T1 after the machining
    // time.
    let (t0, t1) = (planned[1], planned[last] - planned[last - 1]);
    for k in 1..last {
        assert!((times[k] - (planned[k] + t0)).abs() < 1e-12);
    }
    assert!((planned[last] - m.machining_time).abs() <= 1e-9);
    let end = t.points.last().unwrap().time_from_start.as_secs_f64();
    assert!(
        (end - (m.machining_time + t0 + t1)).abs() <= 1e-9,
        "{end} vs {} + {t0} + {t1}",
        m.machining_time
    );
    // Segments and totals: the plan's.
    assert_eq!(m.segments.len(), 100);
    let mut time = 0.0;
    for (s, p) in m.segments.iter().zip(&out.plan.segments) {
        assert_eq!(s.index as usize, p.segment);
        assert_eq!(
            (s.spindle_rpm, s.feed, s.redundancy_angle),
            (p.rpm, p.feed, p.g)
        );
        assert_eq!(
            (s.mu_max, s.condition_indicator, s.time, s.reward),
            (
                p.spectral_radius,
                p.condition_indicator,
                p.time,
                p.reward.total
            )
        );
        assert_eq!(s.joint_positions, p.joints.to_vec());
        time += s.time;
    }
    assert!((time - m.machining_time).abs() < 1e-9);
    assert_eq!(m.machining_time, out.plan.total_time);
    assert_eq!(m.chatter_free, out.plan.chatter_free);
    let max_mu = m.segments.iter().map(|s| s.mu_max).fold(0.0, f64::max);
    assert_eq!(m.max_mu, max_mu);
    assert_eq!(m.chatter_free, max_mu < 1.0);
    let min_ci = m
        .segments
        .iter()
        .map(|s| s.condition_indicator)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(m.min_condition_indicator, min_ci);
    assert_eq!(m.total_reward, out.plan.total_reward);
    // The text form is the same message.
    let back: msg::MillPlan = serde_yaml_ng::from_str(&text::plan_text(&m)).unwrap();
    assert_eq!(back, m);
    println!("{}", m.message);
    println!(
        "naive: {} rpm, {} m/s, machining time {:.3} s, max |mu| {:.4}",
        m.segments[0].spindle_rpm, m.segments[0].feed, m.machining_time, m.max_mu
    );
}

#[test]
fn a_defective_trajectory_is_an_internal_error_not_a_plan() {
    let good = naive_output();
    type Defect = (&'static str, fn(&mut MillPlanOutput));
    let defects: [Defect; 4] = [
        ("is NaN", |o| {
            o.trajectory.points[5].velocities[2] = f64::NAN
        }),
        ("times do not increase at point 3", |o| {
            o.trajectory.points[3].time_from_start = o.trajectory.points[2].time_from_start
        }),
        ("5 joint names", |o| {
            o.trajectory.joint_names.pop();
        }),
        ("not at time 0", |o| {
            o.trajectory.points[0].time_from_start = 0.1
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

#[test]
fn ramps_double_the_first_and_last_half_segments() {
    assert_eq!(
        convert::ramped_times(&[0.0, 1.0, 3.0, 4.5]),
        [0.0, 2.0, 4.0, 7.0]
    );
    assert_eq!(convert::ramped_times(&[0.0, 0.5]), [0.0, 1.0]);
    assert_eq!(convert::ramped_times(&[0.0]), [0.0]);
    // A joint moving uniformly at v over the first half-segment of planned time h: the cubic
    // from rest to (v h, v) over 2h has the same acceleration v / (2h) at both ends
    // (Hermite: a(0) = 6 d / T^2 - 2 v / T, a(T) = -6 d / T^2 + 4 v / T).
    let (v, h): (f64, f64) = (0.3, 0.08);
    let (d, t) = (v * h, 2.0 * h);
    let a0 = 6.0 * d / (t * t) - 2.0 * v / t;
    let a1 = -6.0 * d / (t * t) + 4.0 * v / t;
    assert!((a0 - v / (2.0 * h)).abs() < 1e-12 && (a1 - v / (2.0 * h)).abs() < 1e-12);
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
    let limit = |v: f64, a: Option<f64>| {
        vec![convert::JointLimit {
            name: "a".into(),
            max_velocity: v,
            max_acceleration: a,
        }]
    };
    assert_eq!(
        convert::first_limit_excess(&t, &limit(0.76, Some(1.51))),
        None
    );
    assert_eq!(convert::first_limit_excess(&t, &limit(0.76, None)), None);
    let e = convert::first_limit_excess(&t, &limit(0.76, Some(1.49))).unwrap();
    assert!(
        e.contains("joint 'a'") && e.contains("acceleration 1.5000") && e.contains("t = 0.000 s"),
        "{e}"
    );
    let e = convert::first_limit_excess(&t, &limit(0.74, Some(1.51))).unwrap();
    assert!(
        e.contains("velocity 0.7500") && e.contains("t = 1.000 s") && e.contains("limit 0.74"),
        "{e}"
    );
    // A joint without limits is not checked.
    assert_eq!(convert::first_limit_excess(&t, &[]), None);
}

#[test]
fn the_naive_plan_is_within_the_robot_limits() {
    let planner = MillPlanner::with_default_cell().expect("planner");
    let limits = kerf_milling_planner::robot_limits(&planner);
    let names: Vec<&str> = limits.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"]
    );
    // urdf/irb6660_limits.yaml: joint_5 4 rad/s², URDF 120 deg/s.
    assert_eq!(limits[4].max_acceleration, Some(4.0));
    assert!((limits[4].max_velocity - 120f64.to_radians()).abs() < 1e-3);
    let m = convert::output_to_msg(naive_output());
    assert_eq!(convert::first_limit_excess(&m.trajectory, &limits), None);
}
