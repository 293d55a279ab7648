//! Issue 28, items 1 and 2: no planner answers SUCCESS for a plan that chatters as executed,
//! ramps included, and every planner answers every valid path with a correct status.
//!
//! The check of an answered plan does not use the planner's judge: it runs the published
//! trajectory through the executor's own validation and interpolation
//! (`kerf_executor::check_executable`), takes the tool tip by forward kinematics every 40 ms,
//! finds its place on the path by a brute-force closest point on a fine polyline, its feed by a
//! central difference of the tip positions, and evaluates the chatter indicator there directly
//! (`kerf_chatter::chatter_indicator` at the segment's tool-tip dynamics).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_chatter::chatter_indicator;
use kerf_executor::{check_executable, ExecutorConfig, JointSample};
use kerf_mill::MillCell;
use kerf_millplan::path_distribution::{sample_path, PathDistribution, HELD_OUT_SEEDS};
use kerf_millplan::planner::status;
use kerf_millplan::{status_of, MillPlanError, MillPlanOutput, MillPlanner, MillRequest};
use nalgebra::Vector3;

/// Time between the independent check's samples \[s\].
const CHECK_PERIOD: f64 = 0.04;

/// Central-difference step of the tip's feed \[s\].
const FEED_STEP: f64 = 1e-3;

/// The largest |μ|max the independent check finds on the executed trajectory in the
/// material, and how many samples it evaluated.
fn independent_max_mu(cell: &MillCell, out: &MillPlanOutput) -> (f64, usize) {
    let traj = &out.executed.scaling.trajectory;
    let limits = cell.robot().executor_limits().unwrap();
    let run = check_executable(&limits, &ExecutorConfig::default(), &traj.request).unwrap();
    let path = cell.path();
    let length = path.total_length();
    // The path as 20 000 chords, with arc lengths.
    let fine: Vec<(Vector3<f64>, f64)> = (0..=20_000)
        .map(|k| {
            let u = k as f64 / 20_000.0;
            (path.point(u).unwrap(), path.arc_length_at(u).unwrap())
        })
        .collect();
    let mut boundaries = vec![0.0];
    for i in 0..path.segments().len() {
        boundaries.push(boundaries[i] + path.segment(i).unwrap().length);
    }
    let mut sample = JointSample::default();
    let mut tip = |t: f64| {
        run.sample_into(t, &mut sample);
        let q: [f64; 6] = sample.positions.clone().try_into().unwrap();
        cell.kinematics().tcp_pose(&q).unwrap().translation.vector
    };
    let profiles = &out.executed.scaling.profiles;
    let (mut worst, mut evaluated) = (0.0_f64, 0);
    let end = run.end_time() - run.start_time();
    let mut t = FEED_STEP;
    while t < end - FEED_STEP {
        let x = tip(t);
        let (closest, s) = fine
            .iter()
            .map(|(p, s)| ((p - x).norm(), *s))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap();
        // On the path (not the run-in or run-out, which end at its ends), clear of its ends.
        if closest < 1e-3 && s > 1e-3 && s < length - 1e-3 {
            let feed = (tip(t + FEED_STEP) - tip(t - FEED_STEP)).norm() / (2.0 * FEED_STEP);
            let segment = boundaries[1..]
                .partition_point(|b| *b <= s)
                .min(path.segments().len() - 1);
            let g = profiles.g.eval(s).value;
            let rpm = profiles.rpm.eval(s).value;
            let reference = segment.checked_sub(1).map(|p| out.plan.segments[p].joints);
            let state = cell.evaluate(segment, g, reference.as_ref()).unwrap();
            let mu = chatter_indicator(
                &state.modal,
                &cell.milling_process(),
                rpm,
                feed,
                cell.indicator_settings(),
            )
            .map(|i| i.spectral_radius)
            .unwrap_or(f64::INFINITY);
            worst = worst.max(mu);
            evaluated += 1;
        }
        t += CHECK_PERIOD;
    }
    (worst, evaluated)
}

/// The statuses a valid path may get instead of a plan: a path property, never an internal
/// error or a policy-file error.
fn allowed_refusal(e: &MillPlanError) -> bool {
    matches!(
        status_of(e),
        status::CHATTER | status::INFEASIBLE | status::UNREACHABLE
    )
}

/// Every planner on the default path and on held-out paths: a plan that is answered
/// (SUCCESS) does not chatter as the executor runs it (the independent check), and a refusal
/// is CHATTER, INFEASIBLE or UNREACHABLE with a message.
#[test]
fn no_planner_answers_success_for_a_plan_that_chatters_as_executed() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let base = MillCell::default_cell().unwrap();
    let all = [
        "ddpg",
        "fixed_g",
        "naive",
        "greedy",
        "greedy_best_g",
        "best",
    ];
    let mut paths = vec![(
        "default".to_string(),
        MillRequest::default().points,
        &all[..],
    )];
    // Held-out 900002 (g = 0 infeasible on segment 46) with every planner; on 900008 no
    // planner has a chatter-free plan (each refusal replans the path with the other
    // candidates for its message, so only `best` here).
    for (k, kinds) in [(1, &all[..]), (7, &all[5..])] {
        let p = sample_path(&base, &PathDistribution::default(), HELD_OUT_SEEDS[k]).unwrap();
        paths.push((format!("held-out {}", p.seed), p.spec.points, kinds));
    }
    let mut answered = 0;
    let mut refused = 0;
    for (name, points, kinds) in &paths {
        let cell = base
            .with_path(&kerf_mill::PathSpec {
                points: points.clone(),
                ..kerf_mill::PathSpec::default()
            })
            .unwrap();
        for &kind in kinds.iter() {
            let request = MillRequest {
                points: points.clone(),
                planner: kind.to_string(),
                ..MillRequest::default()
            };
            match planner.plan(&request) {
                Ok(out) => {
                    answered += 1;
                    assert!(!out.executed.chatters(), "{name} {kind}");
                    assert!(out.executed.chatter.chatter_free);
                    let (mu, n) = independent_max_mu(&cell, &out);
                    println!(
                        "{name} {kind}: SUCCESS ({}), judge {:.4} at {} samples, independent \
                         {mu:.4} at {n}",
                        out.planner.name(),
                        out.executed.chatter.max_spectral_radius,
                        out.executed.chatter.samples
                    );
                    assert!(n > 100, "{name} {kind}: {n} samples checked");
                    // The central difference of the feed is good to about 1e-6 relative.
                    assert!(mu < 1.0 + 1e-4, "{name} {kind}: |mu| {mu} as executed");
                }
                Err(e) => {
                    refused += 1;
                    println!("{name} {kind}: {}: {e}", status_of(&e));
                    assert!(allowed_refusal(&e), "{name} {kind}: {e}");
                    assert!(!e.to_string().is_empty());
                }
            }
        }
    }
    assert!(answered >= 6 && refused >= 1, "{answered} {refused}");
}

/// A plan that chatters as executed is CHATTER, naming the segment, its |μ|max and the lowest
/// |μ|max any planner reached on the path; with `allow_chatter` it is answered, and the judge
/// found what the segments' values say too.
#[test]
fn a_chattering_plan_is_chatter_unless_allowed() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let request = MillRequest {
        planner: "fixed_g".to_string(),
        ..MillRequest::default()
    };
    let e = planner
        .plan(&request)
        .expect_err("fixed_g chatters on the default path");
    assert_eq!(status_of(&e), status::CHATTER, "{e}");
    let MillPlanError::Chattering {
        planner: who,
        worst,
        lowest,
        reason,
    } = &e
    else {
        panic!("{e:?}")
    };
    assert_eq!(who, "fixed_g");
    assert!(worst.spectral_radius >= 1.0, "{worst:?}");
    let (other, mu) = lowest.clone().expect("the lowest |mu|");
    assert!(mu < 1.0, "{other} {mu}");
    assert!(
        reason.contains("chatter-free") && reason.contains("ask for planner"),
        "{reason}"
    );
    let text = e.to_string();
    assert!(
        text.contains(&format!("segment {}", worst.segment))
            && text.contains("lowest |μ|max any planner reached"),
        "{text}"
    );
    let allowed = planner
        .plan(&MillRequest {
            allow_chatter: true,
            ..request
        })
        .expect("allowed");
    assert!(allowed.executed.chatters());
    assert!(!allowed.executed.plan.chatter_free);
    let v = &allowed.executed.chatter;
    assert_eq!(v.max_spectral_radius, worst.spectral_radius);
    assert!(v.chattering_segments.contains(&worst.segment));
    assert!(v.first_chatter.is_some());
}

/// Ramps from rest in the material (entry in_material) pass every feed from 0, and the cut
/// chatters there at any spindle speed: CHATTER with that reason. The default entry (a run-in
/// outside the material) plans the same request chatter-free, and its judge sees no sample in
/// the material below the first segment's feed.
#[test]
fn ramps_in_the_material_cannot_be_stable() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let request = MillRequest {
        planner: "naive".to_string(),
        entry: Some("in_material".to_string()),
        ..MillRequest::default()
    };
    let e = planner.plan(&request).expect_err("ramps in the material");
    assert_eq!(status_of(&e), status::CHATTER, "{e}");
    let MillPlanError::Chattering { worst, reason, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(reason.contains("entry in_material"), "{reason}");
    assert!(
        worst.feed < 0.015,
        "the worst sample is in a ramp: {worst:?}"
    );
    let allowed = planner
        .plan(&MillRequest {
            allow_chatter: true,
            ..request.clone()
        })
        .unwrap();
    let lowest = allowed.executed.chatter.lowest_feed.unwrap();
    assert!(lowest.feed < 1e-3, "{lowest:?}");
    assert_eq!(allowed.executed.scaling.run_in, 0.0);
    // The run-in: in the material at feed.
    let out = planner
        .plan(&MillRequest {
            entry: None,
            ..request
        })
        .unwrap();
    assert!(!out.executed.chatters());
    let sc = &out.executed.scaling;
    assert!(sc.run_in > 0.0 && sc.run_out > 0.0);
    // A constant plan cruises at its segments' own states: the judge reuses their values.
    let v = &out.executed.chatter;
    assert!(
        v.reused > 0 && v.evaluations + v.reused <= v.samples,
        "{v:?}"
    );
    let lowest = out.executed.chatter.lowest_feed.unwrap();
    let slowest_segment = out
        .executed
        .plan
        .segments
        .iter()
        .map(|s| s.feed)
        .fold(f64::INFINITY, f64::min);
    assert!(
        lowest.feed >= slowest_segment * 0.99,
        "{lowest:?} vs {slowest_segment}"
    );
}

/// A path on which g = 0 leaves a joint's limit (held-out seed 900002): `fixed_g`, `greedy` and
/// `naive`, which hold g at g0 = 0, answer INFEASIBLE naming the segment (issue 28 "Bad input";
/// POLICY_ERROR and UNREACHABLE before), and `best` still plans it.
#[test]
fn a_path_infeasible_at_the_held_g_is_infeasible() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let base = MillCell::default_cell().unwrap();
    let p = sample_path(&base, &PathDistribution::default(), HELD_OUT_SEEDS[1]).unwrap();
    for kind in ["fixed_g", "greedy", "naive"] {
        let e = planner
            .plan(&MillRequest {
                points: p.spec.points.clone(),
                planner: kind.to_string(),
                ..MillRequest::default()
            })
            .expect_err(kind);
        assert_eq!(status_of(&e), status::INFEASIBLE, "{kind}: {e}");
        let text = e.to_string();
        assert!(
            text.contains("holds g at the initial 0 rad") && text.contains("segment"),
            "{text}"
        );
    }
    let out = planner
        .plan(&MillRequest {
            points: p.spec.points.clone(),
            ..MillRequest::default()
        })
        .expect("best plans it");
    assert!(!out.executed.chatters());
    let infeasible = out
        .candidates
        .iter()
        .filter(|c| c.status == status::INFEASIBLE)
        .count();
    assert!(infeasible >= 2, "{}", out.candidates_text());
}
