//! Test data shared by the integration tests of `kerf_millplan`.

use kerf_mill::MillCell;
use kerf_millplan::dp::DpSpec;
use kerf_millplan::reward::RewardWeights;

/// The DP on a reduced grid of the default cell (Ω 2000–2400 rpm, f 0.03–0.06 m/s, g ±1 rad:
/// 21 × 31 × 11 nodes), default weights, g free: fast enough for a debug test.
pub fn reduced_dp_spec(cell: &MillCell) -> DpSpec {
    DpSpec {
        rpm_range: [2000.0, 2400.0],
        feed_range: [0.03, 0.06],
        g_range: [-1.0, 1.0],
        ..DpSpec::full(cell, RewardWeights::default(), false)
    }
}
