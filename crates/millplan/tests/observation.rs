//! The path-independent observation (kerf_millplan::observation, issue 13 item 4), the
//! minimum condition indicator of the environment (issue 13 item 2), and the planner's refusal
//! of a policy trained for another observation (issue 13, "Bad input").
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::{MillCell, PathSpec};
use kerf_millplan::ddpg::DdpgSettings;
use kerf_millplan::nets::{Mlp, OutputActivation};
use kerf_millplan::observation::{normalize, OBSERVATION_DIM, OBSERVATION_LAYOUT};
use kerf_millplan::policy::{Policy, PolicyMetadata, POLICY_FORMAT};
use kerf_millplan::rng::Rng;
use kerf_millplan::{
    status_of, EnvConfig, Environment, MillEnv, MillPlanError, MillPlanner, MillRequest,
};

fn cell() -> Arc<MillCell> {
    Arc::new(MillCell::default_cell().expect("default cell"))
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "kerf_millplan_observation_{name}_{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The observation after reset, entry by entry, against the cell's own model.
#[test]
fn initial_observation_by_hand() {
    let c = cell();
    let mut env = MillEnv::new(c.clone(), None, EnvConfig::default()).unwrap();
    assert_eq!(env.observation_dim(), OBSERVATION_DIM);
    assert_eq!(env.observation_layout().len(), OBSERVATION_DIM);
    let o = env.reset().unwrap();
    assert_eq!(o.len(), OBSERVATION_DIM);
    let path = c.path();
    let s0 = &path.segments()[0];
    let remaining = path.total_length() - 0.5 * s0.length;
    let at = |name: &str| o[OBSERVATION_LAYOUT.iter().position(|n| *n == name).unwrap()];
    assert_eq!(at("remaining_length"), normalize(remaining, 0.0, 1.0));
    assert_eq!(at("segment_length"), normalize(s0.length, 0.0, 0.02));
    assert_eq!(at("tangent_x"), s0.tangent.x as f32);
    assert_eq!(at("tangent_y"), s0.tangent.y as f32);
    assert_eq!(at("approach_z"), path.approach().z as f32);
    assert_eq!(at("approach_z"), -1.0, "the tool comes from above (+z)");
    // The default path is planar at z = 1.7 m: its midpoints map to (1.7 - 0.75) / 0.75 - 1.
    assert!((at("position_z") - (2.0 * (1.7 - 0.75) / 1.5 - 1.0) as f32).abs() < 1e-6);
    let cs = c.evaluate(0, 0.0, None).unwrap();
    assert_eq!(
        at("condition_indicator"),
        normalize(cs.condition_indicator, 0.0, 0.7)
    );
    assert_eq!(
        at("wrist_angle"),
        normalize(
            cs.joints[4],
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2
        )
    );
    let mu = chatter_indicator(
        &cs.modal,
        &c.milling_process(),
        2000.0,
        0.04,
        c.indicator_settings(),
    )
    .unwrap()
    .spectral_radius;
    assert_eq!(at("chatter_indicator"), normalize(mu, 0.5, 1.5));
    // Lookahead: 1/K at segment 1 for g = -0.2, 0, +0.2 rad.
    for (name, g) in [
        ("condition_ahead_minus", -0.2),
        ("condition_ahead_same", 0.0),
        ("condition_ahead_plus", 0.2),
    ] {
        let ahead = c.evaluate(1, g, Some(&cs.joints)).unwrap();
        assert_eq!(
            at(name),
            normalize(ahead.condition_indicator, 0.0, 0.7),
            "{name}"
        );
    }
    // Tool-tip stiffness in the cutting frame, of the state and one segment ahead.
    let k = cs.modal.stiffness;
    assert_eq!(at("stiffness_xx"), normalize(k[(0, 0)], 0.0, 3e6));
    assert_eq!(at("stiffness_yy"), normalize(k[(1, 1)], 0.0, 3e6));
    assert_eq!(at("stiffness_xy"), normalize(k[(0, 1)], -1.5e6, 1.5e6));
    let ahead = c
        .evaluate(1, 0.2, Some(&cs.joints))
        .unwrap()
        .modal
        .stiffness;
    assert_eq!(
        at("stiffness_ahead_plus_yy"),
        normalize(ahead[(1, 1)], 0.0, 3e6)
    );
    // The filter starts at rest.
    assert_eq!(
        [at("filter_spindle"), at("filter_feed"), at("filter_g")],
        [0.0; 3]
    );
    // No entry is the segment index: nothing in the layout names it.
    assert!(!OBSERVATION_LAYOUT
        .iter()
        .any(|n| n.contains("segment_index")));
}

/// A straight path has zero curvature everywhere and one heading; a curved one does not.
#[test]
fn curvature_and_heading_follow_the_geometry() {
    let c = cell();
    let straight = PathSpec {
        points: vec![[1.5, -0.2, 1.6], [1.8, 0.1, 1.6]],
        ..PathSpec::default()
    };
    let sc = Arc::new(c.with_path(&straight).unwrap());
    let mut env = MillEnv::new(sc, None, EnvConfig::default()).unwrap();
    let mut o = env.reset().unwrap();
    let k = |name: &str| OBSERVATION_LAYOUT.iter().position(|n| *n == name).unwrap();
    let mut seen = 0;
    loop {
        assert!(o[k("curvature")].abs() < 1e-6, "{}", o[k("curvature")]);
        assert!(o[k("curvature_ahead")].abs() < 1e-6);
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!((o[k("tangent_x")] - h).abs() < 1e-6 && (o[k("tangent_y")] - h).abs() < 1e-6);
        assert!(o.iter().all(|v| (-1.0..=1.0).contains(v)));
        seen += 1;
        let tr = env.step(&[0.0, 0.0, 0.0]).unwrap();
        o = tr.observation;
        if tr.done {
            break;
        }
    }
    assert_eq!(seen, 99);
    // The default path bends: its curvature entry is non-zero somewhere.
    let mut env = MillEnv::new(c, None, EnvConfig::default()).unwrap();
    let o = env.reset().unwrap();
    assert!(o[k("curvature")].abs() > 1e-3, "{}", o[k("curvature")]);
}

/// With the minimum condition indicator (the default, 0.35) a walk of g into the near-singular
/// band of the default path (1/K falls to 0.1 near g = 0.5 rad) is held out of it and never
/// ends the episode; without it (the paper's environment) the same walk enters the band.
#[test]
fn minimum_condition_indicator_keeps_the_wrist_away() {
    let min_along = |config: EnvConfig| {
        let mut env = MillEnv::new(cell(), None, config).unwrap();
        env.reset().unwrap();
        let mut min = f64::INFINITY;
        let mut steps = 0;
        loop {
            let tr = env.step(&[0.0, 0.0, 1.0]).unwrap();
            let info = env.last_info().unwrap();
            if config.min_condition_indicator.is_some() {
                assert!(info.violation.is_none(), "{:?}", info.violation);
            }
            if let Some(e) = info.evaluation {
                min = min.min(e.condition_indicator);
            }
            steps += 1;
            if tr.done {
                break;
            }
        }
        (min, steps)
    };
    let with = EnvConfig {
        alpha: 1.0,
        ..EnvConfig::default()
    };
    assert_eq!(with.min_condition_indicator, Some(0.35));
    let (min_with, steps) = min_along(with);
    assert_eq!(steps, 99);
    assert!(min_with >= 0.35, "{min_with}");
    let (min_without, _) = min_along(EnvConfig {
        min_condition_indicator: None,
        ..with
    });
    assert!(min_without < 0.2, "{min_without}");
    // A minimum outside [0, 1) is refused.
    for bad in [-0.1, 1.0, f64::NAN] {
        let e = MillEnv::new(
            cell(),
            None,
            EnvConfig {
                min_condition_indicator: Some(bad),
                ..EnvConfig::default()
            },
        )
        .expect_err("bad minimum");
        assert!(matches!(e, MillPlanError::InvalidParameter { .. }), "{e}");
    }
}

/// Writes an actor of `observation_dim` inputs and 3 outputs with the given recorded layout.
fn write_policy(path: &Path, observation_dim: usize, layout: Vec<String>) {
    let mut rng = Rng::new(3);
    let net = Mlp::new(&[observation_dim, 8, 3], OutputActivation::Tanh, &mut rng).unwrap();
    let metadata = PolicyMetadata {
        format: POLICY_FORMAT.to_string(),
        crate_version: "test".to_string(),
        observation_dim,
        action_dim: 3,
        hidden_sizes: vec![8],
        seed: 3,
        settings: DdpgSettings::default()
            .with_hidden_sizes(vec![8])
            .with_seed(3),
        environment: "observation test".to_string(),
        episodes: 0,
        final_reward: None,
        observation_layout: layout,
    };
    Policy::from_actor(&net, metadata)
        .unwrap()
        .save(path)
        .unwrap();
}

fn plan_with(planner: &MillPlanner, path: &Path) -> MillPlanError {
    planner
        .plan(&MillRequest {
            planner: "ddpg".to_string(),
            policy_file: Some(path.display().to_string()),
            ..MillRequest::default()
        })
        .expect_err("refused")
}

/// Issue 13, "Bad input": a policy trained for other observation sizes (the segment-index
/// observation of 4 entries), one of the right size without a recorded layout, and one whose
/// layout differs, are each refused with POLICY_ERROR naming why; the planner then plans.
#[test]
fn policy_for_another_observation_is_a_policy_error() {
    let dir = temp_dir("refusal");
    let planner = MillPlanner::with_default_cell().unwrap();
    let old = dir.join("old.safetensors");
    write_policy(&old, 4, Vec::new());
    let e = plan_with(&planner, &old);
    assert_eq!(status_of(&e), 3, "POLICY_ERROR: {e}");
    let text = e.to_string();
    assert!(
        text.contains("trained for observations of 4 and actions of 3 entries")
            && text.contains("the environment has 37 and 3"),
        "{text}"
    );
    let unnamed = dir.join("unnamed.safetensors");
    write_policy(&unnamed, OBSERVATION_DIM, Vec::new());
    let text = plan_with(&planner, &unnamed).to_string();
    assert!(text.contains("records no observation layout"), "{text}");
    let mut swapped: Vec<String> = OBSERVATION_LAYOUT.iter().map(|s| s.to_string()).collect();
    swapped.swap(0, 1);
    let other = dir.join("other.safetensors");
    write_policy(&other, OBSERVATION_DIM, swapped);
    let e = plan_with(&planner, &other);
    assert_eq!(status_of(&e), 3);
    let text = e.to_string();
    assert!(
        text.contains("observation entry 0 is \"segment_length\" in the policy")
            && text.contains("\"remaining_length\" in the planner"),
        "{text}"
    );
    // The layout must have one name per input.
    let mut rng = Rng::new(3);
    let net = Mlp::new(&[OBSERVATION_DIM, 8, 3], OutputActivation::Tanh, &mut rng).unwrap();
    let mut p = Policy::from_actor(
        &net,
        PolicyMetadata {
            observation_layout: Vec::new(),
            ..Policy::load(&other).unwrap().metadata().clone()
        },
    )
    .unwrap();
    assert!(p.set_observation_layout(vec!["a".to_string()]).is_err());
    // The planner keeps serving: the default request plans.
    planner
        .plan(&MillRequest {
            planner: "naive".to_string(),
            ..MillRequest::default()
        })
        .expect("the planner still plans");
}

/// The repair: with g commanded to stay at 0, 1/K of the default path falls from 0.46 to 0.18
/// (segment 51 on is below 0.35, on the IK branch continued from the IVP); with the minimum the
/// environment moves g by at most the step bound to the nearest feasible value, and the episode
/// runs to the end above the minimum.
#[test]
fn repair_moves_g_off_the_band_when_the_band_reaches_it() {
    let run = |min_condition_indicator| {
        let mut env = MillEnv::new(
            cell(),
            None,
            EnvConfig {
                alpha: 1.0,
                min_condition_indicator,
                ..EnvConfig::default()
            },
        )
        .unwrap();
        let r = env.rollout(|_, _| Ok(vec![0.0, 0.0, 0.0])).unwrap();
        assert!(r.completed, "{}", r.stop_reason());
        let mins: Vec<f64> = r
            .steps
            .iter()
            .map(|s| s.evaluation.unwrap().condition_indicator)
            .collect();
        let moved: Vec<f64> = r.steps.iter().map(|s| s.state.g).collect();
        (mins, moved)
    };
    let (free, g_free) = run(None);
    assert!(g_free.iter().all(|g| *g == 0.0));
    let min_free = free.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(min_free < 0.2, "{min_free}");
    let (held, g_held) = run(Some(0.35));
    assert!(held.iter().all(|c| *c >= 0.35), "{held:?}");
    assert!(g_held.iter().any(|g| *g != 0.0));
    for w in g_held.windows(2) {
        assert!((w[1] - w[0]).abs() <= 0.2 + 1e-12);
    }
}

/// The joint-limit margin of the planner's rollouts: the walk of g towards the edge of the
/// reachable band (joint 5 at its limit) stops 0.01 rad inside every limit; without the margin
/// the walk gets closer; a bad margin is refused.
#[test]
fn joint_limit_margin_keeps_the_joints_inside() {
    let closest = |joint_limit_margin: f64| {
        let c = cell();
        let mut env = MillEnv::new(
            c.clone(),
            None,
            EnvConfig {
                alpha: 1.0,
                joint_limit_margin,
                ..EnvConfig::default()
            },
        )
        .unwrap();
        let r = env.rollout(|_, _| Ok(vec![0.0, 0.0, -1.0])).unwrap();
        assert!(r.completed, "{}", r.stop_reason());
        let ranges = c.kinematics().joints();
        r.steps
            .iter()
            .flat_map(|s| {
                let q = s.evaluation.unwrap().joints;
                ranges
                    .iter()
                    .zip(q)
                    .map(|(j, q)| (q - j.lower).min(j.upper - q))
                    .collect::<Vec<_>>()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let with = closest(kerf_millplan::env::PLANNER_JOINT_LIMIT_MARGIN);
    assert!(with >= 0.01, "{with}");
    let without = closest(0.0);
    assert!(without < 0.01, "{without}");
    for bad in [-0.1, 0.5, f64::NAN] {
        assert!(MillEnv::new(
            cell(),
            None,
            EnvConfig {
                joint_limit_margin: bad,
                ..EnvConfig::default()
            }
        )
        .is_err());
    }
}
