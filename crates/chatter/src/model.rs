//! The shared vocabulary of the chatter models: the 2-DOF tool-tip dynamics,
//! the milling process, and the linear periodic delay-differential equation
//! whose monodromy matrix decides stability.
//!
//! # Frame and angle conventions (seed 004, Fig. 2 and eq. 2)
//!
//! The cutting plane carries the frame (x, y); the tool feeds along −x.
//! Tooth j sits at immersion angle φ_j(t) = Ω t + 2π j / N_t (Ω in rad/s),
//! its tip at `c(t) + R u(φ)` with `u(φ) = −(sin φ, cos φ)` (seed 004
//! eq. 2 writes the tip as `x − R sin φ, y − R cos φ`). The nominal chip is
//! `h = f_z sin φ` (f_z = feed per tooth), so a tooth can cut for
//! φ ∈ (0, π); down milling leaves the finished wall at φ = π (+y side),
//! up milling enters at φ = 0 (−y side).
//!
//! The cutting force on the tool of a tooth with chip h is
//! `F = a_p h (K_t (cos φ, −sin φ) + K_n (sin φ, cos φ))`: tangential
//! force against the tooth velocity direction `v = du/dφ`, normal force
//! towards the tool centre. Its dynamic part for a small vibration `p`
//! about the nominal cut is `−a_p H(t) (p(t) − p(t − τ))` with
//! `H = Σ_j g_j b(φ_j) c(φ_j)ᵀ`, [`force_direction`] `b` and
//! [`chip_direction`] `c`; these are the directional coefficients of
//! Insperger & Stépán (2004, Int. J. Numer. Meth. Eng. 61:117, eq. 44) —
//! the sign conventions of both papers give the same `H`.

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use crate::error::{check_non_negative, check_positive, ChatterError};

/// Most teeth a cutter may have: the model sums the cutting forces over every tooth at every
/// time step, so the count bounds the work (issue 11, item 2). Milling cutters have at most a
/// few dozen.
pub const MAX_TEETH: usize = 100;

/// One vibration mode along one direction of the cutting plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mode {
    /// Undamped natural frequency f_n [Hz].
    pub natural_frequency_hz: f64,
    /// Damping ratio ζ [-], 0 ≤ ζ < 1.
    pub damping_ratio: f64,
    /// Modal mass m [kg].
    pub modal_mass: f64,
}

/// 2-DOF tool-tip dynamics `M p̈ + C ṗ + K p = F` in the (x, y) frame of
/// the module documentation (seed 004 eq. 1, left-hand side). SI units:
/// kg, N s/m, N/m. The matrices may be coupled (off-diagonal terms), as the
/// pose-dependent stiffness of a robot is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Modal2 {
    /// Mass matrix M [kg], symmetric positive definite.
    pub mass: Matrix2<f64>,
    /// Damping matrix C [N s/m], symmetric positive semidefinite.
    pub damping: Matrix2<f64>,
    /// Stiffness matrix K [N/m], symmetric positive definite.
    pub stiffness: Matrix2<f64>,
}

impl Modal2 {
    /// Two uncoupled modes, one along x and one along y:
    /// `m ẍ + 2 ζ m ω_n ẋ + m ω_n² x = F_x` (and likewise for y).
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] for a non-finite or non-positive
    /// frequency or mass, or a damping ratio outside [0, 1).
    pub fn from_modes(x: Mode, y: Mode) -> Result<Self, ChatterError> {
        let mut mass = Matrix2::zeros();
        let mut damping = Matrix2::zeros();
        let mut stiffness = Matrix2::zeros();
        for (i, (axis, mode)) in [("x", x), ("y", y)].into_iter().enumerate() {
            let fnat = check_positive(
                &format!("{axis} natural frequency [Hz]"),
                mode.natural_frequency_hz,
            )?;
            let m = check_positive(&format!("{axis} modal mass [kg]"), mode.modal_mass)?;
            let zeta =
                check_non_negative(&format!("{axis} damping ratio [-]"), mode.damping_ratio)?;
            if zeta >= 1.0 {
                return Err(ChatterError::InvalidParameter {
                    name: format!("{axis} damping ratio [-]"),
                    value: zeta,
                    reason: "must be < 1 (an underdamped mode)".to_string(),
                });
            }
            let wn = 2.0 * std::f64::consts::PI * fnat;
            mass[(i, i)] = m;
            damping[(i, i)] = 2.0 * zeta * m * wn;
            stiffness[(i, i)] = m * wn * wn;
        }
        Ok(Self {
            mass,
            damping,
            stiffness,
        })
    }

    /// The inverse mass matrix M⁻¹ [1/kg].
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] when M is singular (its
    /// determinant is reported).
    pub fn mass_inverse(&self) -> Result<Matrix2<f64>, ChatterError> {
        self.mass
            .try_inverse()
            .ok_or_else(|| ChatterError::InvalidParameter {
                name: "mass matrix [kg]".to_string(),
                value: self.mass.determinant(),
                reason: "is singular".to_string(),
            })
    }

    /// Checks that every entry is finite, M and K are symmetric positive
    /// definite and C is symmetric positive semidefinite (relative symmetry
    /// tolerance 1e-9).
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] naming the matrix at fault.
    pub fn validate(&self) -> Result<(), ChatterError> {
        for (name, m, definite) in [
            ("mass matrix [kg]", &self.mass, true),
            ("damping matrix [N s/m]", &self.damping, false),
            ("stiffness matrix [N/m]", &self.stiffness, true),
        ] {
            let bad = |value: f64, reason: &str| ChatterError::InvalidParameter {
                name: name.to_string(),
                value,
                reason: reason.to_string(),
            };
            if let Some(v) = m.iter().find(|v| !v.is_finite()) {
                return Err(bad(*v, "has a non-finite entry"));
            }
            let scale = m.abs().max().max(f64::MIN_POSITIVE);
            let asym = (m[(0, 1)] - m[(1, 0)]).abs();
            if asym > 1e-9 * scale {
                return Err(bad(asym, "is not symmetric (|m01 - m10| shown)"));
            }
            let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
            let ok = if definite {
                m[(0, 0)] > 0.0 && det > 0.0
            } else {
                m[(0, 0)] >= 0.0 && m[(1, 1)] >= 0.0 && det >= -1e-12 * scale * scale
            };
            if !ok {
                let reason = if definite {
                    "is not positive definite (determinant shown)"
                } else {
                    "is not positive semidefinite (determinant shown)"
                };
                return Err(bad(det, reason));
            }
        }
        Ok(())
    }
}

/// The milling operation: cutter, cutting-force law and engagement
/// (seed 004 Table 1 holds the defaults of the paper's cell).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MillingProcess {
    /// Number of teeth N_t (equally spaced).
    pub teeth: usize,
    /// Nominal tool radius R [m].
    pub radius: f64,
    /// Axial depth of cut a_p [m].
    pub axial_depth: f64,
    /// Tangential cutting-force coefficient K_t [N/m²].
    pub kt: f64,
    /// Normal (radial) cutting-force coefficient K_n [N/m²].
    pub kn: f64,
    /// Entry immersion angle φ_en [rad], 0 ≤ φ_en < φ_ex ≤ π.
    pub entry_angle: f64,
    /// Exit immersion angle φ_ex [rad].
    pub exit_angle: f64,
}

impl MillingProcess {
    /// Engagement of a down-milling cut of radial immersion `a_e / D`:
    /// φ_en = arccos(2 a_e/D − 1), φ_ex = π (Insperger & Stépán 2004).
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] unless 0 < ratio ≤ 1.
    pub fn down_milling_angles(radial_immersion: f64) -> Result<(f64, f64), ChatterError> {
        Self::check_immersion(radial_immersion)?;
        Ok(((2.0 * radial_immersion - 1.0).acos(), std::f64::consts::PI))
    }

    /// Engagement of an up-milling cut of radial immersion `a_e / D`:
    /// φ_en = 0, φ_ex = arccos(1 − 2 a_e/D).
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] unless 0 < ratio ≤ 1.
    pub fn up_milling_angles(radial_immersion: f64) -> Result<(f64, f64), ChatterError> {
        Self::check_immersion(radial_immersion)?;
        Ok((0.0, (1.0 - 2.0 * radial_immersion).acos()))
    }

    fn check_immersion(r: f64) -> Result<(), ChatterError> {
        if r.is_finite() && r > 0.0 && r <= 1.0 {
            Ok(())
        } else {
            Err(ChatterError::InvalidParameter {
                name: "radial immersion a_e/D [-]".to_string(),
                value: r,
                reason: "must be in (0, 1]".to_string(),
            })
        }
    }

    /// Checks every field (finite, positive where it must be, at most
    /// [`MAX_TEETH`] teeth, engagement inside [0, π] and non-empty).
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), ChatterError> {
        if self.teeth == 0 || self.teeth > MAX_TEETH {
            return Err(ChatterError::InvalidParameter {
                name: "number of teeth".to_string(),
                value: self.teeth as f64,
                reason: format!("must be in 1..={MAX_TEETH}"),
            });
        }
        check_positive("tool radius [m]", self.radius)?;
        check_positive("axial depth of cut [m]", self.axial_depth)?;
        check_non_negative("tangential cutting coefficient Kt [N/m^2]", self.kt)?;
        check_non_negative("normal cutting coefficient Kn [N/m^2]", self.kn)?;
        let pi = std::f64::consts::PI;
        for (name, v) in [
            ("entry angle [rad]", self.entry_angle),
            ("exit angle [rad]", self.exit_angle),
        ] {
            if !(v.is_finite() && (0.0..=pi).contains(&v)) {
                return Err(ChatterError::InvalidParameter {
                    name: name.to_string(),
                    value: v,
                    reason: "must be in [0, pi]".to_string(),
                });
            }
        }
        if self.exit_angle <= self.entry_angle {
            return Err(ChatterError::InvalidParameter {
                name: "exit angle [rad]".to_string(),
                value: self.exit_angle,
                reason: format!("must be > the entry angle {}", self.entry_angle),
            });
        }
        Ok(())
    }

    /// Tooth-passing period T = 60 / (n N_t) [s] for a spindle speed `rpm`.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] for a non-finite or non-positive speed.
    pub fn tooth_period(&self, rpm: f64) -> Result<f64, ChatterError> {
        let n = check_positive("spindle speed [rpm]", rpm)?;
        Ok(60.0 / (n * self.teeth as f64))
    }
}

/// Chip direction `c(φ) = (sin φ, cos φ)`: a tooth at angle φ cuts
/// `h = f_z sin φ − c(φ)·(p(t) − p(t − τ))` (module documentation).
pub fn chip_direction(phi: f64) -> Vector2<f64> {
    Vector2::new(phi.sin(), phi.cos())
}

/// Cutting-force direction per unit chip area,
/// `b(φ) = K_t (cos φ, −sin φ) + K_n (sin φ, cos φ)` [N/m²]: the force on
/// the tool is `a_p h b(φ)` (module documentation).
pub fn force_direction(phi: f64, kt: f64, kn: f64) -> Vector2<f64> {
    let (s, c) = phi.sin_cos();
    Vector2::new(kt * c + kn * s, -kt * s + kn * c)
}

/// One delayed term `B p(t − τ)` of a [`DdeSample`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayTerm {
    /// Gain B [N/m] (already multiplied by the axial depth).
    pub gain: Matrix2<f64>,
    /// Delay τ [s], 0 < τ ≤ the maximum delay of the equation.
    pub delay: f64,
}

/// The right-hand side of the linear periodic DDE on one sub-interval
/// `[i T/m, (i+1) T/m)` of the period:
/// `F = −present · p(t) + Σ_k delayed[k].gain · p(t − delayed[k].delay)`.
///
/// Gains are averages over the sub-interval (the usual semi-discretization
/// choice, which keeps interrupted cutting accurate), delays are the value
/// at the sub-interval's midpoint.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DdeSample {
    /// Gain on the present displacement [N/m].
    pub present: Matrix2<f64>,
    /// Delayed terms (one per engaged tooth and regeneration order).
    pub delayed: Vec<DelayTerm>,
}

/// A linear T-periodic delay-differential equation
/// `M p̈ + C ṗ + K p = −A(t) p(t) + Σ_k B_k(t) p(t − τ_k(t))`,
/// sampled on m equal sub-intervals of one period (seed 004 eq. 8; with
/// `A = B = a_p H(t)` and τ = T it is the constant-delay milling model).
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicDde {
    /// Principal period T [s] (the tooth-passing period).
    pub period: f64,
    /// One sample per sub-interval, `samples.len()` = m.
    pub samples: Vec<DdeSample>,
}

impl PeriodicDde {
    /// Number of sub-intervals m.
    pub fn steps(&self) -> usize {
        self.samples.len()
    }

    /// Largest delay of the equation [s] (0 without delayed terms).
    pub fn max_delay(&self) -> f64 {
        self.samples
            .iter()
            .flat_map(|s| s.delayed.iter().map(|d| d.delay))
            .fold(0.0, f64::max)
    }

    /// Checks period, sizes, finiteness of every gain and delay, and
    /// positivity of every delay.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] or [`ChatterError::NonFinite`].
    pub fn validate(&self) -> Result<(), ChatterError> {
        check_positive("period [s]", self.period)?;
        if self.samples.is_empty() {
            return Err(ChatterError::InvalidParameter {
                name: "number of sub-intervals m".to_string(),
                value: 0.0,
                reason: "must be >= 1".to_string(),
            });
        }
        for (i, s) in self.samples.iter().enumerate() {
            if s.present.iter().any(|v| !v.is_finite()) {
                return Err(ChatterError::NonFinite {
                    what: format!("present gain of sub-interval {i}"),
                });
            }
            for d in &s.delayed {
                if d.gain.iter().any(|v| !v.is_finite()) {
                    return Err(ChatterError::NonFinite {
                        what: format!("delayed gain of sub-interval {i}"),
                    });
                }
                check_positive(&format!("delay of sub-interval {i} [s]"), d.delay)?;
            }
        }
        Ok(())
    }
}
