//! The speed a path allows at a curvature (seed 003, "Feedrate planning
//! based on multiple constraints", eqs. 15–22): the chord error of the
//! interpolation period, the contour error of a second-order servo, and the
//! normal acceleration and jerk, together with the programmed feed.

use crate::error::{check_positive, ToolpathError};
use crate::maximum::golden_argmax;

/// A second-order position loop G(s) = ω_n² / (s² + 2ζω_n s + ω_n²) (seed
/// 003 eq. 17's model: ω_n = √(K_p/J), ζ = B / (2√(J K_p))).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Servo {
    /// Undamped natural frequency ω_n \[rad/s\].
    pub natural_frequency: f64,
    /// Damping ratio ζ (≥ 1/√2: no resonance peak, |G(jω)| ≤ 1).
    pub damping: f64,
    /// Largest contour error ε_lim \[m\].
    pub contour_error: f64,
}

/// The limits of seed 003's eq. 22 (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureLimits {
    /// Programmed (largest) feed v_p \[m/s\].
    pub feed: f64,
    /// Interpolation period T \[s\].
    pub interpolation_period: f64,
    /// Largest chord error Δ_lim \[m\].
    pub chord_error: f64,
    /// Largest normal acceleration a_n,lim \[m/s²\].
    pub normal_acceleration: f64,
    /// Largest normal jerk j_n,lim \[m/s³\].
    pub normal_jerk: f64,
    /// The servo and its contour-error limit (`None`: not limited).
    pub servo: Option<Servo>,
}

impl CurvatureLimits {
    /// Seed 003's Table 1 in SI units: T = 2 ms, v_p = 70 mm/s, ω_n = 60
    /// rad/s, ζ = 0.76, Δ_lim = 1 µm, a_n = 990 mm/s², j_n = 29 000 mm/s³,
    /// ε_lim = 0.05 mm.
    pub fn seed_003_table_1() -> Self {
        Self {
            feed: 0.070,
            interpolation_period: 0.002,
            chord_error: 1e-6,
            normal_acceleration: 0.990,
            normal_jerk: 29.0,
            servo: Some(Servo {
                natural_frequency: 60.0,
                damping: 0.76,
                contour_error: 5e-5,
            }),
        }
    }

    /// Checks every limit.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming a limit that is not
    /// finite and > 0, or a damping ratio below 1/√2.
    pub fn validate(&self) -> Result<(), ToolpathError> {
        let mut checks = vec![
            ("feed [m/s]", self.feed),
            ("interpolation period [s]", self.interpolation_period),
            ("chord error [m]", self.chord_error),
            ("normal acceleration [m/s^2]", self.normal_acceleration),
            ("normal jerk [m/s^3]", self.normal_jerk),
        ];
        if let Some(s) = &self.servo {
            checks.push(("servo natural frequency [rad/s]", s.natural_frequency));
            checks.push(("servo damping ratio [-]", s.damping));
            checks.push(("contour error [m]", s.contour_error));
        }
        check_positive(&checks)?;
        if let Some(s) = &self.servo {
            if s.damping < std::f64::consts::FRAC_1_SQRT_2 {
                return Err(ToolpathError::InvalidParameter {
                    name: "servo damping ratio [-]".to_string(),
                    value: s.damping,
                    reason: "must be >= 1/sqrt(2): below it the loop overshoots outward and \
                             eq. 17 does not bound the contour error"
                        .to_string(),
                });
            }
        }
        Ok(())
    }

    /// The largest speed at curvature κ \[1/m\] (seed 003 eq. 22: the least of
    /// the programmed feed and eqs. 16, 17, 19, 21), in m/s.
    pub fn speed(&self, curvature: f64) -> f64 {
        if curvature <= 0.0 {
            return self.feed;
        }
        let rho = 1.0 / curvature;
        [
            self.feed,
            self.chord_speed(rho),
            (rho * self.normal_acceleration).sqrt(),
            (rho * rho * self.normal_jerk).cbrt(),
            self.contour_speed(rho),
        ]
        .into_iter()
        .fold(f64::INFINITY, f64::min)
    }

    /// The radius at which eq. 17's speed is least \[m\] (`None` without a
    /// servo).
    ///
    /// Eq. 17 is not monotone in ρ: with r = ρ/ε, v_c² = ε² ω_n² r² y(r),
    /// y = −a + √(a² + x), x = (2r − 1)/(r − 1)², a = 2ζ² − 1. For large r,
    /// v_c ≈ ω_n √(ερ/a) grows with ρ; as r → 1⁺, x → ∞ and v_c → ∞ (a
    /// circle barely larger than ε cannot shrink by ε). Between them v_c has
    /// one minimum, at r* depending on ζ alone, found here by golden section
    /// on ln(r − 1) ∈ [−20, 20]. On curvatures above 1/ρ* (radii of a few ε)
    /// the contour law rises with κ, so the least speed over a range of
    /// curvature is not at its largest ([`Self::contour_speed_over`]).
    pub fn contour_critical_radius(&self) -> Option<f64> {
        let servo = self.servo.as_ref()?;
        let e = servo.contour_error;
        let t = golden_argmax(-20.0, 20.0, 120, |t| {
            -self.contour_speed(e * (1.0 + t.exp()))
        });
        Some(e * (1.0 + t.exp()))
    }

    /// The least speed of eq. 17 over the curvatures [`kappa_lo`,
    /// `kappa_hi`] \[m/s\]: at the critical radius
    /// ([`Self::contour_critical_radius`], passed as `critical`) where it
    /// lies in the range, else at the end nearer to it (eq. 17 falls with κ
    /// below 1/ρ* and rises above). Infinite without a servo or for
    /// `kappa_hi` ≤ 0.
    pub fn contour_speed_over(&self, kappa_lo: f64, kappa_hi: f64, critical: Option<f64>) -> f64 {
        let Some(rho_star) = critical else {
            return f64::INFINITY;
        };
        if kappa_hi <= 0.0 {
            return f64::INFINITY;
        }
        let k_star = 1.0 / rho_star;
        if kappa_hi <= k_star {
            self.contour_speed(1.0 / kappa_hi)
        } else if kappa_lo >= k_star {
            self.contour_speed(1.0 / kappa_lo.max(f64::MIN_POSITIVE))
        } else {
            self.contour_speed(rho_star)
        }
    }

    /// Eq. 16: v_Δ = 2 √(2ρΔ − Δ²) / T. Where Δ_lim ≥ ρ no chord can sag
    /// more than Δ_lim (a chord spans at most the diameter), and the speed
    /// is that of a chord of one diameter, 2ρ / T (eq. 16 at Δ = ρ).
    pub fn chord_speed(&self, rho: f64) -> f64 {
        let d = self.chord_error.min(rho);
        2.0 * (2.0 * rho * d - d * d).max(0.0).sqrt() / self.interpolation_period
    }

    /// Eq. 17: the speed at which the servo's steady-state radius on a
    /// circle of radius ρ, ρ |G(j v/ρ)|, is ρ − ε_lim:
    /// v_c = ρ ω_n √(1 − 2ζ² + √((2ζ² − 1)² − (ε² − 2ερ)/(ρ − ε)²)).
    /// Unlimited (infinite) without a servo or where ε_lim ≥ ρ.
    pub fn contour_speed(&self, rho: f64) -> f64 {
        let Some(s) = &self.servo else {
            return f64::INFINITY;
        };
        let e = s.contour_error;
        if e >= rho {
            return f64::INFINITY;
        }
        // With a = 2ζ² − 1 ≥ 0 (validated) and x = (2ερ − ε²)/(ρ − ε)² ≥ 0, the bracket
        // 1 − 2ζ² + √(a² + x) = −a + √(a² + x) is computed as x / (√(a² + x) + a): the
        // difference of two nearly equal numbers cancels to 0 for x ≪ a² (a numerically
        // straight joint, κ ~ 1e-14 1/m), which made the speed 0 there.
        let a = 2.0 * s.damping * s.damping - 1.0;
        let x = (2.0 * e * rho - e * e) / ((rho - e) * (rho - e));
        let root = (a * a + x).sqrt();
        let bracket = if root + a > 0.0 { x / (root + a) } else { 0.0 };
        rho * s.natural_frequency * bracket.max(0.0).sqrt()
    }
}
