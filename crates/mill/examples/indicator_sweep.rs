//! The state-dependent chatter indicator over a sweep of cell states, for
//! checking a change of its implementation against stored reference values
//! (issue 13, item 5).
//!
//! ```sh
//! # write the reference (with the implementation to compare against)
//! cargo run --release -p kerf_mill --example indicator_sweep -- write FILE [N] [SEED]
//! # compare the current implementation with it (max / p99 / mean |Δ|μ|max|, time)
//! cargo run --release -p kerf_mill --example indicator_sweep -- compare FILE
//! ```
//!
//! The states are drawn with a fixed-seed generator: segment uniform over
//! the path, Ω uniform in 2000–4000 rpm, f uniform in 0.01–0.06 m/s, g
//! uniform over the cell's redundancy-angle range; a (segment, g) whose
//! pose is infeasible (IK unreachable, joint limit, singular) is drawn
//! again, so the kept g span the reachable band. An indicator that fails
//! is stored as `error`. `crates/mill/tests/data/indicator_reference.txt`
//! (1000 states, seed 13) was written by the implementation before issue
//! 13's speed-up; `tests/indicator_reference.rs` compares against it.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a tool: failures end it with a message

use std::fmt::Write as _;
use std::time::Instant;

use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::MillCell;

/// SplitMix64 (Steele, Lea & Flood 2014): a fixed, documented sequence.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: indicator_sweep write FILE [N] [SEED] | compare FILE";
    let (mode, file) = match (args.get(1), args.get(2)) {
        (Some(m), Some(f)) => (m.as_str(), f.as_str()),
        _ => {
            eprintln!("{usage}");
            std::process::exit(2);
        }
    };
    let cell = MillCell::default_cell().expect("default cell");
    let process = cell.milling_process();
    let settings = *cell.indicator_settings();
    let eval = |seg: usize, g: f64, rpm: f64, feed: f64| -> Option<f64> {
        let state = cell.evaluate(seg, g, None).expect("feasible pose");
        chatter_indicator(&state.modal, &process, rpm, feed, &settings)
            .ok()
            .map(|i| i.spectral_radius)
    };
    match mode {
        "write" => {
            let n: usize = args.get(3).map_or(1000, |s| s.parse().expect("N"));
            let seed: u64 = args.get(4).map_or(13, |s| s.parse().expect("SEED"));
            let mut rng = SplitMix64(seed);
            let segments = cell.path().segments().len();
            let [glo, ghi] = cell.state_limits().redundancy_angle;
            let mut out = String::new();
            writeln!(
                out,
                "# kerf_mill indicator_sweep: default cell, chatter section settings; seed {seed}"
            )
            .unwrap();
            writeln!(out, "# segment g[rad] rpm feed[m/s] |mu|max (or error)").unwrap();
            let mut kept = 0;
            while kept < n {
                let seg = (rng.next_u64() % segments as u64) as usize;
                let g = rng.uniform(glo, ghi);
                let rpm = rng.uniform(2000.0, 4000.0);
                let feed = rng.uniform(0.01, 0.06);
                if cell.evaluate(seg, g, None).is_err() {
                    continue;
                }
                let mu = eval(seg, g, rpm, feed);
                let value = mu.map_or_else(|| "error".to_string(), |v| format!("{v:?}"));
                writeln!(out, "{seg} {g:?} {rpm:?} {feed:?} {value}").unwrap();
                kept += 1;
            }
            std::fs::write(file, out).expect("write");
            eprintln!("wrote {n} states to {file}");
        }
        "compare" => {
            let text = std::fs::read_to_string(file).expect("read");
            let mut diffs = Vec::new();
            let (mut mismatched_errors, mut identical) = (0, 0);
            let start = Instant::now();
            let mut evaluations = 0;
            for line in text
                .lines()
                .filter(|l| !l.starts_with('#') && !l.is_empty())
            {
                let f: Vec<&str> = line.split_whitespace().collect();
                let seg: usize = f[0].parse().expect("segment");
                let (g, rpm, feed): (f64, f64, f64) = (
                    f[1].parse().expect("g"),
                    f[2].parse().expect("rpm"),
                    f[3].parse().expect("feed"),
                );
                let old: Option<f64> = f[4].parse().ok();
                let new = eval(seg, g, rpm, feed);
                evaluations += 1;
                match (old, new) {
                    (Some(a), Some(b)) => {
                        if a.to_bits() == b.to_bits() {
                            identical += 1;
                        }
                        diffs.push((a - b).abs());
                    }
                    (None, None) => identical += 1,
                    _ => {
                        mismatched_errors += 1;
                        eprintln!("error status differs: {line} -> {new:?}");
                    }
                }
            }
            let elapsed = start.elapsed().as_secs_f64();
            diffs.sort_by(f64::total_cmp);
            let max = diffs.last().copied().unwrap_or(0.0);
            let p99 = diffs
                .get(((diffs.len() as f64) * 0.99).ceil() as usize - 1)
                .copied()
                .unwrap_or(0.0);
            let mean = diffs.iter().sum::<f64>() / diffs.len().max(1) as f64;
            println!(
                "{evaluations} states ({} with a value): bit-identical {identical}, \
                 |d mu| max {max:e} p99 {p99:e} mean {mean:e}, error status differs {mismatched_errors}; \
                 {:.3} ms per state (IK + indicator)",
                diffs.len(),
                1e3 * elapsed / evaluations.max(1) as f64
            );
        }
        _ => {
            eprintln!("{usage}");
            std::process::exit(2);
        }
    }
}
