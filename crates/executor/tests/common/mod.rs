//! Helpers shared by the integration tests.
#![allow(dead_code)]

use kerf_executor::{
    Cycle, Executor, ExecutorConfig, JointLimits, JointSample, MockHardware, TrajectoryPoint,
    TrajectoryRequest,
};

/// Control period of the tests (s), the default 250 Hz.
pub const DT: f64 = 0.004;

/// A 6-joint robot: positions ±3, velocity limits 2..3, acceleration limits 10..15.
pub fn limits6() -> Vec<JointLimits> {
    (0..6)
        .map(|i| JointLimits {
            name: format!("j{}", i + 1),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0 + 0.2 * i as f64,
            max_acceleration: 10.0 + i as f64,
        })
        .collect()
}

/// A robot of `n` identical joints with the given limits.
pub fn robot(n: usize, pos: f64, vel: f64, acc: f64) -> Vec<JointLimits> {
    (0..n)
        .map(|i| JointLimits {
            name: format!("j{}", i + 1),
            min_position: -pos,
            max_position: pos,
            max_velocity: vel,
            max_acceleration: acc,
        })
        .collect()
}

pub fn names(limits: &[JointLimits]) -> Vec<String> {
    limits.iter().map(|l| l.name.clone()).collect()
}

/// A point; `v`/`a` empty slices mean "not given".
pub fn pt(t: f64, p: &[f64], v: &[f64], a: &[f64]) -> TrajectoryPoint {
    TrajectoryPoint {
        positions: p.to_vec(),
        velocities: v.to_vec(),
        accelerations: a.to_vec(),
        effort: Vec::new(),
        time_from_start: t,
    }
}

pub fn request(limits: &[JointLimits], points: Vec<TrajectoryPoint>) -> TrajectoryRequest {
    TrajectoryRequest {
        joint_names: names(limits),
        points,
        start_time: None,
    }
}

pub fn rest(n: usize, p: f64) -> JointSample {
    JointSample::at_rest(vec![p; n])
}

/// Deterministic PRNG (SplitMix64), so failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Minimum-jerk rest-to-rest motion from `p0` by `d` in time `t_total`, at `t`:
/// p0 + d (10 s³ − 15 s⁴ + 6 s⁵), s = t / t_total (Flash & Hogan 1985).
pub fn min_jerk(p0: f64, d: f64, t_total: f64, t: f64) -> (f64, f64, f64) {
    let s = t / t_total;
    let p = p0 + d * (10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5));
    let v = d / t_total * (30.0 * s.powi(2) - 60.0 * s.powi(3) + 30.0 * s.powi(4));
    let a = d / (t_total * t_total) * (60.0 * s - 180.0 * s.powi(2) + 120.0 * s.powi(3));
    (p, v, a)
}

/// A closed-loop run: every `DT` from `t0` while `t < t1`, read the mock, update, write.
pub fn run(exec: &mut Executor, hw: &mut MockHardware, t0: f64, t1: f64) -> Vec<Cycle> {
    let limits = exec.limits().to_vec();
    let mut cycles = Vec::new();
    let mut k = 0u64;
    loop {
        let t = t0 + k as f64 * DT;
        if t >= t1 {
            break;
        }
        let measured = hw.state().clone();
        let cycle = exec.update(t, &measured).expect("valid update");
        hw.write(&limits, &cycle.reference, DT)
            .expect("valid command");
        cycles.push(cycle);
        k += 1;
    }
    cycles
}

pub fn executor(limits: &[JointLimits], cfg: ExecutorConfig, p: f64) -> Executor {
    Executor::new(limits.to_vec(), cfg, vec![p; limits.len()]).expect("valid executor")
}
