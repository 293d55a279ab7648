//! Placing a workpiece in the machine: where a path's nominal M points lie.

use kerf_mjto::request::CutOptions;
use nalgebra::{Point3, UnitQuaternion, Vector3};

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
