//! Pose-dependent 2-DOF tool-tip dynamics from joint stiffnesses, replacing
//! the Gaussian-process prediction of seed 004 (section 3, "MTGPR") with a
//! physical model.
//!
//! # Model
//!
//! * **Compliance.** With joint stiffnesses `K_q = diag(k_1..k_6)` [N m/rad]
//!   and rigid links, a wrench `w` at the tool tip deflects the joints by
//!   `Δq = K_q⁻¹ Jᵀ w` and the tip by `J Δq`, so the Cartesian compliance is
//!   `C = J K_q⁻¹ Jᵀ` (Salisbury 1980; Dumas, Caro, Garnier & Furet,
//!   *Robotics and Computer-Integrated Manufacturing* 27(4):881, 2011, eq. 3
//!   — the same model, there inverted for identification). J is the
//!   geometric Jacobian at the tool tip ([`Kinematics::jacobian`]).
//! * **Projection.** The cutting forces act at the tip with no moment, so
//!   only the translational block `C_tt = J_v K_q⁻¹ J_vᵀ` matters; in the
//!   cutting plane (x_c, y_c) of the segment, `E = [x_c y_c]` (3×2):
//!   `C₂ = Eᵀ C_tt E`, and the 2-DOF stiffness is `K₂ = C₂⁻¹` (coupled,
//!   symmetric). The out-of-plane (axial) compliance is neglected, as in the
//!   2-DOF model of seed 004 eq. 1.
//! * **Mass.** `M₂ = diag(m_x, m_y)` \[kg\], modal masses from the cell YAML.
//! * **Damping.** A modal damping ratio ζ on each mode of (M₂, K₂): with
//!   mass-normalized eigenvectors Φ (`Φᵀ M₂ Φ = I`, `Φᵀ K₂ Φ = diag(ω_i²)`),
//!   `Φᵀ C Φ = diag(2 ζ ω_i)`, hence `C = M₂ Φ diag(2 ζ ω_i) Φᵀ M₂` (since
//!   `Φ⁻¹ = Φᵀ M₂`; Craig & Kurdila, *Fundamentals of Structural Dynamics*,
//!   §11.4, modal damping).
//!
//! A user with measured FRFs bypasses all this with
//! [`ToolTipDynamics::Measured`]: one mode (f_n, ζ, m) along x_c and one
//! along y_c ([`Modal2::from_modes`]).

use kerf_chatter::{Modal2, Mode};
use nalgebra::{Matrix2, Matrix3, Matrix3x2, Matrix6};
use serde::{Deserialize, Serialize};

use crate::error::{check_positive, MillError};
use crate::path::CuttingFrame;

#[allow(unused_imports)] // for the documentation links
use crate::ik::Kinematics;

/// The joint-stiffness (compliance) model of the module documentation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComplianceModel {
    /// Joint stiffnesses k_1..k_6 [N m/rad].
    pub joint_stiffness: [f64; 6],
    /// Modal masses [m_x, m_y] along x_c and y_c \[kg\].
    pub modal_mass: [f64; 2],
    /// Modal damping ratio ζ of both modes [-], 0 ≤ ζ < 1.
    pub damping_ratio: f64,
}

/// Where the 2-DOF tool-tip dynamics come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolTipDynamics {
    /// The pose-dependent joint-stiffness model.
    Compliance(ComplianceModel),
    /// Measured modal parameters (pose-independent), one mode along x_c and
    /// one along y_c.
    Measured {
        /// Mode along x_c (feed direction reversed).
        x: Mode,
        /// Mode along y_c.
        y: Mode,
    },
}

impl ComplianceModel {
    /// Checks every field.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), MillError> {
        for (i, k) in self.joint_stiffness.iter().enumerate() {
            check_positive(&format!("dynamics.joint_stiffness[{i}] [N m/rad]"), *k)?;
        }
        for (i, m) in self.modal_mass.iter().enumerate() {
            check_positive(&format!("dynamics.modal_mass[{i}] [kg]"), *m)?;
        }
        let z = self.damping_ratio;
        if !(z.is_finite() && (0.0..1.0).contains(&z)) {
            return Err(MillError::InvalidParameter {
                name: "dynamics.damping_ratio [-]".to_string(),
                value: z,
                reason: "must be in [0, 1)".to_string(),
            });
        }
        Ok(())
    }

    /// The Cartesian compliance `C = J K_q⁻¹ Jᵀ` (6×6, linear rows first)
    /// [m/N, rad/(N m) and mixed].
    ///
    /// # Errors
    /// As [`ComplianceModel::validate`]; [`MillError::NonFinite`] for a
    /// non-finite J.
    pub fn cartesian_compliance(&self, j: &Matrix6<f64>) -> Result<Matrix6<f64>, MillError> {
        self.validate()?;
        check_matrix_finite("Jacobian", j.iter())?;
        let kinv = Matrix6::from_diagonal(&nalgebra::Vector6::from(
            self.joint_stiffness.map(|k| 1.0 / k),
        ));
        Ok(j * kinv * j.transpose())
    }

    /// The 2×2 compliance `C₂ = Eᵀ C_tt E` in the cutting plane [m/N].
    ///
    /// # Errors
    /// As [`ComplianceModel::cartesian_compliance`].
    pub fn planar_compliance(
        &self,
        j: &Matrix6<f64>,
        frame: &CuttingFrame,
    ) -> Result<Matrix2<f64>, MillError> {
        let c = self.cartesian_compliance(j)?;
        let ctt: Matrix3<f64> = c.fixed_view::<3, 3>(0, 0).into_owned();
        let e = Matrix3x2::from_columns(&[frame.x, frame.y]);
        let c2 = e.transpose() * ctt * e;
        Ok(0.5 * (c2 + c2.transpose()))
    }

    /// The 2×2 stiffness `K₂ = C₂⁻¹` [N/m].
    ///
    /// # Errors
    /// [`MillError::Singular`] when C₂ is singular (the tip cannot move in
    /// some direction of the cutting plane: infinite stiffness), and the
    /// errors of [`ComplianceModel::planar_compliance`].
    pub fn planar_stiffness(
        &self,
        j: &Matrix6<f64>,
        frame: &CuttingFrame,
    ) -> Result<Matrix2<f64>, MillError> {
        let c2 = self.planar_compliance(j, frame)?;
        let det = c2[(0, 0)] * c2[(1, 1)] - c2[(0, 1)] * c2[(1, 0)];
        let scale = c2.abs().max();
        if !(det.is_finite() && det > 1e-12 * scale * scale) {
            return Err(MillError::Singular {
                what: format!(
                    "planar tool-tip compliance C2 (determinant {det:e}): the tip cannot \
                     move in some direction of the cutting plane"
                ),
            });
        }
        let k = Matrix2::new(c2[(1, 1)], -c2[(0, 1)], -c2[(1, 0)], c2[(0, 0)]) / det;
        Ok(0.5 * (k + k.transpose()))
    }

    /// The 2-DOF dynamics `(M₂, C, K₂)` at a pose (module documentation).
    ///
    /// # Errors
    /// As [`ComplianceModel::planar_stiffness`]; [`MillError::Chatter`] if
    /// the result fails [`Modal2::validate`].
    pub fn modal2(&self, j: &Matrix6<f64>, frame: &CuttingFrame) -> Result<Modal2, MillError> {
        let k2 = self.planar_stiffness(j, frame)?;
        let m2 = Matrix2::new(self.modal_mass[0], 0.0, 0.0, self.modal_mass[1]);
        let c2 = modal_damping(&m2, &k2, self.damping_ratio)?;
        let out = Modal2 {
            mass: m2,
            damping: c2,
            stiffness: k2,
        };
        out.validate()?;
        Ok(out)
    }
}

impl ToolTipDynamics {
    /// The 2-DOF dynamics at a pose: the compliance model with this J and
    /// cutting frame, or the measured modes (J and frame unused).
    ///
    /// # Errors
    /// As [`ComplianceModel::modal2`] or [`Modal2::from_modes`].
    pub fn modal2(&self, j: &Matrix6<f64>, frame: &CuttingFrame) -> Result<Modal2, MillError> {
        match self {
            ToolTipDynamics::Compliance(c) => c.modal2(j, frame),
            ToolTipDynamics::Measured { x, y } => {
                let m = Modal2::from_modes(*x, *y)?;
                m.validate()?;
                Ok(m)
            }
        }
    }

    /// Checks the parameters without a pose.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] or [`MillError::Chatter`].
    pub fn validate(&self) -> Result<(), MillError> {
        match self {
            ToolTipDynamics::Compliance(c) => c.validate(),
            ToolTipDynamics::Measured { x, y } => {
                Modal2::from_modes(*x, *y)?;
                Ok(())
            }
        }
    }
}

/// Eigenvalues (ascending) and orthonormal eigenvectors (columns) of a
/// symmetric 2×2 matrix, in closed form (Jacobi rotation by
/// `θ = ½ atan2(2b, a − d)`).
pub fn symmetric_eigen2(a: &Matrix2<f64>) -> ([f64; 2], Matrix2<f64>) {
    let (p, b, d) = (a[(0, 0)], 0.5 * (a[(0, 1)] + a[(1, 0)]), a[(1, 1)]);
    let theta = 0.5 * (2.0 * b).atan2(p - d);
    let (s, c) = theta.sin_cos();
    let l1 = p * c * c + 2.0 * b * s * c + d * s * s;
    let l2 = p * s * s - 2.0 * b * s * c + d * c * c;
    let v1 = nalgebra::Vector2::new(c, s);
    let v2 = nalgebra::Vector2::new(-s, c);
    if l1 <= l2 {
        ([l1, l2], Matrix2::from_columns(&[v1, v2]))
    } else {
        ([l2, l1], Matrix2::from_columns(&[v2, v1]))
    }
}

/// The modal damping matrix `C = M Φ diag(2 ζ ω_i) Φᵀ M` of (M, K) with one
/// ratio ζ for both modes (module documentation).
///
/// # Errors
/// [`MillError::InvalidParameter`] unless M is diagonal positive and K is
/// symmetric positive definite, ζ ∈ [0, 1).
pub fn modal_damping(
    m: &Matrix2<f64>,
    k: &Matrix2<f64>,
    zeta: f64,
) -> Result<Matrix2<f64>, MillError> {
    let (mx, my) = (m[(0, 0)], m[(1, 1)]);
    check_positive("modal mass m_x [kg]", mx)?;
    check_positive("modal mass m_y [kg]", my)?;
    if m[(0, 1)] != 0.0 || m[(1, 0)] != 0.0 {
        return Err(MillError::InvalidParameter {
            name: "modal mass matrix [kg]".to_string(),
            value: m[(0, 1)],
            reason: "must be diagonal".to_string(),
        });
    }
    if !(zeta.is_finite() && (0.0..1.0).contains(&zeta)) {
        return Err(MillError::InvalidParameter {
            name: "damping ratio [-]".to_string(),
            value: zeta,
            reason: "must be in [0, 1)".to_string(),
        });
    }
    check_matrix_finite("stiffness K2", k.iter())?;
    let mih = Matrix2::new(1.0 / mx.sqrt(), 0.0, 0.0, 1.0 / my.sqrt());
    let a = mih * k * mih;
    let (lam, v) = symmetric_eigen2(&a);
    if lam[0] <= 0.0 {
        return Err(MillError::InvalidParameter {
            name: "stiffness K2 [N/m]".to_string(),
            value: lam[0],
            reason: "must be positive definite (smallest eigenvalue of M^-1/2 K M^-1/2 shown)"
                .to_string(),
        });
    }
    let phi = mih * v;
    let d = Matrix2::new(
        2.0 * zeta * lam[0].sqrt(),
        0.0,
        0.0,
        2.0 * zeta * lam[1].sqrt(),
    );
    let c = m * phi * d * phi.transpose() * m;
    Ok(0.5 * (c + c.transpose()))
}

fn check_matrix_finite<'a>(
    what: &str,
    mut it: impl Iterator<Item = &'a f64>,
) -> Result<(), MillError> {
    if it.all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(MillError::NonFinite {
            what: what.to_string(),
        })
    }
}
