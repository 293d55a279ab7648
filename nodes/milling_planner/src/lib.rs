//! The kerf milling planner node (issue 5): `kerf_msgs/msg/MillRequest` (or its YAML text
//! form) in, `kerf_msgs/msg/MillPlan` and the IRB-6660 joint trajectory out (planner:
//! `kerf_millplan`).

/// Default node name.
pub const DEFAULT_NAME: &str = "milling_planner";
