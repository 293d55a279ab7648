//! CPU time per 4 ms control cycle of the simulated cell (4 physics sub-steps at 1 kHz, or
//! the rate in `KERF_CELL_PHYSICS_HZ`),
//! kinematic and dynamic, free and in contact with the 4 964-triangle B-pillar.
//!
//! Run: `cargo bench -p kerf_cell --bench cycle`. Prints, per scenario, the mean, median,
//! 99th percentile and worst CPU time of the calling thread (`CLOCK_THREAD_CPUTIME_ID`) in
//! `Cell::step` over 5 000 cycles (after 200 warm-up cycles), the worst wall-clock time, and
//! the contacts seen. CPU time excludes the time the thread waits for a core on a loaded
//! machine; the wall-clock worst case includes it. `KERF_CELL_SCENARIOS` selects scenarios
//! (see [`selected`]).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::path::PathBuf;
use std::time::Instant;

use kerf_cell::{Cell, CellSettings, Mode};
use kerf_executor::JointSample;
use nalgebra::Vector3;

fn urdf_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf")
}

/// A timed joint path: samples of positions, velocities, accelerations, and the period.
struct Path {
    q: Vec<[f64; 6]>,
    qd: Vec<[f64; 6]>,
    qdd: Vec<[f64; 6]>,
    period: f64,
}

/// Case 1 planned by kerf_mjto's planner, its samples moved `offset` m along the tool axis
/// (negative: into the part).
fn case1_joints(offset: f64) -> Path {
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mjto/cases/case1.yaml"),
    )
    .unwrap();
    let request = kerf_mjto::CutRequest::from_yaml(&text).unwrap();
    let machine = kerf_mjto::LaserMachine::default_machine().unwrap();
    let robot = machine.robot().clone();
    let plan = kerf_mjto::planner::Planner::new(machine)
        .unwrap()
        .plan(&request)
        .unwrap();
    let q = plan
        .positions
        .iter()
        .map(|q| {
            let o = robot.forward_kinematics(q).unwrap().rotation * Vector3::z();
            [
                q[0] + o.x * offset,
                q[1] + o.y * offset,
                q[2] + o.z * offset,
                q[3],
                q[4],
                q[5],
            ]
        })
        .collect();
    Path {
        q,
        qd: plan.velocities.clone(),
        qdd: plan.accelerations.clone(),
        period: request.sample_period,
    }
}

/// The command at time `t`: cubic Hermite of positions and velocities between samples,
/// accelerations linear; forward, then backward in time (the paths start and end at rest).
fn command(path: &Path, t: f64) -> JointSample {
    let n = path.q.len() - 1;
    let f = t / path.period;
    let lap = (f / n as f64).floor() as usize;
    let mut x = f - (lap * n) as f64;
    let mut dir = 1.0;
    if lap % 2 == 1 {
        x = n as f64 - x;
        dir = -1.0;
    }
    let i = (x.floor() as usize).min(n - 1);
    let s = x - i as f64;
    let h = path.period;
    let basis = kerf_cell::hermite::Hermite::at(s);
    let (p0, p1, v0, v1) = (path.q[i], path.q[i + 1], path.qd[i], path.qd[i + 1]);
    let (a0, a1) = (path.qdd[i], path.qdd[i + 1]);
    JointSample {
        positions: (0..6)
            .map(|j| basis.position(p0[j], v0[j], p1[j], v1[j], h))
            .collect(),
        velocities: (0..6)
            .map(|j| dir * basis.velocity(p0[j], v0[j], p1[j], v1[j], h))
            .collect(),
        accelerations: (0..6).map(|j| a0[j] + s * (a1[j] - a0[j])).collect(),
    }
}

/// CPU time of the calling thread (s).
fn thread_cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec through a valid pointer.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// The physics rate: `KERF_CELL_PHYSICS_HZ`, else the cell's default (1 kHz).
fn physics_rate() -> f64 {
    std::env::var("KERF_CELL_PHYSICS_HZ")
        .map(|v| v.parse().expect("KERF_CELL_PHYSICS_HZ: a rate in Hz"))
        .unwrap_or(CellSettings::default().physics_rate_hz)
}

/// Whether the scenario runs: `KERF_CELL_SCENARIOS` is a comma-separated list of substrings
/// of "<name> <mode>" (e.g. `into,Dynamic`: every scenario containing either); unset: all.
fn selected(name: &str, mode: Mode) -> bool {
    match std::env::var("KERF_CELL_SCENARIOS") {
        Ok(list) => {
            let label = format!("{name} {mode:?}");
            list.split(',').any(|f| !f.is_empty() && label.contains(f))
        }
        Err(_) => true,
    }
}

fn run(name: &str, cell_name: &str, mode: Mode, path: &Path) {
    if !selected(name, mode) {
        return;
    }
    let settings = CellSettings {
        mode,
        physics_rate_hz: physics_rate(),
        ..CellSettings::default()
    };
    let urdf = if cell_name.starts_with("laser") {
        "laser_cutter.urdf"
    } else {
        "irb6660.urdf"
    };
    let mut cell = Cell::from_files(
        &urdf_dir().join(urdf),
        &urdf_dir().join(format!("cells/{cell_name}.yaml")),
        settings,
    )
    .unwrap();
    cell.reset(&path.q[0]).unwrap();
    let dt = 1.0 / settings.control_rate_hz;
    let (warm, cycles) = (200, 5000);
    let mut times = Vec::with_capacity(cycles);
    let mut with_contact = 0;
    let mut deepest: f64 = 0.0;
    let mut wall_max: f64 = 0.0;
    let mut tracking: f64 = 0.0;
    for k in 1..=warm + cycles {
        let c = command(path, k as f64 * dt);
        let start = Instant::now();
        let cpu = thread_cpu();
        let state = cell.step(&c, dt).unwrap();
        let cpu = thread_cpu() - cpu;
        let elapsed = start.elapsed().as_secs_f64();
        if k > warm {
            times.push(cpu);
            wall_max = wall_max.max(elapsed);
            if !state.contacts.is_empty() {
                with_contact += 1;
            }
            for e in &state.tracking_error {
                tracking = tracking.max(e.abs());
            }
            for c in &state.contacts {
                deepest = deepest.max(c.depth);
            }
        }
    }
    let counts = cell.checker().counts();
    let per_cycle = |n: u64| n as f64 / (warm + cycles) as f64;
    times.sort_by(f64::total_cmp);
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    let median = times[times.len() / 2];
    let p99 = times[times.len() * 99 / 100];
    let max = times[times.len() - 1];
    println!(
        "{name:<34} {mode:<9} CPU mean {:>6.1} us  median {:>6.1} us  p99 {:>6.1} us  max {:>7.1} us | wall max {:>7.1} us | contact in {with_contact}/{cycles} cycles, deepest {:.2} mm | max tracking error {:.1e} | per cycle: {:.2} queries, {:.2} box tests, {:.2} skipped, {:.1} triangles, {:.2} tested",
        mean * 1e6,
        median * 1e6,
        p99 * 1e6,
        max * 1e6,
        wall_max * 1e6,
        deepest * 1e3,
        tracking,
        per_cycle(counts.queries),
        per_cycle(counts.boxes),
        per_cycle(counts.skipped),
        per_cycle(counts.triangles),
        per_cycle(counts.tested),
        mode = format!("{mode:?}"),
    );
}

/// The IRB 6660 along irb6660_milling.yaml's path at g = 0 (kerf_mill's IK at 400
/// samples), at the paper's initial feed 0.04 m/s with a quintic rest-to-rest time law;
/// joint velocities and accelerations by central differences of the samples.
fn milling_joints() -> Path {
    let mill = kerf_mill::MillCell::default_cell().unwrap();
    let n = 400;
    let mut reference = *mill.reference_joints();
    let mut q = Vec::new();
    let mut length = 0.0;
    let mut last: Option<Vector3<f64>> = None;
    let mut arc = Vec::new();
    for i in 0..=n {
        let u = i as f64 / n as f64;
        let p = mill
            .tool_pose_at_parameter(u, 0.0)
            .unwrap()
            .translation
            .vector;
        if let Some(l) = last {
            length += (p - l).norm();
        }
        last = Some(p);
        arc.push(length);
    }
    // Time law: s(t) quintic over T = 1.875 L / v_max (peak speed 0.04 m/s); sample u at
    // equal times by inverting the arc length.
    let total = 1.875 * length / 0.04;
    let period = total / n as f64;
    for k in 0..=n {
        let tau = k as f64 / n as f64;
        let s = length * (10.0 * tau.powi(3) - 15.0 * tau.powi(4) + 6.0 * tau.powi(5));
        let i = arc.partition_point(|&a| a < s).clamp(1, n);
        let w = (s - arc[i - 1]) / (arc[i] - arc[i - 1]).max(1e-15);
        let u = ((i - 1) as f64 + w) / n as f64;
        let qk = mill.joints_at_parameter(u, 0.0, Some(&reference)).unwrap();
        reference = qk;
        q.push(qk);
    }
    let diff = |a: &[[f64; 6]], k: usize| -> [f64; 6] {
        let (i0, i1) = (k.saturating_sub(1), (k + 1).min(n));
        let h = (i1 - i0) as f64 * period;
        std::array::from_fn(|j| (a[i1][j] - a[i0][j]) / h)
    };
    let qd: Vec<[f64; 6]> = (0..=n).map(|k| diff(&q, k)).collect();
    let qdd: Vec<[f64; 6]> = (0..=n).map(|k| diff(&qd, k)).collect();
    Path { q, qd, qdd, period }
}

fn main() {
    let far = case1_joints(0.3);
    let cutting = case1_joints(0.0);
    let contact = case1_joints(-0.002);
    let milling = milling_joints();
    println!(
        "laser cutter + B-pillar (4 964 triangles), 4 ms control cycle, {} Hz physics",
        physics_rate()
    );
    for mode in [Mode::Kinematic, Mode::Dynamic] {
        run(
            "case 1 plan, 0.3 m above the part",
            "laser_bpillar",
            mode,
            &far,
        );
        run(
            "case 1 plan (tip 1 mm off)",
            "laser_bpillar",
            mode,
            &cutting,
        );
        run(
            "case 1 plan 2 mm into the part",
            "laser_bpillar",
            mode,
            &contact,
        );
    }
    println!("IRB 6660 + stock and fixture plate (boxes), cutter engaged 3 mm");
    for mode in [Mode::Kinematic, Mode::Dynamic] {
        run(
            "milling path, g = 0, 0.04 m/s",
            "irb6660_plate",
            mode,
            &milling,
        );
    }
}
