//! CPU time per 4 ms control cycle of the simulated cell (4 physics sub-steps at 1 kHz),
//! kinematic and dynamic, free and in contact with the 4 964-triangle B-pillar.
//!
//! Run: `cargo bench -p kerf_cell --bench cycle`. Prints, per scenario, the mean, median,
//! 99th percentile and worst CPU time of the calling thread (`CLOCK_THREAD_CPUTIME_ID`) in
//! `Cell::step` over 5 000 cycles (after 200 warm-up cycles), the worst wall-clock time, and
//! the contacts seen. CPU time excludes the time the thread waits for a core on a loaded
//! machine; the wall-clock worst case includes it.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::path::PathBuf;
use std::time::Instant;

use kerf_cell::{Cell, CellSettings, Mode};
use kerf_executor::JointSample;
use nalgebra::Vector3;

fn urdf_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf")
}

/// Case 1 planned by kerf_mjto's planner, its samples moved `offset` m along the tool axis
/// (negative: into the part), and its sample period.
fn case1_joints(offset: f64) -> (Vec<[f64; 6]>, f64) {
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
    let path = plan
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
    (path, request.sample_period)
}

/// The command at time `t`: linear interpolation of `path` at `period` per sample, back and
/// forth.
fn command(path: &[[f64; 6]], period: f64, t: f64) -> JointSample {
    let n = path.len() - 1;
    let f = t / period;
    let lap = (f / n as f64).floor() as usize;
    let mut x = f - (lap * n) as f64;
    let mut dir = 1.0;
    if lap % 2 == 1 {
        x = n as f64 - x;
        dir = -1.0;
    }
    let i = (x.floor() as usize).min(n - 1);
    let s = x - i as f64;
    let (a, b) = (path[i], path[i + 1]);
    JointSample {
        positions: (0..6).map(|j| a[j] + s * (b[j] - a[j])).collect(),
        velocities: (0..6).map(|j| dir * (b[j] - a[j]) / period).collect(),
        accelerations: vec![0.0; 6],
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

fn run(name: &str, mode: Mode, (path, period): &(Vec<[f64; 6]>, f64)) {
    let settings = CellSettings {
        mode,
        ..CellSettings::default()
    };
    let mut cell = Cell::from_files(
        &urdf_dir().join("laser_cutter.urdf"),
        &urdf_dir().join("cells/laser_bpillar.yaml"),
        settings,
    )
    .unwrap();
    cell.reset(&path[0]).unwrap();
    let dt = 1.0 / settings.control_rate_hz;
    let (warm, cycles) = (200, 5000);
    let mut times = Vec::with_capacity(cycles);
    let mut with_contact = 0;
    let mut deepest: f64 = 0.0;
    let mut wall_max: f64 = 0.0;
    for k in 1..=warm + cycles {
        let c = command(path, *period, k as f64 * dt);
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
            for c in &state.contacts {
                deepest = deepest.max(c.depth);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    let median = times[times.len() / 2];
    let p99 = times[times.len() * 99 / 100];
    let max = times[times.len() - 1];
    println!(
        "{name:<34} {mode:<9} CPU mean {:>6.1} us  median {:>6.1} us  p99 {:>6.1} us  max {:>7.1} us | wall max {:>7.1} us | contact in {with_contact}/{cycles} cycles, deepest {:.2} mm",
        mean * 1e6,
        median * 1e6,
        p99 * 1e6,
        max * 1e6,
        wall_max * 1e6,
        deepest * 1e3,
        mode = format!("{mode:?}"),
    );
}

fn main() {
    let far = case1_joints(0.3);
    let cutting = case1_joints(0.0);
    let contact = case1_joints(-0.002);
    println!("laser cutter + B-pillar (4 964 triangles), 4 ms control cycle, 1 kHz physics");
    for mode in [Mode::Kinematic, Mode::Dynamic] {
        run("case 1 plan, 0.3 m above the part", mode, &far);
        run("case 1 plan (tip 1 mm off)", mode, &cutting);
        run("case 1 plan 2 mm into the part", mode, &contact);
    }
}
