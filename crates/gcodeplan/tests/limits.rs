//! Request numbers out of range (issue 33, item 3): NaN, ±inf, denormal and absurd limits are
//! refused by the request's own validation, naming the field, before anything is planned; and
//! the same limits given to the library directly (bypassing the request) end in a named
//! refusal of the budget, not in the allocator.
#![allow(clippy::unwrap_used)]

use std::time::{Duration, Instant};

use kerf_budget::{Budget, CancelToken};
use kerf_gcodeplan::{
    plan_program, plan_request, GcodePlanError, GcodeRequest, LaserSheet, LimitOverrides,
    MachineBase, MachineKind, PlanSettings,
};

const PROGRAM: &str = "G21 G90\nM3\nG1 X20 F3000\nG1 Y20\nG1 X0\nM5\n";

fn request() -> GcodeRequest {
    GcodeRequest {
        request_id: "limits".into(),
        program: Some(PROGRAM.into()),
        ..GcodeRequest::default()
    }
}

/// The refusal of `request`: InvalidRequest naming `field`, returned at once.
fn refused(request: &GcodeRequest, base: &MachineBase, field: &str) {
    let started = Instant::now();
    let Err(e) = plan_request(request, base, &Budget::unlimited()) else {
        panic!("{field}: planned");
    };
    assert!(
        started.elapsed() < Duration::from_secs(15),
        "hang guard: {field}"
    );
    match &e {
        GcodePlanError::InvalidRequest { field: f, .. } => {
            assert!(f.contains(field), "{field}: {e}")
        }
        other => panic!("{field}: expected InvalidRequest, got {other:?}"),
    }
    // The node's check before queueing refuses it too (the same validation).
    assert!(request.settings().is_err(), "{field}");
}

#[test]
fn non_finite_denormal_and_absurd_limits_are_refused_naming_the_field() {
    let laser = MachineBase::load(MachineKind::LaserCutter).unwrap();
    // The valid request plans (the refusals below are the numbers', nothing else's).
    plan_request(&request(), &laser, &Budget::unlimited()).unwrap();
    let bad = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        5e-324,
        1e-300,
        -1.0,
        0.0,
        1e308,
    ];
    type Set = fn(&mut LimitOverrides, f64);
    let fields: [(&str, Set); 7] = [
        ("limits.max_feed", |l, v| l.max_feed = Some(v)),
        ("limits.tangential_acceleration", |l, v| {
            l.tangential_acceleration = Some(v)
        }),
        ("limits.tangential_jerk", |l, v| l.tangential_jerk = Some(v)),
        ("limits.normal_acceleration", |l, v| {
            l.normal_acceleration = Some(v)
        }),
        ("limits.normal_jerk", |l, v| l.normal_jerk = Some(v)),
        ("limits.chord_error", |l, v| l.chord_error = Some(v)),
        ("limits.contour_error", |l, v| l.contour_error = Some(v)),
    ];
    for (field, set) in fields {
        for v in bad {
            let mut l = LimitOverrides::default();
            set(&mut l, v);
            let r = GcodeRequest {
                limits: Some(l),
                ..request()
            };
            refused(&r, &laser, field);
        }
    }
    for v in bad {
        refused(
            &GcodeRequest {
                rapid_feed: Some(v),
                ..request()
            },
            &laser,
            "rapid_feed",
        );
        if !(0.0..=1e5).contains(&v) {
            // 0 is "none of its own"; a tiny budget is a budget (answered TIMEOUT at once).
            refused(
                &GcodeRequest {
                    time_budget: Some(v),
                    ..request()
                },
                &laser,
                "time_budget",
            );
        }
        refused(
            &GcodeRequest {
                tolerance: Some(v),
                ..request()
            },
            &laser,
            "tolerance",
        );
    }
    // Placement numbers: NaN refused even where the field does not apply to the machine.
    for v in [f64::NAN, f64::INFINITY, 1e308] {
        refused(
            &GcodeRequest {
                redundancy_angle: Some(v),
                ..request()
            },
            &laser,
            "redundancy_angle",
        );
        refused(
            &GcodeRequest {
                origin: Some([0.0, v, 0.0]),
                ..request()
            },
            &laser,
            "origin",
        );
    }
    let irb = MachineBase::load(MachineKind::Irb6660).unwrap();
    let irb_request = || GcodeRequest {
        machine: "irb6660".into(),
        ..request()
    };
    plan_request(&irb_request(), &irb, &Budget::unlimited()).unwrap();
    for v in [f64::NAN, f64::NEG_INFINITY] {
        refused(
            &GcodeRequest {
                standoff_axis: Some(v),
                ..irb_request()
            },
            &irb,
            "standoff_axis",
        );
        refused(
            &GcodeRequest {
                limits: Some(LimitOverrides {
                    tangential_jerk: Some(5e-324),
                    ..LimitOverrides::default()
                }),
                redundancy_angle: Some(v),
                ..irb_request()
            },
            &irb,
            "limits.tangential_jerk",
        );
    }
}

#[test]
fn in_range_limits_still_plan() {
    let laser = MachineBase::load(MachineKind::LaserCutter).unwrap();
    let r = GcodeRequest {
        limits: Some(LimitOverrides {
            max_feed: Some(0.05),
            tangential_acceleration: Some(2.0),
            tangential_jerk: Some(20.0),
            ..LimitOverrides::default()
        }),
        time_budget: Some(60.0),
        ..request()
    };
    let plan = plan_request(&r, &laser, &Budget::unlimited()).unwrap();
    assert!(plan.duration > 0.0);
}

/// Denormal limits given to the library directly, past the request's validation: the budget's
/// estimates refuse what they would make (a feed of 5e-324 m/s: a plan of 10³²⁰ s), naming
/// it, before anything of that size is allocated.
#[test]
fn denormal_limits_past_the_request_end_in_a_named_refusal_of_the_budget() {
    let laser = LaserSheet::default_sheet().unwrap();
    type Set = fn(&mut PlanSettings);
    let cases: [(&str, Set); 3] = [
        ("max_feed", |s| s.limits.curvature.feed = 5e-324),
        ("tangential_acceleration", |s| {
            s.limits.tangential_acceleration = 5e-324
        }),
        ("tangential_jerk", |s| s.limits.tangential_jerk = 5e-324),
    ];
    for (name, set) in cases {
        let mut settings = PlanSettings::laser_cutter();
        set(&mut settings);
        let budget = Budget::new(Some(Duration::from_secs(10)), CancelToken::new())
            .with_memory(Some(256 << 20));
        let started = Instant::now();
        let e = plan_program(PROGRAM.as_bytes(), &laser, &settings, &budget).unwrap_err();
        assert!(started.elapsed() < Duration::from_secs(15), "hang guard");
        let text = e.to_string();
        eprintln!("{name}: {text}");
        assert!(
            matches!(
                e,
                GcodePlanError::Interrupted(kerf_budget::Interrupt::OverMemory { .. })
                    | GcodePlanError::TooManyPoints { .. }
                    | GcodePlanError::InvalidSetting { .. }
                    | GcodePlanError::Path { .. }
            ),
            "{name}: {e:?}"
        );
        assert_eq!(
            budget.memory_used(),
            0,
            "{name}: everything held is given back"
        );
    }
}

/// A program of comment lines makes no motion, yet its reading is under the deadline too
/// (without the check at every line it would be read whole and refused as empty).
#[test]
fn lines_without_motion_are_read_under_the_deadline() {
    let laser = LaserSheet::default_sheet().unwrap();
    let mut program = String::from("G21\n");
    for _ in 0..1_000_000 {
        program.push_str("(c)\n");
    }
    let settings = PlanSettings::laser_cutter();
    let budget = Budget::new(Some(Duration::ZERO), CancelToken::new());
    let started = Instant::now();
    let e = plan_program(program.as_bytes(), &laser, &settings, &budget).unwrap_err();
    assert!(started.elapsed() < Duration::from_secs(15), "hang guard");
    match &e {
        GcodePlanError::Interrupted(kerf_budget::Interrupt::TimedOut { stage, .. }) => {
            assert_eq!(*stage, "reading the program", "{e}")
        }
        other => panic!("{other:?}"),
    }
}
