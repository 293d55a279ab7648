//! Robot descriptions for kerf: a URDF plus a MoveIt `joint_limits.yaml`
//! loaded into a validated serial kinematic model.
//!
//! [`RobotModel`] is used by every other kerf crate: the trajectory
//! executor checks joint vectors against its limits, planners evaluate its
//! forward kinematics, and collision checking and simulation read the link
//! geometry from [`RobotModel::urdf`] placed by [`RobotModel::link_poses`].
//!
//! * The URDF gives the tree, joint origins and axes, position, velocity
//!   and effort limits. Supported joints: revolute, prismatic, fixed.
//! * The optional limits YAML (MoveIt format) adds acceleration and jerk
//!   limits and may tighten, never widen, the URDF position and velocity
//!   limits.
//! * Units are SI throughout: m, rad, s.
//!
//! The repository's `urdf/` directory holds the two machines of kerf: the
//! 6-axis laser cutting machine of seed 001 (`laser_cutter.urdf`) and the
//! ABB IRB 6660-130/3.1 (`irb6660.urdf`), each with its `*_limits.yaml`.
//! [`data`] finds them, and every other shipped file, in the source tree or an installed
//! kerf's share directory (`KERF_DATA_DIR`, then `<exe dir>/../share/kerf`, then the source
//! tree).
//!
//! # Example
//!
//! ```
//! use kerf_robot::{data, JointKind, RobotModel};
//!
//! // The shipped descriptions, found by the data search of [`data`].
//! let dir = data::path("urdf")?;
//! let robot = RobotModel::from_files(
//!     &dir.join("irb6660.urdf"),
//!     Some(&dir.join("irb6660_limits.yaml")),
//! )?;
//! assert_eq!(robot.dof(), 6);
//! assert_eq!(robot.tip_link(), "tool0");
//! let j2 = &robot.joints()[1];
//! assert_eq!((j2.name.as_str(), j2.kind), ("joint_2", JointKind::Revolute));
//! assert_eq!(j2.max_acceleration, Some(4.0)); // rad/s², from the YAML
//!
//! // All joints at zero: the flange is 0.3 + 1.5055 + 0.2 m in front of the
//! // base axis and 0.8145 + 1.28 + 0.28 m above the floor.
//! let q = [0.0; 6];
//! robot.check_positions(&q)?;
//! let tool0 = robot.forward_kinematics(&q)?;
//! assert!((tool0.translation.x - 2.0055).abs() < 1e-12);
//! assert!((tool0.translation.z - 2.3745).abs() < 1e-12);
//!
//! // Joint vectors are validated.
//! assert!(robot.check_positions(&[0.0, 2.0, 0.0, 0.0, 0.0, 0.0]).is_err()); // J2 > 85°
//! assert!(robot.forward_kinematics(&[f64::NAN; 6]).is_err());
//! # Ok::<(), kerf_robot::RobotError>(())
//! ```

mod chain;
pub mod data;
pub mod document;
mod error;
mod executor_limits;
pub mod file;
mod joint;
mod limits;
mod model;
mod pose;
pub mod roots;

pub use error::RobotError;
pub use joint::{JointKind, JointSpec};
pub use model::RobotModel;
