//! The path-independent observation of the milling environment (issue 13,
//! item 4): what the DDPG actor and critic see of a state, with no segment
//! index and nothing else that only means something on one path.
//!
//! # Why not the paper's state
//! Seed 004 section 3 observes `S = (s_pa, Ω, f, g)`, `s_pa` the position on
//! THE path (the segment index). A policy trained on that state learns which
//! g and feed suit segment t of one path; on another path segment t has
//! another pose, curvature and conditioning, and the policy acts blind (the
//! issue measured POLICY_ERROR or chattering plans on 3 other paths). kerf
//! replaces `s_pa` by what the paper's reward depends on and what decides
//! it along a path: the local geometry of the path, the pose of the robot
//! (conditioning, wrist angle), the chatter indicator of the current state,
//! and the distance left. Measured in `BENCHMARKS.md` ("Milling: a policy that
//! generalizes": chatter-free on 5 of 10 held-out paths, min 1/K ≥ 0.348 on
//! all).
//!
//! # Layout ([`OBSERVATION_LAYOUT`], recorded in the policy's sidecar)
//! Every entry is mapped to [−1, 1] (clamped) as the DDPG networks expect
//! ([`crate::rl::Environment`]):
//!
//! | k | name | meaning | map |
//! |---|---|---|---|
//! | 0 | `remaining_length` | arc length from the segment's midpoint to the path end \[m\] | [0, 1 m] |
//! | 1 | `segment_length` | the segment's arc length \[m\] (L/N) | [0, 0.02 m] |
//! | 2 | `curvature` | signed curvature κ at the segment, about the plane normal \[1/m\] | tanh(κ · 0.1 m) |
//! | 3 | `curvature_ahead` | mean signed curvature over the next 10 segments \[1/m\] | tanh(κ · 0.1 m) |
//! | 4–6 | `tangent_{x,y,z}` | unit tangent of the path at the segment, base frame (the heading) | as is |
//! | 7–9 | `approach_{x,y,z}` | tool approach direction (−plane normal), base frame | as is |
//! | 10–12 | `position_{x,y,z}` | segment midpoint, base frame \[m\] | ([`WORKSPACE_CENTER`] ± [`WORKSPACE_HALF_EXTENT`]) |
//! | 13 | `condition_indicator` | 1/K of the state (seed 004 eq. 14) | [0, 0.7] |
//! | 14 | `wrist_angle` | q5 of the state \[rad\] (q5 = 0: the wrist singularity) | [−π/2, π/2] |
//! | 15–17 | `condition_ahead_{minus,same,plus}` | 1/K at the next segment for g − Δg_max, g, g + Δg_max (0 where infeasible) | [0, 0.7] |
//! | 18–20 | `spindle_speed`, `feed`, `redundancy_angle` | Ω, f, g | their state ranges |
//! | 21–23 | `filter_{spindle,feed,g}` | the filter state â of eq. 11 (the last applied move) | ± the step bounds |
//! | 24 | `chatter_indicator` | \|μ\|max of the state | [0.5, 1.5] |
//! | 25–27 | `stiffness_{xx,yy,xy}` | tool-tip stiffness K of the state in the cutting frame (`kerf_mill::ToolTipDynamics`, seed 004 eq. 9–10) \[N/m\] | [0, 3e6] (xy: ±1.5e6) |
//! | 28–36 | `stiffness_ahead_{minus,same,plus}_{xx,yy,xy}` | the same at the next segment for g − Δg_max, g, g + Δg_max (0 where infeasible) | as 25–27 |
//!
//! Why the stiffness: |μ|max at f_max depends on g through the tool-tip
//! dynamics, and not monotonically (measured on held-out paths: along g it
//! alternates between 0.84 and 1.10 within 0.4 rad); the stiffness of the
//! lookahead states is what the policy can see of that dependence without
//! evaluating the chatter indicator (a few µs per state instead of about a
//! millisecond).
//!
//! A violating state (no evaluation) observes 0 for entries 13–17 and
//! 24–36; it is terminal, so DDPG never bootstraps from it.
//!
//! The last segment has no next one: its lookahead entries repeat its own
//! segment, its `curvature_ahead` is its curvature.

use kerf_mill::{MillCell, StateLimits};
use nalgebra::Vector3;

use crate::error::MillPlanError;

/// Names of the observation entries, in order (module documentation).
pub const OBSERVATION_LAYOUT: [&str; 37] = [
    "remaining_length",
    "segment_length",
    "curvature",
    "curvature_ahead",
    "tangent_x",
    "tangent_y",
    "tangent_z",
    "approach_x",
    "approach_y",
    "approach_z",
    "position_x",
    "position_y",
    "position_z",
    "condition_indicator",
    "wrist_angle",
    "condition_ahead_minus",
    "condition_ahead_same",
    "condition_ahead_plus",
    "spindle_speed",
    "feed",
    "redundancy_angle",
    "filter_spindle",
    "filter_feed",
    "filter_g",
    "chatter_indicator",
    "stiffness_xx",
    "stiffness_yy",
    "stiffness_xy",
    "stiffness_ahead_minus_xx",
    "stiffness_ahead_minus_yy",
    "stiffness_ahead_minus_xy",
    "stiffness_ahead_same_xx",
    "stiffness_ahead_same_yy",
    "stiffness_ahead_same_xy",
    "stiffness_ahead_plus_xx",
    "stiffness_ahead_plus_yy",
    "stiffness_ahead_plus_xy",
];

/// Length of an observation.
pub const OBSERVATION_DIM: usize = OBSERVATION_LAYOUT.len();

/// Remaining arc length that maps to +1 \[m\].
pub const REMAINING_SCALE: f64 = 1.0;
/// Segment length that maps to +1 \[m\].
pub const SEGMENT_LENGTH_SCALE: f64 = 0.02;
/// Length scale of the curvature map \[m\] (κ = 10 /m maps to tanh(1)).
pub const CURVATURE_SCALE: f64 = 0.1;
/// Segments averaged by `curvature_ahead`.
pub const CURVATURE_LOOKAHEAD: usize = 10;
/// Centre of the position map \[m\] (the IRB 6660's milling region of the
/// default cell: seed 004 Table 1 points are at x 1.4–2.1, y ±0.3, z 1.7).
pub const WORKSPACE_CENTER: [f64; 3] = [1.75, 0.0, 1.5];
/// Half extents of the position map \[m\].
pub const WORKSPACE_HALF_EXTENT: [f64; 3] = [0.75, 0.75, 0.75];
/// 1/K that maps to +1 (the default cell's best 1/K is about 0.68).
pub const CONDITION_SCALE: f64 = 0.7;
/// |μ|max range of the map.
pub const CHATTER_RANGE: [f64; 2] = [0.5, 1.5];
/// Diagonal stiffness that maps to +1 \[N/m\] (the default cell's tool tip
/// is 0.5e6–3e6 N/m in the cutting frame); the off-diagonal maps ± half of it.
pub const STIFFNESS_SCALE: f64 = 3e6;

/// The layout as owned strings (for the policy sidecar).
pub fn layout() -> Vec<String> {
    OBSERVATION_LAYOUT.iter().map(|s| s.to_string()).collect()
}

/// Maps `v` in [lo, hi] to [−1, 1], clamped.
pub fn normalize(v: f64, lo: f64, hi: f64) -> f32 {
    ((2.0 * (v - lo) / (hi - lo) - 1.0).clamp(-1.0, 1.0)) as f32
}

/// The geometry of one segment, as observed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentFeatures {
    /// Arc length from the segment's midpoint to the path end \[m\].
    pub remaining: f64,
    /// Segment arc length \[m\].
    pub length: f64,
    /// Signed curvature about the plane normal \[1/m\].
    pub curvature: f64,
    /// Mean signed curvature of the next [`CURVATURE_LOOKAHEAD`] segments \[1/m\].
    pub curvature_ahead: f64,
    /// Unit tangent (base frame).
    pub tangent: [f64; 3],
    /// Midpoint \[m\] (base frame).
    pub position: [f64; 3],
}

/// The per-segment geometry of a cell's path, computed once per environment.
#[derive(Debug, Clone, PartialEq)]
pub struct PathFeatures {
    /// One per segment.
    pub segments: Vec<SegmentFeatures>,
    /// Tool approach direction (base frame).
    pub approach: [f64; 3],
}

impl PathFeatures {
    /// The features of `cell`'s path.
    ///
    /// Curvature: the turning angle of the segment tangents about the plane
    /// normal n, `κ_i = θ(t_{i−1}, t_{i+1}) / (s_{i+1} − s_{i−1})` with
    /// `θ(a, b) = atan2(n · (a × b), a · b)` (central difference of the
    /// tangent angle over arc length, one-sided at the ends; the definition
    /// of signed curvature as dθ/ds, do Carmo, *Differential Geometry of
    /// Curves and Surfaces*, section 1-5).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a path of fewer than 2 segments.
    pub fn new(cell: &MillCell) -> Result<Self, MillPlanError> {
        let path = cell.path();
        let segs = path.segments();
        let n = segs.len();
        if n < 2 {
            return Err(MillPlanError::InvalidConfig {
                name: "milling path".to_string(),
                reason: "needs at least 2 segments".to_string(),
            });
        }
        let normal: Vector3<f64> = path.normal();
        let total = path.total_length();
        let mut starts = Vec::with_capacity(n);
        let mut acc = 0.0;
        for s in segs {
            starts.push(acc);
            acc += s.length;
        }
        let mid_s = |i: usize| starts[i] + 0.5 * segs[i].length;
        let curvature = |i: usize| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let (ta, tb) = (segs[a].tangent, segs[b].tangent);
            let angle = normal.dot(&ta.cross(&tb)).atan2(ta.dot(&tb));
            let ds = mid_s(b) - mid_s(a);
            if ds > 0.0 {
                angle / ds
            } else {
                0.0
            }
        };
        let kappa: Vec<f64> = (0..n).map(curvature).collect();
        let segments = (0..n)
            .map(|i| {
                let ahead: Vec<f64> = ((i + 1)..=(i + CURVATURE_LOOKAHEAD).min(n - 1))
                    .map(|k| kappa[k])
                    .collect();
                let curvature_ahead = if ahead.is_empty() {
                    kappa[i]
                } else {
                    ahead.iter().sum::<f64>() / ahead.len() as f64
                };
                let s = &segs[i];
                SegmentFeatures {
                    remaining: (total - mid_s(i)).max(0.0),
                    length: s.length,
                    curvature: kappa[i],
                    curvature_ahead,
                    tangent: [s.tangent.x, s.tangent.y, s.tangent.z],
                    position: [s.mid.x, s.mid.y, s.mid.z],
                }
            })
            .collect();
        let a = path.approach();
        Ok(Self {
            segments,
            approach: [a.x, a.y, a.z],
        })
    }
}

/// What the environment knows of a state besides the path (inputs of
/// [`observe`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateFeatures {
    /// Segment index (only to look up the path features; not observed).
    pub segment: usize,
    /// Ω \[rpm\], f \[m/s\], g \[rad\].
    pub rpm: f64,
    /// Feed \[m/s\].
    pub feed: f64,
    /// Redundancy angle \[rad\].
    pub g: f64,
    /// The filter state â (rpm, m/s, rad).
    pub filter: [f64; 3],
    /// 1/K, q5 and |μ|max of the state; `None` for a violating state.
    pub pose: Option<PoseFeatures>,
    /// 1/K at the next segment for g − Δg_max, g, g + Δg_max (0 where
    /// infeasible).
    pub condition_ahead: [f64; 3],
    /// The tool-tip stiffness (xx, yy, xy) \[N/m\] at the same three
    /// lookahead states (`None` where infeasible).
    pub stiffness_ahead: [Option<[f64; 3]>; 3],
}

/// The pose part of a feasible state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseFeatures {
    /// 1/K (seed 004 eq. 14).
    pub condition_indicator: f64,
    /// q5 \[rad\].
    pub wrist_angle: f64,
    /// |μ|max.
    pub chatter_indicator: f64,
    /// Tool-tip stiffness (xx, yy, xy) in the cutting frame \[N/m\].
    pub stiffness: [f64; 3],
}

/// The three stiffness entries mapped to [−1, 1] (zeros for `None`).
fn stiffness_entries(k: Option<[f64; 3]>) -> [f32; 3] {
    match k {
        Some([xx, yy, xy]) => [
            normalize(xx, 0.0, STIFFNESS_SCALE),
            normalize(yy, 0.0, STIFFNESS_SCALE),
            normalize(xy, -0.5 * STIFFNESS_SCALE, 0.5 * STIFFNESS_SCALE),
        ],
        None => [0.0; 3],
    }
}

/// The observation vector ([`OBSERVATION_LAYOUT`]).
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for a segment index outside the path.
pub fn observe(
    path: &PathFeatures,
    limits: &StateLimits,
    state: &StateFeatures,
) -> Result<Vec<f32>, MillPlanError> {
    let seg = path
        .segments
        .get(state.segment)
        .ok_or_else(|| MillPlanError::InvalidParameter {
            name: "segment index".to_string(),
            value: state.segment as f64,
            reason: format!("the path has {} segments", path.segments.len()),
        })?;
    let mut o = Vec::with_capacity(OBSERVATION_DIM);
    o.push(normalize(seg.remaining, 0.0, REMAINING_SCALE));
    o.push(normalize(seg.length, 0.0, SEGMENT_LENGTH_SCALE));
    o.push((seg.curvature * CURVATURE_SCALE).tanh() as f32);
    o.push((seg.curvature_ahead * CURVATURE_SCALE).tanh() as f32);
    o.extend(seg.tangent.iter().map(|v| v.clamp(-1.0, 1.0) as f32));
    o.extend(path.approach.iter().map(|v| v.clamp(-1.0, 1.0) as f32));
    for k in 0..3 {
        let (c, h) = (WORKSPACE_CENTER[k], WORKSPACE_HALF_EXTENT[k]);
        o.push(normalize(seg.position[k], c - h, c + h));
    }
    match &state.pose {
        Some(p) => {
            o.push(normalize(p.condition_indicator, 0.0, CONDITION_SCALE));
            o.push(normalize(
                p.wrist_angle,
                -std::f64::consts::FRAC_PI_2,
                std::f64::consts::FRAC_PI_2,
            ));
        }
        None => o.extend([0.0, 0.0]),
    }
    for c in state.condition_ahead {
        o.push(normalize(c, 0.0, CONDITION_SCALE));
    }
    o.push(normalize(
        state.rpm,
        limits.spindle_rpm[0],
        limits.spindle_rpm[1],
    ));
    o.push(normalize(state.feed, limits.feed[0], limits.feed[1]));
    o.push(normalize(
        state.g,
        limits.redundancy_angle[0],
        limits.redundancy_angle[1],
    ));
    let bounds = [
        limits.max_spindle_step_rpm,
        limits.max_feed_step,
        limits.max_redundancy_step,
    ];
    for (f, b) in state.filter.iter().zip(bounds) {
        o.push(if b > 0.0 { normalize(*f, -b, b) } else { 0.0 });
    }
    o.push(match &state.pose {
        Some(p) => normalize(p.chatter_indicator, CHATTER_RANGE[0], CHATTER_RANGE[1]),
        None => 0.0,
    });
    o.extend(stiffness_entries(state.pose.map(|p| p.stiffness)));
    for k in state.stiffness_ahead {
        o.extend(stiffness_entries(k));
    }
    debug_assert_eq!(o.len(), OBSERVATION_DIM);
    Ok(o)
}
