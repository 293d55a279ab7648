//! Robotic milling model of kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`): the ABB IRB-6660 with the redundancy
//! angle about the tool axis, its condition number, the milling path and
//! the pose-dependent tool-tip dynamics fed to `kerf_chatter`.

pub mod cell;
pub mod dynamics;
pub mod error;
pub mod ik;
pub mod jacobian;
pub mod mdh;
pub mod path;

pub use cell::{CellState, MillCell, StateLimits};
pub use dynamics::{ComplianceModel, ToolTipDynamics};
pub use error::MillError;
pub use ik::{BranchJump, IkPath, IkSolution, JointRange, Kinematics};
pub use jacobian::{characteristic_length, condition_indicator, condition_number};
pub use mdh::{ArmGeometry, MdhRow};
pub use path::{CuttingFrame, MillingPath, PathSpec, Segment};
