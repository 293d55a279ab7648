//! Plan evaluation on several threads (kerf_millplan::plan): the plan is
//! bit for bit the sequential one whatever the thread count, every
//! segment's |μ|max is the direct evaluation, errors are those of a
//! sequential evaluation (the first bad segment), and the planner's
//! evaluation-thread option and phase timings.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::sync::{Arc, OnceLock};

use kerf_mill::MillCell;
use kerf_millplan::cache::direct_indicator;
use kerf_millplan::plan::{default_eval_threads, IndicatorSource, Plan, MAX_EVAL_THREADS};
use kerf_millplan::{MillPlanError, MillPlanner, MillRequest, PhysicalState, RewardWeights};

fn cell() -> &'static Arc<MillCell> {
    static C: OnceLock<Arc<MillCell>> = OnceLock::new();
    C.get_or_init(|| Arc::new(MillCell::default_cell().expect("default cell")))
}

/// A feasible state sequence of the default cell with Ω, f and g varying
/// along the path (g falls back to 0 where the varied g is infeasible on
/// the branch-continuous IK chain).
fn varied_states(cell: &MillCell) -> Vec<PhysicalState> {
    let lim = *cell.state_limits();
    let n = cell.path().segments().len();
    let mut states = Vec::with_capacity(n);
    let mut reference: Option<[f64; 6]> = None;
    for i in 0..n {
        let x = i as f64 / n as f64;
        let rpm = lim.spindle_rpm[0]
            + (lim.spindle_rpm[1] - lim.spindle_rpm[0]) * (0.5 + 0.45 * (7.0 * x).sin());
        let feed = lim.feed[0] + (lim.feed[1] - lim.feed[0]) * (0.5 + 0.45 * (5.0 * x).cos());
        let mut g = 0.3 * (4.0 * x).sin();
        let cs = match cell.evaluate(i, g, reference.as_ref()) {
            Ok(cs) => cs,
            Err(_) => {
                g = 0.0;
                cell.evaluate(i, g, reference.as_ref())
                    .expect("g = 0 feasible on the default path")
            }
        };
        reference = Some(cs.joints);
        states.push(PhysicalState {
            segment: i,
            rpm,
            feed,
            g,
        });
    }
    states
}

/// Every f64 of a plan as bits, for a bit-for-bit comparison (NaN-safe,
/// unlike `==`).
fn bits(plan: &Plan) -> Vec<u64> {
    let mut out = vec![
        plan.total_time.to_bits(),
        plan.max_spectral_radius.to_bits(),
        plan.min_condition_indicator.to_bits(),
        plan.total_reward.to_bits(),
        u64::from(plan.chatter_free),
    ];
    for s in &plan.segments {
        out.extend(
            [
                s.rpm,
                s.feed,
                s.g,
                s.spectral_radius,
                s.condition_number,
                s.condition_indicator,
                s.time,
                s.reward.total,
                s.reward.operational,
                s.reward.efficiency,
                s.reward.stability,
            ]
            .iter()
            .chain(&s.joints)
            .map(|v| v.to_bits()),
        );
        out.push(s.segment as u64);
    }
    out
}

#[test]
fn parallel_evaluation_is_the_sequential_one_bit_for_bit_and_direct() {
    let cell = cell();
    let states = varied_states(cell);
    let w = RewardWeights::default();
    let seq = Plan::evaluate_with_threads(cell, &w, &states, "varied", 1).expect("sequential");
    assert_eq!(seq.segments.len(), states.len());
    // 2 (the machine), 3 (uneven hand-out), more than the cap.
    for threads in [2, 3, MAX_EVAL_THREADS + 5] {
        let par =
            Plan::evaluate_with_threads(cell, &w, &states, "varied", threads).expect("parallel");
        assert_eq!(bits(&par), bits(&seq), "{threads} threads");
        assert_eq!(par, seq);
    }
    let default = Plan::evaluate(cell, &w, &states, "varied").expect("default threads");
    assert_eq!(bits(&default), bits(&seq));
    // Every |μ|max is the direct evaluation on the branch-continuous chain,
    // and the states are the ones given.
    let mut reference: Option<[f64; 6]> = None;
    let mut distinct_mu = std::collections::BTreeSet::new();
    for (s, st) in seq.segments.iter().zip(&states) {
        assert_eq!(
            (s.segment, s.rpm, s.feed, s.g),
            (st.segment, st.rpm, st.feed, st.g)
        );
        let mu = direct_indicator(cell, s.segment, s.rpm, s.feed, s.g, reference.as_ref())
            .expect("direct")
            .expect("feasible");
        assert_eq!(
            mu.to_bits(),
            s.spectral_radius.to_bits(),
            "segment {}",
            s.segment
        );
        distinct_mu.insert(mu.to_bits());
        reference = Some(s.joints);
    }
    // The sequence really varies (a constant |μ| would hide a mix-up of
    // segments between threads).
    assert!(
        distinct_mu.len() > 90,
        "{} distinct |mu|",
        distinct_mu.len()
    );
    let max = seq
        .segments
        .iter()
        .map(|s| s.spectral_radius)
        .fold(0.0, f64::max);
    assert_eq!(seq.max_spectral_radius, max);
}

#[test]
fn errors_are_those_of_the_first_bad_segment_for_every_thread_count() {
    let cell = cell();
    let states = varied_states(cell);
    let w = RewardWeights::default();
    // Two bad segments: a NaN feed at 37 and a NaN spindle speed at 12.
    let mut bad = states.clone();
    bad[37].feed = f64::NAN;
    bad[12].rpm = f64::NAN;
    for threads in [1, 2, 4] {
        let e =
            Plan::evaluate_with_threads(cell, &w, &bad, "bad", threads).expect_err("NaN refused");
        match &e {
            MillPlanError::InvalidParameter { name, value, .. } => {
                assert!(
                    name.contains("spindle speed") && name.contains("segment 12"),
                    "{e}"
                );
                assert!(value.is_nan());
            }
            other => panic!("{threads} threads: {other:?}"),
        }
    }
    // Only the NaN feed: named, never evaluated into a plan.
    let mut nan_feed = states.clone();
    nan_feed[99].feed = f64::NAN;
    let e = Plan::evaluate_with_threads(cell, &w, &nan_feed, "bad", 2).expect_err("NaN feed");
    assert!(e.to_string().contains("feed [m/s] at segment 99"), "{e}");
    // Out of order, wrong length, zero threads.
    let mut order = states.clone();
    order.swap(3, 4);
    let e = Plan::evaluate_with_threads(cell, &w, &order, "bad", 2).expect_err("order");
    assert!(e.to_string().contains("state 3 is for segment 4"), "{e}");
    assert!(matches!(
        Plan::evaluate_with_threads(cell, &w, &states[1..], "bad", 2),
        Err(MillPlanError::InvalidConfig { .. })
    ));
    assert!(matches!(
        Plan::evaluate_with_threads(cell, &w, &states, "bad", 0),
        Err(MillPlanError::InvalidParameter { .. })
    ));
    // An infeasible g at segment 50 (beyond the cell's range is a
    // parameter error; the message names the segment).
    let mut far = states;
    far[50].g = cell.state_limits().redundancy_angle[1] + 1.0;
    let e = Plan::evaluate_with_threads(cell, &w, &far, "bad", 3).expect_err("g range");
    assert!(e.to_string().contains("segment 50"), "{e}");
}

#[test]
fn planner_eval_threads_option_and_phases() {
    assert!((1..=MAX_EVAL_THREADS).contains(&default_eval_threads()));
    let base = MillPlanner::with_default_cell().expect("planner");
    assert_eq!(base.eval_threads(), default_eval_threads());
    assert!(matches!(
        MillPlanner::with_default_cell()
            .expect("planner")
            .with_eval_threads(0),
        Err(MillPlanError::InvalidParameter { .. })
    ));
    assert!(
        base.cache().is_some(),
        "the default indicator cache must load (naive planner)"
    );
    let one = base.with_eval_threads(1).expect("1 thread");
    let two = MillPlanner::with_default_cell()
        .and_then(|p| p.with_eval_threads(2))
        .expect("2 threads");
    assert_eq!((one.eval_threads(), two.eval_threads()), (1, 2));
    let request = MillRequest {
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    let a = one.plan(&request).expect("naive, 1 thread");
    let b = two.plan(&request).expect("naive, 2 threads");
    assert_eq!(bits(&a.plan), bits(&b.plan));
    assert_eq!(a.trajectory, b.trajectory);
    for out in [&a, &b] {
        let p = out.phases;
        for v in [p.setup, p.planner, p.evaluation, p.trajectory] {
            assert!(v.is_finite() && v >= 0.0, "{p:?}");
        }
        // The evaluation (100 indicator evaluations) is not free, and the
        // phases fit in the total.
        assert!(p.evaluation > 0.0, "{p:?}");
        let sum = p.setup + p.planner + p.evaluation + p.trajectory;
        assert!(
            sum <= out.planning_seconds + 1e-9,
            "{p:?} vs {}",
            out.planning_seconds
        );
        assert!(
            sum >= 0.5 * out.planning_seconds,
            "{p:?} vs {}",
            out.planning_seconds
        );
    }
}

/// `IndicatorSource::Cache`: the cached segments, their bound and the
/// conservative chatter-free claim are reported; every cached |μ|max is
/// within the stated bound of the direct value, every other segment is the
/// direct value bit for bit; a cache without a stated bound falls back to
/// direct evaluation and says so; the default stays direct.
#[test]
fn cache_source_reports_cached_segments_and_bound_and_stays_within_it() {
    let direct = MillPlanner::with_default_cell().expect("planner");
    assert_eq!(direct.indicator_source(), IndicatorSource::Direct);
    let cache = direct
        .cache()
        .cloned()
        .expect("the default cache must load");
    let request = MillRequest {
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    let d = direct.plan(&request).expect("direct naive");
    assert!(d.indicator.all_direct());
    assert_eq!(d.indicator.requested, IndicatorSource::Direct);
    assert_eq!(d.indicator.error_bound, None);
    assert!(
        d.indicator.note.contains("directly"),
        "{}",
        d.indicator.note
    );

    let cached = MillPlanner::new(direct.cell().clone(), Some(cache.clone()))
        .expect("planner")
        .with_indicator_source(IndicatorSource::Cache);
    let c = cached.plan(&request).expect("cached naive");
    let prov = &c.indicator;
    assert_eq!(prov.requested, IndicatorSource::Cache);
    assert_eq!(prov.segments, 100);
    // The naive plan keeps g = g0 = 0, a g node of the default cache, so
    // the bound is the g-node one when the cache states it.
    assert!(!prov.cached_segments.is_empty(), "{}", prov.note);
    let header = cache.header();
    let expected_bound = header
        .error_bound_g_nodes
        .map_or(header.error_bound, |b| header.error_bound.map(|g| b.min(g)));
    assert_eq!(prov.error_bound, expected_bound);
    let bound = prov.error_bound.expect("bound");
    assert!(prov.note.contains("INTERPOLATED"), "{}", prov.note);
    assert!(prov.note.contains(&format!("{bound:.3}")), "{}", prov.note);
    // Same states, same trajectory; |μ| cached within the bound or direct.
    assert_eq!(d.trajectory, c.trajectory);
    let mut reached_bound = 0.0f64;
    for (a, b) in d.plan.segments.iter().zip(&c.plan.segments) {
        assert_eq!(
            (a.rpm, a.feed, a.g, a.joints),
            (b.rpm, b.feed, b.g, b.joints)
        );
        if prov.cached_segments.contains(&a.segment) {
            let err = (a.spectral_radius - b.spectral_radius).abs();
            assert!(
                err <= bound,
                "segment {}: error {err} > bound {bound}",
                a.segment
            );
            reached_bound = reached_bound.max(err);
        } else {
            assert_eq!(a.spectral_radius.to_bits(), b.spectral_radius.to_bits());
        }
    }
    // The cache is an interpolation, not the direct value everywhere.
    assert!(reached_bound > 0.0);
    let conservative = c.plan.segments.iter().all(|s| {
        let m = if prov.cached_segments.contains(&s.segment) {
            bound
        } else {
            0.0
        };
        s.spectral_radius + m < 1.0
    });
    assert_eq!(c.plan.chatter_free, conservative);
    println!(
        "cache source: {} cached, max |cached - direct| {reached_bound:.4} (bound {bound}); \
         evaluation {:.1} ms cached vs {:.1} ms direct (dev profile)",
        prov.cached_segments.len(),
        c.phases.evaluation * 1e3,
        d.phases.evaluation * 1e3
    );

    // No stated bound: direct evaluation, and the note says why.
    let mut unbounded = (*cache).clone();
    unbounded
        .set_error((None, None), (None, None), "test: no bound")
        .expect("set");
    let u = MillPlanner::new(direct.cell().clone(), Some(Arc::new(unbounded)))
        .expect("planner")
        .with_indicator_source(IndicatorSource::Cache)
        .plan(&request)
        .expect("unbounded cache plan");
    assert!(u.indicator.all_direct());
    assert_eq!(u.indicator.requested, IndicatorSource::Cache);
    assert!(
        u.indicator.note.contains("no error bound"),
        "{}",
        u.indicator.note
    );
    assert_eq!(bits(&u.plan), bits(&d.plan));
}

/// The planner keeps the cells of recent (path, process) pairs: planning
/// the default path, another path, then the default path again gives the
/// first plan bit for bit, and the other path is still recognized as
/// another model (the default cache does not apply to it).
#[test]
fn request_cells_are_kept_per_path_without_mixing_paths() {
    let planner = MillPlanner::with_default_cell().expect("planner");
    assert!(planner.cache().is_some(), "the default cache must load");
    let a = MillRequest {
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    let mut b = a.clone();
    for p in &mut b.points {
        p[0] += 0.005;
    }
    let first = planner.plan(&a).expect("default path");
    assert!(first.cache_used);
    // The other path with the greedy ramp (direct |μ|: no cache; naive would build a per-path
    // cache for it, `path_cache`).
    b.planner = "greedy".to_string();
    for round in 0..2 {
        let other = planner.plan(&b).expect("another path");
        assert!(
            !other.cache_used,
            "round {round}: the default cache does not apply"
        );
        let again = planner.plan(&a).expect("default path again");
        assert!(again.cache_used, "round {round}");
        assert_eq!(bits(&again.plan), bits(&first.plan), "round {round}");
        assert_eq!(again.trajectory, first.trajectory);
        println!(
            "setup: first {:.1} ms, kept {:.1} ms (dev profile)",
            first.phases.setup * 1e3,
            again.phases.setup * 1e3
        );
    }
}

/// The plan as executed (time-scaled to the joint limits) in both modes:
/// the committed DDPG policy's plan is slowed in most intervals; with the
/// cache source the slowed segments take the cache's value where it applies
/// (within its bound of the direct value) and are listed, and the
/// chatter-free claim keeps the bound; with the direct source nothing is
/// cached and the executed values are direct.
#[test]
fn executed_plan_in_cache_and_direct_modes() {
    let direct = MillPlanner::with_default_cell().expect("planner");
    let cache = direct
        .cache()
        .cloned()
        .expect("the default cache must load");
    let cached = MillPlanner::new(direct.cell().clone(), Some(cache))
        .expect("planner")
        .with_indicator_source(IndicatorSource::Cache);
    let request = MillRequest {
        planner: "ddpg".to_string(),
        ..MillRequest::default()
    };
    let d = direct.plan(&request).expect("direct ddpg");
    let c = cached.plan(&request).expect("cached ddpg");
    assert!(d.executed.cached_segments.is_empty());
    assert_eq!(d.executed.scaling, c.executed.scaling);
    assert!(d.executed.scaling.slowed_segments() > 0);
    let bound = c.indicator.error_bound.expect("bound");
    let mut changed_and_cached = 0;
    for (a, b) in d
        .executed
        .plan
        .segments
        .iter()
        .zip(&c.executed.plan.segments)
    {
        assert_eq!((a.rpm, a.feed, a.g, a.time), (b.rpm, b.feed, b.g, b.time));
        if c.executed.cached_segments.contains(&a.segment) {
            assert!((a.spectral_radius - b.spectral_radius).abs() <= bound);
            let planned = &c.plan.segments[a.segment];
            if planned.feed != b.feed {
                changed_and_cached += 1;
            }
        } else {
            assert_eq!(a.spectral_radius.to_bits(), b.spectral_radius.to_bits());
        }
    }
    assert!(changed_and_cached > 0);
    let claimed = c.executed.plan.segments.iter().all(|s| {
        s.spectral_radius
            + if c.executed.cached_segments.contains(&s.segment) {
                bound
            } else {
                0.0
            }
            < 1.0
    });
    assert_eq!(c.executed.plan.chatter_free, claimed);
}
