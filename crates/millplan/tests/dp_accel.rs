//! The DP with joint accelerations in its state (issue 13, item 3: "the DP with the executed
//! timing in its cost"): `grid_dp::solve_grid_with_history` against the plain DP, and
//! `DpSpec::joint_acceleration_limits` plans whose every move is within the robot's
//! acceleration limits at the planned feeds (recomputed here).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;
use support::reduced_dp_spec;

use kerf_budget::Budget;
use kerf_mill::MillCell;
use kerf_millplan::dp::{self, solve_grid_with_history, solve_grid_with_moves, DpSpec};
use kerf_millplan::joint_speed::{midpoint_interval, smallest_motion};
use kerf_millplan::IndicatorCache;

/// A synthetic stage reward on a small grid: prefers k high, with a stage-dependent twist.
fn reward(t: usize, x: [usize; 3]) -> Option<f64> {
    let [i, j, k] = x;
    if (t + i + j) % 7 == 3 && k == 2 {
        return None;
    }
    Some(((t * 31 + i * 7 + j * 3) % 11) as f64 * 0.1 + k as f64 * 0.5)
}

#[test]
fn history_dp_is_the_plain_dp_without_its_filter_and_obeys_it_with() {
    let dims = [3, 4, 5];
    let start = [1, 1, 0];
    let budget = Budget::unlimited();
    let plain = solve_grid_with_moves(12, dims, start, reward, |_, _, _| true, &budget)
        .unwrap()
        .unwrap();
    let same = solve_grid_with_history(
        12,
        dims,
        start,
        reward,
        |_, _, _| true,
        |_, _, _, _| true,
        &budget,
    )
    .unwrap()
    .unwrap();
    assert_eq!(same.value, plain.value);
    assert_eq!(same.nodes, plain.nodes);
    // Forbid two consecutive moves of k in the same direction (a "second difference" rule).
    let no_repeat = |_: usize, p: usize, x: [usize; 3], y: [usize; 3]| {
        let dk = y[2] + 1 - x[2];
        !(dk == p && dk != 1)
    };
    let r = solve_grid_with_history(12, dims, start, reward, |_, _, _| true, no_repeat, &budget)
        .unwrap()
        .unwrap();
    let mut previous = 1usize;
    for w in r.nodes.windows(2) {
        let dk = w[1][2] + 1 - w[0][2];
        assert!(!(dk == previous && dk != 1), "{:?}", r.nodes);
        previous = dk;
    }
    // The plain DP climbs k in consecutive steps here, so the rule costs value.
    assert!(r.value <= plain.value);
    let climbs = plain
        .nodes
        .windows(3)
        .any(|w| w[1][2] == w[0][2] + 1 && w[2][2] == w[1][2] + 1);
    assert!(climbs, "{:?}", plain.nodes);
    assert!(r.value < plain.value);
}

#[test]
fn acceleration_dp_moves_within_the_joint_acceleration_limits() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let spec = DpSpec {
        joint_acceleration_limits: true,
        ..reduced_dp_spec(&cell)
    };
    let r = dp::solve(&cell, &cache, &spec).unwrap();
    let free = dp::solve(
        &cell,
        &cache,
        &DpSpec {
            joint_acceleration_limits: false,
            ..spec
        },
    )
    .unwrap();
    // A constraint can only lower the optimum.
    assert!(r.value <= free.value + 1e-9);
    let limits: Vec<f64> = cell
        .kinematics()
        .joints()
        .iter()
        .map(|k| {
            cell.robot()
                .joints()
                .iter()
                .find(|j| j.name == k.name)
                .and_then(|j| j.max_acceleration)
                .unwrap_or(f64::INFINITY)
        })
        .collect();
    let lengths: Vec<f64> = cell.path().segments().iter().map(|s| s.length).collect();
    let joints: Vec<[f64; 6]> = r
        .states
        .iter()
        .map(|s| cell.evaluate(s.segment, s.g, None).unwrap().joints)
        .collect();
    let mut worst: f64 = 0.0;
    for t in 1..r.states.len() - 1 {
        let f = r.states[t].feed;
        let h1 = midpoint_interval([lengths[t - 1], lengths[t]], [f, f]);
        let h2 = midpoint_interval([lengths[t], lengths[t + 1]], [f, r.states[t + 1].feed]);
        let back = smallest_motion(&joints[t - 1], &joints[t]);
        let ahead = smallest_motion(&joints[t], &joints[t + 1]);
        for q in 0..6 {
            let a = 2.0 * (ahead[q] / h2 - back[q] / h1) / (h1 + h2);
            assert!(
                a.abs() <= limits[q],
                "segment {t}, joint {q}: {a} rad/s^2 over {}",
                limits[q]
            );
            worst = worst.max(a.abs() / limits[q]);
        }
    }
    // Not vacuous: the plain DP's plan breaks the limit somewhere (its g steps).
    let joints_free: Vec<[f64; 6]> = free
        .states
        .iter()
        .map(|s| cell.evaluate(s.segment, s.g, None).unwrap().joints)
        .collect();
    let breaks = (1..free.states.len() - 1).any(|t| {
        let f = free.states[t].feed;
        let h1 = midpoint_interval([lengths[t - 1], lengths[t]], [f, f]);
        let h2 = midpoint_interval([lengths[t], lengths[t + 1]], [f, free.states[t + 1].feed]);
        let back = smallest_motion(&joints_free[t - 1], &joints_free[t]);
        let ahead = smallest_motion(&joints_free[t], &joints_free[t + 1]);
        (0..6).any(|q| (2.0 * (ahead[q] / h2 - back[q] / h1) / (h1 + h2)).abs() > limits[q])
    });
    assert!(
        breaks,
        "the plain DP already respects the limits: the test shows nothing"
    );
    println!("worst acceleration / limit along the plan: {worst:.3}");
}
