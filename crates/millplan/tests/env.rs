//! MillEnv (seed 004 section 3, eq. 11-17) and plan evaluation on the
//! default cell, without the cache (direct evaluation), against hand
//! computations and the model itself.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::sync::Arc;

use approx::assert_relative_eq;
use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::MillCell;
use kerf_millplan::env::{EnvConfig, MillEnv, PhysicalState};
use kerf_millplan::plan::{comparison_table, Plan};
use kerf_millplan::reward::{step_reward, RewardWeights};
use kerf_millplan::{Environment, MillPlanError};

fn cell() -> Arc<MillCell> {
    Arc::new(MillCell::default_cell().expect("default cell"))
}

fn env(config: EnvConfig) -> MillEnv {
    MillEnv::new(cell(), None, config).expect("env")
}

#[test]
fn initial_value_problem_observation_and_reward() {
    let mut e = env(EnvConfig::default());
    assert_eq!(e.observation_dim(), 37);
    assert_eq!(e.action_dim(), 3);
    assert_eq!(e.max_steps(), 99);
    let obs = e.reset().unwrap();
    // The state part of the observation (kerf_millplan::observation): 2000 rpm in
    // [2000, 4000], 0.04 m/s in [0, 0.06], g = 0 in [-pi, pi], the filter at rest.
    assert_eq!(
        obs[18..24].to_vec(),
        vec![-1.0, (2.0 * 0.04 / 0.06 - 1.0) as f32, 0.0, 0.0, 0.0, 0.0]
    );
    let s = e.state().unwrap();
    assert_eq!(
        s,
        PhysicalState {
            segment: 0,
            rpm: 2000.0,
            feed: 0.04,
            g: 0.0
        }
    );
    // r(s_0) from the model directly.
    let c = e.cell();
    let cs = c.evaluate(0, 0.0, None).unwrap();
    let mu = chatter_indicator(
        &cs.modal,
        &c.milling_process(),
        2000.0,
        0.04,
        c.indicator_settings(),
    )
    .unwrap()
    .spectral_radius;
    let r = step_reward(
        &RewardWeights::default(),
        cs.condition_number,
        0.04,
        0.06,
        mu,
    )
    .unwrap();
    let info = e.initial_info().unwrap();
    let ev = info.evaluation.unwrap();
    assert_eq!(ev.spectral_radius, mu);
    assert!(!ev.from_cache);
    // The step reward is eq. 12 minus the default chatter margin
    // 20 (|mu| - 0.95)+ (kerf's shaping, reward::ChatterMargin).
    let margin = 20.0 * (mu - 0.95).max(0.0);
    assert_relative_eq!(ev.chatter_penalty, margin, epsilon = 1e-15);
    assert_relative_eq!(ev.reward.total, r.total, epsilon = 1e-15);
    assert_relative_eq!(info.reward, r.total - margin, epsilon = 1e-15);
    assert_relative_eq!(
        ev.segment_time,
        c.path().segments()[0].length / 0.04,
        epsilon = 1e-15
    );
}

#[test]
fn inertial_filter_and_clip_by_hand() {
    // alpha = 0.5: a_hat_{t+1} = 0.5 a_{t+1} + 0.5 a_hat_t (eq. 11).
    let mut e = env(EnvConfig::default());
    e.reset().unwrap();
    e.step(&[1.0, 1.0, 0.5]).unwrap();
    // a = (20 rpm, 1e-3 m/s, 0.1 rad): a_hat_1 = (10, 5e-4, 0.05).
    let s1 = e.state().unwrap();
    assert_eq!(s1.segment, 1);
    assert_relative_eq!(s1.rpm, 2010.0, epsilon = 1e-9);
    assert_relative_eq!(s1.feed, 0.0405, epsilon = 1e-12);
    assert_relative_eq!(s1.g, 0.05, epsilon = 1e-12);
    e.step(&[1.0, -1.0, 0.5]).unwrap();
    // a_hat_2 = (0.5*20 + 0.5*10, 0.5*(-1e-3) + 0.5*5e-4, 0.5*0.1 + 0.5*0.05)
    //         = (15, -2.5e-4, 0.075).
    let s2 = e.state().unwrap();
    assert_relative_eq!(s2.rpm, 2025.0, epsilon = 1e-9);
    assert_relative_eq!(s2.feed, 0.04025, epsilon = 1e-12);
    assert_relative_eq!(s2.g, 0.125, epsilon = 1e-12);
    let f = e.filter_state();
    assert_relative_eq!(f[0], 15.0, epsilon = 1e-12);
    assert_relative_eq!(f[1], -2.5e-4, epsilon = 1e-15);

    // alpha = 1, clip at the lower spindle bound: 2000 - 20 -> 2000.
    let mut e = env(EnvConfig {
        alpha: 1.0,
        ..EnvConfig::default()
    });
    e.reset().unwrap();
    let tr = e.step(&[-1.0, 1.0, -1.0]).unwrap();
    let s = e.state().unwrap();
    assert_eq!(s.rpm, 2000.0);
    assert_relative_eq!(s.feed, 0.041, epsilon = 1e-12);
    assert_relative_eq!(s.g, -0.2, epsilon = 1e-12);
    assert!(!tr.done);
    assert!(tr.observation.iter().all(|v| (-1.0..=1.0).contains(v)));
    // The step reward is eq. 12 of the NEW state on segment 1 (Algorithm 1).
    let c = e.cell();
    let cs = c
        .evaluate(
            1,
            -0.2,
            Some(&e.initial_info().unwrap().evaluation.unwrap().joints),
        )
        .unwrap();
    let mu = chatter_indicator(
        &cs.modal,
        &c.milling_process(),
        2000.0,
        0.041,
        c.indicator_settings(),
    )
    .unwrap()
    .spectral_radius;
    let r = step_reward(
        &RewardWeights::default(),
        cs.condition_number,
        0.041,
        0.06,
        mu,
    )
    .unwrap();
    assert_relative_eq!(tr.reward, r.total, epsilon = 1e-12);
}

#[test]
fn clip_at_the_upper_feed_bound() {
    let mut e = env(EnvConfig {
        alpha: 1.0,
        initial_feed: 0.0595,
        ..EnvConfig::default()
    });
    e.reset().unwrap();
    e.step(&[0.0, 1.0, 0.5]).unwrap();
    assert_eq!(e.state().unwrap().feed, 0.06);
}

#[test]
fn bad_actions_are_errors_and_change_nothing() {
    let mut e = env(EnvConfig::default());
    assert!(e.step(&[0.0, 0.0, 0.0]).is_err(), "step before reset");
    e.reset().unwrap();
    let before = e.state().unwrap();
    for bad in [
        vec![f32::NAN, 0.0, 0.0],
        vec![0.0, 1.5, 0.0],
        vec![0.0, 0.0, -1.0001],
        vec![0.0, f32::INFINITY, 0.0],
        vec![0.0, 0.0],
        vec![0.0, 0.0, 0.0, 0.0],
    ] {
        let err = e.step(&bad).unwrap_err();
        assert!(
            matches!(
                err,
                MillPlanError::InvalidParameter { .. } | MillPlanError::InvalidConfig { .. }
            ),
            "{err}"
        );
        assert_eq!(e.state().unwrap(), before);
        assert_eq!(e.filter_state(), [0.0; 3]);
    }
    // The fixed-g ablation takes (dOmega, df).
    let mut e = env(EnvConfig {
        fixed_g: true,
        ..EnvConfig::default()
    });
    assert_eq!(e.action_dim(), 2);
    e.reset().unwrap();
    assert!(e.step(&[0.0, 0.0, 1.0]).is_err());
    e.step(&[1.0, 1.0]).unwrap();
    assert_eq!(e.state().unwrap().g, 0.0);
    // Bad configurations.
    for bad in [
        EnvConfig {
            alpha: 0.0,
            ..EnvConfig::default()
        },
        EnvConfig {
            alpha: f64::NAN,
            ..EnvConfig::default()
        },
        EnvConfig {
            initial_feed: 0.0,
            ..EnvConfig::default()
        },
        EnvConfig {
            initial_rpm: 5000.0,
            ..EnvConfig::default()
        },
        EnvConfig {
            violation_penalty: 1.0,
            ..EnvConfig::default()
        },
    ] {
        assert!(MillEnv::new(cell(), None, bad).is_err());
    }
}

#[test]
fn infeasible_g_is_a_terminal_violation() {
    let mut e = env(EnvConfig {
        alpha: 1.0,
        project_g: false,
        ..EnvConfig::default()
    });
    e.reset().unwrap();
    // Turn g down by 0.2 rad per step: every segment is valid only down to
    // about -1.27 rad (kerf_mill tests/reachability.rs), so the episode
    // must end before g is clipped at -pi (16 steps).
    let mut last = None;
    for _ in 0..20 {
        let tr = e.step(&[0.0, 0.0, -1.0]).unwrap();
        if tr.done {
            last = Some(tr);
            break;
        }
    }
    let tr = last.expect("a violation within 20 steps");
    assert_eq!(tr.reward, -100.0);
    let info = e.last_info().unwrap();
    assert!(info.evaluation.is_none());
    let reason = info.violation.clone().unwrap();
    assert!(
        reason.contains("joint") || reason.contains("unreachable"),
        "{reason}"
    );
    let s = e.state().unwrap();
    assert!(s.g < -1.2 && s.segment < 17, "{s:?}");
    // Independent check: the model refuses that (segment, g).
    assert!(e.cell().evaluate(s.segment, s.g, None).is_err());
    // The episode is over.
    assert!(e.is_done());
    assert!(e.step(&[0.0, 0.0, 0.0]).is_err());
}

#[test]
fn zero_feed_is_a_terminal_violation() {
    let mut e = env(EnvConfig {
        alpha: 1.0,
        initial_feed: 0.0015,
        // The paper's clip at f_min = 0 (the default clips at 0.01 m/s).
        min_feed: 0.0,
        ..EnvConfig::default()
    });
    e.reset().unwrap();
    let tr = e.step(&[0.0, -1.0, 0.0]).unwrap();
    assert!(!tr.done);
    let tr = e.step(&[0.0, -1.0, 0.0]).unwrap();
    assert!(tr.done);
    assert_eq!(tr.reward, -100.0);
    assert_eq!(e.state().unwrap().feed, 0.0);
    assert!(e
        .last_info()
        .unwrap()
        .violation
        .as_ref()
        .unwrap()
        .contains("zero feed"));
}

#[test]
fn time_accounting_and_plan_totals() {
    // A whole episode of gentle actions at g in the reachable band.
    let mut e = env(EnvConfig::default());
    let rollout = e
        .rollout(|_, s| {
            let g_action = if s.g < 0.2 { 0.5 } else { 0.0 };
            Ok(vec![0.5, 0.5, g_action])
        })
        .unwrap();
    assert!(rollout.completed);
    assert_eq!(rollout.steps.len(), 99);
    let cell = e.cell();
    let mut time = rollout.initial.evaluation.unwrap().segment_time;
    for st in &rollout.steps {
        let ev = st.evaluation.unwrap();
        let l = cell.path().segments()[st.state.segment].length;
        assert_relative_eq!(ev.segment_time, l / st.state.feed, epsilon = 1e-15);
        time += ev.segment_time;
    }
    let states = rollout.states();
    assert_eq!(states.len(), 100);
    // The plan re-evaluates the same states directly: same rewards, same
    // joints (same branch-continuous IK), times adding up.
    let plan = Plan::evaluate(cell, &RewardWeights::default(), &states, "test").unwrap();
    assert_relative_eq!(plan.total_time, time, epsilon = 1e-9);
    let by_hand: f64 = states
        .iter()
        .map(|s| cell.path().segments()[s.segment].length / s.feed)
        .sum();
    assert_relative_eq!(plan.total_time, by_hand, epsilon = 1e-9);
    // The plan reports eq. 12; the rollout's rewards also carry the chatter
    // margin of the environment.
    let penalties: f64 = std::iter::once(&rollout.initial)
        .chain(&rollout.steps)
        .map(|st| st.evaluation.unwrap().chatter_penalty)
        .sum();
    assert_relative_eq!(
        plan.total_reward - penalties,
        rollout.total_reward,
        epsilon = 1e-9
    );
    for (p, st) in plan.segments.iter().skip(1).zip(&rollout.steps) {
        let ev = st.evaluation.unwrap();
        assert_eq!(p.joints, ev.joints);
        assert_eq!(p.spectral_radius, ev.spectral_radius);
    }
    let max_mu = plan
        .segments
        .iter()
        .map(|s| s.spectral_radius)
        .fold(0.0, f64::max);
    assert_eq!(plan.max_spectral_radius, max_mu);
    assert_eq!(plan.chatter_free, max_mu < 1.0);
    let min_ind = plan
        .segments
        .iter()
        .map(|s| s.condition_indicator)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(plan.min_condition_indicator, min_ind);
    let table = comparison_table(&[plan.row()]);
    assert!(
        table.contains(&format!("| test | {:.2} |", plan.total_time)),
        "{table}"
    );
    assert_eq!(table.lines().count(), 3);
    // A '|' in a name stays inside its cell: 7 unescaped separators a row.
    let mut row = plan.row();
    row.planner = "DP, |mu| < 0.99".to_string();
    let table = comparison_table(&[row]);
    let last = table.lines().last().unwrap();
    assert_eq!(last.replace("\\|", "").matches('|').count(), 7, "{last}");

    // Plans refuse a zero feed and a wrong length.
    let mut bad = states.clone();
    bad[10].feed = 0.0;
    assert!(Plan::evaluate(cell, &RewardWeights::default(), &bad, "bad").is_err());
    assert!(Plan::evaluate(cell, &RewardWeights::default(), &states[1..], "bad").is_err());
}

#[test]
fn projection_stops_g_at_the_edge_of_the_feasible_set() {
    // The walk of infeasible_g_is_a_terminal_violation with the projection
    // on: the episode runs to the end, every state is feasible for the
    // model, g never goes below the edge it would have crossed, and the
    // filter holds the applied (shortened) move.
    let mut e = env(EnvConfig {
        alpha: 1.0,
        ..EnvConfig::default()
    });
    e.reset().unwrap();
    let mut shortened = 0;
    let mut previous = e.state().unwrap();
    loop {
        let tr = e.step(&[0.0, 0.0, -1.0]).unwrap();
        let s = e.state().unwrap();
        let info = e.last_info().unwrap();
        assert!(info.violation.is_none(), "{:?}", info.violation);
        assert!(e.cell().evaluate(s.segment, s.g, None).is_ok());
        let moved = s.g - previous.g;
        assert!((-0.2 - 1e-12..=1e-12).contains(&moved), "{moved}");
        assert!((e.filter_state()[2] - moved).abs() < 1e-12);
        if moved > -0.2 + 1e-9 {
            shortened += 1;
        }
        previous = s;
        if tr.done {
            break;
        }
    }
    assert_eq!(previous.segment, 99);
    // The band's lower edge is about -1.2 rad at the start and moves to
    // about -1.9 rad at the end (kerf_mill tests/reachability.rs): the walk
    // reaches it and is held there.
    assert!(shortened > 50, "{shortened}");
    assert!(previous.g < -1.5, "{previous:?}");
}

#[test]
fn default_clip_keeps_the_feed_at_the_minimum_feed() {
    let mut e = env(EnvConfig {
        alpha: 1.0,
        initial_feed: 0.012,
        ..EnvConfig::default()
    });
    e.reset().unwrap();
    for _ in 0..5 {
        let tr = e.step(&[0.0, -1.0, 0.0]).unwrap();
        assert!(!tr.done);
    }
    assert_eq!(e.state().unwrap().feed, 0.01);
    // An initial feed below it, or a minimum feed above f_max, is refused.
    for bad in [
        EnvConfig {
            initial_feed: 0.005,
            ..EnvConfig::default()
        },
        EnvConfig {
            min_feed: 0.07,
            ..EnvConfig::default()
        },
        EnvConfig {
            min_feed: f64::NAN,
            ..EnvConfig::default()
        },
    ] {
        let cell = Arc::new(MillCell::default_cell().unwrap());
        assert!(MillEnv::new(cell, None, bad).is_err());
    }
}

/// EnvConfig::acceleration_penalty: the same dithering g actions (+1, −1,
/// …) run with and without the shaping; the rewards differ exactly by
/// w · Σ_j (|a_j|/a_max,j − 1)₊, recomputed here from the joints of the
/// three midpoints (IK nearest the previous joints) and the midpoint times;
/// the first step (no earlier midpoint) is not shaped; a NaN or negative
/// weight is refused.
#[test]
fn acceleration_penalty_by_hand() {
    let w = 0.7;
    let base = EnvConfig::default();
    let shaped_cfg = EnvConfig {
        acceleration_penalty: Some(w),
        ..base
    };
    let mut plain = env(base);
    let mut shaped = env(shaped_cfg);
    plain.reset().unwrap();
    shaped.reset().unwrap();
    let c = cell();
    let limits: Vec<f64> = c
        .robot()
        .joints()
        .iter()
        .map(|j| j.max_acceleration.unwrap_or(f64::INFINITY))
        .collect();
    let lengths: Vec<f64> = c.path().segments().iter().map(|s| s.length).collect();
    let mut states = vec![shaped.state().unwrap()];
    let mut joints = vec![c.evaluate(0, 0.0, None).unwrap().joints];
    let mut any_positive = false;
    for k in 0..8 {
        let a = [0.0, 1.0, if k % 2 == 0 { 1.0 } else { -1.0 }];
        let tp = plain.step(&a).unwrap();
        let ts = shaped.step(&a).unwrap();
        let s = shaped.state().unwrap();
        assert_eq!(s, plain.state().unwrap());
        let q = c
            .evaluate(s.segment, s.g, Some(joints.last().unwrap()))
            .unwrap()
            .joints;
        states.push(s);
        joints.push(q);
        let expected = if k == 0 {
            0.0
        } else {
            let mid = |i: usize| {
                0.5 * lengths[states[i].segment] / states[i].feed
                    + 0.5 * lengths[states[i + 1].segment] / states[i + 1].feed
            };
            let (h1, h2) = (mid(k - 1), mid(k));
            let (q0, q1, q2) = (joints[k - 1], joints[k], joints[k + 1]);
            (0..6)
                .map(|j| {
                    let acc = 2.0 * ((q2[j] - q1[j]) / h2 - (q1[j] - q0[j]) / h1) / (h1 + h2);
                    (acc.abs() / limits[j] - 1.0).max(0.0)
                })
                .sum::<f64>()
                * w
        };
        any_positive |= expected > 0.0;
        assert_relative_eq!(
            tp.reward - ts.reward,
            expected,
            epsilon = 1e-9,
            max_relative = 1e-9
        );
    }
    assert!(
        any_positive,
        "the dither must exceed some acceleration limit"
    );
    for bad in [f64::NAN, -1.0] {
        let e = MillEnv::new(
            cell(),
            None,
            EnvConfig {
                acceleration_penalty: Some(bad),
                ..base
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("acceleration penalty"), "{e}");
    }
}

/// Rollout::stop_reason names the first violating step's segment and
/// violation; a rollout without a violation gets the generic text.
#[test]
fn rollout_stop_reason_names_the_violation() {
    let mut e = env(EnvConfig {
        alpha: 1.0,
        project_g: false,
        ..EnvConfig::default()
    });
    let r = e.rollout(|_, _| Ok(vec![0.0, 0.0, -1.0])).unwrap();
    assert!(!r.completed);
    let last = r.steps.last().unwrap();
    assert_eq!(
        r.stop_reason(),
        format!(
            "segment {}: {}",
            last.state.segment,
            last.violation.as_deref().unwrap()
        )
    );
    // g held at 0 machines every segment when the minimum condition
    // indicator is off (with it, 1/K at g = 0 falls below 0.35 from
    // segment 51 on, to 0.18: tests/observation.rs).
    let mut e = env(EnvConfig {
        alpha: 1.0,
        project_g: false,
        min_condition_indicator: None,
        ..EnvConfig::default()
    });
    let r = e.rollout(|_, _| Ok(vec![0.0, 0.0, 0.0])).unwrap();
    assert!(r.completed);
    assert_eq!(r.stop_reason(), "the rollout ended early");
}

/// kerf's chatter shield (`EnvConfig::chatter_shield`): a move whose state reaches the limit is
/// replaced by a feasible one within the step bounds whose |μ|max, evaluated here directly, is
/// below it; the filter takes the applied move; without the shield the same action keeps its
/// state.
#[test]
fn the_chatter_shield_replaces_a_move_into_its_limit() {
    let action = [1.0_f32, 1.0, 0.5];
    let mut alone = env(EnvConfig::default());
    alone.reset().unwrap();
    alone.step(&action).unwrap();
    let proposed = alone.state().unwrap();
    let mu = alone
        .last_info()
        .unwrap()
        .evaluation
        .as_ref()
        .unwrap()
        .spectral_radius;
    // A limit just below the proposal's |μ|max makes the shield act.
    let limit = mu - 0.01;
    let mut shielded = env(EnvConfig {
        chatter_shield: Some(limit),
        ..EnvConfig::default()
    });
    shielded.reset().unwrap();
    let start = shielded.state().unwrap();
    shielded.step(&action).unwrap();
    let next = shielded.state().unwrap();
    assert_ne!(next, proposed, "the shield acted");
    let info = shielded.last_info().unwrap();
    assert!(info.violation.is_none());
    let e = info.evaluation.as_ref().unwrap();
    let c = shielded.cell();
    let cs = c.evaluate(next.segment, next.g, None).unwrap();
    let direct = chatter_indicator(
        &cs.modal,
        &c.milling_process(),
        next.rpm,
        next.feed,
        c.indicator_settings(),
    )
    .unwrap()
    .spectral_radius;
    assert_relative_eq!(e.spectral_radius, direct, max_relative = 1e-12);
    assert!(direct < limit, "{direct} >= {limit}");
    let lim = c.state_limits();
    let moved = [
        next.rpm - start.rpm,
        next.feed - start.feed,
        next.g - start.g,
    ];
    assert!(moved[0].abs() <= lim.max_spindle_step_rpm + 1e-9);
    assert!(moved[1].abs() <= lim.max_feed_step + 1e-12);
    assert!(moved[2].abs() <= lim.max_redundancy_step + 1e-12);
    assert_eq!(shielded.filter_state(), moved);
}

#[test]
fn bad_shield_settings_are_refused_by_name() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = MillEnv::new(
            cell(),
            None,
            EnvConfig {
                chatter_shield: Some(bad),
                ..EnvConfig::default()
            },
        )
        .unwrap_err();
        assert!(err.to_string().contains("chatter shield"), "{err}");
    }
    let e = env(EnvConfig::default());
    let n = e.segment_count();
    let short: Arc<[f64]> = vec![1.0; n - 1].into();
    let err = e.clone().with_shield_slowdown(short).unwrap_err();
    assert!(err.to_string().contains("factors for"), "{err}");
    let mut below = vec![1.0; n];
    below[3] = 0.5;
    let err = e.clone().with_shield_slowdown(below.into()).unwrap_err();
    assert!(err.to_string().contains("shield slowdown factor"), "{err}");
    let ok: Arc<[f64]> = vec![1.5; n].into();
    assert!(e.with_shield_slowdown(ok).is_ok());
}

/// `MillEnv::with_held_g`: a held move keeps g whatever the policy asks (the shield offers no g
/// move there either); the next, unheld move follows the action again; a wrong length is refused.
#[test]
fn held_moves_keep_g() {
    let e = env(EnvConfig {
        chatter_shield: Some(0.99),
        ..EnvConfig::default()
    });
    let n = e.segment_count();
    let short: Arc<[bool]> = vec![true; n - 1].into();
    let err = e.clone().with_held_g(short).unwrap_err();
    assert!(err.to_string().contains("entries for"), "{err}");
    let mut held = vec![false; n];
    held[0] = true;
    let mut e = e.with_held_g(held.into()).unwrap();
    e.reset().unwrap();
    let g0 = e.state().unwrap().g;
    e.step(&[0.0, 0.0, 1.0]).unwrap();
    assert_eq!(e.state().unwrap().g, g0, "held: g kept");
    assert_eq!(e.filter_state()[2], 0.0);
    e.step(&[0.0, 0.0, 1.0]).unwrap();
    assert!(e.state().unwrap().g > g0, "not held: g follows the action");
}
