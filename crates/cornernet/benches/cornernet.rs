//! drls-net against the swarm on held-out corners: time per corner,
//! largest curvature, fallback rate (issue 30, item 3). Needs the weights
//! of `examples/train_cornernet.rs`.
//!
//! ```text
//! cargo bench -p kerf_cornernet --bench cornernet [-- CORNERS]
//! ```
//!
//! Corners: CORNERS (default 400) drawn from the trained distribution with
//! a seed the dataset did not use, δ = 10 µm, at a vertex off the origin.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::time::Instant;

use kerf_cornernet::predict::swarm_transition;
use kerf_cornernet::{Distribution, DrlsNet, Model, Source};
use kerf_rng::Rng;
use kerf_toolpath::vec3::{add, scale, sub};

fn percentile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(400);
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("weights/drls.safetensors");
    let distribution = Distribution::default();
    let model = Model::load(&path, &distribution).expect("run examples/train_cornernet first");
    let swarm = model.sidecar.swarm;
    let layers = model.net.architecture.layers;
    let mut drls = DrlsNet::new(model);
    let mut rng = Rng::new(0xbe7c_4003);
    let delta = 1e-5;
    let (mut t_net, mut t_pso) = (0.0, 0.0);
    let mut ratios = Vec::new();
    let mut reasons = Vec::new();
    for _ in 0..n {
        let c = distribution.draw(&mut rng);
        let available = c.ratio * delta;
        let v = [0.25, -0.1, 0.05];
        let (t1, t2) = c.directions();
        let prev = sub(v, scale(t1, 2.0 * available));
        let next = add(v, scale(t2, 2.0 * available));
        let s = Instant::now();
        let r = drls.transition(prev, v, next, delta, available).unwrap();
        t_net += s.elapsed().as_secs_f64();
        let s = Instant::now();
        let p = swarm_transition(&swarm, prev, v, next, delta, available).unwrap();
        t_pso += s.elapsed().as_secs_f64();
        let (Some(r_t), Some(p_t)) = (r.transition, p) else {
            continue;
        };
        if let Source::Fallback(why) = r.source {
            reasons.push(why);
        } else {
            ratios.push(r_t.max_curvature / p_t.max_curvature);
        }
    }
    let counts = drls.counts();
    let within: usize = ratios.iter().filter(|r| **r <= 1.05).count();
    let mut rel: Vec<f64> = ratios.iter().map(|r| r - 1.0).collect();
    println!("drls-net ({layers} layers) vs NURBS-PSO on {n} held-out corners, δ = 10 µm");
    println!("| metric | value | goal |");
    println!("|---|---|---|");
    println!(
        "| time per corner, drls-net (incl. fallbacks) | {:.2} µs | |",
        1e6 * t_net / n as f64
    );
    println!(
        "| time per corner, PSO | {:.1} µs | |",
        1e6 * t_pso / n as f64
    );
    println!("| speed-up | {:.0}× | ≥ 100× |", t_pso / t_net);
    println!(
        "| κ_max drls / PSO − 1: median, p95, max | {:+.2} %, {:+.2} %, {:+.2} % | within 5 % |",
        100.0 * percentile(&mut rel, 0.5),
        100.0 * percentile(&mut rel, 0.95),
        100.0 * percentile(&mut rel, 1.0)
    );
    println!(
        "| κ_max within +5 % of PSO | {:.1} % of {} predicted | |",
        100.0 * within as f64 / ratios.len().max(1) as f64,
        ratios.len()
    );
    println!(
        "| fallback rate | {:.2} % ({} of {}) | < 2 % |",
        100.0 * counts.fallback as f64 / n as f64,
        counts.fallback,
        n
    );
    for r in reasons.iter().take(5) {
        println!("fallback: {r}");
    }
}
