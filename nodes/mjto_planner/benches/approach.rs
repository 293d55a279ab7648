//! Approach and retract of laser cuts (issue 27, figures): for cases 1 and 2 and the job-shop
//! cuts, from the executor's start pose and from poses around it, how long framing the plan
//! takes (`kerf_approach::frame` with the head against the part by exact distance), how long
//! the approach lasts, and how long the straight joint move to the first process point would
//! last (the same minimum-jerk profile at the same limits, no clearance, no lead-in).
//!
//! `cargo bench -p kerf_mjto_planner --bench approach`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::path::Path;
use std::time::{Duration, Instant};

use kerf_approach::{frame, FrameSettings, JointMove, Route};
use kerf_mjto::{planner::Planner, CutRequest, LaserMachine};
use kerf_mjto_planner::surroundings::{approach_limits, LaserSurroundings};
use kerf_ros::planner::framing::process_samples;

/// The laser cutter's start pose in launch_scripts/params/laser_cutter.yaml.
const HOME: [f64; 6] = [0.8, 0.7, 1.5, 0.0, 0.0, -0.05];

fn cases() -> Vec<(String, CutRequest)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../crates/mjto/cases");
    let mut files: Vec<_> = ["case1.yaml", "case2.yaml"]
        .iter()
        .map(|f| dir.join(f))
        .collect();
    let mut shop: Vec<_> = std::fs::read_dir(dir.join("jobshop"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    shop.sort();
    files.extend(shop);
    files
        .into_iter()
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (
                name,
                CutRequest::from_yaml(&std::fs::read_to_string(&p).unwrap()).unwrap(),
            )
        })
        .collect()
}

fn main() {
    let machine = LaserMachine::default_machine().unwrap();
    let names: Vec<String> = (1..=6).map(|i| format!("q{i}")).collect();
    let limits = approach_limits(&machine, &names);
    let settings = FrameSettings::default();
    let starts: [(&str, [f64; 6]); 3] = [
        ("home", HOME),
        (
            "home +0.3 m q1, -0.2 m q2",
            [1.1, 0.5, 1.5, 0.0, 0.0, -0.05],
        ),
        (
            "home, head tilted 0.4 rad",
            [0.8, 0.7, 1.5, 1.0, 0.4, -0.05],
        ),
    ];
    println!(
        "| cut | start | framing (ms) | route | approach (s) | straight move (s) | ratio | retract (s) | min clearance (mm) |"
    );
    println!("|---|---|---:|---|---:|---:|---:|---:|---:|");
    let mut planner = Planner::new(machine.clone()).unwrap();
    for (name, request) in cases() {
        let plan = match planner.plan(&request) {
            Ok(p) => p,
            Err(e) => {
                println!("| {name} | – | – | does not plan: {e} | | | | | |");
                continue;
            }
        };
        let trajectory = plan.joint_trajectory();
        let process =
            process_samples(&kerf_ros::planner::trajectory_msg(&trajectory).unwrap()).unwrap();
        let world = LaserSurroundings::new(
            &machine,
            limits.clone(),
            &request,
            &kerf_mjto::mesh::load(&request.mesh).unwrap(),
        )
        .unwrap();
        let first = process[0].q.clone();
        for (label, start) in &starts {
            let mut times = Vec::new();
            let mut outcome = None;
            for _ in 0..5 {
                let t = Instant::now();
                let r = frame(start, process.clone(), &limits, &world, &settings);
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
                        "| {name} | {label} | {:.1} | {route} | {:.3} | {:.3} | {:.2} | {:.3} | {:.1} |",
                        median.as_secs_f64() * 1e3,
                        tl.process_start,
                        straight,
                        tl.process_start / straight,
                        end - tl.process_end,
                        f.approach_closest.distance * 1e3,
                    );
                }
                Err(e) => println!(
                    "| {name} | {label} | {:.1} | refused: {e} | | {straight:.3} | | | |",
                    median.as_secs_f64() * 1e3
                ),
            }
        }
    }
}
