//! Helpers shared by the integration tests of kerf_mjto.

use kerf_mjto::CutRequest;

/// The committed request `crates/mjto/cases/<name>.yaml`.
#[allow(dead_code)] // each test file uses a subset
pub fn case(name: &str) -> CutRequest {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(format!("{name}.yaml"));
    CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Deterministic xorshift64* generator.
pub struct Rng(pub u64);

#[allow(dead_code)] // each test file uses a subset
impl Rng {
    /// Uniform in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    /// Uniform in [-1, 1).
    pub fn signed(&mut self) -> f64 {
        2.0 * self.next() - 1.0
    }
}

pub mod saddle;
