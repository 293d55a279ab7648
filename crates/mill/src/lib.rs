//! Robotic milling model of kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`): the ABB IRB-6660 with the redundancy
//! angle about the tool axis, its condition number, the milling path and
//! the pose-dependent tool-tip dynamics fed to `kerf_chatter`.
