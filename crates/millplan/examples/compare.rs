//! The comparison of issue 5 section 3 on the default cell: DDPG (the
//! committed policy), DDPG with g = 0 (the paper's ablation, its committed
//! policy), the DP optimum with free g and with g = 0, and the naive
//! constant plan — each planned by `MillPlanner` from the default request
//! (the paper's IVP) and evaluated directly (|μ|max never from the cache).
//! Also the DP of eq. 12 alone (no chatter margin, no joint-speed limits),
//! the paper's objective without kerf's constraints.
//!
//! A second table gives every plan AS EXECUTED: its trajectory from rest to
//! rest, time-scaled to the IRB 6660's joint velocity and acceleration
//! limits (`kerf_millplan::timing`), with |μ|max re-evaluated directly at
//! the feeds that result.
//!
//! ```sh
//! cargo run --release -p kerf_millplan --example compare
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mill::MillCell;
use kerf_millplan::cache::IndicatorCache;
use kerf_millplan::dp::{self, DpSpec};
use kerf_millplan::plan::default_eval_threads;
use kerf_millplan::plan::{comparison_table, Plan};
use kerf_millplan::request::MillRequest;
use kerf_millplan::{execute, Executed, MillPlanError, MillPlanner};

/// One line on the time scaling of a plan.
fn describe_executed(e: &Executed) {
    let s = &e.scaling;
    println!(
        "  as executed: {:.3} s, {} of {} segments slowed (largest slowdown {:.2}, lowest feed \
         {:.4} m/s), tool tip within {:.4} mm of the path, max |mu| {:.4}",
        s.duration(),
        s.slowed_segments(),
        s.segment_slowdown.len(),
        s.segment_slowdown.iter().copied().fold(0.0, f64::max),
        s.segment_feeds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min),
        e.scaling
            .deviation
            .max_off_path
            .max(e.scaling.deviation.max_off_plane)
            * 1e3,
        e.plan.max_spectral_radius
    );
}

/// Prints where a plan chatters, its time, speed, feed and g every 10
/// segments.
fn describe(plan: &Plan) {
    let chatter: Vec<usize> = plan
        .segments
        .iter()
        .filter(|s| s.spectral_radius >= 1.0)
        .map(|s| s.segment)
        .collect();
    println!(
        "{}: chattering segments {chatter:?}; max |mu| in the first half {:.4}, second half {:.4}",
        plan.planner,
        plan.segments[..50]
            .iter()
            .map(|s| s.spectral_radius)
            .fold(0.0, f64::max),
        plan.segments[50..]
            .iter()
            .map(|s| s.spectral_radius)
            .fold(0.0, f64::max)
    );
    let mut line = String::new();
    for s in plan.segments.iter().step_by(10) {
        line.push_str(&format!(
            " [{} {:.0} {:.4} {:+.2} {:.3}]",
            s.segment, s.rpm, s.feed, s.g, s.spectral_radius
        ));
    }
    println!("  [segment rpm f g |mu|]:{line}");
}

fn main() -> Result<(), MillPlanError> {
    let planner = MillPlanner::with_default_cell()?;
    let mut rows = Vec::new();
    let mut executed_rows = Vec::new();
    for (kind, name) in [
        ("ddpg", "DDPG"),
        ("fixed_g", "DDPG, g = 0"),
        ("dp", "DP"),
        ("naive", "naive (constant, not from the IVP)"),
    ] {
        let request = MillRequest {
            planner: kind.to_string(),
            ..MillRequest::default()
        };
        match planner.plan(&request) {
            Ok(out) => {
                let mut plan = out.plan;
                plan.planner = name.to_string();
                describe(&plan);
                println!("  planning {:.3} s", out.planning_seconds);
                describe_executed(&out.executed);
                rows.push(plan.row());
                let mut executed = out.executed.plan;
                executed.planner = name.to_string();
                executed_rows.push(executed.row());
            }
            Err(e) => println!("{name}: {e}"),
        }
    }
    let cell: &MillCell = planner.cell();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), cell)?;
    let weights = planner.env_config().weights;
    for (name, spec) in [
        ("DP, g = 0", DpSpec::full(cell, weights, true)),
        (
            "DP of eq. 12 alone (no margin, no joint speeds)",
            DpSpec {
                chatter_margin: None,
                joint_speed_limits: false,
                ..DpSpec::full(cell, weights, false)
            },
        ),
    ] {
        let r = dp::solve(cell, &cache, &spec)?;
        let plan = Plan::evaluate(cell, &weights, &r.states, name)?;
        describe(&plan);
        println!("  DP {:.2} s", r.seconds);
        let e = execute(cell, &plan, &weights, default_eval_threads())?;
        describe_executed(&e);
        rows.push(plan.row());
        let mut executed = e.plan;
        executed.planner = name.to_string();
        executed_rows.push(executed.row());
    }
    println!("As planned (timed by the planned feeds):");
    println!("{}", comparison_table(&rows));
    println!("As executed (from rest to rest, time-scaled to the joint limits):");
    println!("{}", comparison_table(&executed_rows));
    Ok(())
}
