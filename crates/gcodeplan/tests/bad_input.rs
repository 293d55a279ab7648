//! Bad programs and settings: each refused with the line or the setting
//! named, and the program modes that change how a path is cut.
#![allow(clippy::unwrap_used)]

use std::time::Duration;

use kerf_budget::{Budget, CancelToken};
use kerf_gcodeplan::{
    plan_program, GcodePlanError, LaserSheet, MillingPlane, PlanSettings, RunKind,
};
use kerf_toolpath::Sampling;

fn laser_plan(
    text: &str,
    settings: &PlanSettings,
) -> Result<kerf_gcodeplan::GcodePlan, GcodePlanError> {
    let laser = LaserSheet::default_sheet().unwrap();
    plan_program(text.as_bytes(), &laser, settings, &Budget::unlimited())
}

#[test]
fn a_point_out_of_the_stroke_names_its_line() {
    let e = laser_plan(
        "G21 G90\nG1 X100 F1000\nG1 X1500\n",
        &PlanSettings::laser_cutter(),
    )
    .unwrap_err();
    match e {
        GcodePlanError::Unreachable { line, reason, .. } => {
            assert_eq!(line, 3, "the motion that goes there");
            assert!(reason.contains("q1"), "{reason}");
        }
        other => panic!("{other}"),
    }
    let plane = MillingPlane::default_plane(0.0).unwrap();
    let e = plan_program(
        "G1 X5000 F600\n".as_bytes(),
        &plane,
        &PlanSettings::irb6660(),
        &Budget::unlimited(),
    )
    .unwrap_err();
    assert!(
        matches!(e, GcodePlanError::Unreachable { line: 1, .. }),
        "{e}"
    );
}

#[test]
fn reader_errors_keep_their_line_and_column() {
    let e = laser_plan("G21\nG1 X1 F100\nG93 X2\n", &PlanSettings::laser_cutter()).unwrap_err();
    assert!(
        matches!(e, GcodePlanError::Program(ref g) if g.line() == 3),
        "{e}"
    );
    assert!(e.to_string().contains("line 3"), "{e}");
    let e = laser_plan("G1 X1\n", &PlanSettings::laser_cutter()).unwrap_err();
    assert!(
        e.to_string().contains("line 1"),
        "a cut move without a feed: {e}"
    );
}

#[test]
fn text_after_the_program_end_is_refused_not_ignored() {
    let settings = PlanSettings::laser_cutter();
    let e = laser_plan("G21 G90\nG1 X10 F1000\nM2\nG1 X20\n", &settings).unwrap_err();
    assert!(
        matches!(e, GcodePlanError::Program(ref g) if g.line() == 4),
        "{e}"
    );
    assert!(e.to_string().contains("after the program end"), "{e}");
    assert_eq!(e.line(), 4);
    // Blank lines and comments after it are fine.
    laser_plan("G21 G90\nG1 X10 F1000\nM30\n\n(done)\n; end\n", &settings).unwrap();
}

#[test]
fn a_program_that_does_not_move_is_refused() {
    let e = laser_plan(
        "G21 G90\nG1 X0 Y0 F100\nM30\n",
        &PlanSettings::laser_cutter(),
    )
    .unwrap_err();
    assert!(matches!(e, GcodePlanError::Empty { .. }), "{e}");
    assert!(e.to_string().contains("zero-length moves: 1"), "{e}");
}

#[test]
fn bad_settings_are_named() {
    let program = "G1 X10 F600\n";
    for (settings, name) in [
        (
            PlanSettings::laser_cutter().with_tolerance(f64::NAN),
            "tolerance",
        ),
        (
            PlanSettings::laser_cutter().with_tolerance(0.0),
            "tolerance",
        ),
        (
            PlanSettings::laser_cutter().with_tolerance(0.05),
            "tolerance",
        ),
        (
            PlanSettings::laser_cutter().with_rapid_feed(-1.0),
            "rapid feed",
        ),
        (
            PlanSettings::laser_cutter().with_max_points(1),
            "max points",
        ),
        (
            PlanSettings {
                interpolation_share: 0.9,
                ..PlanSettings::laser_cutter()
            },
            "interpolation share",
        ),
        (
            PlanSettings {
                sampling: Sampling::Adaptive {
                    max_step: 1e-3,
                    max_turn: 0.0,
                },
                ..PlanSettings::laser_cutter()
            },
            "sample turn",
        ),
        (
            PlanSettings {
                sampling: Sampling::Fixed { step: -1e-5 },
                ..PlanSettings::laser_cutter()
            },
            "sample step",
        ),
        (
            PlanSettings {
                knot_spacing: 0.001,
                ..PlanSettings::laser_cutter()
            },
            "knot spacing",
        ),
    ] {
        let e = laser_plan(program, &settings).unwrap_err();
        match &e {
            GcodePlanError::InvalidSetting { name: n, .. } => assert!(n.starts_with(name), "{e}"),
            other => panic!("{name}: {other}"),
        }
    }
    let mut limits = PlanSettings::laser_cutter().limits;
    limits.tangential_jerk = 0.0;
    let e = laser_plan(
        program,
        &PlanSettings::laser_cutter().with_limits_of(limits),
    )
    .unwrap_err();
    assert!(e.to_string().contains("tangential jerk"), "{e}");
    // Arcs need a share of the tolerance for their chords.
    let settings = PlanSettings {
        approximation_share: 0.0,
        ..PlanSettings::laser_cutter()
    };
    let e = laser_plan("G1 X10 F600\nG3 X0 Y10 R10\n", &settings).unwrap_err();
    assert!(
        e.to_string().starts_with("line 2: an arc") && e.line() == 2,
        "{e}"
    );
    assert!(
        laser_plan(program, &settings).is_ok(),
        "no arc: a share of 0 is fine"
    );
}

#[test]
fn too_many_points_is_refused_not_truncated() {
    let settings = PlanSettings::laser_cutter().with_max_points(5);
    let e = laser_plan("G1 X100 F600\n", &settings).unwrap_err();
    assert!(matches!(e, GcodePlanError::TooManyPoints { max: 5 }), "{e}");
}

#[test]
fn a_program_longer_than_the_line_limit_is_refused_while_reading() {
    let settings = PlanSettings::laser_cutter().with_max_lines(3);
    let e = laser_plan("G1 X1 F600\nG1 X2\nG1 X3\nG1 X4\nG1 X5\n", &settings).unwrap_err();
    assert!(e.to_string().contains("more than 3 lines"), "{e}");
    // Issue 30, item 1: the refusal names the first line beyond the limit (its error line),
    // and lines that hold no motion count: comments past the limit are refused too.
    assert!(e.to_string().contains("line 4:"), "{e}");
    assert_eq!(e.line(), 4);
    for text in [
        "G1 X1 F600\nG1 X2\nG1 X3\n(comment)\n(comment)\n",
        "G1 X1 F600\n(comment)\n(comment)\n(comment)\n(comment)\nG1 X2\n",
    ] {
        let e = laser_plan(text, &settings).unwrap_err();
        assert_eq!(e.line(), 4, "{text:?}: {e}");
        assert!(e.to_string().contains("line 4:"), "{e}");
    }
    assert!(laser_plan("G1 X1 F600\nG1 X2\nG1 X3\n", &settings).is_ok());
    let e = laser_plan(
        "G1 X1 F600\n",
        &PlanSettings::laser_cutter().with_max_lines(0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("max lines"), "{e}");
}

#[test]
fn an_arc_needing_more_chords_than_points_is_refused() {
    let settings = PlanSettings::laser_cutter().with_max_points(100);
    // A full circle of 100 m radius within 10 um needs 2 222 chords.
    let e = laser_plan("G1 X1 F600\nG2 X1 Y0 I100000 J0\n", &settings).unwrap_err();
    assert!(e.to_string().contains("line 2: the arc of radius"), "{e}");
}

#[test]
fn a_feed_above_the_machine_is_planned_at_its_maximum_and_said() {
    // 20 m/min asked; the laser cutter's default cuts at most 10 m/min.
    let plan = laser_plan("M3\nG1 X100 F20000\n", &PlanSettings::laser_cutter()).unwrap();
    assert!((plan.runs[0].feed - 10.0 / 60.0).abs() < 1e-12);
    assert!(
        plan.warnings
            .iter()
            .any(|w| w.contains("above the machine's")),
        "{:?}",
        plan.warnings
    );
}

#[test]
fn reversals_exact_path_and_blend_tolerances_shape_the_runs() {
    let settings = PlanSettings::laser_cutter();
    // A reversal stops the machine: two runs.
    let plan = laser_plan("G1 X10 F600\nG1 X0\n", &settings).unwrap();
    assert_eq!(plan.runs.len(), 2);
    assert!(plan.runs.iter().all(|r| r.kind == RunKind::Travel));
    // G61: a stop at every vertex, no corner smoothed.
    let plan = laser_plan("G61\nG1 X10 F600\nG1 Y10\nG1 X0\n", &settings).unwrap();
    assert_eq!(plan.runs.len(), 3);
    assert!(plan.runs.iter().all(|r| r.corners == 0));
    // G64 P0.01 (mm): corners within 10 um, below the planner's 70 um.
    let plan = laser_plan("G64 P0.01\nG1 X10 F600\nG1 Y10\nG1 X0\n", &settings).unwrap();
    assert_eq!(plan.runs.len(), 1);
    assert_eq!(plan.runs[0].corners, 2);
    assert!((plan.runs[0].corner_tolerance - 1e-5).abs() < 1e-18);
    assert!(plan.max_corner_deviation <= 1e-5 + 1e-15);
    // Without G64 P: the planner's corner tolerance, 70 % of 0.1 mm.
    let plan = laser_plan("G1 X10 F600\nG1 Y10\nG1 X0\n", &settings).unwrap();
    assert!((plan.runs[0].corner_tolerance - 7e-5).abs() < 1e-15);
    assert!(plan.max_corner_deviation > 0.5 * 7e-5);
    // A change of feed does not stop the machine: one run, each segment at its own F.
    let plan = laser_plan("G1 X10 F600\nG1 Y10 F300\n", &settings).unwrap();
    assert_eq!(plan.runs.len(), 1);
    let run = &plan.timed[0];
    let mut fastest_second: f64 = 0.0;
    for s in run.plan.sample(0.001) {
        let point = kerf_toolpath::point_at(&run.path, &run.samples, s.s);
        // Past the corner's reach (70 um), on the second segment: 5 mm/s at most.
        if point[1] > 1e-3 {
            fastest_second = fastest_second.max(s.v);
        }
        assert!(s.v <= 0.01 + 1e-12, "{s:?}");
    }
    assert!(
        fastest_second <= 0.005 + 1e-12 && fastest_second > 0.0049,
        "{fastest_second}"
    );
}

#[test]
fn a_cancelled_or_expired_budget_stops_the_plan() {
    let laser = LaserSheet::default_sheet().unwrap();
    let token = CancelToken::new();
    token.cancel();
    let budget = Budget::new(None, token);
    let e = plan_program(
        "G1 X10 F600\n".as_bytes(),
        &laser,
        &PlanSettings::laser_cutter(),
        &budget,
    )
    .unwrap_err();
    assert!(matches!(e, GcodePlanError::Interrupted(_)), "{e}");
    let budget = Budget::new(Some(Duration::ZERO), CancelToken::new());
    let e = plan_program(
        "G1 X10 F600\n".as_bytes(),
        &laser,
        &PlanSettings::laser_cutter(),
        &budget,
    )
    .unwrap_err();
    assert!(e.to_string().contains("time budget"), "{e}");
}

#[test]
fn an_unknown_machine_or_method_is_named() {
    use kerf_gcodeplan::{GcodeRequest, MachineKind};
    let request = GcodeRequest {
        machine: "drill".into(),
        program: Some("G1 X1 F100".into()),
        ..GcodeRequest::default()
    };
    let e = request.settings().unwrap_err();
    assert!(e.to_string().contains("machine 'drill'"), "{e}");
    assert!(e.to_string().contains("laser-cutter or irb6660"), "{e}");
    assert!(MachineKind::parse("irb6660").is_ok());
    let request = GcodeRequest {
        feed_method: Some("fast".into()),
        program: Some("G1 X1 F100".into()),
        ..GcodeRequest::default()
    };
    let e = request.settings().unwrap_err();
    assert!(e.to_string().contains("feed_method 'fast'"), "{e}");
    // A field of the other machine is refused, not ignored.
    let request = GcodeRequest {
        redundancy_angle: Some(0.3),
        program: Some("G1 X1 F100".into()),
        ..GcodeRequest::default()
    };
    let e = request.settings().unwrap_err();
    assert!(e.to_string().contains("other machine"), "{e}");
}
