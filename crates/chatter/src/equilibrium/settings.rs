//! The cutting-force law and the settings of the equilibrium computation.

use crate::error::{check_positive, ChatterError};

/// Cutting-force law `F(h)`: the force of a tooth with chip h is
/// `a_p F(h) b(φ)` with `F(h) = h_ref (h / h_ref)^x_F` for h > 0, 0 else.
///
/// `x_F = 1` is the paper's linear law (seed 004 eq. 1 with the shear
/// coefficients of its Table 1) and `h_ref` then plays no role. `x_F < 1`
/// is the Kienzle-type power law (x_F ≈ 0.75 in Stépán 2001, Phil. Trans.
/// R. Soc. A 359:739, "Modelling nonlinear regenerative effects in metal
/// cutting"); K_t, K_n are then the coefficients at the chip `h_ref`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceLaw {
    /// Exponent x_F, 0 < x_F ≤ 1 (default 1: linear).
    pub exponent: f64,
    /// Reference chip h_ref [m] at which K_t, K_n hold (default 1e-4 m).
    pub reference_chip: f64,
}

impl Default for ForceLaw {
    fn default() -> Self {
        Self {
            exponent: 1.0,
            reference_chip: 1e-4,
        }
    }
}

impl ForceLaw {
    /// Checks 0 < x_F ≤ 1 and h_ref > 0.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), ChatterError> {
        let x = check_positive("force exponent x_F [-]", self.exponent)?;
        if x > 1.0 {
            return Err(ChatterError::InvalidParameter {
                name: "force exponent x_F [-]".to_string(),
                value: x,
                reason: "must be in (0, 1]".to_string(),
            });
        }
        check_positive("reference chip thickness [m]", self.reference_chip)?;
        Ok(())
    }

    /// `F(h)` [m] (force per unit a_p and per unit coefficient).
    pub fn value(&self, h: f64) -> f64 {
        if h <= 0.0 {
            0.0
        } else if self.exponent == 1.0 {
            h
        } else {
            self.reference_chip * (h / self.reference_chip).powf(self.exponent)
        }
    }

    /// `F'(h) = x_F (h / h_ref)^(x_F − 1)` [-], the factor on the cutting
    /// stiffness of the linearized model; 1 for the linear law.
    pub fn slope(&self, h: f64) -> f64 {
        if self.exponent == 1.0 {
            1.0
        } else {
            self.exponent
                * (h.max(f64::MIN_POSITIVE) / self.reference_chip).powf(self.exponent - 1.0)
        }
    }
}

/// Numerical settings of [`Equilibrium::compute`](super::Equilibrium::compute).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumSettings {
    /// Grid nodes per tooth period (≥ 200; default 200).
    pub points_per_period: usize,
    /// Highest regeneration order m searched for the chip (1..=8; default 3).
    pub max_regeneration: usize,
    /// Relative change of the node positions that ends the fixed-point
    /// iteration (default 1e-10).
    pub tolerance: f64,
    /// Iteration cap of the fixed-point iteration (default 50).
    pub max_iterations: usize,
    /// Cutting-force law (default linear).
    pub force_law: ForceLaw,
}

impl Default for EquilibriumSettings {
    fn default() -> Self {
        Self {
            points_per_period: 200,
            max_regeneration: 3,
            tolerance: 1e-10,
            max_iterations: 50,
            force_law: ForceLaw::default(),
        }
    }
}

impl EquilibriumSettings {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), ChatterError> {
        let bad = ChatterError::invalid;
        if self.points_per_period < 200 {
            return Err(bad(
                "equilibrium grid points per period",
                self.points_per_period as f64,
                "must be >= 200",
            ));
        }
        if self.points_per_period > 1_000_000 {
            return Err(bad(
                "equilibrium grid points per period",
                self.points_per_period as f64,
                "must be <= 1e6",
            ));
        }
        if !(1..=8).contains(&self.max_regeneration) {
            return Err(bad(
                "maximum regeneration order",
                self.max_regeneration as f64,
                "must be in 1..=8",
            ));
        }
        check_positive("equilibrium tolerance [-]", self.tolerance)?;
        if self.max_iterations == 0 {
            return Err(bad("equilibrium iteration cap", 0.0, "must be >= 1"));
        }
        self.force_law.validate()
    }
}
