//! The executed trajectory of a plan (kerf_millplan::timing, issue 13 item 1) on hand-made
//! plans of the default path: a slow constant plan that must not be slowed, a zig-zag of g
//! that must be slowed to the joints' limits, a tighter tolerance that needs more samples,
//! and every refused input. What is checked is what the executor runs: its own
//! interpolation sampled at the control period (`executed_deviation`), and the joints'
//! limits on the quintic pieces by central differences.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_budget::Budget;
use kerf_mill::MillCell;
use kerf_millplan::deviation::executed_deviation;
use kerf_millplan::plan::SegmentPlan;
use kerf_millplan::spline1d::Profile;
use kerf_millplan::timing::{
    joint_limits, three_point_velocity, time_scale, Entry, JointLimit, TrajectorySettings,
};
use kerf_millplan::{MillPlanError, Plan, RewardParts, TimeScaling};

fn limits(cell: &MillCell) -> Vec<JointLimit> {
    joint_limits(cell).unwrap()
}

/// A plan of the cell's path with feed `feed(i)` and redundancy angle `g(i)` per segment
/// (joints from the cell's IK on one branch; |μ| and rewards are not used by the timing).
fn plan(cell: &MillCell, feed: impl Fn(usize) -> f64, g: impl Fn(usize) -> f64) -> Plan {
    let mut reference = None;
    let segments = (0..cell.path().segments().len())
        .map(|i| {
            let state = cell.evaluate(i, g(i), reference.as_ref()).unwrap();
            reference = Some(state.joints);
            let length = cell.path().segment(i).unwrap().length;
            SegmentPlan {
                segment: i,
                rpm: 3000.0,
                feed: feed(i),
                g: g(i),
                spectral_radius: 0.5,
                condition_number: state.condition_number,
                condition_indicator: state.condition_indicator,
                joints: state.joints,
                time: length / feed(i),
                reward: RewardParts {
                    operational: 0.0,
                    efficiency: 0.0,
                    stability: 0.0,
                    total: 0.0,
                },
            }
        })
        .collect::<Vec<_>>();
    let total_time = segments.iter().map(|s| s.time).sum();
    Plan {
        planner: "test".to_string(),
        segments,
        total_time,
        chatter_free: true,
        max_spectral_radius: 0.5,
        min_condition_indicator: 0.0,
        total_reward: 0.0,
    }
}

fn scale(cell: &MillCell, plan: &Plan, settings: &TrajectorySettings) -> TimeScaling {
    time_scale(cell, plan, &limits(cell), settings, &Budget::unlimited()).unwrap()
}

/// The largest ratio of a sampled joint velocity, acceleration or jerk to its limit over the
/// executor's quintic pieces (central differences of the executor's own sampling).
fn worst_ratio(cell: &MillCell, sc: &TimeScaling) -> f64 {
    let limits = cell.robot().executor_limits().unwrap();
    let prepared = kerf_executor::check_executable(
        &limits,
        &kerf_executor::ExecutorConfig::default(),
        &sc.trajectory.request,
    )
    .unwrap();
    let jerk_limits: Vec<f64> = cell
        .robot()
        .joints()
        .iter()
        .map(|j| j.max_jerk.unwrap())
        .collect();
    let mut sample = kerf_executor::JointSample::default();
    let mut position = |t: f64| {
        prepared.sample_into(t, &mut sample);
        sample.positions.clone()
    };
    let d = 1e-3;
    let mut worst: f64 = 0.0;
    let end = sc.duration();
    let mut t = 2.0 * d;
    while t < end - 2.0 * d {
        let p: Vec<Vec<f64>> = [-2.0, -1.0, 0.0, 1.0, 2.0]
            .iter()
            .map(|x| position(t + x * d))
            .collect();
        for (j, l) in limits.iter().enumerate() {
            let v = (p[3][j] - p[1][j]) / (2.0 * d);
            let a = (p[3][j] - 2.0 * p[2][j] + p[1][j]) / (d * d);
            let jerk = (p[4][j] - 2.0 * p[3][j] + 2.0 * p[1][j] - p[0][j]) / (2.0 * d * d * d);
            worst = worst
                .max(v.abs() / l.max_velocity)
                .max(a.abs() / l.max_acceleration)
                .max(jerk.abs() / jerk_limits[j]);
        }
        t += 0.01;
    }
    worst
}

#[test]
fn a_slow_constant_plan_runs_at_its_feed() {
    let cell = MillCell::default_cell().unwrap();
    let p = plan(&cell, |_| 0.02, |_| -0.4);
    let settings = TrajectorySettings::default();
    let sc = scale(&cell, &p, &settings);
    assert_eq!(sc.slowed_segments(), 0);
    assert_eq!((sc.rounds, sc.uniform), (1, false));
    assert!(sc.segment_feeds.iter().all(|f| *f == 0.02));
    // The ramps lie on the run-in and run-out (Entry::RunIn, the default), each losing half
    // its ramp time: T = (run-in + L + run-out)/f + T_r, and the path itself is machined at
    // the feed throughout: L/f.
    let length = cell.path().total_length();
    let expected = (sc.run_in + length + sc.run_out) / 0.02 + settings.ramp_time;
    assert!(
        (sc.duration() - expected).abs() < 1e-6,
        "{} vs {expected}",
        sc.duration()
    );
    assert!(
        (sc.machining_time() - length / 0.02).abs() < 1e-6,
        "{}",
        sc.machining_time()
    );
    let (enter, leave) = sc.material_times();
    assert!(enter >= settings.ramp_time && leave <= sc.duration() - settings.ramp_time);
    assert!(sc.run_in > 0.0 && sc.run_out > 0.0);
    // With the ramps in the material: T = L/f + T_r, all of it machining.
    let inside = scale(&cell, &p, &settings.with_entry(Entry::InMaterial));
    let expected = length / 0.02 + settings.ramp_time;
    assert!(
        (inside.duration() - expected).abs() < 1e-6,
        "{} vs {expected}",
        inside.duration()
    );
    assert!((inside.machining_time() - inside.duration()).abs() < 1e-9);
    assert_eq!((inside.run_in, inside.run_out), (0.0, 0.0));
    let d = executed_deviation(&cell, &sc.trajectory, settings.control_period).unwrap();
    assert!(d.max_off_path <= 5e-5 && d.max_off_plane <= 5e-5, "{d:?}");
    assert_eq!(d, sc.deviation);
    assert!(worst_ratio(&cell, &sc) <= 1.0 + 1e-2);
}

#[test]
fn a_zigzag_of_g_is_slowed_to_the_joint_limits_and_stays_on_the_path() {
    let cell = MillCell::default_cell().unwrap();
    // g alternating by 0.2 rad (the step bound) at the fastest feed.
    let p = plan(&cell, |_| 0.06, |i| if i % 2 == 0 { -0.3 } else { -0.5 });
    let settings = TrajectorySettings::default();
    let sc = scale(&cell, &p, &settings);
    assert!(sc.slowed_segments() > 0);
    assert!(sc.duration() > p.total_time + settings.ramp_time);
    for (f, s) in sc.segment_feeds.iter().zip(&p.segments) {
        assert!(*f <= s.feed);
    }
    let ratio = worst_ratio(&cell, &sc);
    assert!(ratio <= 1.0 + 1e-2, "{ratio}");
    assert!(ratio > 0.5, "the limits are what slowed it: {ratio}");
    let d = executed_deviation(&cell, &sc.trajectory, settings.control_period).unwrap();
    assert!(d.max_off_path <= 5e-5 && d.max_off_plane <= 5e-5, "{d:?}");
    // At the midpoints the samples are the plan's joints (the profiles pass through them).
    let mid = &sc.trajectory;
    let k = mid
        .arc_length
        .iter()
        .position(|s| (s - 1.5 * cell.path().segment(1).unwrap().length).abs() < 1e-12)
        .expect("the midpoint of segment 1 is a sample");
    for (a, b) in mid.points()[k].positions.iter().zip(&p.segments[1].joints) {
        assert!((a - b).abs() < 1e-9);
    }
}

#[test]
fn the_measurement_is_the_same_on_any_number_of_threads() {
    let cell = MillCell::default_cell().unwrap();
    let p = plan(&cell, |_| 0.05, |i| -0.4 + 0.1 * ((i % 4) as f64 - 1.5));
    let one = scale(&cell, &p, &TrajectorySettings::default());
    for threads in [2, 3] {
        let many = scale(
            &cell,
            &p,
            &TrajectorySettings::default().with_threads(threads),
        );
        assert_eq!(one, many, "{threads} threads");
    }
    assert!(one.deviation.samples > 1000);
}

/// A plan whose g zig-zags between the two ends of a narrowed g range: the cubic spline through
/// its values would leave the range, so the smootherstep profile (which cannot) is used.
#[test]
fn g_at_the_edges_of_its_range_stays_in_range() {
    let default = MillCell::default_cell().unwrap();
    let mut limits = *default.state_limits();
    limits.redundancy_angle = [-0.5, -0.3];
    let cell = default.with_state_limits(limits).unwrap();
    let p = plan(&cell, |_| 0.04, |i| if i % 2 == 0 { -0.3 } else { -0.5 });
    let sc = scale(&cell, &p, &TrajectorySettings::default());
    assert!(matches!(sc.profiles.g, Profile::Step(_)));
    let length = cell.path().total_length();
    for k in 0..=4000 {
        let g = sc.profiles.g.eval(length * k as f64 / 4000.0).value;
        assert!((-0.5 - 1e-12..=-0.3 + 1e-12).contains(&g), "{g}");
    }
    assert!(sc.deviation.max_off_path <= 5e-5);
    // Inside the default range the spline is kept.
    let q = plan(&default, |_| 0.04, |i| if i % 2 == 0 { -0.3 } else { -0.5 });
    let sq = scale(&default, &q, &TrajectorySettings::default());
    assert!(matches!(sq.profiles.g, Profile::Cubic(_)));
}

#[test]
fn a_tighter_tolerance_needs_more_samples() {
    let cell = MillCell::default_cell().unwrap();
    let p = plan(&cell, |_| 0.06, |i| if i % 2 == 0 { -0.3 } else { -0.5 });
    let loose = scale(&cell, &p, &TrajectorySettings::default());
    let tight_settings = TrajectorySettings::default().with_path_tolerance(5e-6);
    let tight = scale(&cell, &p, &tight_settings);
    assert!(tight.trajectory.points().len() > loose.trajectory.points().len());
    let d = executed_deviation(&cell, &tight.trajectory, 0.004).unwrap();
    assert!(d.max_off_path <= 5e-6 && d.max_off_plane <= 5e-6, "{d:?}");
    // Too few points allowed for the tolerance: refused, not silently coarser.
    let few = TrajectorySettings::default()
        .with_path_tolerance(1e-7)
        .with_max_points(250);
    let e = time_scale(&cell, &p, &limits(&cell), &few, &Budget::unlimited()).unwrap_err();
    assert!(matches!(e, MillPlanError::NotExecutable { .. }), "{e}");
    assert!(e.to_string().contains("250 trajectory points"), "{e}");
}

#[test]
fn bad_inputs_are_refused() {
    let cell = MillCell::default_cell().unwrap();
    let p = plan(&cell, |_| 0.03, |_| -0.4);
    let l = limits(&cell);
    let run = |p: &Plan, l: &[JointLimit], s: &TrajectorySettings| {
        time_scale(&cell, p, l, s, &Budget::unlimited())
    };
    let ok = TrajectorySettings::default();
    for bad in [
        ok.with_path_tolerance(0.0),
        ok.with_path_tolerance(-1e-5),
        ok.with_path_tolerance(f64::NAN),
        ok.with_control_period(0.0),
        ok.with_ramp_time(f64::INFINITY),
        ok.with_max_points(2),
    ] {
        let e = run(&p, &l, &bad).unwrap_err();
        assert!(matches!(e, MillPlanError::InvalidParameter { .. }), "{e}");
    }
    let mut zero_feed = p.clone();
    zero_feed.segments[7].feed = 0.0;
    assert!(run(&zero_feed, &l, &ok)
        .unwrap_err()
        .to_string()
        .contains("segment 7"));
    let mut short = p.clone();
    short.segments.pop();
    assert!(run(&short, &l, &ok).is_err());
    assert!(run(&p, &l[..5], &ok).is_err());
    let mut no_speed = l.clone();
    no_speed[2].max_velocity = 0.0;
    assert!(run(&p, &no_speed, &ok).is_err());
    // A cancelled budget stops it.
    let token = kerf_budget::CancelToken::new();
    token.cancel();
    let budget = Budget::new(None, token);
    let e = time_scale(&cell, &p, &l, &ok, &budget).unwrap_err();
    assert!(matches!(e, MillPlanError::Interrupted(_)), "{e}");
}

#[test]
fn three_point_velocity_is_exact_on_parabolas() {
    let q = |t: f64| 0.3 - 1.2 * t + 2.5 * t * t;
    let dq = |t: f64| -1.2 + 5.0 * t;
    let (t, h1, h2) = (0.7, 0.13, 0.41);
    let v = three_point_velocity(h1, h2, q(t - h1), q(t), q(t + h2));
    assert!((v - dq(t)).abs() < 1e-12);
}
