//! The DP with the executed timing in the loop (`kerf_millplan::dp_executed`, issue 13 item 3)
//! on a reduced grid of the default cell with the committed cache: held moves are obeyed, holds
//! only grow from round to round, the answer is the round with the best eq. 12 total as
//! executed, and holding every move is the fixed-g DP.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;
use support::reduced_dp_spec;

use kerf_budget::Budget;
use kerf_mill::MillCell;
use kerf_millplan::cache::IndicatorCache;
use kerf_millplan::dp::{self, DpSpec};
use kerf_millplan::dp_executed::{solve_executed, DP_EXECUTED_ROUNDS};

#[test]
fn holding_every_move_is_the_fixed_g_dp() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let spec = reduced_dp_spec(&cell);
    let n = cell.path().segments().len();
    let held =
        dp::solve_holding(&cell, &cache, &spec, &vec![true; n], &Budget::unlimited()).unwrap();
    let fixed = dp::solve(
        &cell,
        &cache,
        &DpSpec {
            g_range: [0.0, 0.0],
            ..spec
        },
    )
    .unwrap();
    assert_eq!(held.states, fixed.states);
    // Not vacuous: the free DP moves g.
    let free = dp::solve(&cell, &cache, &spec).unwrap();
    assert!(free.states.iter().any(|s| s.g != 0.0));
}

#[test]
fn rounds_obey_and_grow_their_holds_and_answer_the_best_as_executed() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let r = solve_executed(
        &cell,
        &cache,
        &reduced_dp_spec(&cell),
        2,
        &Budget::unlimited(),
    )
    .unwrap();
    assert!(!r.rounds.is_empty() && r.rounds.len() <= DP_EXECUTED_ROUNDS);
    assert!(
        r.rounds[0].held.iter().all(|h| !h),
        "the first round holds nothing"
    );
    for (k, round) in r.rounds.iter().enumerate() {
        let states = &round.result.states;
        for (t, h) in round.held.iter().enumerate() {
            if *h && t + 1 < states.len() {
                assert_eq!(states[t].g, states[t + 1].g, "round {k}: held move {t}");
            }
        }
        if let Some(next) = r.rounds.get(k + 1) {
            assert!(round.held.iter().zip(&next.held).all(|(a, b)| !a || *b));
            assert!(
                next.held.iter().filter(|h| **h).count()
                    > round.held.iter().filter(|h| **h).count()
            );
        }
        println!(
            "round {k}: {} held, planned {:.3} s, executed {:.3} s, reward as executed {:.3}",
            round.held.iter().filter(|h| **h).count(),
            round.plan.total_time,
            round.executed.plan.total_time,
            round.executed.plan.total_reward
        );
    }
    // The first DP plan moves g and is slowed as executed: the loop has work to do.
    assert!(r.rounds[0].executed.scaling.slowed_segments() > 0);
    let best = r.best().unwrap().executed.plan.total_reward;
    assert!(r
        .rounds
        .iter()
        .all(|round| round.executed.plan.total_reward <= best));
}
