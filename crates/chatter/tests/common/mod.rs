//! Fixtures shared by the kerf_chatter integration tests: the two systems
//! every test file uses (the textbook example of Insperger & Stépán and the
//! cut of seed 004 Table 1) and symmetric robot-like tool tips.

#![allow(dead_code)] // each test file uses a subset

use std::f64::consts::PI;

use kerf_chatter::{MillingProcess, Modal2, Mode};

/// The same mode in x and y: f_n [Hz], ζ [-], modal mass [kg].
pub fn symmetric_modal(natural_frequency_hz: f64, damping_ratio: f64, modal_mass: f64) -> Modal2 {
    let mode = Mode {
        natural_frequency_hz,
        damping_ratio,
        modal_mass,
    };
    Modal2::from_modes(mode, mode).expect("valid fixture modes")
}

/// The 2-DOF textbook system of Insperger & Stépán (2004, Int. J. Numer.
/// Meth. Eng. 61:117, section 5): f_n = 922 Hz, ζ = 0.011, m = 0.03993 kg
/// in x and y.
pub fn textbook_modal() -> Modal2 {
    symmetric_modal(922.0, 0.011, 0.03993)
}

/// Its cut: 2 teeth, K_t = 6e8, K_n = 2e8 N/m², down milling at the given
/// radial immersion a/D (0.05 in the textbook); the radius only matters to
/// the state-dependent model and the simulation.
pub fn textbook_process(radial_immersion: f64, radius: f64, axial_depth: f64) -> MillingProcess {
    let (entry_angle, exit_angle) =
        MillingProcess::down_milling_angles(radial_immersion).expect("valid immersion");
    MillingProcess {
        teeth: 2,
        radius,
        axial_depth,
        kt: 6e8,
        kn: 2e8,
        entry_angle,
        exit_angle,
    }
}

/// The cut of seed 004 Table 1: 2 teeth, R = 0.04 m, K_t = 6.44e8,
/// K_n = 2.37e8 N/m², engagement [0.75π, π] (down milling), at the given
/// axial depth (3 mm in the paper).
pub fn seed004_process(axial_depth: f64) -> MillingProcess {
    MillingProcess {
        teeth: 2,
        radius: 0.04,
        axial_depth,
        kt: 6.44e8,
        kn: 2.37e8,
        entry_angle: 0.75 * PI,
        exit_angle: PI,
    }
}
