//! The structure of the tool and one RK4 step of its equation of motion.

use nalgebra::{Matrix2, Matrix4, Vector2};

use crate::error::{check_positive, ChatterError};
use crate::model::Modal2;

/// `M⁻¹`, `M⁻¹ C`, `M⁻¹ K` and the first-order matrix `A` of
/// `ż = A z + (0, M⁻¹ F)`, `z = (o, ȯ)`.
pub(super) struct Structure {
    pub(super) minv: Matrix2<f64>,
    pub(super) minv_c: Matrix2<f64>,
    pub(super) minv_k: Matrix2<f64>,
    pub(super) a: Matrix4<f64>,
    pub(super) velocity_scale: f64,
}

impl Structure {
    pub(super) fn new(modal: &Modal2) -> Result<Self, ChatterError> {
        let minv = modal.mass_inverse()?;
        let minv_c = minv * modal.damping;
        let minv_k = minv * modal.stiffness;
        let mut a = Matrix4::zeros();
        a.fixed_view_mut::<2, 2>(0, 2)
            .copy_from(&Matrix2::identity());
        a.fixed_view_mut::<2, 2>(2, 0).copy_from(&(-minv_k));
        a.fixed_view_mut::<2, 2>(2, 2).copy_from(&(-minv_c));
        let velocity_scale = check_positive(
            "reference frequency sqrt(tr K / tr M) [rad/s]",
            (modal.stiffness.trace() / modal.mass.trace()).sqrt(),
        )?;
        Ok(Self {
            minv,
            minv_c,
            minv_k,
            a,
            velocity_scale,
        })
    }

    /// Acceleration `M⁻¹ (F − C ȯ − K o)`.
    pub(super) fn accel(&self, o: Vector2<f64>, v: Vector2<f64>, f: Vector2<f64>) -> Vector2<f64> {
        self.minv * f - self.minv_c * v - self.minv_k * o
    }
}

/// One classic RK4 step of `ö = M⁻¹ (F(t, o) − C ȯ − K o)`; `f0` is the
/// force at the start of the step, `force` gives it at the later stages.
pub(super) fn rk4_step<F>(
    s: &Structure,
    t: f64,
    h: f64,
    o: Vector2<f64>,
    v: Vector2<f64>,
    f0: Vector2<f64>,
    mut force: F,
) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError>
where
    F: FnMut(f64, Vector2<f64>) -> Result<Vector2<f64>, ChatterError>,
{
    let k1o = v;
    let k1v = s.accel(o, v, f0);
    let o2 = o + 0.5 * h * k1o;
    let v2 = v + 0.5 * h * k1v;
    let k2o = v2;
    let k2v = s.accel(o2, v2, force(t + 0.5 * h, o2)?);
    let o3 = o + 0.5 * h * k2o;
    let v3 = v + 0.5 * h * k2v;
    let k3o = v3;
    let k3v = s.accel(o3, v3, force(t + 0.5 * h, o3)?);
    let o4 = o + h * k3o;
    let v4 = v + h * k3v;
    let k4o = v4;
    let k4v = s.accel(o4, v4, force(t + h, o4)?);
    Ok((
        o + h / 6.0 * (k1o + 2.0 * k2o + 2.0 * k3o + k4o),
        v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
    ))
}
