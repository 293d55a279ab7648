//! The G-code planner on the shipped programs (issue 14 figures): per program and machine, the
//! plan's time, T_m along the path, T_lb and T_m/T_lb, the largest joint slowdown, the executed
//! deviation, the trajectory's points and the planning time (median of 3); the corner methods
//! on three programs on the laser cutter (also with the feed plan bounding the whole normal jerk,
//! `PlanSettings::feed_whole_normal_jerk`); and a dense synthetic program of `--lines N` G01 moves (default 100 000,
//! [`Dense`]) planned whole, with its time and peak memory.
//!
//! `cargo bench -p kerf_gcodeplan --bench programs [-- --lines 1000000]`
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Read;
use std::time::Instant;

use kerf_budget::Budget;
use kerf_gcodeplan::{
    plan_program, plan_request, GcodePlan, GcodeRequest, LaserSheet, MachineBase, MachineKind,
    PlanSettings,
};
use kerf_toolpath::Sampling;

/// Fixed 10 µm samples against adaptive ones (1 mm, 2°) on the laser cutter: the feed plans'
/// time, the executed time, the largest uniform slowdown, planning time (one run).
fn sampling_table(dir: &std::path::Path) {
    println!("| program | sampling | T [s] | T_run [s] | T_m [s] | T_lb [s] | T_m/T_lb | slowdown | plan [ms] |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    let sheet = LaserSheet::default_sheet().unwrap();
    for name in ["w_shape", "dress", "torch", "rosette_dense_g64", "arcs"] {
        for (label, sampling) in [
            ("fixed 10 um", Sampling::default()),
            ("adaptive 1 mm, 2 deg", Sampling::adaptive()),
        ] {
            let settings = PlanSettings {
                sampling,
                ..PlanSettings::laser_cutter()
            };
            let file = std::fs::File::open(dir.join(format!("{name}.ngc"))).unwrap();
            let t = Instant::now();
            let plan = plan_program(
                std::io::BufReader::new(file),
                &sheet,
                &settings,
                &Budget::unlimited(),
            )
            .unwrap();
            let took = t.elapsed().as_secs_f64();
            let slowdown = plan.runs.iter().map(|r| r.slowdown).fold(1.0, f64::max);
            println!(
                "| {name} | {label} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.1} |",
                plan.duration,
                plan.feed_time,
                plan.path_time,
                plan.lower_bound,
                plan.lower_bound_ratio(),
                slowdown,
                took * 1e3
            );
        }
    }
}

fn median_plan(request: &GcodeRequest, base: &MachineBase) -> (GcodePlan, f64) {
    let mut times = Vec::new();
    let mut plan = None;
    for _ in 0..3 {
        let t = Instant::now();
        let p = plan_request(request, base, &Budget::unlimited()).unwrap();
        times.push(t.elapsed().as_secs_f64());
        plan = Some(p);
    }
    times.sort_by(f64::total_cmp);
    (plan.unwrap(), times[1])
}

fn row(name: &str, machine: &str, plan: &GcodePlan, took: f64) {
    let slowdown = plan.runs.iter().map(|r| r.slowdown).fold(1.0, f64::max);
    println!(
        "| {name} | {machine} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.1} |",
        plan.lines,
        plan.runs.len(),
        plan.trajectory.points.len(),
        plan.duration,
        plan.feed_time,
        plan.path_time,
        plan.lower_bound,
        plan.lower_bound_ratio(),
        slowdown,
        plan.max_interpolation_deviation * 1e6,
        took * 1e3
    );
}

/// Peak resident set (kB), from /proc/self/status.
fn peak_kib() -> Option<u64> {
    let mut s = String::new();
    std::fs::File::open("/proc/self/status")
        .ok()?
        .read_to_string(&mut s)
        .ok()?;
    s.lines()
        .find(|l| l.starts_with("VmHWM:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

/// A reader of a dense G01 program generated line by line, as CAM output of a wavy contour:
/// `n` moves 0.1 mm apart along X on serpentine rows 1 m long (10 000 moves each) 5 mm
/// apart, each row a 1 mm sine of 20 mm wavelength (every vertex a corner of 1.8° at most),
/// F 3000 mm/min, beam on.
struct Dense {
    n: usize,
    k: usize,
    line: Vec<u8>,
    at: usize,
}

/// Moves per row.
const ROW: usize = 10_000;

impl Dense {
    /// The k-th point (mm).
    fn point(k: usize) -> (f64, f64) {
        let (row, i) = (k / (ROW + 1), k % (ROW + 1));
        let along = 0.1 * i as f64;
        let x = if row % 2 == 0 { along } else { 1000.0 - along };
        let y = 5.0 * row as f64 + (std::f64::consts::TAU * x / 20.0).sin();
        (x, y)
    }
}

impl Read for Dense {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.at == self.line.len() {
            self.line.clear();
            self.at = 0;
            if self.k == 0 {
                self.line
                    .extend_from_slice(b"G21 G90 G17\nG0 X0 Y0\nM3\nF3000\n");
            } else if self.k <= self.n {
                let (x, y) = Self::point(self.k);
                self.line
                    .extend_from_slice(format!("G1 X{x:.4} Y{y:.4}\n").as_bytes());
            } else if self.k == self.n + 1 {
                self.line.extend_from_slice(b"M5\nM30\n");
            } else {
                return Ok(0);
            }
            self.k += 1;
        }
        let m = out.len().min(self.line.len() - self.at);
        out[..m].copy_from_slice(&self.line[self.at..self.at + m]);
        self.at += m;
        Ok(m)
    }
}

/// Seed 003 Table 2's comparison on the W-shape (and the dress and torch): per corner, the
/// largest curvature and the exact deviation of seed 003's method 1 (five control points: two
/// on each segment and the vertex, which is ICR's construction) "before" and of its NURBS corner
/// optimised by the swarm "after", with the reduction, and kerf's corner (its default jerk
/// shape and its min-κ shape) beside them; δ = 0.1
/// mm as the seed's case 1.
fn corner_table(dir: &std::path::Path) {
    use kerf_gcode::{read_program, Motion, ReaderSettings};
    use kerf_toolpath::{corner_metrics, smooth_polyline_with, CornerMethod, NurbsSettings};
    println!("| program | corner | turn [°] | ICR κ_max [1/mm] | NURBS κ_max [1/mm] | reduction | NURBS dev. [mm] | kerf κ_max [1/mm] | kerf min-κ κ_max [1/mm] |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for name in ["w_shape", "dress", "torch"] {
        let text = std::fs::read_to_string(dir.join(format!("{name}.ngc"))).unwrap();
        let mut polyline: Vec<[f64; 3]> = Vec::new();
        for m in read_program(&text, ReaderSettings::default()).unwrap() {
            if let Motion::Line {
                start,
                end,
                tool_on: true,
                ..
            } = m
            {
                if polyline.is_empty() {
                    polyline.push(start);
                }
                polyline.push(end);
            }
        }
        let metrics = |method: CornerMethod| {
            corner_metrics(&smooth_polyline_with(&polyline, 1e-4, &method).unwrap())
        };
        let icr = metrics(CornerMethod::Icr);
        let nurbs = metrics(CornerMethod::Nurbs(NurbsSettings::default()));
        let kerf = metrics(CornerMethod::Kerf);
        let kerf_kappa = metrics(CornerMethod::KerfCurvature);
        for (k, (((a, b), c), d)) in icr
            .iter()
            .zip(&nurbs)
            .zip(&kerf)
            .zip(&kerf_kappa)
            .enumerate()
        {
            println!(
                "| {name} | {k} | {:.1} | {:.3} | {:.3} | {:.1} % | {:.4} | {:.3} | {:.3} |",
                a.turn.to_degrees(),
                a.max_curvature * 1e-3,
                b.max_curvature * 1e-3,
                100.0 * (a.max_curvature - b.max_curvature) / a.max_curvature,
                b.approximation_error * 1e3,
                c.max_curvature * 1e-3,
                d.max_curvature * 1e-3
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let lines = args
        .iter()
        .position(|a| a == "--lines")
        .and_then(|i| args.get(i + 1))
        .map_or(100_000, |v| v.parse().unwrap());
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../gcode/data/programs");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ngc"))
        .collect();
    names.sort();
    let laser = MachineBase::load(MachineKind::LaserCutter).unwrap();
    let irb = MachineBase::load(MachineKind::Irb6660).unwrap();
    println!("| program | machine | lines | runs | points | T [s] | T_run [s] | T_m [s] | T_lb [s] | T_m/T_lb | slowdown | dev. [um] | plan [ms] |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for path in &names {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        for base in [&laser, &irb] {
            let request = GcodeRequest {
                request_id: name.clone(),
                machine: base.kind().name().into(),
                program_file: Some(path.display().to_string()),
                ..GcodeRequest::default()
            };
            let (plan, took) = median_plan(&request, base);
            row(&name, base.kind().name(), &plan, took);
        }
    }
    println!();
    println!("| program | method | whole j_n | T [s] | T_run [s] | T_lb [s] | kappa_max [1/m] | slowdown | plan [ms] |");
    println!("|---|---|---|---:|---:|---:|---:|---:|---:|");
    for name in ["dress", "torch", "w_shape"] {
        for (method, whole) in [
            ("kerf", false),
            ("kerf", true),
            ("kerf-curvature", false),
            ("kerf-curvature", true),
            ("icr", false),
            ("icr", true),
            ("ccr", false),
            ("nurbs", false),
        ] {
            let file = dir.join(format!("{name}.ngc"));
            let request = GcodeRequest {
                request_id: name.into(),
                program_file: Some(file.display().to_string()),
                method: Some(method.into()),
                ..GcodeRequest::default()
            };
            // The feed plan bounding the whole normal jerk (`feed_whole_normal_jerk`): the
            // request's settings and machine, planned by `plan_program`.
            let (plan, took) = if whole {
                let mut settings = request.settings().unwrap();
                settings.feed_whole_normal_jerk = true;
                let machine = laser.place(&request).unwrap();
                let mut times = Vec::new();
                let mut plan = None;
                for _ in 0..3 {
                    let t = Instant::now();
                    let source = std::io::BufReader::new(std::fs::File::open(&file).unwrap());
                    let p = plan_program(source, machine.as_ref(), &settings, &Budget::unlimited())
                        .unwrap();
                    times.push(t.elapsed().as_secs_f64());
                    plan = Some(p);
                }
                times.sort_by(f64::total_cmp);
                (plan.unwrap(), times[1])
            } else {
                median_plan(&request, &laser)
            };
            let slowdown = plan.runs.iter().map(|r| r.slowdown).fold(1.0, f64::max);
            println!(
                "| {name} | {method} | {} | {:.3} | {:.3} | {:.3} | {:.0} | {:.2} | {:.1} |",
                if whole { "yes" } else { "no" },
                plan.duration,
                plan.feed_time,
                plan.lower_bound,
                plan.cut_metrics().max_curvature,
                slowdown,
                took * 1e3
            );
        }
    }
    println!();
    sampling_table(&dir);
    println!();
    corner_table(&dir);
    println!();
    let before = peak_kib();
    let sheet = LaserSheet::default_sheet().unwrap();
    let t = Instant::now();
    let source = std::io::BufReader::new(Dense {
        n: lines,
        k: 0,
        line: Vec::new(),
        at: 0,
    });
    // The program's header and footer lines come on top of its G01 lines.
    let settings = PlanSettings::laser_cutter()
        .with_max_points(20_000_000)
        .with_max_lines(lines + 100);
    let plan = plan_program(source, &sheet, &settings, &Budget::unlimited());
    let took = t.elapsed().as_secs_f64();
    match plan {
        Ok(plan) => println!(
            "dense program, {lines} G01 lines: planned in {took:.2} s; {} points, T {:.1} s, T_m/T_lb {:.3}; peak RSS {:?} -> {:?} kB",
            plan.trajectory.points.len(),
            plan.duration,
            plan.lower_bound_ratio(),
            before,
            peak_kib()
        ),
        Err(e) => println!("dense program, {lines} G01 lines: failed after {took:.2} s: {e}"),
    }
}
