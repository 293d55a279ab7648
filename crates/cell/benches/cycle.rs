//! CPU time per 4 ms control cycle of the simulated cell (4 physics sub-steps at 1 kHz),
//! kinematic and dynamic, free and in contact with the 4 964-triangle B-pillar.
//!
//! Run: `cargo bench -p kerf_cell --bench cycle`. Prints, per scenario, the mean, 99th
//! percentile and worst wall-clock time of `Cell::step` over 5 000 cycles (after 200
//! warm-up cycles), and the contacts seen.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::path::PathBuf;
use std::time::Instant;

use kerf_cell::{Cell, CellSettings, Mode};
use kerf_executor::JointSample;
use nalgebra::{Point3, Vector3};

fn urdf_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf")
}

/// Case 1's path as joint vectors with the CL point `offset` m off the surface along the
/// tool axis (negative: into the part), standoff axis at -0.07 m.
fn case1_joints(offset: f64) -> Vec<[f64; 6]> {
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mjto/cases/case1.yaml"),
    )
    .unwrap();
    let request = kerf_mjto::CutRequest::from_yaml(&text).unwrap();
    let pose = request.workpiece_pose.isometry().unwrap();
    request
        .points
        .iter()
        .zip(&request.axes)
        .map(|(p, a)| {
            let o = pose.rotation * Vector3::from(*a);
            let c = pose * Point3::from(*p) + o * offset;
            let (q4, q5, q6) = (o.y.atan2(o.x), o.z.acos(), -0.07);
            let m = c.coords - q6 * o;
            [m.x, m.y, m.z, q4, q5, q6]
        })
        .collect()
}

/// The command at time `t`: linear interpolation of `path` at 10 ms per point (case 1's
/// 0.333 m/s over its 3.3 mm point spacing), back and forth.
fn command(path: &[[f64; 6]], t: f64) -> JointSample {
    let period = 0.01;
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

fn run(name: &str, mode: Mode, path: &[[f64; 6]]) {
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
    for k in 1..=warm + cycles {
        let c = command(path, k as f64 * dt);
        let start = Instant::now();
        let state = cell.step(&c, dt).unwrap();
        let elapsed = start.elapsed().as_secs_f64();
        if k > warm {
            times.push(elapsed);
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
    let p99 = times[times.len() * 99 / 100];
    let max = times[times.len() - 1];
    println!(
        "{name:<34} {mode:<9} mean {:>7.1} us  p99 {:>7.1} us  max {:>7.1} us  cycles with contact {with_contact}/{cycles}, deepest {:.2} mm",
        mean * 1e6,
        p99 * 1e6,
        max * 1e6,
        deepest * 1e3,
        mode = format!("{mode:?}"),
    );
}

fn main() {
    let far: Vec<[f64; 6]> = case1_joints(0.3);
    let cutting = case1_joints(0.0);
    let contact = case1_joints(-0.002);
    println!("laser cutter + B-pillar (4 964 triangles), 4 ms control cycle, 1 kHz physics");
    for mode in [Mode::Kinematic, Mode::Dynamic] {
        run("far (0.3 m above the part)", mode, &far);
        run("cutting case 1 (tip 1 mm off)", mode, &cutting);
        run("in contact (CL 2 mm into the part)", mode, &contact);
    }
}
