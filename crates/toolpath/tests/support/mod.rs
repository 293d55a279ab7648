//! Test data shared by the integration tests of `kerf_toolpath`.

use kerf_toolpath::{CurvatureLimits, FeedLimits};

/// A zig-zag of short and long segments with right-angle, acute and obtuse corners \[m\].
pub const ZIG_ZAG: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [0.02, 0.0, 0.0],
    [0.03, 0.01, 0.0],
    [0.05, 0.01, 0.0],
    [0.05, 0.03, 0.0],
    [0.045, 0.031, 0.0],
];

/// Seed 003's Table 1 with its tangential limits (A_t 800 mm/s², J_t 20 000 mm/s³).
pub fn feed_limits() -> FeedLimits {
    FeedLimits {
        curvature: CurvatureLimits::seed_003_table_1(),
        tangential_acceleration: 0.8,
        tangential_jerk: 20.0,
    }
}
