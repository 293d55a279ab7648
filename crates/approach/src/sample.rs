//! One time-stamped joint state: the unit of every sampled motion.

/// A joint state at a time: `(t, q, q̇, q̈)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sample {
    /// Time (s), from the start of the motion it belongs to.
    pub t: f64,
    /// Positions (rad or m), one per joint.
    pub q: Vec<f64>,
    /// Velocities (rad/s or m/s), one per joint.
    pub qd: Vec<f64>,
    /// Accelerations (rad/s² or m/s²), one per joint.
    pub qdd: Vec<f64>,
}

impl Sample {
    /// A state at rest at `q` at time `t`.
    pub fn at_rest(t: f64, q: Vec<f64>) -> Self {
        let n = q.len();
        Self {
            t,
            q,
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
        }
    }
}

impl From<(f64, Vec<f64>, Vec<f64>, Vec<f64>)> for Sample {
    /// `(t, q, qd, qdd)`, the tuple form of a process sample.
    fn from((t, q, qd, qdd): (f64, Vec<f64>, Vec<f64>, Vec<f64>)) -> Self {
        Self { t, q, qd, qdd }
    }
}
