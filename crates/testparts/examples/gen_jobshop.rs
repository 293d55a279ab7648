//! Generates the job-shop parts and cut requests of issue 16 item 4
//! ([`kerf_testparts::jobshop`]).
//!
//! ```sh
//! cargo run -p kerf_testparts --example gen_jobshop -- --out .
//! cargo run --release -p kerf_testparts --example gen_jobshop -- --out /tmp/x --plan
//! ```
//!
//! writes `urdf/meshes/jobshop_*.obj` and `crates/mjto/cases/jobshop/*.yaml` under the given
//! repository root (default `.`) and prints each mesh's size and each case's points, length
//! and spacing. With `--plan` it also plans every case with `kerf_mjto::planner::Planner`
//! (meshes read from the source tree) and prints the outcome: cycle time and wall-clock plan
//! time (and the constant-feed time, the peak feed and where the feed is limited), or the
//! error.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use kerf_mjto::planner::Planner;
use kerf_mjto::LaserMachine;
use kerf_testparts::jobshop;

fn main() -> ExitCode {
    let mut out = PathBuf::from(".");
    let mut plan = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => match args.next() {
                Some(dir) => out = PathBuf::from(dir),
                None => {
                    eprintln!("--out needs a directory (the repository root)");
                    return ExitCode::from(2);
                }
            },
            "--plan" => plan = true,
            "-h" | "--help" => {
                println!("usage: gen_jobshop [--out <repository root>] [--plan]");
                return ExitCode::SUCCESS;
            }
            other => {
                eprintln!(
                    "unknown argument '{other}' (usage: gen_jobshop [--out <root>] [--plan])"
                );
                return ExitCode::from(2);
            }
        }
    }
    match run(&out, plan) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gen_jobshop: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(out: &std::path::Path, plan: bool) -> Result<(), Box<dyn std::error::Error>> {
    let (shop, written) = jobshop::write_files(out)?;
    for (_, p) in &written {
        println!("wrote {}", p.display());
    }
    for part in &shop.parts {
        println!(
            "part {}: {} vertices, {} triangles, thickness {} m, surface tolerance {:.2e} m, axis tolerance {:.2e} rad",
            part.name,
            part.mesh.vertices.len(),
            part.mesh.triangles.len(),
            part.thickness,
            part.surface_tolerance,
            part.axis_tolerance
        );
    }
    let mut planner = if plan {
        Some(Planner::new(LaserMachine::default_machine()?)?)
    } else {
        None
    };
    for case in &shop.cases {
        let r = &case.request;
        let v = r.validate()?;
        println!(
            "{}: {} points, {:.4} m, f = {:.4} m/s, dt = {} s, f dt = {:.5} m, expect {:?}",
            case.name,
            r.points.len(),
            v.sigma,
            r.feedrate,
            r.sample_period,
            r.feedrate * r.sample_period,
            case.expect
        );
        if let Some(planner) = planner.as_mut() {
            let t = Instant::now();
            let result = planner.plan(r);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            match result {
                Ok(p) => {
                    println!(
                        "  planned in {ms:.1} ms: cycle {:.3} s (constant feed {:.3} s), peak feed {:.2} m/min, {} samples, {} RTOs, {} iteration(s), max CL error {:.2e} m",
                        p.feed.cycle_time,
                        p.feed.constant_feed_time,
                        p.feed.peak_feed * 60.0,
                        p.times.len(),
                        p.rtos.len(),
                        p.iterations,
                        p.metrics.max_cl_error
                    );
                    for l in &p.feed.limits {
                        println!(
                            "    feed limited by {} over s = {:.4}..{:.4} m",
                            l.limited_by, l.s_start, l.s_end
                        );
                    }
                }
                Err(e) => println!("  refused in {ms:.1} ms (status {}): {e}", e.status()),
            }
        }
    }
    Ok(())
}
