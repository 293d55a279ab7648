//! Steps, accuracy and per-period cost of RPRO (look-ahead 0, 1, 2) and the
//! Ruckig reference on held-out paths of seed 002's database (issue 29,
//! figures "Steps and accuracy of RPRO, DDQN and the Ruckig reference on
//! held-out paths" and "Per-period cost of the controller and of the
//! agent").
//!
//! Held-out paths: `database::path(len, density, 100 + k)`, k = 0..10 (the
//! database holds indices 0..10), lengths 15 and 50, every density, four
//! limit combinations of Table 1 (the slowest, two middle, the fastest).
//!
//! Run: `cargo bench -p kerf_stepping --bench stepping` (release). Set
//! `KERF_STEPPING_PATHS=3` for a quicker run over fewer paths.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use kerf_stepping::{
    database::{self, Density},
    ddqn::{Agent, Shielded},
    ruckig_ref::{self, Method},
    run, Action, Controller, Course, Decision, Lattice, Limits, Rpro, RproSettings, StepError,
};

/// Indices in `limit_grid()`: slowest, two middle ones, fastest.
const LIMITS: [usize; 4] = [0, 22, 37, 59];
const LENGTHS: [usize; 2] = [15, 50];
const MAX_STEPS: usize = 2_000_000;

/// One process: a held-out path and its limits.
struct Process {
    points: Vec<f64>,
    limits: Limits,
}

fn processes(length: usize, density: Density, paths: usize) -> Vec<Process> {
    let grid = database::limit_grid();
    let mut out = Vec::new();
    for k in 0..paths {
        let points = database::path(length, density, 100 + k);
        for &i in &LIMITS {
            out.push(Process {
                points: points.clone(),
                limits: grid[i],
            });
        }
    }
    out
}

/// Steps and accuracy of one column over one subset, per process
/// (`None`: the run failed).
#[derive(Default, Clone)]
struct Column {
    runs: Vec<Option<(usize, f64, f64)>>,
    first_error: Option<String>,
}

impl Column {
    fn add(&mut self, steps: usize, mean_error: f64, max_error: f64) {
        self.runs.push(Some((steps, mean_error, max_error)));
    }

    fn fail(&mut self, e: &StepError) {
        self.runs.push(None);
        self.first_error.get_or_insert_with(|| e.to_string());
    }

    fn failures(&self) -> usize {
        self.runs.iter().filter(|r| r.is_none()).count()
    }

    /// Over the processes where `common` holds and this column succeeded.
    fn cell(&self, common: &[bool]) -> String {
        let ok: Vec<(usize, f64, f64)> = self
            .runs
            .iter()
            .zip(common)
            .filter_map(|(r, c)| if *c { *r } else { None })
            .collect();
        let failed = match self.failures() {
            0 => String::new(),
            n => format!(" ({n} failed)"),
        };
        if ok.is_empty() {
            return format!("—{failed}");
        }
        let mut s: Vec<usize> = ok.iter().map(|r| r.0).collect();
        s.sort_unstable();
        let median = s[s.len() / 2];
        let sum: usize = s.iter().sum();
        let mean = ok.iter().map(|r| r.1).sum::<f64>() / ok.len() as f64;
        let max = ok.iter().map(|r| r.2).fold(0.0, f64::max);
        format!(
            "{median} / {sum} / {:.2} / {:.2}{failed}",
            mean * 1e6,
            max * 1e6
        )
    }
}

/// Times every `decide` of the controller it wraps.
struct Timed<'a> {
    inner: &'a mut dyn Controller,
    nanos: Vec<u64>,
}

impl Controller for Timed<'_> {
    fn decide(&mut self, course: &Course, decision: &Decision) -> Result<Action, StepError> {
        let t = Instant::now();
        let a = self.inner.decide(course, decision);
        self.nanos.push(t.elapsed().as_nanos() as u64);
        a
    }
}

/// Builds a per-period controller for one course (RPRO, an agent, a
/// shielded agent).
type Factory<'a> = dyn FnMut(&Course) -> Result<Box<dyn Controller>, StepError> + 'a;

/// A controller column: runs `factory`'s controller on every process,
/// records steps and accuracy, and the time of every decision.
///
/// This is the place for further columns (the DDQN agent and the shielded
/// agent): give a factory building them from a course.
fn controller_column(ps: &[Process], factory: &mut Factory<'_>, nanos: &mut Vec<u64>) -> Column {
    let mut col = Column::default();
    for p in ps {
        let lat = Lattice::new(p.limits, database::PERIOD).unwrap();
        let course = Course::new(lat, p.points.clone(), database::PRECISION).unwrap();
        let mut ctrl = match factory(&course) {
            Ok(c) => c,
            Err(e) => {
                col.fail(&e);
                continue;
            }
        };
        let mut timed = Timed {
            inner: ctrl.as_mut(),
            nanos: Vec::new(),
        };
        match run(&course, &mut timed, MAX_STEPS) {
            Ok(r) => col.add(r.steps(), r.mean_error(), r.max_error()),
            Err(e) => col.fail(&e),
        }
        nanos.extend_from_slice(&timed.nanos);
    }
    col
}

fn rpro_factory(lookahead: usize) -> impl FnMut(&Course) -> Result<Box<dyn Controller>, StepError> {
    move |course: &Course| {
        Ok(Box::new(Rpro::new(
            course,
            RproSettings::default().lookahead_points(lookahead),
        )?) as Box<dyn Controller>)
    }
}

fn ruckig_column(ps: &[Process], method: Method, micros: &mut Vec<f64>) -> Column {
    let mut col = Column::default();
    for p in ps {
        let pts: Vec<Vec<f64>> = p.points.iter().map(|x| vec![*x]).collect();
        let t = Instant::now();
        match ruckig_ref::reference(&pts, &[p.limits], database::PERIOD, method) {
            Ok(r) => {
                micros.push(t.elapsed().as_secs_f64() * 1e6);
                col.add(r.steps(), r.mean_error(), r.max_error());
            }
            Err(e) => col.fail(&e),
        }
    }
    col
}

fn bound_column(ps: &[Process]) -> Column {
    let mut col = Column::default();
    for p in ps {
        let pts: Vec<Vec<f64>> = p.points.iter().map(|x| vec![*x]).collect();
        match ruckig_ref::lower_bound(&pts, &[p.limits], database::PERIOD) {
            Ok(n) => col.add(n, 0.0, 0.0),
            Err(e) => col.fail(&e),
        }
    }
    col
}

fn stats(nanos: &mut [u64]) -> (f64, f64, usize) {
    if nanos.is_empty() {
        return (f64::NAN, f64::NAN, 0);
    }
    nanos.sort_unstable();
    let mean = nanos.iter().sum::<u64>() as f64 / nanos.len() as f64;
    let p99 = nanos[(nanos.len() * 99 / 100).min(nanos.len() - 1)];
    (mean / 1e3, p99 as f64 / 1e3, nanos.len())
}

/// The DDQN agent of `crates/stepping/weights/ddqn_high_arch2.safetensors`
/// (trained on high-density paths), if it loads.
fn ddqn_agent() -> Option<Agent> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("weights/ddqn_high_arch2.safetensors");
    match Agent::load(&path) {
        Ok(a) => Some(a),
        Err(e) => {
            eprintln!("no DDQN columns: {e}");
            None
        }
    }
}

fn main() {
    let paths: usize = std::env::var("KERF_STEPPING_PATHS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10)
        .clamp(1, 10);
    let started = Instant::now();
    let agent = ddqn_agent();
    let lookaheads = [0usize, 1, 2];
    // Controller columns: RPRO per look-ahead, then the agent and the
    // shielded agent (shield: RPRO look-ahead 1).
    let mut names: Vec<String> = lookaheads
        .iter()
        .map(|k| format!("RPRO look-ahead {k}"))
        .collect();
    if agent.is_some() {
        names.push("DDQN".to_string());
        names.push("DDQN + shield".to_string());
    }
    let mut cost: Vec<Vec<u64>> = vec![Vec::new(); names.len()];
    let mut ruckig_micros: Vec<(Method, Vec<f64>)> =
        Method::ALL.iter().map(|m| (*m, Vec::new())).collect();
    let mut errors: Vec<String> = Vec::new();

    println!(
        "## Steps and accuracy on held-out paths ({paths} paths × {} limit sets per row)\n",
        LIMITS.len()
    );
    println!(
        "Cells: median steps / sum of steps / mean accuracy µm / max accuracy µm, over the \
         processes every RPRO column and the Ruckig reference completed (failures counted in \
         brackets; DDQN cells over the same processes where the agent completed). Bound: \
         time-optimal rest-to-rest over the whole path (no motion within the limits is \
         faster). Ruckig: `ruckig_ref::reference`, method `{}`.\n",
        Method::default().name()
    );
    print!("| length | density | bound |");
    for n in &names {
        print!(" {n} |");
    }
    println!(" Ruckig |");
    println!("|---|---|---|{}---|", "---|".repeat(names.len()));
    let mut method_rows = Vec::new();
    for length in LENGTHS {
        for density in [Density::High, Density::Medium, Density::Low] {
            let ps = processes(length, density, paths);
            let bound = bound_column(&ps);
            let mut cols = Vec::new();
            for (i, k) in lookaheads.iter().enumerate() {
                let mut f = rpro_factory(*k);
                cols.push(controller_column(&ps, &mut f, &mut cost[i]));
            }
            if let Some(agent) = &agent {
                let mut plain = |_: &Course| Ok(Box::new(agent.clone()) as Box<dyn Controller>);
                cols.push(controller_column(&ps, &mut plain, &mut cost[3]));
                let mut shielded = |course: &Course| {
                    Ok(Box::new(Shielded::new(
                        agent.clone(),
                        course,
                        RproSettings::default(),
                    )?) as Box<dyn Controller>)
                };
                cols.push(controller_column(&ps, &mut shielded, &mut cost[4]));
            }
            let mut ruckig_cols = Vec::new();
            for (m, micros) in ruckig_micros.iter_mut() {
                ruckig_cols.push(ruckig_column(&ps, *m, micros));
            }
            let common: Vec<bool> = (0..ps.len())
                .map(|p| {
                    cols[..lookaheads.len()]
                        .iter()
                        .chain([&ruckig_cols[0], &bound])
                        .all(|c| c.runs[p].is_some())
                })
                .collect();
            let bound_cell = {
                let mut s: Vec<usize> = bound
                    .runs
                    .iter()
                    .zip(&common)
                    .filter_map(|(r, c)| if *c { r.map(|r| r.0) } else { None })
                    .collect();
                s.sort_unstable();
                format!(
                    "{} / {}",
                    s.get(s.len() / 2).copied().unwrap_or(0),
                    s.iter().sum::<usize>()
                )
            };
            print!("| {length} | {} | {bound_cell} |", density.name());
            for c in &cols {
                print!(" {} |", c.cell(&common));
            }
            println!(" {} |", ruckig_cols[0].cell(&common));
            for (n, c) in names.iter().zip(&cols) {
                if let Some(e) = &c.first_error {
                    errors.push(format!(
                        "{length} {}: {n}: {} failed, first: {e}",
                        density.name(),
                        c.failures()
                    ));
                }
            }
            method_rows.push((length, density, ruckig_cols, common));
        }
    }
    if !errors.is_empty() {
        println!("\nFailures:\n");
        for e in &errors {
            println!("* {e}");
        }
    }

    println!("\n## Ruckig reference: the four ways through the points (same processes)\n");
    print!("| length | density |");
    for m in Method::ALL {
        print!(" {} |", m.name());
    }
    println!("\n|---|---|---|---|---|---|");
    for (length, density, cols, common) in &method_rows {
        print!("| {length} | {} |", density.name());
        for c in cols {
            print!(" {} |", c.cell(common));
        }
        println!();
    }

    println!("\n## Per-period cost (release, one core of a shared 2-core machine)\n");
    println!("| controller | decisions | mean µs | p99 µs |");
    println!("|---|---|---|---|");
    for (name, nanos) in names.iter().zip(cost.iter_mut()) {
        let (mean, p99, n) = stats(nanos);
        println!("| {name} | {n} | {mean:.2} | {p99:.2} |");
    }
    println!("\n| Ruckig reference (whole path, offline) | paths | mean ms | max ms |");
    println!("|---|---|---|---|");
    for (m, micros) in &ruckig_micros {
        let mean = micros.iter().sum::<f64>() / micros.len().max(1) as f64;
        let max = micros.iter().copied().fold(0.0, f64::max);
        println!(
            "| {} | {} | {:.2} | {:.2} |",
            m.name(),
            micros.len(),
            mean / 1e3,
            max / 1e3
        );
    }
    println!("\n(total {:.1} s)", started.elapsed().as_secs_f64());
}
