//! Generates the B-pillar-like test workpiece and the two cut requests of
//! seed 001 section 3 ([`kerf_testparts::bpillar`]).
//!
//! ```sh
//! cargo run -p kerf_testparts --example gen_bpillar -- --out .
//! ```
//!
//! writes `urdf/meshes/bpillar.obj` and `crates/mjto/cases/case{1,2}.yaml`
//! under the given repository root (default `.`) and prints what it wrote:
//! point counts, path lengths, the tool-axis change between adjacent RTOs,
//! the mesh's bounding box and the machine-frame range of the nominal M
//! points. The output is deterministic.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::PathBuf;
use std::process::ExitCode;

use kerf_mjto::{CutRequest, LaserMachine};
use kerf_testparts::bpillar::{self, Generated};

fn main() -> ExitCode {
    let mut out = PathBuf::from(".");
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
            "-h" | "--help" => {
                println!("usage: gen_bpillar [--out <repository root>]");
                return ExitCode::SUCCESS;
            }
            other => {
                eprintln!(
                    "unknown argument '{other}' (usage: gen_bpillar [--out <repository root>])"
                );
                return ExitCode::from(2);
            }
        }
    }
    match run(&out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gen_bpillar: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(out: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let (g, paths) = bpillar::write_files(out)?;
    for p in &paths {
        println!("wrote {}", p.display());
    }
    report_mesh(&g);
    let machine = LaserMachine::default_machine()?;
    report_case("case 1", &g.case1, &machine)?;
    report_case("case 2", &g.case2, &machine)?;
    Ok(())
}

fn report_mesh(g: &Generated) {
    let mesh = g.pillar.mesh();
    println!(
        "mesh: {} vertices, {} triangles, {} stations x {} profile vertices",
        mesh.vertices.len(),
        mesh.triangles.len(),
        g.pillar.stations().len(),
        g.pillar.profile_len()
    );
    if let Some((lo, hi)) = mesh.bounds() {
        println!(
            "  bounding box (workpiece frame): x [{:.4}, {:.4}]  y [{:.4}, {:.4}]  z [{:.4}, {:.4}] m",
            lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
        );
    }
}

fn report_case(
    name: &str,
    req: &CutRequest,
    machine: &LaserMachine,
) -> Result<(), Box<dyn std::error::Error>> {
    let v = req.validate()?;
    let changes = bpillar::rto_angle_changes(req)?;
    let max_change = changes.iter().copied().fold(0.0, f64::max);
    println!(
        "{name}: {} CL points, path {:.4} m, f = {:.5} m/s, dt = {} s, spacing {:.5} m",
        req.points.len(),
        v.sigma,
        req.feedrate,
        req.sample_period,
        req.feedrate * req.sample_period
    );
    println!(
        "  RTOs {:?}; axis change between adjacent RTOs (deg): [{}]; max {:.2} deg",
        req.options.rto_indices,
        changes
            .iter()
            .map(|c| format!("{:.2}", c.to_degrees()))
            .collect::<Vec<_>>()
            .join(", "),
        max_change.to_degrees()
    );
    let q6 = req.options.reference_standoff;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut min_oz = f64::INFINITY;
    for (c, o) in v.points.iter().zip(&v.axes) {
        let m = c - o * q6;
        for k in 0..3 {
            lo[k] = lo[k].min(m[k]);
            hi[k] = hi[k].max(m[k]);
        }
        min_oz = min_oz.min(o.z);
    }
    let lim = machine.limits();
    println!(
        "  nominal M (q6 = {q6}) in the machine frame: q1 [{:.3}, {:.3}] of [{}, {}], q2 [{:.3}, {:.3}] of [{}, {}], q3 [{:.3}, {:.3}] of [{}, {}] m",
        lo[0], hi[0], lim[0].min, lim[0].max, lo[1], hi[1], lim[1].min, lim[1].max, lo[2], hi[2],
        lim[2].min, lim[2].max
    );
    println!(
        "  smallest O_z {:.4} (largest tilt {:.2} deg; q5 limit {:.1} deg)",
        min_oz,
        min_oz.clamp(-1.0, 1.0).acos().to_degrees(),
        lim[4].max.to_degrees()
    );
    Ok(())
}
