//! Placing a workpiece in the machine: where a path's nominal M points lie.

use kerf_mjto::request::{CutOptions, PoseSpec};
use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::rounding::{round_to, AXIS_SCALE};

/// The centre of the bounding box of the nominal M points `M = C − q6 O` (seed 001 eq. 2, q6
/// the default reference standoff) of the CL points `points` with tool axes `axes`, the
/// workpiece turned by `rotation`. Not finite for an empty path.
pub(crate) fn nominal_m_centre(
    points: &[[f64; 3]],
    axes: &[[f64; 3]],
    rotation: &UnitQuaternion<f64>,
) -> Vector3<f64> {
    let q6 = CutOptions::default().reference_standoff;
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for (c, o) in points.iter().zip(axes) {
        let c = rotation * Point3::new(c[0], c[1], c[2]);
        let o = rotation * Vector3::new(o[0], o[1], o[2]);
        let m = c.coords - o * q6;
        lo = lo.inf(&m);
        hi = hi.sup(&m);
    }
    (lo + hi) * 0.5
}

/// The workpiece pose of a generated request: turned by `rotation`, then translated so that
/// the nominal M points' bounding-box centre ([`nominal_m_centre`]) lies on `m_center`, the
/// position rounded to 1 mm and the quaternion to [`AXIS_SCALE`]. The position is not finite
/// for an empty path.
pub(crate) fn workpiece_pose(
    points: &[[f64; 3]],
    axes: &[[f64; 3]],
    rotation: &UnitQuaternion<f64>,
    m_center: [f64; 3],
) -> PoseSpec {
    let centre = nominal_m_centre(points, axes, rotation);
    let mm = |v: f64| round_to(v, 1e3);
    let q = rotation.quaternion();
    let r = |v: f64| round_to(v, AXIS_SCALE);
    PoseSpec {
        position: [
            mm(m_center[0] - centre.x),
            mm(m_center[1] - centre.y),
            mm(m_center[2] - centre.z),
        ],
        orientation: [r(q.i), r(q.j), r(q.k), r(q.w)],
    }
}
