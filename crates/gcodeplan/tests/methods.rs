//! Every corner method of the G-code front end (`METHODS`) on one program: planned, its
//! corners within δ_c, the executed tip within δ of the program by the URDF's forward
//! kinematics; and the `drls-net` method's fallbacks counted (issue 30, item 3).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

use kerf_budget::Budget;
use kerf_cornernet::{DrlsNet, Source};
use kerf_gcodeplan::{
    committed_network, corner_method, load_network, plan_program, plan_program_with, GcodePlan,
    GcodePlanError, LaserSheet, PlanSettings, DRLS_NET, METHODS,
};
use nalgebra::Isometry3;
use support::{distance, execute, shapes, tips};

/// A square with a rounded corner and a second contour of four corners (7 corners of 90°
/// and less, each with millimetres on either side: inside the trained distribution).
const PROGRAM: &str = "\
G21 G90 G17
G0 X0 Y0
M3
G1 X20 Y0 F3000
G1 X20 Y15
G3 X15 Y20 I-5 J0
G1 X0 Y20
G1 X0 Y0
M5
G0 X30 Y0
M3
G1 X40 Y0 F1500
G1 X45 Y8
G1 X30 Y10
G1 X30 Y0
M5
";

fn settings(method: &str) -> PlanSettings {
    PlanSettings::laser_cutter()
        .with_corner_method(corner_method(method).unwrap())
        .with_learned_corners(method == DRLS_NET)
}

fn plan(program: &str, method: &str) -> GcodePlan {
    let laser = LaserSheet::default_sheet().unwrap();
    plan_program(
        program.as_bytes(),
        &laser,
        &settings(method),
        &Budget::unlimited(),
    )
    .unwrap_or_else(|e| panic!("{method}: {e}"))
}

/// The executed tip's largest distance from the program.
fn executed_worst(program: &str, plan: &GcodePlan) -> f64 {
    let laser = LaserSheet::default_sheet().unwrap();
    let robot = kerf_gcodeplan::Machine::robot(&laser);
    let executed = execute(robot, plan);
    let origin = laser.origin();
    let tip = tips(robot, &executed, &Isometry3::identity(), |p| {
        [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]]
    });
    let geometry = shapes(program);
    tip.iter()
        .map(|p| distance(&geometry, *p))
        .fold(0.0, f64::max)
}

/// The corners of a plan (transitions built).
fn corners(plan: &GcodePlan) -> usize {
    plan.runs.iter().map(|r| r.corners).sum()
}

#[test]
fn every_method_plans_within_the_tolerance() {
    assert!(METHODS.contains(&DRLS_NET));
    for method in METHODS {
        let plan = plan(PROGRAM, method);
        let s = settings(method);
        assert!(corners(&plan) >= 7, "{method}: {} corners", corners(&plan));
        assert!(
            plan.max_corner_deviation <= s.corner_tolerance() * (1.0 + 1e-9),
            "{method}: corner deviation {:e} above δ_c {:e}",
            plan.max_corner_deviation,
            s.corner_tolerance()
        );
        let worst = executed_worst(PROGRAM, &plan);
        assert!(
            worst <= plan.tolerance,
            "{method}: the executed tip is {worst:.3e} m from the program (δ {:.1e})",
            plan.tolerance
        );
        assert!(plan.max_interpolation_deviation <= s.interpolation_tolerance());
        if *method == DRLS_NET {
            // Every corner is the network's or the swarm's, and the in-distribution corners
            // of this program are the network's.
            assert_eq!(
                plan.corner_predictions + plan.corner_fallbacks,
                corners(&plan)
            );
            assert!(
                plan.corner_predictions >= 7,
                "{} predicted, {} fell back: {:?}",
                plan.corner_predictions,
                plan.corner_fallbacks,
                plan.warnings
            );
        } else {
            assert_eq!((plan.corner_predictions, plan.corner_fallbacks), (0, 0));
        }
    }
}

/// The plan's counts are the predictor's own on the same polylines, tolerances and lengths.
#[test]
fn drls_net_counts_are_the_predictors() {
    let model = committed_network().unwrap();
    let laser = LaserSheet::default_sheet().unwrap();
    let program = format!("{PROGRAM}M3\nG1 X40 Y0.02 F1500\nG1 X49 Y0.1\nG1 X30 Y0.4\nM5\n");
    let plan = plan_program_with(
        program.as_bytes(),
        &laser,
        &settings(DRLS_NET),
        model,
        &Budget::unlimited(),
    )
    .unwrap();
    let mut net = DrlsNet::new(model.clone());
    let mut fell_back = 0;
    for timed in &plan.timed {
        let path = &timed.path;
        kerf_toolpath::smooth_polyline_by(
            &path.polyline,
            path.tolerance,
            &Budget::unlimited(),
            |prev, vertex, next, tolerance, available, index| {
                let c = net
                    .transition_within(
                        prev,
                        vertex,
                        next,
                        tolerance,
                        available,
                        index,
                        &Budget::unlimited(),
                    )
                    .unwrap();
                fell_back += usize::from(matches!(c.source, Source::Fallback(_)));
                Ok(c.transition)
            },
        )
        .unwrap();
    }
    let counts = net.counts();
    assert_eq!(plan.corner_fallbacks, counts.fallback);
    assert_eq!(plan.corner_fallbacks, fell_back);
    assert_eq!(plan.corner_predictions, counts.network);
    assert!(plan.corner_fallbacks >= 1, "the 179° corner falls back");
}

/// A corner turning by more than the trained 175°, and corners with less length than 2 δ_c on
/// a side, fall back to the swarm, are counted, and stay within δ.
#[test]
fn corners_outside_the_trained_distribution_fall_back_and_are_counted() {
    // Turn 180° − atan(0.4 / 20) = 178.85°.
    let sharp = "G21 G90\nM3\nG1 X20 F3000\nG1 X0 Y0.4\nM5\n";
    // Two 90° corners around a 0.04 mm segment: A / δ_c = 0.02 / 0.07 < 2.
    let tiny = "G21 G90\nM3\nG1 X20 F3000\nG1 X20 Y0.04\nG1 X40 Y0.04\nM5\n";
    for (program, fallbacks, says) in [
        (sharp, 1, "turning angle"),
        (tiny, 2, "available / tolerance"),
    ] {
        let plan = plan(program, DRLS_NET);
        assert_eq!(plan.corner_fallbacks, fallbacks, "{program:?}");
        assert_eq!(plan.corner_predictions, 0, "{program:?}");
        assert_eq!(corners(&plan), fallbacks);
        let warning = plan
            .warnings
            .iter()
            .find(|w| w.starts_with("drls-net"))
            .unwrap_or_else(|| panic!("{:?}", plan.warnings));
        assert!(
            warning.contains(&format!("{fallbacks} of {fallbacks} corners"))
                && warning.contains(says),
            "{warning}"
        );
        let s = settings(DRLS_NET);
        assert!(plan.max_corner_deviation <= s.corner_tolerance() * (1.0 + 1e-9));
        let worst = executed_worst(program, &plan);
        assert!(worst <= plan.tolerance, "{program:?}: {worst:.3e}");
    }
}

/// A missing or unreadable network is refused naming the method and the file.
#[test]
fn a_bad_network_file_is_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("kerf_methods_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("none.safetensors");
    let e = load_network(&missing).unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, GcodePlanError::InvalidRequest { .. }), "{e:?}");
    assert!(
        text.contains("method drls-net") && text.contains("none.safetensors"),
        "{text}"
    );
    // A sidecar of another format.
    let bad = dir.join("bad.safetensors");
    std::fs::write(&bad, b"not a tensor file").unwrap();
    std::fs::write(dir.join("bad.json"), b"{\"format\": \"other\"}").unwrap();
    let text = load_network(&bad).unwrap_err().to_string();
    assert!(text.contains("refused network file"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}
