//! MJTO: minimized-jerk trajectory optimization for the 6-axis laser cutting
//! machine of seed 001 (Ding, Indri, Rizzo, *Machines* 13(5):339, 2025).
//!
//! The planner turns a cutter-location (CL) path with unit tool axes into a
//! smooth, collision-free joint trajectory of the machine in
//! `urdf/laser_cutter.urdf` (q1..q3 linear, q4/q5 rotary, q6 standoff):
//!
//! 1. 3D geometric feasible domains (GFD) over (q4, q5, q6) at the
//!    representative tool orientations (RTO) ([`gfd`], section 2.4);
//! 2. initial RTO selection by a shortest path over the layered candidate
//!    graph ([`selection`], eq. 56);
//! 3. the rotary-axis jerk QP ([`rotary`], eq. 15-45, 57-61) and the
//!    M-path QP of the standoff axis ([`standoff`], eq. 46-54, 62, App. A),
//!    both solved with Clarabel as second-order cone programs;
//! 4. a collision check of the whole trajectory at every controller sample,
//!    RTO insertion and repetition (Figure 6; [`planner`]);
//! 5. metrics beside the quaternion-interpolation baseline ([`baseline`],
//!    [`metrics`]).
//!
//! Everything here is ROS-free; `nodes/mjto_planner` and `kerf plan cut`
//! only parse, call [`planner::plan`] and publish.

pub mod baseline;
pub mod collision;
pub mod error;
pub mod executed;
pub mod gfd;
pub mod kinematics;
pub mod machine;
pub mod mesh;
pub mod metrics;
pub mod optimal_feed;
pub mod orientation;
pub mod plan;
pub mod planner;
pub mod request;
pub mod rotary;
pub mod selection;
pub mod series;
pub mod standoff;
pub mod timelaw;
pub mod tip;
pub mod trajectory;

pub use error::PlanError;
pub use machine::{AxisLimits, LaserMachine};
pub use plan::CutPlan;
pub use request::CutRequest;
