//! kerf_cell: a ROS-free simulated robot cell on rapier3d-f64 (issue 15, item 1).
//!
//! A [`Cell`] holds one robot (URDF plus a mass sidecar, as rapier multibody joints) and a
//! static scene (workpiece meshes, fixtures) from a cell file. The executor's control loop
//! calls [`Cell::step`] once per control period; the cell runs its physics sub-steps in
//! lock-step and returns a [`CellState`]: positions, velocities, efforts, tracking error and
//! the contacts found.
//!
//! | module | concept |
//! |---|---|
//! | [`config`] | the cell file: robot, scene objects, tool shapes, contact rules |
//! | [`inertia`] | the mass sidecar of a URDF without `<inertial>` |
//! | [`chain`] | URDF links merged into rigid bodies (the converter to rapier) |
//! | [`world`] | the rapier multibody |
//! | [`dynamics`] | recursive Newton-Euler inverse dynamics (feed-forward), mass-matrix diagonal (gains) |
//! | [`geometry`] | parry shapes of robot and scene |
//! | [`contact`] | contacts by distance threshold, allowances for standoff and engagement |
//! | [`motion`] | how far a shape can have moved: pairs skipped while their clearance holds |
//! | [`mesh_contact`] | a shape against a triangle mesh, triangles deepest-first, pruned by plane |
//! | [`settings`] | mode, rates, servo bandwidth |
//! | [`cell`] | [`Cell`], the lock-step of control and physics |
//! | [`surroundings`] | [`CellSurroundings`]: the robot against the cell by exact distance, for a plan's approach and retract (issue 27) |
//! | [`lipschitz`] | per-joint bounds of how fast a robot shape point moves |
//! | [`milling_tool`] | the IRB 6660's milling tool axis by `kerf_mill`'s IK; its cell's surroundings |

pub mod cell;
pub mod chain;
pub mod config;
pub mod contact;
pub mod dynamics;
pub mod error;
pub mod geometry;
pub mod hermite;
pub mod inertia;
pub mod lipschitz;
pub mod mesh_contact;
pub mod milling_tool;
pub mod motion;
pub mod settings;
pub mod surroundings;
pub mod world;

pub use cell::{load_robot, Cell, CellState};
pub use config::CellFile;
pub use contact::{Contact, QueryCounts};
pub use error::CellError;
pub use milling_tool::{irb6660_cell_path, milling_surroundings, IRB6660_CELL};
pub use settings::{CellSettings, Mode};
pub use surroundings::{approach_limits, CellSurroundings, ToolAxis};
