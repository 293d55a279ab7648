//! Shared test helpers: a deterministic generator and the IRB-6660 model.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use kerf_mill::{Kinematics, MillCell, MillError};
use kerf_robot::RobotModel;
use nalgebra::Isometry3;

/// xorshift64* generator (deterministic, no dependency).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}

pub fn urdf_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf")
}

pub fn robot() -> RobotModel {
    let dir = urdf_dir();
    RobotModel::from_files(
        &dir.join("irb6660.urdf"),
        Some(&dir.join("irb6660_limits.yaml")),
    )
    .expect("IRB 6660 model loads")
}

pub fn kinematics() -> Kinematics {
    Kinematics::from_robot(&robot(), Isometry3::identity(), [1.0; 6]).expect("kinematics")
}

/// A random joint vector within the URDF limits.
pub fn random_q(rng: &mut Rng, kin: &Kinematics) -> [f64; 6] {
    let mut q = [0.0; 6];
    for (v, j) in q.iter_mut().zip(kin.joints()) {
        *v = rng.range(j.lower, j.upper);
    }
    q
}

/// Position distance and Frobenius rotation distance of two poses.
pub fn pose_error(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let dr = (a.rotation.to_rotation_matrix().into_inner()
        - b.rotation.to_rotation_matrix().into_inner())
    .norm();
    (dp, dr)
}

/// The text of the shipped cell file `urdf/irb6660_milling.yaml`.
pub fn default_cell_text() -> String {
    std::fs::read_to_string(MillCell::default_path()).expect("read the default cell")
}

/// A cell from YAML text, with robot paths relative to the shipped `urdf/`.
pub fn load_cell_text(text: &str) -> Result<MillCell, MillError> {
    let dir = MillCell::default_path()
        .parent()
        .expect("urdf dir")
        .to_path_buf();
    MillCell::from_yaml_str(text, &dir, Path::new("test.yaml"))
}
