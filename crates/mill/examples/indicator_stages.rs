//! Where the time of one state-dependent chatter indicator evaluation goes
//! (issue 13, item 5): the default cell's case of the kinematics bench
//! (segment 50, g = −0.4 rad, 3000 rpm, 0.04 m/s, the cell's `chatter`
//! settings), each stage given the previous one's result, timed N times
//! one by one. Prints the minimum (the uncontended cost: on the shared
//! 2-core machine the mean follows the load of other processes), the
//! lower quartile and the median per stage.
//!
//! ```sh
//! cargo run --release -p kerf_mill --example indicator_stages -- [N]
//! # instruction counts (independent of the load), e.g. of the whole evaluation:
//! valgrind --tool=callgrind --toggle-collect='kerf_chatter::indicator::chatter_indicator' \
//!     target/release/examples/indicator_stages 100 whole
//! ```
//!
//! With a second argument `whole` or `equilibrium` it only runs that stage
//! N times (for a profiler).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a tool: failures end it with a message

use std::hint::black_box;
use std::time::Instant;

use kerf_chatter::indicator::{chatter_indicator, indicator_dde};
use kerf_chatter::{linearize, Discretization, Equilibrium, LinearizeSettings};
use kerf_mill::MillCell;

fn stats(label: &str, n: usize, mut f: impl FnMut()) {
    let mut v: Vec<f64> = (0..n)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    v.sort_by(f64::total_cmp);
    println!(
        "{label:>40}: min {:7.1} µs   p25 {:7.1} µs   median {:7.1} µs",
        v[0],
        v[n / 4],
        v[n / 2]
    );
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(3000, |s| s.parse().expect("N"));
    let only = std::env::args().nth(2).unwrap_or_default();
    let cell = MillCell::default_cell().expect("default cell");
    let modal = cell.evaluate(50, -0.4, None).expect("segment 50").modal;
    let process = cell.milling_process();
    let settings = *cell.indicator_settings();
    let (rpm, feed) = (3000.0, 0.04);
    let whole = || chatter_indicator(&modal, &process, rpm, feed, &settings).expect("indicator");
    let equilibrium = || {
        Equilibrium::compute(&modal, &process, rpm, feed, &settings.equilibrium)
            .expect("equilibrium")
    };
    match only.as_str() {
        "whole" => {
            for _ in 0..n {
                black_box(whole());
            }
            return;
        }
        "equilibrium" => {
            for _ in 0..n {
                black_box(equilibrium());
            }
            return;
        }
        _ => {}
    }
    let eq = equilibrium();
    let lin = LinearizeSettings {
        steps: settings.steps,
        wall_term: settings.wall_term,
    };
    let (dde, _) = indicator_dde(&modal, &process, rpm, feed, &settings).expect("dde");
    let max_delay = dde.max_delay().max(dde.period);
    let disc = Discretization::new(&modal, dde.period, settings.steps, max_delay).expect("disc");
    println!("|mu|max = {:?}, N = {n}", whole().spectral_radius);
    stats("whole evaluation (chatter_indicator)", n, || {
        black_box(whole());
    });
    stats("1 equilibrium", n, || {
        black_box(equilibrium());
    });
    stats("2 linearization", n, || {
        black_box(linearize(&eq, &lin).expect("dde"));
    });
    stats("3 equilibrium diagnostics", n, || {
        black_box(eq.diagnostics().expect("diagnostics"));
    });
    stats("4 Discretization::new", n, || {
        black_box(Discretization::new(&modal, dde.period, settings.steps, max_delay).expect("d"));
    });
    stats("5 compile + Arnoldi", n, || {
        black_box(disc.spectral_radius(&dde).expect("rho"));
    });
}
