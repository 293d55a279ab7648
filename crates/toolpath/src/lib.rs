//! Tool path geometry of kerf's G-code front end (issue 14, item 2): corner
//! smoothing of G01 polylines under a tolerance with curvature-continuous
//! transitions ([`corner`]).

pub mod bezier;
pub mod corner;
pub mod error;
pub mod smooth;
pub mod vec3;

pub use bezier::QuinticBezier;
pub use corner::{corner_transition, Binding, CornerShape, CornerTransition};
pub use error::ToolpathError;
pub use smooth::{smooth_polyline, Piece, SmoothedPath};
