//! Approach and retract of the milling plan (issue 27, figures): the README's request (naive
//! planner, the seed-004 path) framed from start poses around the cell, against the shipped
//! collision cell (urdf/cells/irb6660_plate.yaml) by exact distance: the time
//! `kerf_approach::frame` takes, the approach's duration, and the straight joint move's to the
//! first process point (same profile and limits, no clearance, no lead-in).
//!
//! `cargo bench -p kerf_milling_planner --bench approach`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::{Duration, Instant};

use kerf_approach::{frame, FrameSettings, JointMove, Route, StartSpec};
use kerf_budget::Budget;
use kerf_milling_planner::{DefaultPolicies, MillService};
use kerf_millplan::{MillPlanner, MillRequest};
use kerf_msgs::msg::MillPlan;
use kerf_ros::planner::{framing::process_samples, plan_checked, PlanningService};

fn main() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let policies = DefaultPolicies {
        ddpg: "/nonexistent/ddpg.safetensors".into(),
        fixed_g: "/nonexistent/fixed_g.safetensors".into(),
    };
    let service = MillService::new(planner, policies, String::new()).unwrap();
    let request = MillRequest {
        request_id: "approach".into(),
        planner: "naive".into(),
        start: StartSpec::None,
        ..MillRequest::default()
    };
    let plan = plan_checked(
        &service,
        request.clone(),
        &Budget::unlimited(),
        &FrameSettings::default(),
        None,
    );
    assert_eq!(plan.status, MillPlan::SUCCESS, "{}", plan.message);
    let process = process_samples(&plan.trajectory).unwrap();
    let first = process[0].q.clone();
    let world = service.surroundings(&request).unwrap();
    let limits = service.approach_limits().to_vec();
    let settings = FrameSettings::default();
    let starts: [(&str, [f64; 6]); 3] = [
        (
            "launch start pose (0.2 m above the path)",
            [
                -0.369639, -0.539469, 0.534629, 1.565075, 0.702171, -1.563303,
            ],
        ),
        ("all joints 0", [0.0; 6]),
        (
            "joint_1 +0.5 rad, joint_2 -0.3 rad",
            [0.5, -0.3, 0.0, 0.0, 0.0, 0.0],
        ),
    ];
    println!(
        "| start | framing (ms) | route | approach (s) | straight move (s) | ratio | retract (s) | min clearance (mm) |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    for (label, start) in &starts {
        let mut times = Vec::new();
        let mut outcome = None;
        for _ in 0..5 {
            let t = Instant::now();
            let r = frame(start, process.clone(), &limits, world.as_ref(), &settings);
            times.push(t.elapsed());
            outcome = Some(r);
        }
        times.sort();
        let median: Duration = times[times.len() / 2];
        let straight = JointMove::new(start, &first, &limits).unwrap().duration();
        match outcome.unwrap() {
            Ok(f) => {
                let tl = &f.timeline;
                let end = tl.samples.last().map_or(0.0, |s| s.t);
                let route = match (f.approach_route, f.auto_via) {
                    (Route::ViaSafePose(_), Some(d)) => format!("via tool axis +{d} m"),
                    (Route::ViaSafePose(i), None) => format!("via safe pose {i}"),
                    _ => "direct".into(),
                };
                println!(
                    "| {label} | {:.1} | {route} | {:.3} | {:.3} | {:.2} | {:.3} | {:.1} |",
                    median.as_secs_f64() * 1e3,
                    tl.process_start,
                    straight,
                    tl.process_start / straight,
                    end - tl.process_end,
                    f.approach_closest.distance * 1e3,
                );
            }
            Err(e) => println!(
                "| {label} | {:.1} | refused: {e} | | {straight:.3} | | | |",
                median.as_secs_f64() * 1e3
            ),
        }
    }
}
