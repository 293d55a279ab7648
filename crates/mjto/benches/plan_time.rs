//! Bench binary: the planning time of cases 1 and 2 (issue 16 item 5), warm and cold, in wall
//! and CPU time, with the time of every stage; and a dump of every committed case's plan for
//! comparing builds.
//!
//! ```text
//! cargo bench -p kerf_mjto --bench plan_time
//! KERF_PLAN_RUNS=40 cargo bench -p kerf_mjto --bench plan_time
//! KERF_PLAN_CASES=case1 KERF_PLAN_COLD=0 cargo bench -p kerf_mjto --bench plan_time
//! KERF_PLAN_DUMP=/tmp/plans.txt cargo bench -p kerf_mjto --bench plan_time
//! KERF_PLAN_SEQUENCE=rto_box cargo bench -p kerf_mjto --bench plan_time
//! KERF_ORIENTATION_CORRIDOR=none cargo bench -p kerf_mjto --bench plan_time
//! ```
//!
//! * **warm**: one [`Planner`] plans the same request again and again, as a planner node does
//!   across requests on one part: the mesh is in its cache and the collision world (BVH) of
//!   the last plan is kept. One warm-up plan, then `KERF_PLAN_RUNS` (default 20) timed plans.
//! * **cold**: a new [`Planner`] for every plan (its construction not timed): the plan reads
//!   and parses the mesh and builds the collision world.
//!
//! Each figure is the median over the runs of the wall time and of the process's CPU time
//! (`CLOCK_PROCESS_CPUTIME_ID`: both threads of the dense check; less disturbed than wall time
//! when other processes load the machine). The cases run interleaved (case 1, case 2, case 1,
//! ...), so a change of the machine's load hits both alike.
//!
//! With `KERF_PLAN_DUMP=<file>`, every committed case (cases 1 and 2 with RTO boxes and with
//! equalities, the job-shop cuts under both feed laws) is planned once by a new planner and
//! its outcome written to `<file>`: every sample's time and joint positions, velocities and
//! accelerations, the RTOs, the cycle time and the metrics, with every float in its exact
//! shortest round-trip form (or the error's text); no timing.
//!
//! With `KERF_PLAN_SEQUENCE=plan_cases` or `rto_box`, case 1 is timed after the plans that
//! precede it in that bench (issue 16 item 5: the two benches disagreed by 5 ms on case 1);
//! under `valgrind --tool=callgrind --toggle-collect=plan_time::timed` the two sequences'
//! instruction counts compare the work done.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use kerf_mjto::optimal_feed::FeedMode;
use kerf_mjto::plan::StageTimes;
use kerf_mjto::planner::Planner;
use kerf_mjto::request::RtoConstraint;
use kerf_mjto::{CutRequest, LaserMachine};

#[path = "../tests/common/saddle.rs"]
mod saddle;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// CPU time of this process (all threads), in seconds.
fn cpu_time() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn planner() -> Planner {
    Planner::new(LaserMachine::default_machine().expect("machine")).expect("planner")
}

fn cases_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases")
}

fn request(file: &Path) -> CutRequest {
    CutRequest::from_yaml(&std::fs::read_to_string(file).expect("case file")).expect("request")
}

/// One timed plan: (wall s, CPU s, stage times).
fn timed(planner: &mut Planner, request: &CutRequest) -> (f64, f64, StageTimes) {
    let (t, c) = (Instant::now(), cpu_time());
    let plan = planner.plan(request).expect("plan");
    let cpu = cpu_time() - c;
    (t.elapsed().as_secs_f64(), cpu, plan.times_per_stage)
}

#[derive(Default)]
struct Series {
    wall: Vec<f64>,
    cpu: Vec<f64>,
    stages: Vec<StageTimes>,
}

impl Series {
    fn push(&mut self, (wall, cpu, stages): (f64, f64, StageTimes)) {
        self.wall.push(wall);
        self.cpu.push(cpu);
        self.stages.push(stages);
    }

    fn stage(&self, f: impl Fn(&StageTimes) -> f64) -> f64 {
        median(self.stages.iter().map(f).collect()) * 1e3
    }
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

fn time_cases(runs: usize) {
    let dir = cases_dir();
    // KERF_PLAN_CASES=case1 times one case; KERF_PLAN_COLD=0 leaves out the cold planners.
    let names: Vec<String> = std::env::var("KERF_PLAN_CASES")
        .map(|v| v.split(',').map(str::to_string).collect())
        .unwrap_or_else(|_| vec!["case1".into(), "case2".into()]);
    let with_cold = std::env::var("KERF_PLAN_COLD").map_or(true, |v| v != "0");
    // KERF_ORIENTATION_CORRIDOR (`none` or `allowance`) overrides the requests' option.
    let corridor = std::env::var("KERF_ORIENTATION_CORRIDOR").ok().map(|v| {
        kerf_mjto::request::OrientationCorridor::parse(&v).expect("KERF_ORIENTATION_CORRIDOR")
    });
    let requests: Vec<CutRequest> = names
        .iter()
        .map(|n| {
            let mut r = request(&dir.join(format!("{n}.yaml")));
            if let Some(c) = corridor {
                r.options.orientation_corridor = c;
            }
            r
        })
        .collect();
    println!("load average before: {}", load_average());
    let mut warm: Vec<Series> = names.iter().map(|_| Series::default()).collect();
    let mut cold: Vec<Series> = names.iter().map(|_| Series::default()).collect();
    // A warm planner keeps the collision world of its last plan: the two cases on two
    // planners, so that each case's plans find their own world.
    let mut warm_planners: Vec<Planner> = requests
        .iter()
        .map(|r| {
            let mut p = planner();
            p.plan(r).expect("warm-up plan");
            p
        })
        .collect();
    for _ in 0..runs {
        for (k, r) in requests.iter().enumerate() {
            warm[k].push(timed(&mut warm_planners[k], r));
            if with_cold {
                let mut fresh = planner();
                cold[k].push(timed(&mut fresh, r));
            }
        }
    }
    println!("load average after: {}", load_average());
    println!();
    println!("| case | planner | wall (median of {runs}) | CPU, both threads (median) | setup | Hessian | GFD + insertion | selection + boxes | rotary QPs | M-path QP | dense checks | feed (TOPP3) | evaluation |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (k, name) in names.iter().enumerate() {
        for (label, s) in [("warm", &warm[k]), ("cold", &cold[k])] {
            if s.wall.is_empty() {
                continue;
            }
            println!(
                "| {name} | {label} | {:.2} ms | {:.2} ms | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                median(s.wall.clone()) * 1e3,
                median(s.cpu.clone()) * 1e3,
                s.stage(|t| t.setup),
                s.stage(|t| t.hessian),
                s.stage(|t| t.gfd),
                s.stage(|t| t.selection),
                s.stage(|t| t.rotary_qp),
                s.stage(|t| t.mpath_qp),
                s.stage(|t| t.collision),
                s.stage(|t| t.feed),
                s.stage(|t| t.evaluation),
            );
        }
    }
}

fn rows(out: &mut String, label: &str, v: &[[f64; 6]]) {
    for (k, r) in v.iter().enumerate() {
        writeln!(out, "{label}[{k}] {r:?}").unwrap();
    }
}

fn dump(path: &Path) {
    let dir = cases_dir();
    let mut jobs: Vec<(String, CutRequest)> = Vec::new();
    for name in ["case1", "case2"] {
        let r = request(&dir.join(format!("{name}.yaml")));
        for c in [RtoConstraint::Box, RtoConstraint::Equality] {
            let mut r = r.clone();
            r.options.rto_constraint = c;
            jobs.push((format!("{name} {}", c.as_str()), r));
        }
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("jobshop"))
        .expect("cases/jobshop")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    files.sort();
    for f in &files {
        let r = request(f);
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        for law in [FeedMode::Constant, FeedMode::TimeOptimal] {
            let mut r = r.clone();
            r.options.feed_law = law;
            jobs.push((format!("{name} {law:?}"), r));
        }
    }
    let mut out = String::new();
    for (name, r) in &jobs {
        writeln!(out, "=== {name}").unwrap();
        match planner().plan(r) {
            Err(e) => writeln!(out, "error: {e}").unwrap(),
            Ok(p) => {
                writeln!(
                    out,
                    "iterations {} rtos {} queries {} control points {}",
                    p.iterations,
                    p.rtos.len(),
                    p.collision_queries,
                    p.control_points
                )
                .unwrap();
                writeln!(out, "feed {:?}", p.feed).unwrap();
                writeln!(out, "metrics {:?}", p.metrics).unwrap();
                writeln!(out, "qi metrics {:?}", p.qi_metrics).unwrap();
                for rto in &p.rtos {
                    writeln!(out, "rto {rto:?}").unwrap();
                }
                writeln!(out, "times {:?}", p.times).unwrap();
                writeln!(out, "path {:?}", p.path_positions).unwrap();
                rows(&mut out, "q", &p.positions);
                rows(&mut out, "qd", &p.velocities);
                rows(&mut out, "qdd", &p.accelerations);
            }
        }
        eprintln!("planned {name}");
    }
    std::fs::write(path, out).expect("write the dump");
}

/// Case 1 (RTO boxes) timed after the work that precedes it in `benches/plan_cases.rs`
/// (`plan_cases`: a new planner, one warm-up plan) or in `benches/rto_box.rs` (`rto_box`: the
/// saddle's mesh written, a new planner, case 1 with equalities planned 1 + `runs` times, then
/// one warm-up plan with boxes): `runs` plans of each sequence, median wall and CPU time.
fn sequence(which: &str, runs: usize) {
    let r = request(&cases_dir().join("case1.yaml"));
    let mut p = planner();
    let geometry = saddle::Saddle::default();
    let mesh = saddle::TempMesh::new("plan_time", &geometry.mesh());
    let _saddle = geometry.request(&mesh.reference(), 0.1);
    match which {
        "plan_cases" => {}
        "rto_box" => {
            let mut e = r.clone();
            e.options.rto_constraint = RtoConstraint::Equality;
            for _ in 0..=runs {
                p.plan(&e).expect("plan");
            }
        }
        other => panic!("KERF_PLAN_SEQUENCE={other}: plan_cases or rto_box"),
    }
    let mut b = r.clone();
    b.options.rto_constraint = RtoConstraint::Box;
    p.plan(&b).expect("warm-up plan");
    let mut s = Series::default();
    for _ in 0..runs {
        s.push(timed(&mut p, &b));
    }
    println!(
        "case1 after the {which} sequence: wall {:.2} ms, CPU {:.2} ms (medians of {runs}; load {})",
        median(s.wall) * 1e3,
        median(s.cpu) * 1e3,
        load_average()
    );
}

fn main() {
    if let Ok(path) = std::env::var("KERF_PLAN_DUMP") {
        dump(Path::new(&path));
        return;
    }
    let runs: usize = std::env::var("KERF_PLAN_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20)
        .max(1);
    if let Ok(which) = std::env::var("KERF_PLAN_SEQUENCE") {
        sequence(&which, runs);
        return;
    }
    time_cases(runs);
}
