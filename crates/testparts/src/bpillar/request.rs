//! Cut requests on the part: placement of the workpiece, the process
//! parameters, the YAML form and the tool-axis changes between RTOs.

use kerf_mjto::request::{CutOptions, CutRequest, PoseSpec};
use nalgebra::{UnitQuaternion, Vector3};

use super::cl_path::ClPath;
use super::{AXIS_SCALE, MESH_REFERENCE, REGENERATE_COMMAND};
use crate::placement::nominal_m_centre;
use crate::rounding::round_to;
use crate::TestPartError;

/// The CL point spacing `f Δt` of a feedrate and a sample period.
///
/// # Errors
/// [`TestPartError::Invalid`] naming the value that is not finite or not
/// positive.
pub(super) fn path_spacing(feedrate: f64, sample_period: f64) -> Result<f64, TestPartError> {
    for (name, v) in [("feedrate", feedrate), ("sample_period", sample_period)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(TestPartError::invalid(
                name,
                format!("{v} must be finite and > 0"),
            ));
        }
    }
    Ok(feedrate * sample_period)
}

/// The process parameters of Table 1 that go into a request unchanged.
#[derive(Debug, Clone, Copy)]
pub(super) struct Process {
    pub(super) feedrate: f64,
    pub(super) sample_period: f64,
    pub(super) max_lead_angle: f64,
    pub(super) max_tilt_angle: f64,
}

/// Assembles a request: places the workpiece (rotation, then the
/// translation that centres the nominal M points `M = C - q6 O` (seed 001
/// eq. 2, C = M + q6 O), q6 = the default reference standoff, on
/// `m_center`, rounded to 1 mm).
pub(super) fn make_request(
    id: &str,
    path: ClPath,
    rotation: UnitQuaternion<f64>,
    m_center: [f64; 3],
    process: Process,
    rto_indices: Vec<usize>,
) -> Result<CutRequest, TestPartError> {
    if m_center.iter().any(|v| !v.is_finite()) || !rotation.coords.iter().all(|v| v.is_finite()) {
        return Err(TestPartError::invalid("workpiece placement", "not finite"));
    }
    for (name, a) in [
        ("max_lead_angle", process.max_lead_angle),
        ("max_tilt_angle", process.max_tilt_angle),
    ] {
        if !(a.is_finite() && a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
            return Err(TestPartError::invalid(
                name,
                format!("{a} rad must be in (0, π/2)"),
            ));
        }
    }
    let centre = nominal_m_centre(&path.points, &path.axes, &rotation);
    let mm = |v: f64| round_to(v, 1e3);
    let position = [
        mm(m_center[0] - centre.x),
        mm(m_center[1] - centre.y),
        mm(m_center[2] - centre.z),
    ];
    let q = rotation.quaternion();
    let r = |v: f64| round_to(v, AXIS_SCALE);
    let workpiece_pose = PoseSpec {
        position,
        orientation: [r(q.i), r(q.j), r(q.k), r(q.w)],
    };
    Ok(CutRequest {
        request_id: id.to_owned(),
        points: path.points,
        axes: path.axes,
        feedrate: process.feedrate,
        feed_acceleration: 8.0,
        feed_jerk: 80.0,
        sample_period: process.sample_period,
        max_lead_angle: process.max_lead_angle,
        max_tilt_angle: process.max_tilt_angle,
        mesh: MESH_REFERENCE.to_owned(),
        workpiece_pose,
        options: CutOptions {
            rto_indices,
            ..CutOptions::default()
        },
        time_budget: 0.0,
    })
}

/// Angles (rad) between the nominal tool axes of adjacent initial RTOs
/// (`options.rto_indices`) of a request.
///
/// # Errors
/// [`TestPartError::Invalid`] when an RTO index is out of range or an
/// axis is not finite.
pub fn rto_angle_changes(req: &CutRequest) -> Result<Vec<f64>, TestPartError> {
    let axis = |i: usize| -> Result<Vector3<f64>, TestPartError> {
        let a = req.axes.get(i).ok_or_else(|| {
            TestPartError::invalid(
                "options.rto_indices",
                format!("index {i} is beyond the {} axes", req.axes.len()),
            )
        })?;
        let v = Vector3::new(a[0], a[1], a[2]);
        if v.iter().all(|c| c.is_finite()) {
            Ok(v)
        } else {
            Err(TestPartError::invalid(format!("axes[{i}]"), "not finite"))
        }
    };
    req.options
        .rto_indices
        .windows(2)
        .map(|w| {
            let (a, b) = (axis(w[0])?, axis(w[1])?);
            Ok(a.cross(&b).norm().atan2(a.dot(&b)))
        })
        .collect()
}

/// A request as a YAML document with a comment header.
///
/// # Arguments
/// * `req` - the request (serialized with serde_yaml_ng, the schema of
///   [`CutRequest`]).
/// * `title` - first header line (what the request is).
///
/// # Errors
/// [`TestPartError::Invalid`] if serialization fails.
pub fn request_yaml(req: &CutRequest, title: &str) -> Result<String, TestPartError> {
    let body = serde_yaml_ng::to_string(req)
        .map_err(|e| TestPartError::invalid("request", e.to_string()))?;
    Ok(format!(
        "# {title}\n\
         # Workpiece: {MESH_REFERENCE} (kerf_testparts::bpillar, a B-pillar-like hat section).\n\
         # Points and axes in the workpiece frame (m); SI units throughout.\n\
         # Generated by kerf_testparts::bpillar - do not edit. Regenerate from the repository root with\n\
         #   {REGENERATE_COMMAND}\n\
         {body}"
    ))
}
