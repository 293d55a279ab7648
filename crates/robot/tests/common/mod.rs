//! Shared helpers for the kerf_robot integration tests.
#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

use kerf_robot::RobotModel;

/// The repository's `urdf/` directory.
pub fn urdf_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf")
}

/// Reads a file of the `urdf/` directory.
pub fn read(name: &str) -> String {
    let path = urdf_dir().join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {path:?}: {e}"))
}

/// The laser cutter with its limits YAML.
pub fn laser_cutter() -> RobotModel {
    let dir = urdf_dir();
    RobotModel::from_files(
        &dir.join("laser_cutter.urdf"),
        Some(&dir.join("laser_cutter_limits.yaml")),
    )
    .unwrap_or_else(|e| panic!("laser cutter must load: {e}"))
}

/// The IRB 6660 with its limits YAML.
pub fn irb6660() -> RobotModel {
    let dir = urdf_dir();
    RobotModel::from_files(
        &dir.join("irb6660.urdf"),
        Some(&dir.join("irb6660_limits.yaml")),
    )
    .unwrap_or_else(|e| panic!("IRB 6660 must load: {e}"))
}

/// SplitMix64 pseudo-random generator (Steele, Lea, Flood, "Fast splittable
/// pseudorandom number generators", OOPSLA 2014): deterministic, no crate.
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }

    /// A joint vector uniformly inside the model's position limits.
    pub fn joint_vector(&mut self, model: &RobotModel) -> Vec<f64> {
        model
            .joints()
            .iter()
            .map(|j| self.uniform(j.min_position, j.max_position))
            .collect()
    }
}

/// A small URDF with the given links and raw `<joint>` elements.
pub fn urdf(links: &[&str], joints: &str) -> String {
    let links: String = links
        .iter()
        .map(|l| format!("<link name=\"{l}\"/>\n"))
        .collect();
    format!("<?xml version=\"1.0\"?>\n<robot name=\"test\">\n{links}{joints}</robot>\n")
}

/// A raw `<joint>` element with standard limits [-1, 1], 1 /s, effort 10.
pub fn joint(name: &str, kind: &str, parent: &str, child: &str, axis: &str) -> String {
    format!(
        "<joint name=\"{name}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"{child}\"/>\
         <origin xyz=\"0 0 0.5\" rpy=\"0 0 0\"/><axis xyz=\"{axis}\"/>\
         <limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"1\"/></joint>\n"
    )
}
