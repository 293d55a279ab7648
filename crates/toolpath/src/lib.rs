//! Tool path geometry of kerf's G-code front end (issue 14, items 2 and 3):
//! corner smoothing of G01 polylines under a tolerance with
//! curvature-continuous transitions ([`corner`], [`smooth`]; their shape of
//! least jerk norm √(κ′² + κ⁴) by default, [`corner_jerk`]), arc-length
//! samples ([`samples`]) and the bang-bang time bound T_lb
//! ([`lower_bound`]).
//!
//! Feed planning: seed 003's constant-interval planner ([`feed`]) and kerf's
//! near time-optimal one ([`feed_optimal`]) over a velocity-limit curve
//! ([`limit_curve`](mod@limit_curve)) with per-sample feeds and axis limits ([`constraints`],
//! [`axis`]), picked by [`FeedMethod`] and verified on their output by
//! [`check_plan`] ([`plan_check`]).

pub mod adaptive;
pub mod axis;
pub mod baseline;
pub mod bezier;
pub mod constraints;
pub mod corner;
pub mod corner_curve;
pub mod corner_jerk;
pub mod error;
pub mod feed;
pub mod feed_method;
pub mod feed_optimal;
pub mod limit_curve;
pub mod lower_bound;
mod maximum;
pub mod merge;
pub mod metrics;
pub mod plan_check;
mod quadrature;
pub mod samples;
pub mod scurve;
pub mod smooth;
pub mod speed_limit;
pub mod spline;
pub mod vec3;

pub use adaptive::{sample_path_adaptive, sample_path_adaptive_within, Sampling};
pub use axis::AxisLimits;
pub use baseline::{CornerMethod, NurbsSettings};
pub use bezier::QuinticBezier;
pub use constraints::FeedConstraints;
pub use corner::{
    corner_frame, corner_transition, corner_transition_with, Binding, CornerFrame, CornerShape,
    CornerTransition, ShapeObjective,
};
pub use corner_curve::CornerCurve;
pub use error::ToolpathError;
pub use feed::{plan_feed, plan_feed_within, FeedLimits, FeedPlan, FeedSample};
pub use feed_method::FeedMethod;
pub use feed_optimal::{plan_feed_optimal, plan_feed_optimal_within};
pub use limit_curve::{limit_curve, LimitCurve};
pub use lower_bound::{
    bang_bang, bang_bang_under, bang_bang_under_within, BangBang, BangBangLimits,
};
pub use merge::{merge_collinear, merge_collinear_indices, merge_collinear_indices_within};
pub use metrics::{metrics, metrics_within, Metrics};
pub use plan_check::{check_plan, check_plan_within, PlanCheck, Worst};
pub use samples::{derivatives_at, point_at, sample_path, sample_path_within, PathSample};
pub use smooth::{smooth_polyline, Piece, SmoothedPath};
pub use smooth::{smooth_polyline_by, smooth_polyline_with, smooth_polyline_within};
pub use speed_limit::{CurvatureLimits, Servo};
pub use spline::CubicSpline;
pub mod plot;
pub use plot::{pipeline_plots, Chart};
pub mod corner_metrics;
pub use corner_metrics::{corner_metrics, CornerMetrics};
