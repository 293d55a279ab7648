//! The DP optimum: the generic grid DP against brute-force enumeration and
//! a closed-form optimum; the cell DP against feasible plans it must beat,
//! and its chatter constraint.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;
use support::reduced_dp_spec;

use kerf_mill::MillCell;
use kerf_millplan::cache::{IndicatorCache, SplitMix64};
use kerf_millplan::dp::{self, solve_grid, DpSpec};
use kerf_millplan::env::PhysicalState;
use kerf_millplan::plan::Plan;
use kerf_millplan::reward::{step_reward, ChatterMargin, RewardWeights};

/// A pseudo-random stage reward with forbidden states.
fn synthetic(t: usize, x: [usize; 3]) -> Option<f64> {
    let h = (t * 131 + x[0] * 31 + x[1] * 7 + x[2] * 3 + 5) as u64;
    let v = (h.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40) as f64 / (1u64 << 24) as f64;
    if v < 0.15 && t > 0 {
        None
    } else {
        Some(v - 0.3)
    }
}

fn brute_force(stages: usize, dims: [usize; 3], x: [usize; 3], t: usize) -> Option<f64> {
    let here = synthetic(t, x)?;
    if t + 1 == stages {
        return Some(here);
    }
    let mut best: Option<f64> = None;
    for m in 0..27usize {
        let d = [m / 9, (m / 3) % 3, m % 3];
        let mut y = [0usize; 3];
        let mut ok = true;
        for a in 0..3 {
            match (x[a] + d[a]).checked_sub(1) {
                Some(v) if v < dims[a] => y[a] = v,
                _ => ok = false,
            }
        }
        if !ok {
            continue;
        }
        if let Some(v) = brute_force(stages, dims, y, t + 1) {
            best = Some(best.map_or(v, |b: f64| b.max(v)));
        }
    }
    best.map(|b| here + b)
}

#[test]
fn grid_dp_equals_brute_force_enumeration() {
    for (stages, dims, start) in [
        (4, [3, 3, 2], [1, 1, 0]),
        (5, [2, 3, 3], [0, 2, 1]),
        (3, [4, 1, 3], [3, 0, 0]),
    ] {
        let bf = brute_force(stages, dims, start, 0).expect("a feasible path");
        let dp = solve_grid(stages, dims, start, synthetic).unwrap().unwrap();
        assert!(
            (dp.value - bf).abs() < 1e-5,
            "dp {} vs brute force {bf}",
            dp.value
        );
        // The returned path is feasible, starts at the start, moves by at
        // most one node per axis, and its value is its stage sum.
        assert_eq!(dp.nodes.len(), stages);
        assert_eq!(dp.nodes[0], start);
        let mut sum = 0.0;
        for (t, x) in dp.nodes.iter().enumerate() {
            sum += synthetic(t, *x).unwrap();
            if t > 0 {
                for (a, b) in x.iter().zip(dp.nodes[t - 1]) {
                    assert!(a.abs_diff(b) <= 1);
                }
            }
        }
        assert!((sum - dp.value).abs() < 1e-12);
    }
}

#[test]
fn grid_dp_closed_form_and_infeasible_start() {
    // Reward = feed index: the optimum climbs one node per stage to the
    // top and stays: sum_t min(j0 + t, jmax).
    let dims = [2, 10, 2];
    let r = solve_grid(8, dims, [0, 4, 0], |_, x| Some(x[1] as f64))
        .unwrap()
        .unwrap();
    let expect: f64 = (0..8).map(|t| (4 + t).min(9) as f64).sum();
    assert_eq!(r.value, expect);
    // A forbidden start, or no survivor: None.
    assert!(
        solve_grid(3, dims, [0, 0, 0], |_, x| (x != [0, 0, 0]).then_some(1.0))
            .unwrap()
            .is_none()
    );
    assert!(
        solve_grid(3, dims, [0, 0, 0], |t, _| (t < 2).then_some(1.0))
            .unwrap()
            .is_none()
    );
    assert!(solve_grid(0, dims, [0, 0, 0], |_, _| Some(1.0)).is_err());
    assert!(solve_grid(3, dims, [2, 0, 0], |_, _| Some(1.0)).is_err());
}

/// The value of a state sequence with |μ| from the cache and K from the
/// cell's reference branch — the DP's own objective (eq. 12 minus the
/// default chatter margin), computed here with the reward functions.
fn cache_value(cell: &MillCell, cache: &IndicatorCache, states: &[PhysicalState]) -> Option<f64> {
    cache_value_with(cell, cache, states, Some(ChatterMargin::default()))
}

/// As [`cache_value`] with another margin (`None`: eq. 12 alone).
fn cache_value_with(
    cell: &MillCell,
    cache: &IndicatorCache,
    states: &[PhysicalState],
    margin: Option<ChatterMargin>,
) -> Option<f64> {
    let w = RewardWeights::default();
    let mut total = 0.0;
    for s in states {
        let k = cell.evaluate(s.segment, s.g, None).ok()?.condition_number;
        let mu = cache.try_query(s.segment, s.rpm, s.feed, s.g).ok()??;
        total += step_reward(&w, k, s.feed, 0.06, mu).ok()?.total;
        if let Some(m) = margin {
            // Independent of ChatterMargin::penalty: slope (|mu| - limit)+.
            total -= m.slope * (mu - m.limit).max(0.0);
        }
    }
    Some(total)
}

#[test]
fn cell_dp_beats_every_feasible_plan_it_is_compared_with() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let spec = reduced_dp_spec(&cell);
    let r = dp::solve(&cell, &cache, &spec).unwrap();
    assert_eq!(r.dims, [21, 31, 11]);
    assert_eq!(r.states.len(), 100);
    let s0 = r.states[0];
    assert_eq!((s0.rpm, s0.feed, s0.g), (2000.0, 0.04, 0.0));
    for w in r.states.windows(2) {
        assert!((w[1].rpm - w[0].rpm).abs() <= 20.0 + 1e-9);
        assert!((w[1].feed - w[0].feed).abs() <= 1e-3 + 1e-12);
        assert!((w[1].g - w[0].g).abs() <= 0.2 + 1e-12);
    }
    // Its value is its objective, recomputed independently.
    let own = cache_value(&cell, &cache, &r.states).unwrap();
    assert!((own - r.value).abs() < 1e-9, "{own} vs {}", r.value);
    // It beats holding the IVP, and random feasible walks on its grid.
    let hold: Vec<PhysicalState> = (0..100)
        .map(|segment| PhysicalState { segment, ..s0 })
        .collect();
    let v_hold = cache_value(&cell, &cache, &hold).unwrap();
    assert!(r.value >= v_hold, "{} < hold {v_hold}", r.value);
    let mut rng = SplitMix64::new(5);
    let mut walks = 0;
    while walks < 20 {
        let mut s = s0;
        let mut states = vec![s];
        for t in 1..100 {
            let step = |rng: &mut SplitMix64| rng.integer(0, 2) as f64 - 1.0;
            s = PhysicalState {
                segment: t,
                rpm: (s.rpm + 20.0 * step(&mut rng)).clamp(2000.0, 2400.0),
                // Biased upwards: -1, 0, +1, +1 grid steps.
                feed: (s.feed + 1e-3 * (rng.integer(0, 3).min(2) as f64 - 1.0)).clamp(0.03, 0.06),
                g: (s.g + 0.2 * step(&mut rng)).clamp(-1.0, 1.0),
            };
            // Back onto the grid.
            s.feed = (s.feed * 1e3).round() / 1e3;
            s.g = (s.g * 5.0).round() / 5.0;
            states.push(s);
        }
        if let Some(v) = cache_value(&cell, &cache, &states) {
            assert!(r.value >= v - 1e-6, "walk {v} > dp {}", r.value);
            walks += 1;
        }
    }
    // The plan re-evaluated directly (eq. 12, no margin): the same eq. 12
    // value within the cache's stated bound per segment (w_p e^(|mu|-1)
    // slope about 0.5-0.6).
    let plan = Plan::evaluate(&cell, &RewardWeights::default(), &r.states, "dp").unwrap();
    let bound = cache.header().error_bound_g_nodes.unwrap();
    let eq12 = cache_value_with(&cell, &cache, &r.states, None).unwrap();
    assert!((plan.total_reward - eq12).abs() <= 100.0 * 0.7 * bound);
    // Without the margin the DP optimizes eq. 12 alone, and is no worse on
    // it than the margin's plan.
    let plain = dp::solve(
        &cell,
        &cache,
        &DpSpec {
            chatter_margin: None,
            ..spec
        },
    )
    .unwrap();
    let own = cache_value_with(&cell, &cache, &plain.states, None).unwrap();
    assert!((own - plain.value).abs() < 1e-9, "{own} vs {}", plain.value);
    assert!(plain.value >= eq12 - 1e-9);
}

#[test]
fn chatter_constrained_dp_is_chatter_free_per_the_cache() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let free = dp::solve(&cell, &cache, &reduced_dp_spec(&cell)).unwrap();
    let spec = DpSpec {
        chatter_limit: Some((0.99, 1)),
        ..reduced_dp_spec(&cell)
    };
    let r = dp::solve(&cell, &cache, &spec).unwrap();
    for s in r.states.iter().skip(1) {
        let mu = cache.query(s.segment, s.rpm, s.feed, s.g).unwrap();
        assert!(mu < 0.99, "segment {}: {mu}", s.segment);
    }
    // A constraint can only lower the optimum.
    assert!(r.value <= free.value + 1e-9);
    // The fixed-g variant keeps g = 0 and is no better than free g.
    let fixed = dp::solve(
        &cell,
        &cache,
        &DpSpec {
            g_range: [0.0, 0.0],
            ..reduced_dp_spec(&cell)
        },
    )
    .unwrap();
    assert!(fixed.states.iter().all(|s| s.g == 0.0));
    assert!(fixed.value <= free.value + 1e-9);
}

#[test]
fn dp_plan_replayed_in_the_unfiltered_environment_gives_its_value() {
    // With alpha = 1 every DP plan is an action sequence of the
    // environment (normalized actions -1/0/+1): replaying it must give the
    // same states and, with the same cache, the same total reward.
    use std::sync::Arc;

    use kerf_millplan::env::{EnvConfig, MillEnv};
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let r = dp::solve(&cell, &cache, &reduced_dp_spec(&cell)).unwrap();
    let actions: Vec<Vec<f32>> = r
        .states
        .windows(2)
        .map(|w| {
            vec![
                ((w[1].rpm - w[0].rpm) / 20.0).round() as f32,
                ((w[1].feed - w[0].feed) / 1e-3).round() as f32,
                ((w[1].g - w[0].g) / 0.2).round() as f32,
            ]
        })
        .collect();
    let mut env = MillEnv::new(
        Arc::new(cell),
        Some(Arc::new(cache)),
        EnvConfig {
            alpha: 1.0,
            ..EnvConfig::default()
        },
    )
    .unwrap();
    let rollout = env.rollout_actions(&actions).unwrap();
    assert!(rollout.completed);
    for (a, b) in rollout.states().iter().zip(&r.states) {
        assert_eq!(a.segment, b.segment);
        assert!((a.rpm - b.rpm).abs() < 1e-6 && (a.feed - b.feed).abs() < 1e-12);
        assert!((a.g - b.g).abs() < 1e-12);
    }
    assert!(rollout
        .steps
        .iter()
        .all(|s| s.evaluation.unwrap().from_cache));
    assert!(
        (rollout.total_reward - r.value).abs() < 1e-6,
        "env {} vs dp {}",
        rollout.total_reward,
        r.value
    );
}

#[test]
fn dp_plans_respect_the_joint_speed_limits() {
    // Joint speeds between segment midpoints, from the plan's
    // branch-continuous joints (Plan::evaluate), against the URDF limits
    // read here from the robot model.
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let spec = DpSpec {
        g_range: [-1.2, 1.6],
        ..reduced_dp_spec(&cell)
    };
    let r = dp::solve(&cell, &cache, &spec).unwrap();
    let plan = Plan::evaluate(&cell, &RewardWeights::default(), &r.states, "dp").unwrap();
    let limits: Vec<f64> = cell
        .robot()
        .joints()
        .iter()
        .map(|j| j.max_velocity)
        .collect();
    assert_eq!(limits.len(), 6);
    let segments = cell.path().segments();
    let mut worst: f64 = 0.0;
    for w in plan.segments.windows(2) {
        let dt = segments[w[0].segment].length / (2.0 * w[0].feed)
            + segments[w[1].segment].length / (2.0 * w[1].feed);
        for ((a, b), v) in w[0].joints.iter().zip(&w[1].joints).zip(&limits) {
            worst = worst.max((b - a).abs() / dt / v);
        }
    }
    assert!(worst <= 1.0 + 1e-9, "speed / limit up to {worst}");
}
