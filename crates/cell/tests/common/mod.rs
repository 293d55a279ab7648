//! Shared helpers of the kerf_cell tests: paths of the shipped files, cells, case 1.
#![allow(dead_code)]

use std::path::PathBuf;

use kerf_cell::{Cell, CellFile, CellSettings, Mode};
use kerf_robot::RobotModel;

/// The repository's `urdf/` directory.
pub fn urdf_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf")
}

/// Settings of the given mode, otherwise the defaults (250 Hz control, 1 kHz physics).
pub fn settings(mode: Mode) -> CellSettings {
    CellSettings {
        mode,
        ..CellSettings::default()
    }
}

/// A shipped cell: `laser_bpillar` or `irb6660_plate`.
pub fn shipped(cell: &str, mode: Mode) -> Cell {
    let urdf = if cell.starts_with("laser") {
        "laser_cutter.urdf"
    } else {
        "irb6660.urdf"
    };
    Cell::from_files(
        &urdf_dir().join(urdf),
        &urdf_dir().join("cells").join(format!("{cell}.yaml")),
        settings(mode),
    )
    .unwrap()
}

/// The laser cutter with cell-file text `text` (paths relative to `urdf/cells/`).
pub fn laser_with(text: &str, mode: Mode) -> Result<Cell, kerf_cell::CellError> {
    let model = RobotModel::from_files(&urdf_dir().join("laser_cutter.urdf"), None).unwrap();
    let dir = urdf_dir().join("cells");
    let file = CellFile::from_str_in(text, &dir, &dir.join("<test>"))?;
    Cell::new(model, &file, settings(mode))
}

/// Case 1's request (crates/mjto/cases/case1.yaml).
pub fn case1() -> kerf_mjto::CutRequest {
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mjto/cases/case1.yaml"),
    )
    .unwrap();
    kerf_mjto::CutRequest::from_yaml(&text).unwrap()
}

/// xorshift64*: deterministic pseudo-random numbers in [0, 1).
pub struct Rng(pub u64);

impl Rng {
    /// The next number in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// Case 1 planned by kerf_mjto's planner (the collision-free trajectory at 10 ms samples).
pub fn case1_plan() -> kerf_mjto::CutPlan {
    let machine = kerf_mjto::LaserMachine::default_machine().unwrap();
    let mut planner = kerf_mjto::planner::Planner::new(machine).unwrap();
    planner.plan(&case1()).unwrap()
}

/// The plan's sample at time `t` (s): cubic Hermite of positions and velocities between
/// the 10 ms samples, accelerations linear.
pub fn plan_at(plan: &kerf_mjto::CutPlan, t: f64) -> kerf_executor::JointSample {
    let last = plan.times.len() - 1;
    let i = plan.times.partition_point(|&x| x <= t).clamp(1, last) - 1;
    let (t0, t1) = (plan.times[i], plan.times[i + 1]);
    let h = t1 - t0;
    let s = ((t - t0) / h).clamp(0.0, 1.0);
    let basis = kerf_cell::hermite::Hermite::at(s);
    let (p0, p1) = (plan.positions[i], plan.positions[i + 1]);
    let (v0, v1) = (plan.velocities[i], plan.velocities[i + 1]);
    let (a0, a1) = (plan.accelerations[i], plan.accelerations[i + 1]);
    kerf_executor::JointSample {
        positions: (0..6)
            .map(|j| basis.position(p0[j], v0[j], p1[j], v1[j], h))
            .collect(),
        velocities: (0..6)
            .map(|j| basis.velocity(p0[j], v0[j], p1[j], v1[j], h))
            .collect(),
        accelerations: (0..6).map(|j| a0[j] + s * (a1[j] - a0[j])).collect(),
    }
}
