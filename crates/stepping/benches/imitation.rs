//! A feasible subset of seed 002 Tables 4–6: DDQN agents trained on pair 0
//! of a 15-point subset, measured on its 480 test processes, printed as a
//! markdown table beside the paper's values.
//!
//! ```text
//! cargo bench -p kerf_stepping --bench imitation -- \
//!     [--density high,medium] [--arch 2,8,10] [--lr 1e-3,1e-4] \
//!     [--gamma 0.99,0.999] [--repeats 1] [--episodes 500]
//! ```
//!
//! Defaults: high density, architectures 2, 8 and 10 (the paper's three
//! best), lr {10⁻³, 10⁻⁴}, γ {0.99, 0.999}, one repeat (the paper: 5 pairs
//! × 5 repeats), 500 episodes; each cell is the median over repeats, as the
//! paper's are medians over pairs and repeats. Every column but "paper" is
//! kerf's. The raw agent runs in closed loop (module `ddqn::metrics`):
//! "done" counts its paper-style completions (every point passed within the
//! precision, steps counted to the pass of the last point, no rest
//! required) out of the processes RPRO finished, and "r (kerf)" and
//! "steps (kerf)" are paper-style, RPRO's steps counted the same way (to its
//! pass of the last point; "RPRO steps" is their median on the same
//! processes); "at rest" and "r at rest" count completions that also end at
//! rest on the last point, with both step counts to the stop; "passed %" is
//! the share of points passed within the precision, "subst." the limit
//! substitutions; "shielded done" counts completed shielded runs.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use kerf_stepping::{
    database::{self, Density},
    ddqn::{self, metrics, Architecture, DdqnSettings},
    RproSettings,
};

/// Seed 002 Tables 4 / 5 / 6 (first experiment): (density, architecture,
/// γ, lr) → (correlation, mean error µm, median steps); `None` = "---".
fn paper(density: Density, arch: usize, gamma: f64, lr: f64) -> Option<(Option<f64>, f64, f64)> {
    // Columns: γ 0.99 × lr 1e-3, 1e-4, 1e-5, then γ 0.999 × the same.
    const HIGH_R: [[f64; 6]; 12] = [
        [0.847, 0.750, 0.848, 0.647, 0.844, 0.844],
        [0.855, 0.852, 0.855, 0.847, 0.842, 0.846],
        [0.844, 0.855, 0.848, 0.839, 0.777, 0.847],
        [0.852, 0.851, 0.849, 0.687, 0.848, 0.849],
        [0.849, 0.856, f64::NAN, 0.844, 0.853, f64::NAN],
        [0.849, 0.853, f64::NAN, 0.855, 0.852, f64::NAN],
        [0.825, 0.857, f64::NAN, 0.847, 0.846, f64::NAN],
        [0.850, 0.851, 0.849, 0.850, 0.836, 0.848],
        [0.821, 0.856, f64::NAN, 0.845, 0.850, f64::NAN],
        [0.852, 0.855, 0.846, 0.846, 0.848, 0.845],
        [0.842, 0.851, f64::NAN, 0.848, 0.848, f64::NAN],
        [0.855, 0.849, f64::NAN, 0.844, 0.845, f64::NAN],
    ];
    const MED_R: [[f64; 6]; 12] = [
        [0.773, 0.777, 0.774, 0.772, f64::NAN, f64::NAN],
        [0.777, 0.774, 0.774, f64::NAN, 0.472, 0.538],
        [0.774, 0.774, 0.774, f64::NAN, f64::NAN, f64::NAN],
        [0.771, 0.777, 0.775, f64::NAN, 0.773, 0.726],
        [0.774, 0.774, f64::NAN, f64::NAN, f64::NAN, f64::NAN],
        [0.771, 0.775, 0.664, f64::NAN, 0.386, 0.237],
        [0.777, 0.774, 0.578, f64::NAN, f64::NAN, 0.041],
        [0.775, 0.776, 0.774, f64::NAN, 0.171, 0.172],
        [0.774, 0.774, f64::NAN, f64::NAN, f64::NAN, f64::NAN],
        [0.774, 0.775, 0.774, f64::NAN, 0.009, 0.112],
        [0.772, 0.774, 0.543, f64::NAN, f64::NAN, 0.054],
        [0.774, 0.775, f64::NAN, f64::NAN, f64::NAN, f64::NAN],
    ];
    const HIGH_E: [[f64; 6]; 12] = [
        [2.38, 2.32, 2.56, 2.47, 2.46, 2.55],
        [2.45, 2.43, 2.51, 2.46, 2.44, 2.63],
        [2.4, 2.46, 2.49, 2.44, 2.45, 2.58],
        [2.45, 2.49, 2.51, 2.52, 2.52, 2.46],
        [2.56, 2.5, 3.11, 2.41, 2.48, 3.29],
        [2.47, 2.43, 4.69, 2.48, 2.35, 4.81],
        [2.32, 2.37, 4.45, 2.46, 2.52, 4.57],
        [2.49, 2.47, 2.56, 2.49, 2.43, 2.57],
        [2.4, 2.5, 3.16, 2.41, 2.51, 3.38],
        [2.45, 2.48, 2.54, 2.39, 2.55, 2.54],
        [2.47, 2.51, 3.86, 2.47, 2.49, 4.48],
        [2.41, 2.51, 4.35, 2.46, 2.48, 4.37],
    ];
    const MED_E: [[f64; 6]; 12] = [
        [5.53, 5.9, 5.41, 2708.0, 4496.0, 4450.0],
        [5.79, 5.31, 5.14, 4835.0, 2661.0, 2926.0],
        [5.54, 5.03, 1561.0, 4481.0, 4799.0, 3580.0],
        [4.99, 5.47, 5.34, 4708.0, 2531.0, 816.0],
        [5.37, 6.2, 7.08, 4653.0, 4742.0, 4599.0],
        [5.08, 5.56, 2445.0, 4852.0, 1814.0, 3607.0],
        [5.02, 5.19, 2414.0, 3727.0, 4741.0, 3581.0],
        [5.42, 5.14, 5.06, 4698.0, 3369.0, 2443.0],
        [4.83, 5.14, 3344.0, 3568.0, 3742.0, 4455.0],
        [5.4, 5.34, 5.13, 4677.0, 4286.0, 4366.0],
        [5.55, 5.91, 2446.0, 4450.0, 4622.0, 3472.0],
        [5.21, 5.32, 4421.0, 4736.0, 2635.0, 4832.0],
    ];
    const HIGH_S: [[f64; 6]; 12] = [
        [85.0, 88.0, 80.0, 86.0, 85.0, 80.0],
        [83.0, 83.0, 81.0, 83.0, 82.0, 82.0],
        [85.0, 83.0, 82.0, 84.0, 85.0, 83.0],
        [82.0, 82.0, 80.0, 84.0, 80.0, 82.0],
        [82.0, 81.0, 74.0, 87.0, 82.0, 75.0],
        [83.0, 84.0, 69.0, 82.0, 84.0, 72.0],
        [89.0, 82.0, 71.0, 85.0, 86.0, 71.0],
        [82.0, 83.0, 80.0, 81.0, 88.0, 81.0],
        [86.0, 80.0, 75.0, 85.0, 80.0, 75.0],
        [83.0, 81.0, 80.0, 83.0, 83.0, 82.0],
        [85.0, 80.0, 76.0, 84.0, 81.0, 72.0],
        [84.0, 80.0, 1.0, 83.0, 80.0, 1.0],
    ];
    const MED_S: [[f64; 6]; 12] = [
        [471.0, 469.0, 476.0, 179.0, 71.0, 101.0],
        [475.0, 482.0, 484.0, 1.0, 293.0, 204.0],
        [478.0, 482.0, 446.0, 73.0, 1.0, 101.0],
        [489.0, 467.0, 478.0, 1.0, 322.0, 453.0],
        [482.0, 465.0, 431.0, 1.0, 1.0, 101.0],
        [486.0, 480.0, 410.0, 1.0, 263.0, 234.0],
        [487.0, 482.0, 406.0, 87.0, 1.0, 101.0],
        [481.0, 485.0, 483.0, 1.0, 290.0, 472.0],
        [488.0, 486.0, 367.0, 159.0, 82.0, 109.0],
        [479.0, 481.0, 482.0, 1.0, 280.0, 243.0],
        [476.0, 471.0, 487.0, 68.0, 1.0, 258.0],
        [478.0, 481.0, 71.0, 14.0, 297.0, 1.0],
    ];
    let lr_col = [1e-3, 1e-4, 1e-5]
        .iter()
        .position(|x| (x - lr).abs() < 1e-12 * x.max(lr))?;
    let g_col = [0.99, 0.999]
        .iter()
        .position(|x| (x - gamma).abs() < 1e-9)?;
    let col = 3 * g_col + lr_col;
    let row = arch.checked_sub(1).filter(|r| *r < 12)?;
    let (r, e, s) = match density {
        Density::High => (HIGH_R, HIGH_E, HIGH_S),
        Density::Medium => (MED_R, MED_E, MED_S),
        Density::Low => return None,
    };
    let r = r[row][col];
    Some(((!r.is_nan()).then_some(r), e[row][col], s[row][col]))
}

fn list<T: std::str::FromStr>(args: &[String], flag: &str, default: &str) -> Vec<T> {
    let raw = args
        .iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1).cloned())
        .unwrap_or_else(|| default.to_string());
    raw.split(',')
        .map(|v| {
            v.trim()
                .parse()
                .unwrap_or_else(|_| panic!("{flag}: cannot parse {v}"))
        })
        .collect()
}

fn fmt(x: Option<f64>, d: usize) -> String {
    x.map_or("---".to_string(), |v| format!("{v:.d$}"))
}

fn main() {
    std::env::set_var("RAYON_NUM_THREADS", "1");
    // `cargo bench` passes `--bench`; ignore it.
    let args: Vec<String> = std::env::args().skip(1).collect();
    let densities: Vec<Density> = list::<String>(&args, "--density", "high")
        .iter()
        .map(|d| match d.as_str() {
            "high" => Density::High,
            "medium" => Density::Medium,
            other => panic!("--density: high or medium, not {other}"),
        })
        .collect();
    let archs: Vec<usize> = list(&args, "--arch", "2,8,10");
    let lrs: Vec<f64> = list(&args, "--lr", "1e-3,1e-4");
    let gammas: Vec<f64> = list(&args, "--gamma", "0.99,0.999");
    let repeats: usize = list(&args, "--repeats", "1")[0];
    let episodes: usize = list(&args, "--episodes", "500")[0];
    let t0 = Instant::now();

    println!(
        "| density | arch | γ | lr | r (kerf) | r (paper) | done | at rest | r at rest | passed % \
         | subst. | mean error µm (kerf) | (paper) | steps (kerf) | RPRO steps | (paper) | \
         shielded done | shielded r | shielded steps | overrides | train s |"
    );
    println!(
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for &density in &densities {
        let subset = database::subset(15, density);
        let (train_set, test_set) = database::split(&subset, 0);
        let train_courses = ddqn::courses(&train_set).unwrap();
        let test_courses = ddqn::courses(&test_set).unwrap();
        let base = metrics::baseline(&test_courses, RproSettings::default(), 1_000_000);
        let mut rpro_line = None;
        for &arch in &archs {
            for &gamma in &gammas {
                for &lr in &lrs {
                    let mut cells: Vec<(metrics::Evaluation, f64)> = vec![];
                    for rep in 0..repeats {
                        let settings = DdqnSettings::default()
                            .architecture(Architecture::new(arch).unwrap())
                            .discount(gamma)
                            .learning_rate(lr)
                            .max_episodes(episodes)
                            .seed(1000 + rep as u64);
                        let t = Instant::now();
                        let trained = ddqn::train(&settings, &train_courses).unwrap();
                        let train_s = t.elapsed().as_secs_f64();
                        let e = metrics::evaluate(
                            &trained.agent,
                            &test_courses,
                            &base,
                            Some(RproSettings::default()),
                        )
                        .unwrap();
                        cells.push((e, train_s));
                    }
                    let med = |f: &dyn Fn(&metrics::Evaluation) -> Option<f64>| {
                        metrics::median(&cells.iter().filter_map(|(e, _)| f(e)).collect::<Vec<_>>())
                    };
                    let e0 = &cells[0].0;
                    rpro_line = Some((
                        e0.rpro_completed,
                        e0.processes,
                        e0.rpro_median_error_um,
                        e0.rpro_median_steps,
                        e0.rpro_paper_median_steps,
                    ));
                    let p = paper(density, arch, gamma, lr);
                    println!(
                        "| {} | {arch} | {gamma} | {lr:e} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} |",
                        density.name(),
                        fmt(med(&|e| e.paper_correlation), 3),
                        p.map_or("n/a".into(), |p| fmt(p.0, 3)),
                        fmt(med(&|e| Some(e.paper_completed as f64)), 0) + "/" + &e0.rpro_completed.to_string(),
                        fmt(med(&|e| Some(e.completed as f64)), 0),
                        fmt(med(&|e| e.correlation), 3),
                        fmt(med(&|e| Some(100.0 * e.passed_share)), 1),
                        fmt(med(&|e| Some(e.substitutions as f64)), 0),
                        fmt(med(&|e| e.median_error_um), 2),
                        p.map_or("n/a".into(), |p| format!("{}", p.1)),
                        fmt(med(&|e| e.paper_median_steps), 0),
                        fmt(med(&|e| e.rpro_paper_median_steps_completed), 0),
                        p.map_or("n/a".into(), |p| format!("{}", p.2)),
                        fmt(med(&|e| e.shielded.as_ref().map(|s| s.completed as f64)), 0),
                        fmt(med(&|e| e.shielded.as_ref().and_then(|s| s.correlation)), 3),
                        fmt(med(&|e| e.shielded.as_ref().and_then(|s| s.median_steps)), 0),
                        fmt(
                            med(&|e| e.shielded.as_ref().map(|s| 100.0 * s.override_fraction)),
                            1
                        ) + " %",
                        cells.iter().map(|c| c.1).sum::<f64>() / cells.len() as f64,
                    );
                }
            }
        }
        if let Some((done, n, err, steps, to_last)) = rpro_line {
            let paper_steps = match density {
                Density::High => "110",
                _ => "500",
            };
            println!(
                "| {} | RPRO | | | | | {done}/{n} | {done} | | 100.0 | 0 | {} | | {} (to the stop {}) | | {paper_steps} | | | | | |",
                density.name(),
                fmt(err, 2),
                fmt(to_last, 0),
                fmt(steps, 0)
            );
        }
    }
    eprintln!("total {:.1} s", t0.elapsed().as_secs_f64());
}
