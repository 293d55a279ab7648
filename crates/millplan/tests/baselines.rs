//! The baselines of issue 13, item 3 (the greedy ramp, g held at g0 and the best fixed g) and
//! item 4's "every planner plans any valid path": dp and naive on a path no shipped cache
//! covers, through per-path caches (`kerf_millplan::path_cache`) built under the request's
//! budget. Small requests (few segments, narrowed ranges) keep the tests to seconds; the
//! full-size figures are in `benches/baselines.rs` and `benches/path_cache.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::Duration;

use kerf_budget::{Budget, CancelToken};
use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::MillCell;
use kerf_millplan::greedy;
use kerf_millplan::path_cache::path_grid;
use kerf_millplan::path_distribution::moved_points;
use kerf_millplan::request::{RequestInitial, RequestLimits};
use kerf_millplan::{
    status, status_of, IndicatorCache, MillPlanOutput, MillPlanner, MillRequest, TrajectorySettings,
};

/// A small request on the shifted, turned path: `segments` segments, Ω in 2000–2200 rpm (a
/// per-path cache of 2 Ω × 4 f × 33 g nodes per segment node, about 20 g of them reachable);
/// the g range stays the cell's.
fn small_shifted(planner: &str, segments: usize) -> MillRequest {
    MillRequest {
        points: moved_points(&MillRequest::default().points, 0.3, [-0.1, 0.05, -0.1]),
        segments: Some(segments),
        limits: Some(RequestLimits {
            spindle_rpm: Some([2000.0, 2200.0]),
            ..RequestLimits::default()
        }),
        planner: planner.to_string(),
        ..MillRequest::default()
    }
}

/// Every planned state starts at the request's initial state and moves within the step
/// bounds (default cell bounds: 20 rpm, 1e-3 m/s, 0.2 rad).
fn assert_from_initial_within_steps(out: &MillPlanOutput, initial: [f64; 3]) {
    let s = &out.plan.segments;
    assert_eq!(
        [s[0].rpm, s[0].feed, s[0].g],
        initial,
        "{}",
        out.plan.planner
    );
    for w in s.windows(2) {
        assert!((w[1].rpm - w[0].rpm).abs() <= 20.0 + 1e-9, "{:?}", w);
        assert!((w[1].feed - w[0].feed).abs() <= 1e-3 + 1e-12, "{:?}", w);
        assert!((w[1].g - w[0].g).abs() <= 0.2 + 1e-12, "{:?}", w);
    }
}

/// |μ|max of segment `t` of a plan, evaluated here directly from the plan's joints' cell
/// state (IK nearest the plan's previous joints).
fn direct_mu(cell: &MillCell, out: &MillPlanOutput, t: usize) -> f64 {
    let s = &out.plan.segments[t];
    let reference = (t > 0).then(|| out.plan.segments[t - 1].joints);
    let cs = cell.evaluate(t, s.g, reference.as_ref()).unwrap();
    chatter_indicator(
        &cs.modal,
        &cell.milling_process(),
        s.rpm,
        s.feed,
        cell.indicator_settings(),
    )
    .unwrap()
    .spectral_radius
}

#[test]
fn greedy_ramps_from_the_initial_state_at_the_step_bounds() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let request = MillRequest {
        segments: Some(30),
        initial: Some(RequestInitial {
            spindle_rpm: Some(2100.0),
            feed: Some(0.045),
            g: Some(-0.2),
        }),
        planner: "greedy".to_string(),
        allow_chatter: true,
        ..MillRequest::default()
    };
    let out = planner.plan(&request).unwrap();
    assert_from_initial_within_steps(&out, [2100.0, 0.045, -0.2]);
    let s = &out.plan.segments;
    assert!(s.iter().all(|x| x.g == -0.2), "g is held at the initial g");
    // The rule: at every later segment, a higher feed within one step would have chattered
    // at every speed within one step (checked where the ramp did not take the full step).
    let cell = MillCell::default_cell()
        .unwrap()
        .with_path(&request.path_spec(100))
        .unwrap();
    let mut checked = 0;
    for t in 1..s.len() {
        let higher = (s[t - 1].feed + 1e-3).min(0.06);
        if s[t].feed < higher {
            let cs = cell.evaluate(t, s[t].g, Some(&s[t - 1].joints)).unwrap();
            for rpm in [s[t - 1].rpm - 20.0, s[t - 1].rpm, s[t - 1].rpm + 20.0] {
                let rpm = rpm.clamp(2000.0, 4000.0);
                let mu = chatter_indicator(
                    &cs.modal,
                    &cell.milling_process(),
                    rpm,
                    higher,
                    cell.indicator_settings(),
                )
                .unwrap()
                .spectral_radius;
                assert!(
                    mu >= 1.0,
                    "segment {t}: {rpm} rpm {higher} m/s has |mu| {mu}"
                );
            }
            checked += 1;
        }
    }
    // The feed reaches f_max (0.06 m/s) after 15 steps, and stays there, unless chatter
    // stops it (then the checks above ran).
    assert!(
        s.last().unwrap().feed == 0.06 || checked > 0,
        "{:?}",
        s.last()
    );
    // Stable where the greedy found a stable move: the plan's direct |μ| agrees.
    assert_eq!(out.plan.chatter_free, out.plan.max_spectral_radius < 1.0);
    for t in [0, 7, 29] {
        assert_eq!(
            direct_mu(&cell, &out, t),
            out.plan.segments[t].spectral_radius
        );
    }
}

#[test]
fn greedy_best_g_holds_the_best_reachable_fixed_g() {
    let cell = MillCell::default_cell().unwrap();
    let request = MillRequest {
        segments: Some(20),
        limits: Some(RequestLimits {
            redundancy_angle: Some([-0.4, 0.4]),
            ..RequestLimits::default()
        }),
        ..MillRequest::default()
    };
    let cell = cell
        .with_path(&request.path_spec(100))
        .unwrap()
        .with_state_limits(request.effective_limits(cell.state_limits()))
        .unwrap();
    let settings = TrajectorySettings::default();
    let budget = Budget::unlimited();
    let all = greedy::fixed_g_candidates_within(&cell, [2000.0, 0.04, 0.0], 2, &settings, &budget)
        .unwrap();
    assert_eq!(
        all.iter().map(|r| r.g).collect::<Vec<_>>(),
        [0.0, -0.2, 0.2, -0.4, 0.4],
        "every g0 + k 0.2 rad of the range, nearest g0 first"
    );
    let best =
        greedy::best_fixed_g_within(&cell, [2000.0, 0.04, 0.0], 1, &settings, &budget).unwrap();
    assert_eq!(best.candidates, 5);
    // g moves from g0 to g* at the step bound, then stays.
    let mut g = 0.0_f64;
    for (t, x) in best.states.iter().enumerate() {
        if t > 0 {
            g = if (best.g - g).abs() <= 0.2 {
                best.g
            } else {
                g + 0.2 * (best.g - g).signum()
            };
        }
        assert_eq!(x.g, g, "segment {t}");
    }
    assert_eq!(best.states[0].rpm, 2000.0);
    assert_eq!(best.states[0].feed, 0.04);
    // The choice: chatter-free first, then the shortest time as executed, among the
    // candidates whose trajectory can be built.
    let time = best.executed_time.unwrap();
    assert!(all[0].executed_time.is_some(), "g0 itself is executable");
    for r in all.iter().filter(|r| r.executed_time.is_some()) {
        if r.chatter_free == best.chatter_free {
            assert!(time <= r.executed_time.unwrap(), "g* {} is faster", r.g);
        }
        assert!(best.chatter_free || !r.chatter_free);
    }
    // The same plan with 1 and 2 threads.
    let two =
        greedy::best_fixed_g_within(&cell, [2000.0, 0.04, 0.0], 2, &settings, &budget).unwrap();
    assert_eq!(two.states, best.states);
}

#[test]
fn dp_and_naive_plan_a_path_no_shipped_cache_covers() {
    let planner = MillPlanner::with_default_cell().unwrap();
    assert!(planner.cache().is_some(), "the shipped cache is loaded");
    let cell = MillCell::default_cell()
        .unwrap()
        .with_path(&small_shifted("dp", 6).path_spec(100))
        .unwrap();
    for kind in ["dp", "naive"] {
        let request = small_shifted(kind, 6);
        let out = planner.plan(&request).unwrap();
        assert!(!out.cache_used, "{kind}: the shipped cache does not apply");
        assert_eq!(out.plan.segments.len(), 6);
        // |μ|max of the plan is evaluated directly, not interpolated.
        for t in [0, 3, 5] {
            assert_eq!(
                direct_mu(&cell, &out, t),
                out.plan.segments[t].spectral_radius,
                "{kind} segment {t}"
            );
        }
        // What the robot runs: executable (the planner checked it with the executor's
        // validation), on the path.
        let d = &out.executed.scaling.deviation;
        let tol = out.executed.settings.path_tolerance;
        assert!(
            d.max_off_path <= tol && d.max_off_plane <= tol,
            "{kind}: {d:?}"
        );
        if kind == "dp" {
            assert_from_initial_within_steps(&out, [2000.0, 0.04, 0.0]);
        } else {
            // The naive pair is verified directly at every segment before it is chosen.
            assert!(
                out.plan.chatter_free,
                "naive: {}",
                out.plan.max_spectral_radius
            );
        }
    }
    // One per-path cache (dp and naive share it), kept for the next request; the same plan
    // again.
    assert_eq!(planner.path_caches().len(), 1);
    let again = planner.plan(&small_shifted("dp", 6)).unwrap();
    assert_eq!(planner.path_caches().len(), 1);
    let first = planner.plan(&small_shifted("dp", 6)).unwrap();
    assert_eq!(again.plan, first.plan);
}

#[test]
fn a_speed_range_beyond_the_shipped_cache_gets_a_per_path_cache() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let request = |max_rpm: f64| MillRequest {
        limits: Some(RequestLimits {
            spindle_rpm: Some([3900.0, max_rpm]),
            ..RequestLimits::default()
        }),
        initial: Some(RequestInitial {
            spindle_rpm: Some(4000.0),
            ..RequestInitial::default()
        }),
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    // Within the shipped cache's 2000-4000 rpm: no per-path cache.
    let out = planner.plan(&request(4000.0)).unwrap();
    assert!(out.cache_used);
    assert!(planner.path_caches().is_empty());
    // Up to 4100 rpm: the shipped cache cannot say anything above 4000 rpm.
    let out = planner.plan(&request(4100.0)).unwrap();
    assert_eq!(planner.path_caches().len(), 1);
    assert!(out.plan.chatter_free, "{}", out.plan.max_spectral_radius);
    assert!(out.plan.segments.iter().all(|s| s.rpm <= 4100.0));
}

#[test]
fn the_per_path_cache_build_honours_the_budget() {
    // The planner: a request whose budget ends during its path's cache build (or before)
    // is TIMEOUT, and nothing is kept.
    let planner = MillPlanner::with_default_cell().unwrap();
    let request = MillRequest {
        time_budget: Some(0.05),
        ..small_shifted("dp", 100)
    };
    let request = MillRequest {
        limits: None,
        ..request
    };
    let e = planner.plan(&request).unwrap_err();
    assert_eq!(status_of(&e), status::TIMEOUT, "{e}");
    assert!(planner.path_caches().is_empty());
    // The build itself: its full grid takes seconds; a 20 ms budget ends it.
    let cell = MillCell::default_cell()
        .unwrap()
        .with_path(&request.path_spec(100))
        .unwrap();
    let grid = path_grid(&cell, 0.0).unwrap();
    let budget = Budget::new(Some(Duration::from_millis(20)), CancelToken::new());
    let e = IndicatorCache::build_within(&cell, &grid, 2, &budget).unwrap_err();
    assert_eq!(status_of(&e), status::TIMEOUT, "{e}");
    // A cancelled build stops too (not a timeout: the node is stopping).
    let cancel = CancelToken::new();
    cancel.cancel();
    let e = IndicatorCache::build_within(&cell, &grid, 1, &Budget::new(None, cancel)).unwrap_err();
    assert_eq!(status_of(&e), status::INTERNAL_ERROR, "{e}");
}

#[test]
fn the_per_path_grid_follows_the_request() {
    let cell = MillCell::default_cell().unwrap();
    let grid = path_grid(&cell, 0.0).unwrap();
    assert_eq!(grid.segments, [0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 99]);
    assert_eq!(grid.rpm.len(), 11);
    assert_eq!(grid.rpm[0], 2000.0);
    assert_eq!(grid.rpm[10], 4000.0);
    let feed: Vec<f64> = grid.feed.iter().map(|f| (f * 1e6).round() / 1e6).collect();
    assert_eq!(feed, [0.01, 0.03, 0.045, 0.06]);
    // g: every 0.2 rad from g0 = 0 (the DP's g nodes), and the range's ends.
    assert_eq!(grid.g.len(), 33);
    assert!(grid.g.contains(&0.0) && grid.g.contains(&0.2) && grid.g.contains(&-3.0));
    assert_eq!(grid.g[0], -std::f64::consts::PI);
    // Another g0: its nodes move with it.
    let grid = path_grid(&cell, 0.1).unwrap();
    assert!(grid.g.contains(&0.1) && grid.g.contains(&0.30000000000000004));
    // A g0 outside the range is refused.
    assert!(path_grid(&cell, 4.0).is_err());
    // Longer segments: denser segment nodes (at most 0.1 m apart).
    let request = MillRequest {
        segments: Some(20),
        ..MillRequest::default()
    };
    let cell = cell.with_path(&request.path_spec(100)).unwrap();
    let grid = path_grid(&cell, 0.0).unwrap();
    assert_eq!(grid.segments, [0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 19]);
    // Many short segments: the same spacing along the path, not more nodes.
    let request = MillRequest {
        segments: Some(1000),
        ..MillRequest::default()
    };
    let cell = cell.with_path(&request.path_spec(100)).unwrap();
    let grid = path_grid(&cell, 0.0).unwrap();
    assert_eq!(grid.segments.len(), 11, "{:?}", grid.segments);
    let longest = cell
        .path()
        .segments()
        .iter()
        .map(|s| s.length)
        .fold(0.0, f64::max);
    for w in grid.segments.windows(2) {
        assert!((w[1] - w[0]) as f64 * longest <= 0.1 + 1e-12, "{w:?}");
    }
}

#[test]
fn a_subgrid_copies_the_nodes_and_refuses_others() {
    let cell = MillCell::default_cell().unwrap();
    let full = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let grid = full.grid().clone();
    let mut spec = grid.clone();
    spec.segments = vec![0, 50, 99];
    spec.rpm = vec![2000.0, 3000.0, 4000.0];
    let sub = full.subgrid(&spec).unwrap();
    for (s, seg) in [0usize, 50, 99].iter().enumerate() {
        let os = grid.segments.iter().position(|x| x == seg).unwrap();
        for (r, rpm) in spec.rpm.iter().enumerate() {
            let or = grid.rpm.iter().position(|x| x == rpm).unwrap();
            for f in 0..spec.feed.len() {
                for g in 0..spec.g.len() {
                    assert_eq!(sub.node_value(s, r, f, g), full.node_value(os, or, f, g));
                }
            }
        }
    }
    spec.rpm = vec![2000.0, 2050.0];
    assert!(full.subgrid(&spec).is_err());
}
