//! The schema of the cell file: its sections as read by serde.

use kerf_chatter::Mode;
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CellFile {
    pub(super) robot: RobotSection,
    #[serde(default)]
    pub(super) tcp: Option<TcpSection>,
    pub(super) path: PathSection,
    pub(super) condition: ConditionSection,
    pub(super) dynamics: DynamicsSection,
    pub(super) process: ProcessSection,
    #[serde(default)]
    pub(super) chatter: Option<ChatterSection>,
}

/// The `chatter` section: how the chatter indicator is evaluated for this
/// cell (absent: the paper's model, state-dependent delays, linear force
/// law, m = 40).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ChatterSection {
    pub(super) model: String,
    pub(super) steps: usize,
    pub(super) force_exponent: f64,
    pub(super) reference_chip: f64,
    pub(super) wall_term: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RobotSection {
    pub(super) urdf: String,
    #[serde(default)]
    pub(super) limits: Option<String>,
    pub(super) reference_joints: [f64; 6],
    pub(super) joint_weights: [f64; 6],
    pub(super) branch_jump_threshold: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TcpSection {
    pub(super) position: [f64; 3],
    pub(super) z_axis: [f64; 3],
    pub(super) x_axis: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PathSection {
    pub(super) points: Vec<[f64; 3]>,
    pub(super) segments: usize,
    pub(super) approach_from_above: bool,
    pub(super) up: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ConditionSection {
    pub(super) characteristic_length: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DynamicsSection {
    pub(super) model: String,
    pub(super) joint_stiffness: [f64; 6],
    pub(super) modal_mass: [f64; 2],
    pub(super) damping_ratio: f64,
    #[serde(default)]
    pub(super) measured: Option<MeasuredSection>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeasuredSection {
    pub(super) x: Mode,
    pub(super) y: Mode,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StepSection {
    pub(super) feed: f64,
    pub(super) spindle_rpm: f64,
    pub(super) redundancy_angle: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProcessSection {
    pub(super) teeth: usize,
    pub(super) tool_radius: f64,
    pub(super) axial_depth: f64,
    pub(super) kt: f64,
    pub(super) kn: f64,
    pub(super) engagement_over_pi: [f64; 2],
    pub(super) spindle_rpm: [f64; 2],
    pub(super) feed: [f64; 2],
    pub(super) redundancy_angle: [f64; 2],
    pub(super) step_bounds: StepSection,
}
