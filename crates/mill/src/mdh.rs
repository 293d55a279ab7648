//! The modified Denavit–Hartenberg (MDH, Craig convention) model of the
//! ABB IRB-6660 and its forward kinematics.
//!
//! # The table (issue 4; seed 004 Table 1, whose extraction is garbled)
//!
//! | i | α(i−1) | a(i−1) | d(i) | θ(i) |
//! |---|---|---|---|---|
//! | 1 | 0 | 0 | d1 = 0.8145 | q1 |
//! | 2 | −π/2 | a1 = 0.300 | 0 | q2 − π/2 |
//! | 3 | 0 | a2 = 1.280 | 0 | q3 |
//! | 4 | −π/2 | a3 = 0.280 | d4 = 1.5055 | q4 |
//! | 5 | π/2 | 0 | 0 | q5 |
//! | 6 | −π/2 | 0 | d6 = 0.200 | q6 + π |
//!
//! Craig (*Introduction to Robotics*, 3rd ed., eq. 3.6):
//! `T_{i−1,i} = RotX(α_{i−1}) · TransX(a_{i−1}) · RotZ(θ_i) · TransZ(d_i)`;
//! frame i's z axis is the axis of joint i.
//!
//! # Relation to `urdf/irb6660.urdf`
//!
//! At q = 0 the URDF puts `tool0` at (a1 + d4 + d6, 0, d1 + a2 + a3) =
//! (2.0055, 0, 2.3745) with its z axis along base +x and its x axis along
//! base −z. The table gives MDH frame 6 at q = 0: z6 = base +x (α5 = −π/2
//! about x5 = base +z), and the θ6 offset π turns x6 from base +z to base
//! −z, so frame 6 = `tool0` at q = 0. Joint axes agree in sign (z1 = +z,
//! z2 = z3 = z5 = base +y, z4 = z6 = base +x at q = 0, like the URDF's
//! `axis` elements), hence the fixed transform MDH frame 6 → `tool0` is the
//! identity for every q ([`frame6_to_tool0`]; checked against the URDF chain
//! at random joint vectors in `tests/fk_urdf.rs`).

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::error::{check_positive, MillError};

/// One row of an MDH table (Craig convention).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MdhRow {
    /// Link twist α(i−1) \[rad\].
    pub alpha: f64,
    /// Link length a(i−1) \[m\].
    pub a: f64,
    /// Link offset d(i) \[m\].
    pub d: f64,
    /// Joint angle offset: θ(i) = q(i) + `theta_offset` \[rad\].
    pub theta_offset: f64,
}

impl MdhRow {
    /// `T_{i−1,i}(q) = RotX(α) TransX(a) RotZ(q + offset) TransZ(d)`
    /// (Craig eq. 3.6).
    ///
    /// # Performance
    /// O(1), no allocation.
    pub fn transform(&self, q: f64) -> Isometry3<f64> {
        let rx = twist(self.alpha);
        let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), q + self.theta_offset);
        let rot = rx * rz;
        // TransX(a) then, in the rotated frame, TransZ(d).
        let t = Vector3::new(self.a, 0.0, 0.0) + rot * Vector3::new(0.0, 0.0, self.d);
        Isometry3::from_parts(
            Translation3::from(t),
            UnitQuaternion::from_rotation_matrix(&rot),
        )
    }
}

/// RotX(α) (Craig eq. 3.6), for the twists of [`ArmGeometry::mdh_table`] (0, ±π/2) computed
/// once: the rotation of `Rotation3::from_axis_angle` for that α, the same value bit for bit
/// (any other α is computed on the spot).
fn twist(alpha: f64) -> Rotation3<f64> {
    use std::f64::consts::FRAC_PI_2;
    static TWISTS: std::sync::OnceLock<[(u64, Rotation3<f64>); 3]> = std::sync::OnceLock::new();
    let twists = TWISTS.get_or_init(|| {
        [0.0, -FRAC_PI_2, FRAC_PI_2].map(|a: f64| {
            (
                a.to_bits(),
                Rotation3::from_axis_angle(&Vector3::x_axis(), a),
            )
        })
    });
    twists
        .iter()
        .find(|(bits, _)| *bits == alpha.to_bits())
        .map_or_else(
            || Rotation3::from_axis_angle(&Vector3::x_axis(), alpha),
            |(_, r)| *r,
        )
}

/// The fixed transform from MDH frame 6 to the URDF `tool0` frame: the
/// identity (module documentation; verified in `tests/fk_urdf.rs`).
pub fn frame6_to_tool0() -> Isometry3<f64> {
    Isometry3::identity()
}

/// The six lengths of the IRB-6660-type arm (spherical wrist, shoulder
/// offset a1, forearm offset a3) that fill the MDH table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmGeometry {
    /// Shoulder height d1 \[m\].
    pub d1: f64,
    /// Shoulder offset a1 (joint 1 axis to joint 2 axis) \[m\].
    pub a1: f64,
    /// Lower-arm length a2 (joint 2 to joint 3) \[m\].
    pub a2: f64,
    /// Forearm offset a3 (perpendicular to the forearm) \[m\].
    pub a3: f64,
    /// Forearm length d4 (joint 4 axis, up to the wrist centre) \[m\].
    pub d4: f64,
    /// Wrist centre to flange d6 \[m\].
    pub d6: f64,
}

impl ArmGeometry {
    /// The ABB IRB 6660-130/3.1 (issue 4 table, `urdf/irb6660.urdf`).
    pub const IRB6660: ArmGeometry = ArmGeometry {
        d1: 0.8145,
        a1: 0.300,
        a2: 1.280,
        a3: 0.280,
        d4: 1.5055,
        d6: 0.200,
    };

    /// Checks that every length is finite and a2, d4, d6 are > 0.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] naming the length.
    pub fn validate(&self) -> Result<(), MillError> {
        for (name, v) in [("d1", self.d1), ("a1", self.a1), ("a3", self.a3)] {
            crate::error::check_finite(&format!("arm geometry {name} [m]"), v)?;
        }
        for (name, v) in [("a2", self.a2), ("d4", self.d4), ("d6", self.d6)] {
            check_positive(&format!("arm geometry {name} [m]"), v)?;
        }
        Ok(())
    }

    /// The MDH table of the module documentation.
    pub fn mdh_table(&self) -> [MdhRow; 6] {
        use std::f64::consts::{FRAC_PI_2, PI};
        let row = |alpha, a, d, theta_offset| MdhRow {
            alpha,
            a,
            d,
            theta_offset,
        };
        [
            row(0.0, 0.0, self.d1, 0.0),
            row(-FRAC_PI_2, self.a1, 0.0, -FRAC_PI_2),
            row(0.0, self.a2, 0.0, 0.0),
            row(-FRAC_PI_2, self.a3, self.d4, 0.0),
            row(FRAC_PI_2, 0.0, 0.0, 0.0),
            row(-FRAC_PI_2, 0.0, self.d6, PI),
        ]
    }

    /// Poses of the MDH frames 1..6 in the base frame.
    ///
    /// # Arguments
    /// * `q` - joint angles \[rad\] (not checked: NaN propagates; use
    ///   [`crate::Kinematics`] for validated evaluation).
    ///
    /// # Performance
    /// O(1), no allocation.
    pub fn frames(&self, q: &[f64; 6]) -> [Isometry3<f64>; 6] {
        let table = self.mdh_table();
        let mut out = [Isometry3::identity(); 6];
        let mut pose = Isometry3::identity();
        for ((row, &qi), slot) in table.iter().zip(q).zip(out.iter_mut()) {
            pose *= row.transform(qi);
            *slot = pose;
        }
        out
    }

    /// Pose of MDH frame 6 (= `tool0`, the flange) in the base frame.
    pub fn flange_pose(&self, q: &[f64; 6]) -> Isometry3<f64> {
        self.frames(q)[5] * frame6_to_tool0()
    }

    /// Rotation of MDH frame 3 in the base frame for the first three joints
    /// (used by the closed-form IK).
    pub fn r03(&self, q1: f64, q2: f64, q3: f64) -> Matrix3<f64> {
        let table = self.mdh_table();
        let mut r = Rotation3::identity();
        for (row, q) in table.iter().zip([q1, q2, q3]) {
            r *= row.transform(q).rotation.to_rotation_matrix();
        }
        r.into_inner()
    }
}
