//! Which cell properties would show seed 004's claim as executed — an optimized redundancy angle
//! at least 5 % faster than g = 0, chatter-free (issue 13, item 3) — measured on variants of the
//! default cell file: the force law's exponent (kerf's 0.75, the paper's linear law 1.0), the
//! spindle's mounting angle about the tool axis (unturned, kerf's calibrated 0.4 rad, 0.8 rad;
//! turning it by d is g → g + d) and the modal masses (the tool-tip modes' frequencies scale with
//! 1/√m). For each variant: the greedy ramp with g = 0 and with the best fixed g
//! (`kerf_millplan::greedy`), both from the paper's IVP, timed as executed.
//!
//! ```sh
//! cargo bench -p kerf_millplan --bench claim_sweep
//! cargo bench -p kerf_millplan --bench claim_sweep -- --exponents 1.0 --mounts 0.1,0.2,0.3 --masses 60
//! # also the DP with g free and with g held at 0 (g range [-1e-6, 1e-6]): a per-path cache each
//! cargo bench -p kerf_millplan --bench claim_sweep -- --exponents 1.0 --mounts 0.2,0.3 --masses 60 --dp
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::sync::Arc;

use kerf_mill::MillCell;
use kerf_millplan::{MillPlanOutput, MillPlanner, MillRequest};

fn variant(text: &str, exponent: f64, mount: f64, mass: f64) -> String {
    let (s, c) = mount.sin_cos();
    let mut out = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        let indent = &line[..line.len() - t.len()];
        if t.starts_with("force_exponent:") {
            out.push_str(&format!("{indent}force_exponent: {exponent}\n"));
        } else if t.starts_with("x_axis:") {
            out.push_str(&format!("{indent}x_axis: [0.0, {s}, {c}]\n"));
        } else if t.starts_with("modal_mass: [") {
            out.push_str(&format!("{indent}modal_mass: [{mass}, {mass}]\n"));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

fn figures(o: &Result<MillPlanOutput, String>) -> String {
    match o {
        Ok(o) => {
            let e = &o.executed.plan;
            let g = o.plan.segments.last().map(|s| s.g).unwrap_or(0.0);
            format!(
                "{:.2} s, {} ({:.4}), g* {:+.1}",
                e.total_time,
                if e.chatter_free {
                    "chatter-free"
                } else {
                    "chatters"
                },
                e.max_spectral_radius,
                g
            )
        }
        Err(e) => format!("failed: {e}"),
    }
}

/// The comma-separated numbers after `flag`, or `default`.
fn list(args: &[String], flag: &str, default: &[f64]) -> Vec<f64> {
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1))
        .map(|s| s.split(',').map(|v| v.trim().parse().unwrap()).collect())
        .unwrap_or_else(|| default.to_vec())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let exponents = list(&args, "--exponents", &[0.75, 1.0]);
    let mounts = list(&args, "--mounts", &[0.0, 0.4, 0.8]);
    let masses = list(&args, "--masses", &[60.0, 40.0]);
    let with_dp = args.iter().any(|a| a == "--dp");
    let path = kerf_robot::data::path("urdf/irb6660_milling.yaml").unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let dir = path.parent().unwrap().to_path_buf();
    if with_dp {
        println!(
            "| force exponent | mount (rad) | modal mass (kg) | IVP \\|μ\\| at segment 0 | greedy g = 0 (as executed) | greedy, best fixed g (as executed) | best g vs g = 0 | dp, g = 0 | dp | dp vs dp g = 0 |"
        );
        println!("|---:|---:|---:|---:|---|---|---:|---|---|---:|");
    } else {
        println!(
            "| force exponent | mount (rad) | modal mass (kg) | IVP \\|μ\\| at segment 0 | greedy g = 0 (as executed) | greedy, best fixed g (as executed) | best g vs g = 0 |"
        );
        println!("|---:|---:|---:|---:|---|---|---:|");
    }
    for &exponent in &exponents {
        for &mount in &mounts {
            for &mass in &masses {
                let yaml = variant(&text, exponent, mount, mass);
                let cell = match MillCell::from_yaml_str(&yaml, &dir, &path) {
                    Ok(c) => c,
                    Err(e) => {
                        println!("| {exponent} | {mount} | {mass} | cell refused: {e} | | | |");
                        continue;
                    }
                };
                let ivp = kerf_millplan::cache::direct_indicator(&cell, 0, 2000.0, 0.04, 0.0, None)
                    .ok()
                    .flatten()
                    .unwrap_or(f64::NAN);
                let planner = MillPlanner::new(Arc::new(cell), None).unwrap();
                let plan = |kind: &str| {
                    planner
                        .plan(&MillRequest {
                            planner: kind.to_string(),
                            ..MillRequest::default()
                        })
                        .map_err(|e| e.to_string())
                };
                let zero = plan("greedy");
                let best = plan("greedy_best_g");
                let gain = match (&zero, &best) {
                    (Ok(a), Ok(b)) => format!(
                        "{:+.1} %",
                        100.0 * (a.executed.plan.total_time - b.executed.plan.total_time)
                            / a.executed.plan.total_time
                    ),
                    _ => String::new(),
                };
                let mut dp_columns = String::new();
                if with_dp {
                    let dp_zero = planner
                        .plan(&MillRequest {
                            planner: "dp".to_string(),
                            limits: Some(kerf_millplan::request::RequestLimits {
                                redundancy_angle: Some([-1e-6, 1e-6]),
                                ..Default::default()
                            }),
                            ..MillRequest::default()
                        })
                        .map_err(|e| e.to_string());
                    let dp = plan("dp");
                    let gain = match (&dp_zero, &dp) {
                        (Ok(a), Ok(b)) => format!(
                            "{:+.1} %",
                            100.0 * (a.executed.plan.total_time - b.executed.plan.total_time)
                                / a.executed.plan.total_time
                        ),
                        _ => String::new(),
                    };
                    dp_columns = format!(" {} | {} | {gain} |", figures(&dp_zero), figures(&dp));
                }
                println!(
                    "| {exponent} | {mount} | {mass} | {ivp:.4} | {} | {} | {gain} |{dp_columns}",
                    figures(&zero),
                    figures(&best)
                );
            }
        }
    }
}
