//! RPRO over seed 002's database (Table 1): every subset of 10 paths × 60
//! limit combinations, with completions, median steps, median mean accuracy
//! and the cost of a decision (issue 29, figure "Seed 002's tables,
//! reproduced beside the paper's values": the paper gives RPRO's median
//! steps for 15 points, 110 at high and 500 at medium density, section 3).
//!
//! Run: `cargo bench -p kerf_stepping --bench table1` (release; about 3 min).
//! `--lengths 15,50` and `--densities high,medium,low` choose subsets
//! (default: 15 and 50 points, every density; 100 points of low density
//! take about 10 min more). `--limits-every K` keeps every K-th limit set.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use kerf_stepping::{
    database::{self, Density},
    run, Course, Lattice, Rpro, RproSettings,
};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|k| args.get(k + 1).cloned())
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let lengths: Vec<usize> = arg("--lengths")
        .unwrap_or_else(|| "15,50".into())
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    let densities: Vec<Density> = arg("--densities")
        .unwrap_or_else(|| "high,medium,low".into())
        .split(',')
        .map(|d| match d {
            "high" => Density::High,
            "medium" => Density::Medium,
            "low" => Density::Low,
            other => panic!("unknown density {other}"),
        })
        .collect();
    let every: usize = arg("--limits-every").map_or(1, |x| x.parse().unwrap());
    println!("| points | density | processes | completed | median steps (kerf) | median steps (paper) | median mean error µm | max error µm | decision mean µs | seconds |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &len in &lengths {
        for &density in &densities {
            let started = Instant::now();
            let (mut steps, mut errors) = (Vec::new(), Vec::new());
            let (mut total, mut done, mut decisions, mut max_error) = (0, 0, 0usize, 0.0f64);
            let mut decide_seconds = 0.0;
            for p in 0..database::PATHS_PER_SUBSET {
                let points = database::path(len, density, p);
                for (k, limits) in database::limit_grid().iter().enumerate() {
                    if k % every != 0 {
                        continue;
                    }
                    total += 1;
                    let lat = Lattice::new(*limits, database::PERIOD).unwrap();
                    let course = Course::new(lat, points.clone(), database::PRECISION).unwrap();
                    let mut rpro = Rpro::new(&course, RproSettings::default()).unwrap();
                    let t = Instant::now();
                    if let Ok(r) = run(&course, &mut rpro, 10_000_000) {
                        decide_seconds += t.elapsed().as_secs_f64();
                        decisions += r.steps();
                        done += 1;
                        steps.push(r.steps() as f64);
                        errors.push(r.mean_error() * 1e6);
                        max_error = max_error.max(r.max_error() * 1e6);
                    }
                }
            }
            let paper = match (len, density) {
                (15, Density::High) => "110",
                (15, Density::Medium) => "500",
                _ => "–",
            };
            println!(
                "| {len} | {} | {total} | {done} | {:.0} | {paper} | {:.2} | {:.2} | {:.2} | {:.1} |",
                density.name(),
                median(&mut steps),
                median(&mut errors),
                max_error,
                decide_seconds / decisions.max(1) as f64 * 1e6,
                started.elapsed().as_secs_f64()
            );
        }
    }
}
