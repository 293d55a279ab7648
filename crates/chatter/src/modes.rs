//! Closed forms of the 2-DOF tool-tip dynamics ([`Modal2`]) for reports: the eigenvalues
//! of the stiffness matrix and the undamped natural frequencies.

use crate::model::Modal2;

/// Eigenvalues (ascending) of the symmetric 2×2 matrix `[[a, b], [b, d]]`, closed form:
/// `(a + d)/2 ∓ sqrt(((a − d)/2)² + b²)`.
///
/// # Arguments
/// * `a`, `b`, `d` – the diagonal and off-diagonal entries.
///
/// # Returns
/// `[smaller, larger]`.
pub fn symmetric_eigenvalues(a: f64, b: f64, d: f64) -> [f64; 2] {
    let mean = 0.5 * (a + d);
    let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    [mean - r, mean + r]
}

/// Undamped natural frequencies \[Hz\] (ascending) of `M p̈ + K p = 0`: the roots λ = ω² of
/// `det(K − λ M) = 0`, a quadratic `A λ² + B λ + C` with `A = det M`,
/// `B = −(k00 m11 + k11 m00 − 2 k01 m01)`, `C = det K` (M, K symmetric).
///
/// # Arguments
/// * `modal` – the mass and stiffness matrices (damping is ignored).
///
/// # Returns
/// `[f1, f2]` \[Hz\], or `None` when the quadratic has no two positive finite roots.
pub fn natural_frequencies(modal: &Modal2) -> Option<[f64; 2]> {
    let (m, k) = (&modal.mass, &modal.stiffness);
    let a = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
    let b = -(k[(0, 0)] * m[(1, 1)] + k[(1, 1)] * m[(0, 0)] - 2.0 * k[(0, 1)] * m[(0, 1)]);
    let c = k[(0, 0)] * k[(1, 1)] - k[(0, 1)] * k[(1, 0)];
    let disc = b * b - 4.0 * a * c;
    if !(a > 0.0 && disc >= 0.0) {
        return None;
    }
    let l1 = (-b - disc.sqrt()) / (2.0 * a);
    let l2 = (-b + disc.sqrt()) / (2.0 * a);
    if !(l1 > 0.0 && l2.is_finite()) {
        return None;
    }
    let hz = |l: f64| l.sqrt() / (2.0 * std::f64::consts::PI);
    Some([hz(l1), hz(l2)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Mode;

    #[test]
    fn closed_forms_match_uncoupled_modes() {
        let x = Mode {
            natural_frequency_hz: 15.0,
            damping_ratio: 0.05,
            modal_mass: 60.0,
        };
        let y = Mode {
            natural_frequency_hz: 28.0,
            ..x
        };
        let modal = Modal2::from_modes(y, x).expect("modes");
        let f = natural_frequencies(&modal).expect("frequencies");
        assert!(
            (f[0] - 15.0).abs() < 1e-9 && (f[1] - 28.0).abs() < 1e-9,
            "{f:?}"
        );
        // [[2, 1], [1, 2]] has eigenvalues 1 and 3.
        assert_eq!(symmetric_eigenvalues(2.0, 1.0, 2.0), [1.0, 3.0]);
    }

    #[test]
    fn a_singular_mass_has_no_frequencies() {
        let mut modal = Modal2::from_modes(
            Mode {
                natural_frequency_hz: 15.0,
                damping_ratio: 0.05,
                modal_mass: 60.0,
            },
            Mode {
                natural_frequency_hz: 20.0,
                damping_ratio: 0.05,
                modal_mass: 60.0,
            },
        )
        .expect("modes");
        modal.mass[(1, 1)] = 0.0;
        assert_eq!(natural_frequencies(&modal), None);
    }
}
