//! Milling requests (kerf_millplan::request) and the planner's bad-input
//! answers (issue 5 section 5): every bad input gets the right error, a
//! clear message naming the field, and its status category.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking
#![allow(clippy::field_reassign_with_default)]

use std::path::PathBuf;
use std::sync::OnceLock;

use kerf_mill::MillError;
use kerf_millplan::ddpg::DdpgSettings;
use kerf_millplan::nets::{Mlp, OutputActivation};
use kerf_millplan::planner::{status, status_name};
use kerf_millplan::policy::{PolicyMetadata, POLICY_FORMAT};
use kerf_millplan::request::{
    RequestInitial, RequestLimits, RequestProcess, RequestStepBounds, RequestTolerances,
};
use kerf_millplan::rng::Rng;
use kerf_millplan::timing::Entry;
use kerf_millplan::{
    default_policy_path, status_of, MillPlanError, MillPlanner, MillRequest, PlannerKind, Policy,
};

fn planner() -> &'static MillPlanner {
    static P: OnceLock<MillPlanner> = OnceLock::new();
    P.get_or_init(|| MillPlanner::with_default_cell().expect("planner"))
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "kerf_millplan_request_{name}_{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A saved random actor with the given sizes.
fn saved_actor(dir: &std::path::Path, obs: usize, act: usize) -> PathBuf {
    let hidden = vec![8, 8];
    let mut rng = Rng::new(3);
    let net = Mlp::new(&[obs, 8, 8, act], OutputActivation::Tanh, &mut rng).expect("actor");
    let metadata = PolicyMetadata {
        format: POLICY_FORMAT.to_string(),
        crate_version: env!("CARGO_PKG_VERSION").to_string(),
        observation_dim: obs,
        action_dim: act,
        hidden_sizes: hidden.clone(),
        seed: 3,
        settings: DdpgSettings::default().with_hidden_sizes(hidden),
        environment: format!("test actor {obs}x{act}"),
        episodes: 0,
        final_reward: None,
        observation_layout: Vec::new(),
    };
    let mut policy = Policy::from_actor(&net, metadata).expect("policy");
    let path = dir.join(format!("actor_{obs}_{act}.safetensors"));
    policy.save(&path).expect("save");
    path
}

fn full_request() -> MillRequest {
    MillRequest {
        start: Default::default(),
        request_id: "job-17".to_string(),
        points: vec![[1.4, -0.3, 1.7], [1.7, 0.0, 1.7], [2.0, 0.2, 1.7]],
        segments: Some(40),
        process: Some(RequestProcess {
            teeth: 3,
            tool_radius: 0.02,
            axial_depth: 0.002,
            kt: 6.0e8,
            kn: 2.0e8,
            entry_angle: 2.0,
            exit_angle: 3.0,
        }),
        limits: Some(RequestLimits {
            spindle_rpm: Some([2000.0, 3000.0]),
            feed: None,
            redundancy_angle: Some([-1.0, 1.5]),
            step_bounds: Some(RequestStepBounds {
                spindle_rpm: Some(10.0),
                feed: None,
                redundancy_angle: Some(0.1),
            }),
        }),
        initial: Some(RequestInitial {
            spindle_rpm: Some(2500.0),
            feed: None,
            g: Some(0.5),
        }),
        planner: "fixed_g".to_string(),
        allow_chatter: true,
        entry: Some("in_material".to_string()),
        policy_file: Some("policies/x.safetensors".to_string()),
        time_budget: Some(12.5),
        tolerances: Some(RequestTolerances {
            path_tolerance: Some(2e-5),
            min_condition_indicator: Some(0.25),
        }),
    }
}

#[test]
fn yaml_and_json_round_trip_and_unknown_fields() {
    let r = full_request();
    r.validate().expect("valid");
    let yaml = r.to_yaml_string().expect("yaml");
    println!("{yaml}");
    assert_eq!(MillRequest::from_yaml_str(&yaml).expect("parse"), r);
    let json = serde_json::to_string(&r).expect("json");
    assert_eq!(MillRequest::from_json_str(&json).expect("parse"), r);
    assert_eq!(r.initial_state(), [2500.0, 0.04, 0.5]);
    assert_eq!(r.planner_kind().expect("kind"), PlannerKind::FixedG);
    // Minimal request: defaults.
    let min = MillRequest::from_yaml_str("points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n")
        .expect("minimal");
    assert_eq!(min.planner, "best");
    assert!(!min.allow_chatter);
    assert_eq!(min.entry().expect("entry"), Entry::RunIn);
    assert_eq!(min.initial_state(), [2000.0, 0.04, 0.0]);
    assert_eq!(min.request_id, "");
    min.validate().expect("valid");
    // Unknown field, at any level.
    for text in [
        "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nspeed: 3\n",
        "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nlimits: {feeed: [0, 1]}\n",
    ] {
        let e = MillRequest::from_yaml_str(text).expect_err("unknown field");
        assert!(matches!(e, MillPlanError::InvalidConfig { .. }));
        assert!(e.to_string().contains("unknown field"), "{e}");
        assert_eq!(status_of(&e), status::INVALID_REQUEST);
    }
}

fn expect_invalid(r: &MillRequest, field: &str, words: &str) -> MillPlanError {
    let e = r.validate().expect_err(field);
    let msg = e.to_string();
    match &e {
        MillPlanError::InvalidParameter { name, .. }
        | MillPlanError::InvalidConfig { name, .. } => {
            assert_eq!(name, field, "{msg}")
        }
        other => panic!("{field}: unexpected {other:?}"),
    }
    assert!(msg.contains(words), "{field}: {msg}");
    assert_eq!(status_of(&e), status::INVALID_REQUEST);
    e
}

#[test]
fn fewer_than_two_points_repeated_points_and_zero_segments() {
    let mut r = MillRequest::default();
    r.points.truncate(1);
    expect_invalid(&r, "points (count)", "at least 2 points");
    r.points.clear();
    expect_invalid(&r, "points (count)", "at least 2 points");
    let mut r = MillRequest::default();
    r.points[2] = r.points[1];
    expect_invalid(&r, "points[2]", "repeats points[1]");
    let r = MillRequest {
        segments: Some(0),
        ..MillRequest::default()
    };
    expect_invalid(&r, "segments", "1..=10000");
    let r = MillRequest {
        segments: Some(10_001),
        ..MillRequest::default()
    };
    expect_invalid(&r, "segments", "1..=10000");
}

/// Square corners in z = 1.7 and the centre lifted by h = 1 mm: the
/// best-fit plane is z = 1.7 + h/5 by symmetry, the worst point the centre
/// (index 2) at 4h/5 = 0.8 mm.
#[test]
fn not_planar_names_the_worst_point_and_its_distance() {
    let r = MillRequest {
        points: vec![
            [1.5, -0.1, 1.7],
            [1.7, -0.1, 1.7],
            [1.6, 0.0, 1.701],
            [1.7, 0.1, 1.7],
            [1.5, 0.1, 1.7],
        ],
        ..MillRequest::default()
    };
    let e = r.validate().expect_err("not planar");
    match &e {
        MillPlanError::Mill(MillError::NotCoplanar {
            worst_point,
            distance,
            ..
        }) => {
            assert_eq!(*worst_point, 2);
            assert!((distance - 8e-4).abs() < 1e-12, "{distance}");
        }
        other => panic!("unexpected {other:?}"),
    }
    let msg = e.to_string();
    assert!(
        msg.contains("not coplanar") && msg.contains("point 2"),
        "{msg}"
    );
    assert_eq!(status_of(&e), status::INVALID_REQUEST);
    // Through the planner too.
    let e = planner().plan(&r).expect_err("not planar");
    assert_eq!(status_of(&e), status::INVALID_REQUEST);
}

#[test]
fn nan_anywhere_is_refused_by_name() {
    // From YAML text (.nan), as the text topic would carry it.
    let r = MillRequest::from_yaml_str(
        "points: [[1.4, -0.3, 1.7], [1.6, -0.1, .nan], [2.1, 0.3, 1.7]]\n",
    )
    .expect("parses");
    expect_invalid(&r, "points[1][2] [m]", "finite");
    let mut r = MillRequest::default();
    r.limits = Some(RequestLimits {
        feed: Some([0.0, f64::NAN]),
        ..RequestLimits::default()
    });
    expect_invalid(&r, "limits.feed [m/s][1]", "finite");
    let mut r = MillRequest::default();
    r.initial = Some(RequestInitial {
        g: Some(f64::NAN),
        ..RequestInitial::default()
    });
    expect_invalid(&r, "initial.g [rad]", "finite");
    let mut r = full_request();
    if let Some(p) = r.process.as_mut() {
        p.kt = f64::INFINITY;
    }
    expect_invalid(&r, "process.kt [N/m^2]", "finite");
    let mut r = MillRequest::default();
    r.limits = Some(RequestLimits {
        step_bounds: Some(RequestStepBounds {
            feed: Some(f64::NAN),
            ..RequestStepBounds::default()
        }),
        ..RequestLimits::default()
    });
    expect_invalid(&r, "limits.step_bounds.feed [m/s]", "> 0");
    // Through the planner: the same error and status.
    let e = planner()
        .plan(
            &MillRequest::from_yaml_str("points: [[1.4, -0.3, 1.7], [.nan, 0.3, 1.7]]\n")
                .expect("parses"),
        )
        .expect_err("nan");
    assert_eq!(status_of(&e), status::INVALID_REQUEST);
    assert!(e.to_string().contains("points[1][0]"), "{e}");
}

#[test]
fn limits_min_above_max_and_other_limit_errors() {
    let with = |limits: RequestLimits| MillRequest {
        limits: Some(limits),
        ..MillRequest::default()
    };
    expect_invalid(
        &with(RequestLimits {
            feed: Some([0.05, 0.01]),
            ..RequestLimits::default()
        }),
        "limits.feed [m/s][0]",
        "min > max",
    );
    expect_invalid(
        &with(RequestLimits {
            spindle_rpm: Some([4000.0, 2000.0]),
            ..RequestLimits::default()
        }),
        "limits.spindle_rpm [rpm][0]",
        "min > max",
    );
    expect_invalid(
        &with(RequestLimits {
            spindle_rpm: Some([0.0, 2000.0]),
            ..RequestLimits::default()
        }),
        "limits.spindle_rpm [rpm][0]",
        "> 0",
    );
    expect_invalid(
        &with(RequestLimits {
            feed: Some([0.03, 0.03]),
            ..RequestLimits::default()
        }),
        "limits.feed [m/s][1]",
        "empty range",
    );
    expect_invalid(
        &with(RequestLimits {
            redundancy_angle: Some([1.0, -1.0]),
            ..RequestLimits::default()
        }),
        "limits.redundancy_angle [rad][0]",
        "min > max",
    );
    expect_invalid(
        &with(RequestLimits {
            redundancy_angle: Some([-1.0, 4.0]),
            ..RequestLimits::default()
        }),
        "limits.redundancy_angle [rad][1]",
        "<=",
    );
    expect_invalid(
        &with(RequestLimits {
            step_bounds: Some(RequestStepBounds {
                spindle_rpm: Some(0.0),
                ..RequestStepBounds::default()
            }),
            ..RequestLimits::default()
        }),
        "limits.step_bounds.spindle_rpm [rpm]",
        "> 0",
    );
    // The initial state outside the request's limits, and (validate_with)
    // outside the cell's.
    let mut r = with(RequestLimits {
        spindle_rpm: Some([2500.0, 3000.0]),
        ..RequestLimits::default()
    });
    expect_invalid(&r, "initial.spindle_rpm [rpm]", "outside the limits");
    r.limits = None;
    r.initial = Some(RequestInitial {
        feed: Some(0.08),
        ..RequestInitial::default()
    });
    r.validate().expect("no limits in the request");
    let e = planner()
        .plan(&r)
        .expect_err("outside the cell's feed range");
    assert_eq!(status_of(&e), status::INVALID_REQUEST);
    assert!(e.to_string().contains("initial.feed"), "{e}");
    // Unknown planner.
    let r = MillRequest {
        planner: "sarsa".to_string(),
        ..MillRequest::default()
    };
    expect_invalid(&r, "planner", "unknown planner `sarsa`");
}

/// A path 5 m from the robot: UNREACHABLE with the segment; one far point
/// in the middle of the seed path: the first segment without any feasible g
/// is reported, and every earlier segment has one.
#[test]
fn unreachable_points_give_the_segment() {
    let far = MillRequest {
        points: vec![[6.4, -0.1, 1.7], [6.6, 0.1, 1.7]],
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    let e = planner().plan(&far).expect_err("unreachable");
    assert_eq!(status_of(&e), status::UNREACHABLE);
    match &e {
        MillPlanError::Mill(MillError::Unreachable {
            segment,
            distance_beyond_reach,
            ..
        }) => {
            assert_eq!(*segment, Some(0));
            assert!(*distance_beyond_reach > 2.0, "{distance_beyond_reach}");
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(e.to_string().contains("segment 0"), "{e}");

    let mut middle = MillRequest::default();
    middle.points[2] = [6.8, 0.1, 1.7];
    let e = planner().plan(&middle).expect_err("unreachable");
    assert_eq!(status_of(&e), status::UNREACHABLE);
    let k = match &e {
        MillPlanError::Mill(MillError::Unreachable { segment, .. })
        | MillPlanError::Mill(MillError::JointLimit { segment, .. }) => segment.expect("segment"),
        other => panic!("unexpected {other:?}"),
    };
    println!("far middle point: {e}");
    assert!(k > 0, "{k}");
    let cell = planner()
        .cell()
        .with_path(&middle.path_spec(100))
        .expect("cell");
    let reach = |seg: usize| (-30..=30).any(|i| cell.evaluate(seg, i as f64 * 0.1, None).is_ok());
    assert!((0..k).all(reach));
    assert!(!reach(k));
}

#[test]
fn missing_and_incompatible_policy_files() {
    let dir = temp_dir("policies");
    let ddpg = |file: &PathBuf, kind: &str| MillRequest {
        planner: kind.to_string(),
        policy_file: Some(file.display().to_string()),
        ..MillRequest::default()
    };
    // Missing file.
    let missing = dir.join("nope.safetensors");
    let e = planner()
        .plan(&ddpg(&missing, "ddpg"))
        .expect_err("missing");
    assert_eq!(status_of(&e), status::POLICY_ERROR);
    assert!(matches!(e, MillPlanError::Policy { .. }));
    assert!(e.to_string().contains("not found"), "{e}");
    assert!(e.to_string().contains("nope.safetensors"), "{e}");
    // Wrong observation size.
    let obs5 = saved_actor(&dir, 5, 3);
    let e = planner().plan(&ddpg(&obs5, "ddpg")).expect_err("obs 5");
    assert_eq!(status_of(&e), status::POLICY_ERROR);
    assert!(
        e.to_string().contains("observations of 5") && e.to_string().contains("has 37 and 3"),
        "{e}"
    );
    // The same file named by a file:// URI is resolved and loaded (then refused alike); a
    // URI of another scheme is refused naming it.
    let by_uri = |uri: String| MillRequest {
        policy_file: Some(uri),
        ..ddpg(&obs5, "ddpg")
    };
    let e = planner()
        .plan(&by_uri(format!("file://{}", obs5.display())))
        .expect_err("obs 5 by URI");
    assert!(e.to_string().contains("observations of 5"), "{e}");
    let e = planner()
        .plan(&by_uri("http://host/x.safetensors".to_string()))
        .expect_err("http");
    assert_eq!(status_of(&e), status::POLICY_ERROR);
    assert!(
        e.to_string()
            .contains("policy http://host/x.safetensors: URI scheme 'http://'"),
        "{e}"
    );
    // Wrong action size: a 3-action (ddpg) policy for fixed_g (2 actions).
    let act3 = saved_actor(&dir, 4, 3);
    let e = planner().plan(&ddpg(&act3, "fixed_g")).expect_err("act 3");
    assert_eq!(status_of(&e), status::POLICY_ERROR);
    assert!(e.to_string().contains("actions of 3"), "{e}");
    // A corrupt weights file.
    let corrupt = dir.join("corrupt.safetensors");
    std::fs::write(&corrupt, b"not safetensors").expect("write");
    std::fs::copy(obs5.with_extension("json"), corrupt.with_extension("json")).expect("copy");
    let e = planner()
        .plan(&ddpg(&corrupt, "ddpg"))
        .expect_err("corrupt");
    assert_eq!(status_of(&e), status::POLICY_ERROR);
    // The default policy path; while the shipped policy is absent, a
    // request without a policy file names it.
    let default = default_policy_path(PlannerKind::Ddpg).expect("path");
    assert!(default.ends_with("policies/ddpg.safetensors"));
    assert!(default.starts_with(env!("CARGO_MANIFEST_DIR")));
    assert!(default_policy_path(PlannerKind::FixedG)
        .expect("path")
        .ends_with("policies/fixed_g.safetensors"));
    assert_eq!(default_policy_path(PlannerKind::Dp), None);
    if !default.exists() {
        let e = planner()
            .plan(&MillRequest::default())
            .expect_err("no shipped policy yet");
        assert_eq!(status_of(&e), status::POLICY_ERROR);
        assert!(e.to_string().contains("ddpg.safetensors"), "{e}");
    }
}

/// Tolerances: a path tolerance <= 0, NaN or above 1 mm and a minimum condition indicator
/// outside [0, 1) are refused by name; a minimum the plan cannot meet is ILL_CONDITIONED with
/// the value and where; a tighter path tolerance is met and reported.
#[test]
fn tolerances_are_validated_and_enforced() {
    for (tolerance, words) in [
        (0.0, "must be > 0"),
        (-1e-5, "must be > 0"),
        (f64::NAN, "must be > 0"),
        (2e-3, "at most 0.001 m"),
    ] {
        let r = MillRequest {
            tolerances: Some(RequestTolerances {
                path_tolerance: Some(tolerance),
                min_condition_indicator: None,
            }),
            ..MillRequest::default()
        };
        expect_invalid(&r, "tolerances.path_tolerance [m]", words);
    }
    for value in [-0.1, 1.0, f64::INFINITY] {
        let r = MillRequest {
            tolerances: Some(RequestTolerances {
                path_tolerance: None,
                min_condition_indicator: Some(value),
            }),
            ..MillRequest::default()
        };
        expect_invalid(&r, "tolerances.min_condition_indicator", "[0, 1)");
    }
    // The naive plan's smallest 1/K along its trajectory, then a minimum just above it.
    let naive = MillRequest {
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    let out = planner().plan(&naive).expect("naive");
    let (lowest, at) = out.executed.scaling.min_condition_indicator;
    assert!(
        lowest > 0.0 && lowest < 1.0 && (0.0..=0.9).contains(&at),
        "{lowest} at {at}"
    );
    let strict = MillRequest {
        tolerances: Some(RequestTolerances {
            path_tolerance: Some(1e-5),
            min_condition_indicator: Some(lowest + 0.01),
        }),
        ..naive.clone()
    };
    let e = planner().plan(&strict).expect_err("below the minimum");
    assert_eq!(status_of(&e), status::ILL_CONDITIONED, "{e}");
    let text = e.to_string();
    assert!(
        text.contains(&format!("{lowest:.4}")) && text.contains("arc length"),
        "{text}"
    );
    // Just below it: planned, within the tighter path tolerance.
    let met = MillRequest {
        tolerances: Some(RequestTolerances {
            path_tolerance: Some(1e-5),
            min_condition_indicator: Some(lowest - 0.01),
        }),
        ..naive
    };
    let out = planner().plan(&met).expect("met");
    assert_eq!(out.executed.settings.path_tolerance, 1e-5);
    let d = out.executed.scaling.deviation;
    assert!(d.max_off_path <= 1e-5 && d.max_off_plane <= 1e-5, "{d:?}");
}

#[test]
fn status_values_and_names() {
    assert_eq!(
        [
            status::SUCCESS,
            status::INVALID_REQUEST,
            status::UNREACHABLE,
            status::POLICY_ERROR,
            status::CHATTER_MODEL_ERROR,
            status::INTERNAL_ERROR,
            status::TIMEOUT,
            status::ILL_CONDITIONED
        ],
        [0, 1, 2, 3, 4, 6, 7, 8]
    );
    assert_eq!(status_name(8), Some("ILL_CONDITIONED"));
    assert_eq!(status_name(2), Some("UNREACHABLE"));
    assert_eq!(status_name(5), None);
    // Issue 28 (10 is the node's NO_APPROACH).
    assert_eq!((status::CHATTER, status::INFEASIBLE), (11, 12));
    assert_eq!(status_name(11), Some("CHATTER"));
    assert_eq!(status_name(12), Some("INFEASIBLE"));
    assert_eq!(status_name(10), None);
    let infeasible = MillPlanError::Infeasible {
        planner: "fixed_g".to_string(),
        reason: "x".to_string(),
    };
    assert_eq!(status_of(&infeasible), status::INFEASIBLE);
    assert_eq!(infeasible.to_string(), "fixed_g: no plan on this path: x");
    let chatter = kerf_chatter::ChatterError::NotConverged {
        what: "x".to_string(),
        iterations: 3,
        residual: 1.0,
    };
    assert_eq!(
        status_of(&MillPlanError::Chatter(chatter)),
        status::CHATTER_MODEL_ERROR
    );
    assert_eq!(
        status_of(&MillPlanError::Backend("x".to_string())),
        status::INTERNAL_ERROR
    );
}

/// JSON that YAML cannot read (a surrogate-pair `\u` escape) parses as JSON; a JSON document's
/// own error (an unknown field) is the one reported.
#[test]
fn json_with_unicode_escapes_parses() {
    let json = r#"{"request_id": "job \ud83d\ude00 \u00e9", "planner": "naive",
        "points": [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]}"#;
    for r in [
        MillRequest::from_yaml_str(json).expect("as YAML text"),
        MillRequest::from_json_str(json).expect("as JSON text"),
    ] {
        assert_eq!(r.request_id, "job \u{1F600} \u{e9}");
        assert_eq!(r.points.len(), 2);
    }
    let e = MillRequest::from_yaml_str(&json.replace("\"planner\"", "\"planer\""))
        .unwrap_err()
        .to_string();
    assert!(e.contains("planer"), "{e}");
}

/// Issue 11, row 8: deep nesting is refused before parsing, in both forms.
#[test]
fn deep_nesting_is_refused_before_parsing() {
    let deep = format!("{{\"points\": {}}}", "[".repeat(100_000));
    for r in [
        MillRequest::from_yaml_str(&deep),
        MillRequest::from_json_str(&deep),
    ] {
        let e = r.unwrap_err().to_string();
        assert!(
            e.contains("levels deep") && e.contains("limit of 32"),
            "{e}"
        );
    }
}

/// Issue 11, item 2: the number of teeth (the chatter model's work per time step) is bounded;
/// 10^9 teeth is refused at validation, naming the field and the limit.
#[test]
fn teeth_are_bounded() {
    let mut r = full_request();
    if let Some(p) = r.process.as_mut() {
        p.teeth = 1_000_000_000;
    }
    let e = r.validate().unwrap_err().to_string();
    assert!(e.contains("teeth") && e.contains("1..=100"), "{e}");
}

#[test]
fn coordinates_beyond_any_cell_are_refused_by_name() {
    let r = MillRequest {
        points: vec![[1.4, -0.3, 1.7], [1e20, 0.3, 1.7]],
        ..MillRequest::default()
    };
    let e = r.validate().unwrap_err().to_string();
    assert!(
        e.contains("points[1][0] [m]") && e.contains("outside any cell"),
        "{e}"
    );
}

/// Issue 28's request fields: an unknown `entry` is INVALID_REQUEST naming the field (also
/// through the planner, which validates first), the two names parse, and `allow_chatter` takes
/// a boolean only.
#[test]
fn entry_and_allow_chatter_are_validated() {
    let points = "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n";
    for (text, entry) in [
        ("entry: run_in\n", Entry::RunIn),
        ("entry: in_material\n", Entry::InMaterial),
        ("entry: ''\n", Entry::RunIn),
    ] {
        let r = MillRequest::from_yaml_str(&format!("{points}{text}")).expect(text);
        r.validate().expect(text);
        assert_eq!(r.entry().expect(text), entry, "{text}");
    }
    for bad in ["plunge", "RUN_IN", "run_in "] {
        let r = MillRequest {
            entry: Some(bad.to_string()),
            ..MillRequest::default()
        };
        expect_invalid(&r, "entry", "must be run_in or in_material");
        let e = planner().plan(&r).expect_err(bad);
        assert_eq!(status_of(&e), status::INVALID_REQUEST, "{e}");
    }
    for bad in [
        "allow_chatter: 3\n",
        "allow_chatter: yes please\n",
        "allow_chatter: .nan\n",
    ] {
        let e = MillRequest::from_yaml_str(&format!("{points}{bad}")).expect_err(bad);
        assert_eq!(status_of(&e), status::INVALID_REQUEST, "{bad}: {e}");
    }
    let r = MillRequest::from_yaml_str(&format!("{points}allow_chatter: true\n")).unwrap();
    assert!(r.allow_chatter);
}
