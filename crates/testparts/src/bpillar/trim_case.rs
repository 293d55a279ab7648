//! Case 1 of seed 001: the side trim along the left flange.

use kerf_mjto::CutRequest;
use nalgebra::{UnitQuaternion, Vector3};

use super::part::BPillar;
use super::request::{make_request, path_spacing, Process};
use crate::TestPartError;

/// Case 1 of seed 001 (section 3.1, Table 1): a long side trim along the
/// left flange of the pillar body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrimCaseParams {
    /// Feedrate f (m/s). Table 1: 20 m/min.
    pub feedrate: f64,
    /// Controller sample period Δt (s). Table 1: 0.01 s.
    pub sample_period: f64,
    /// Lead angle limit (rad). Table 1: 5°.
    pub max_lead_angle: f64,
    /// Tilt angle limit (rad). Table 1: 5°.
    pub max_tilt_angle: f64,
    /// Path length (m), rounded to a whole number of `f Δt`. Default 0.8.
    pub length: f64,
    /// Spine arc length of the first CL point (m). Default 0.6 (the
    /// path then lies on the curved body part, 0.05 m clear of both ends).
    pub start: f64,
    /// Distance of the trim line from the flange fillet (m). Default
    /// 0.075: the fork arms (0.115 m from the tool axis) reach the wall
    /// when they point across the cut, the housings (≤ 0.05 m to the
    /// side) clear it when the arms point along the cut.
    pub trim_offset: f64,
    /// Number of initial RTOs, evenly spaced (Figure 8: six).
    pub rto_count: usize,
    /// Roll of the workpiece about the machine x axis (rad), after
    /// levelling the flange at the middle of the path. Default 1°: the
    /// tool axis passes 1° from the vertical, where q4 = atan2(O_y, O_x)
    /// swings by about 140° along the path.
    pub roll: f64,
    /// Machine-frame centre of the bounding box of the nominal M points
    /// `C + 0.07 O` (m). Default (0.8, 0.7, 1.0), the middle of the q1, q2
    /// strokes.
    pub m_center: [f64; 3],
}

impl Default for TrimCaseParams {
    fn default() -> Self {
        Self {
            feedrate: 20.0 / 60.0,
            sample_period: 0.01,
            max_lead_angle: 5f64.to_radians(),
            max_tilt_angle: 5f64.to_radians(),
            length: 0.8,
            start: 0.6,
            trim_offset: 0.075,
            rto_count: 6,
            roll: 1f64.to_radians(),
            m_center: [0.8, 0.7, 1.0],
        }
    }
}

/// Builds the case 1 request ([`TrimCaseParams`]).
///
/// The workpiece is pitched so that the flange is level at the middle of
/// the path, then rolled by `roll`; it is placed so that the nominal M
/// points (q6 = the default reference standoff) are centred on `m_center`.
/// The initial RTOs are `rto_count` evenly spaced CL points.
///
/// # Errors
/// [`TestPartError::Invalid`] for parameters out of range (non-finite,
/// non-positive feedrate / period / length, fewer than 2 RTOs or more than
/// points) or a path that leaves the uniform body flange.
pub fn trim_case(pillar: &BPillar, p: &TrimCaseParams) -> Result<CutRequest, TestPartError> {
    let spacing = path_spacing(p.feedrate, p.sample_period)?;
    if !(p.length.is_finite() && p.length > spacing) {
        return Err(TestPartError::invalid(
            "case1.length",
            format!("{} must exceed f Δt", p.length),
        ));
    }
    let steps = (p.length / spacing).round();
    if steps > 1e7 {
        return Err(TestPartError::invalid(
            "case1.length",
            format!("{} m gives more than 1e7 CL points", p.length),
        ));
    }
    let count = steps as usize + 1;
    if p.rto_count < 2 || p.rto_count > count {
        return Err(TestPartError::invalid(
            "case1.rto_count",
            format!("{} must be in [2, {count}]", p.rto_count),
        ));
    }
    let path = pillar.flange_trim_path(p.trim_offset, p.start, spacing, count)?;
    let mid = pillar
        .spine
        .eval(p.start + 0.5 * spacing * (count - 1) as f64);
    // R_y(α) turns the tangent (cos α, 0, sin α) onto x̂, the flange normal
    // u onto ẑ; then the roll about x.
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), p.roll)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), mid.alpha);
    let rto = (0..p.rto_count)
        .map(|k| ((k * (count - 1)) as f64 / (p.rto_count - 1) as f64).round() as usize)
        .collect();
    make_request(
        "bpillar-case1-side-trim",
        path,
        rotation,
        p.m_center,
        Process {
            feedrate: p.feedrate,
            sample_period: p.sample_period,
            max_lead_angle: p.max_lead_angle,
            max_tilt_angle: p.max_tilt_angle,
        },
        rto,
    )
}
