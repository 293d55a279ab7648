//! Robotic milling model of kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`, issue 4 parts 1-3): the ABB IRB-6660 with
//! the redundancy angle about the tool axis, its condition number, the
//! milling path and the pose-dependent tool-tip dynamics fed to
//! `kerf_chatter`.
//!
//! | module | what | source |
//! |---|---|---|
//! | [`mdh`] | MDH table (Craig), forward kinematics = URDF `tool0` | issue 4 table, seed 004 Table 1 |
//! | [`ik`] | closed-form IK, all 8 branches, limits, q4/q6 wrapping, branch continuity | spherical-wrist decoupling (Pieper) |
//! | [`jacobian`] | geometric Jacobian at the tool tip, condition number K and 1/K | seed 004 eq. 14; Angeles' characteristic length |
//! | [`path`] | cubic B-spline through coplanar points, equal arc lengths, cutting frames | seed 004 section 4, Fig. 2 |
//! | [`dynamics`] | `C = J K_q⁻¹ Jᵀ` projected on the cutting plane, modal mass and damping | replaces seed 004's Gaussian process |
//! | [`cell`] | `urdf/irb6660_milling.yaml`: everything above plus the process of Table 1 | seed 004 Table 1 |
//!
//! # The redundancy angle (seed 004 eq. 13)
//!
//! The milling task fixes the tool tip p and the tool axis; g ∈ [−π, π]
//! rotates the tool frame about its axis: `T_tcp(g) = [R0 · RotZ(g), p]`,
//! where R0's z axis is the tool approach direction (into the workpiece)
//! and R0's x axis is the feed direction (path tangent) at g = 0
//! ([`MillingPath::tool_pose`]); then `q = IK(T_tcp(g) · T_tcp⁻¹)` with the
//! TCP offset `T_tcp` (tool tip in `tool0`).
//!
//! **Finding.** With the identity TCP (tool tip = `tool0`, the paper's
//! literal model) the tool axis is the joint-6 axis: g changes q6 only, and
//! neither the Jacobian at the tip (so eq. 14) nor the tool-tip stiffness
//! depends on g (`tests/dynamics.rs`). The default cell therefore uses an
//! offset spindle (tool axis perpendicular to the flange axis; an
//! engineering estimate documented in the YAML), through which g moves the
//! whole arm and changes stiffness and conditioning — the mechanism the
//! paper relies on.
//!
//! # Example
//!
//! ```
//! use kerf_mill::{MillCell, MillError};
//!
//! let cell = MillCell::default_cell()?;
//! assert_eq!(cell.path().segments().len(), 100);
//! assert_eq!(cell.milling_process().teeth, 2);
//!
//! // Follow the path at g = 1 rad, each IK solution nearest the previous one.
//! let mut previous: Option<[f64; 6]> = None;
//! for segment in 0..cell.path().segments().len() {
//!     let state = cell.evaluate(segment, 1.0, previous.as_ref())?;
//!     assert!(state.condition_indicator > 0.0 && state.condition_indicator <= 1.0);
//!     state.modal.validate()?; // a kerf_chatter::Modal2 in the cutting frame
//!     previous = Some(state.joints);
//! }
//!
//! // Out of the reachable band: the error names the segment, g and the joint.
//! match cell.evaluate(10, 3.0, None) {
//!     Err(MillError::JointLimit { segment, joint, excess, .. }) => {
//!         assert_eq!(segment, Some(10));
//!         assert_eq!(joint, "joint_5");
//!         assert!(excess > 0.0);
//!     }
//!     other => panic!("unexpected {other:?}"),
//! }
//! # Ok::<(), MillError>(())
//! ```

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
