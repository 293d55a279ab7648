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

pub mod cell;
pub mod chain;
pub mod config;
pub mod contact;
pub mod dynamics;
pub mod error;
pub mod geometry;
pub mod hermite;
pub mod inertia;
pub mod mesh_contact;
pub mod motion;
pub mod settings;
pub mod world;

pub use cell::{load_robot, Cell, CellState};
pub use config::CellFile;
pub use contact::{Contact, QueryCounts};
pub use error::CellError;
pub use settings::{CellSettings, Mode};
