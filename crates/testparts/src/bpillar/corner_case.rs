//! Case 2 of seed 001: the cut across the hat section of the foot.

use kerf_mjto::CutRequest;
use nalgebra::{UnitQuaternion, Vector3};

use super::part::BPillar;
use super::request::{make_request, path_spacing, Process};
use crate::TestPartError;

/// Case 2 of seed 001 (section 3.2, Table 1): a cut across the hat section
/// of the foot with two 77° turns of the tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerCaseParams {
    /// Feedrate f (m/s). Table 1: 15 m/min.
    pub feedrate: f64,
    /// Controller sample period Δt (s). Table 1: 4 ms.
    pub sample_period: f64,
    /// Lead angle limit (rad). Table 1: 15°.
    pub max_lead_angle: f64,
    /// Tilt angle limit (rad). Table 1: 10°.
    pub max_tilt_angle: f64,
    /// Number of CL points. Section 3.2: 628 (2.51 s at 4 ms).
    pub points: usize,
    /// Spine arc length of the cut plane (m). Default 0.125, the middle of
    /// the uniform foot (the fork arms, 0.115 m to either side, stay over
    /// the uniform section).
    pub station: f64,
    /// Path length on the flange before its fillet (m). Default 0.1.
    pub flange_run: f64,
    /// Yaw of the workpiece about the machine z axis (rad). Default 30°,
    /// so that the cut runs along no machine axis.
    pub yaw: f64,
    /// Machine-frame centre of the bounding box of the nominal M points
    /// (m). Default (0.8, 0.7, 1.0).
    pub m_center: [f64; 3],
}

impl Default for CornerCaseParams {
    fn default() -> Self {
        Self {
            feedrate: 15.0 / 60.0,
            sample_period: 0.004,
            max_lead_angle: 15f64.to_radians(),
            max_tilt_angle: 10f64.to_radians(),
            points: 628,
            station: 0.125,
            flange_run: 0.1,
            yaw: 30f64.to_radians(),
            m_center: [0.8, 0.7, 1.0],
        }
    }
}

/// Builds the case 2 request ([`CornerCaseParams`]).
///
/// Ten initial RTOs at the key waypoints: start, middle of the flange run,
/// both ends of the flange fillet, middle of the wall, both ends of the
/// top fillet, two points on the top, end. The nominal axes at the two
/// ends of each fillet differ by the wall angle (77°); every other pair of
/// adjacent RTOs has the same nominal axis.
///
/// # Errors
/// [`TestPartError::Invalid`] for parameters out of range or a path
/// that does not end on the top ([`BPillar::section_path`]).
pub fn corner_case(pillar: &BPillar, p: &CornerCaseParams) -> Result<CutRequest, TestPartError> {
    let spacing = path_spacing(p.feedrate, p.sample_period)?;
    let (path, marks) = pillar.section_path(p.station, p.flange_run, spacing, p.points)?;
    let [f1s, f1e, f2s, f2e] = marks;
    let end = spacing * (p.points - 1) as f64;
    // Fillet starts round down and fillet ends round up to a CL point, so
    // the RTOs beside each fillet sit on the flat pieces and their nominal
    // axes differ by exactly the wall angle.
    let down = |l: f64| (l / spacing + 1e-9).floor() as usize;
    let up = |l: f64| (l / spacing - 1e-9).ceil() as usize;
    let near = |l: f64| (l / spacing).round() as usize;
    let rto = vec![
        0,
        near(0.5 * f1s),
        down(f1s),
        up(f1e),
        near(0.5 * (f1e + f2s)),
        down(f2s),
        up(f2e),
        near(f2e + (end - f2e) / 3.0),
        near(f2e + 2.0 * (end - f2e) / 3.0),
        p.points - 1,
    ];
    if rto.windows(2).any(|w| w[1] <= w[0]) {
        return Err(TestPartError::invalid(
            "case2",
            format!("the key waypoints fall on the same CL points: {rto:?}"),
        ));
    }
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), p.yaw);
    make_request(
        "bpillar-case2-corner",
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
