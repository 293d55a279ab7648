//! Closed-form inverse kinematics of the IRB-6660 (spherical wrist), all
//! solutions, joint wrapping to the URDF limits and branch continuity.
//!
//! # Derivation (MDH table of [`crate::mdh`])
//!
//! **Wrist centre.** Frames 4 and 5 share their origin, the wrist centre
//! `p_w`; frame 6 (= `tool0`) lies `d6` along its own z axis beyond it, so
//! `p_w = p_flange − d6 · z_flange`.
//!
//! **Joint 1.** All offsets of the arm lie in the plane of joints 2 and 3
//! (no lateral offset), so `q1 = atan2(p_wy, p_wx)` (shoulder front) or
//! that + π (shoulder back). In that plane, with `r` the horizontal
//! distance along the arm direction `(cos q1, sin q1)` measured from the
//! joint-2 axis and `s` the height above it:
//! `r = p_w·(cos q1, sin q1, 0) − a1`, `s = p_wz − d1`.
//!
//! **Joints 2, 3.** From the MDH chain, joint 2 tilts the lower arm by q2
//! from the vertical towards +r, and the forearm vector (d4 along the
//! forearm, a3 perpendicular to it) is turned by q2 + q3:
//! `r = a2 sin q2 + d4 cos q23 + a3 sin q23`,
//! `s = a2 cos q2 − d4 sin q23 + a3 cos q23`.
//! With `L = √(d4² + a3²)`, `β = atan2(a3, d4)` the forearm is
//! `L (cos(q23 − β), −sin(q23 − β))`, and the law of cosines gives
//! `r² + s² = a2² + L² + 2 a2 L sin(β − q3)`, so
//! `q3 = β − asin(c)` (elbow up) or `q3 = β − π + asin(c)` (elbow down),
//! `c = (r² + s² − a2² − L²) / (2 a2 L)`. `|c| > 1` means the wrist centre
//! is out of reach: farther than `a2 + L` or nearer than `|a2 − L|` from the
//! joint-2 axis; the error reports that distance.
//! With `φ = q3 − β`, `A = a2 − L sin φ`, `B = L cos φ`:
//! `r = A sin q2 + B cos q2`, `s = A cos q2 − B sin q2`, i.e.
//! `q2 = atan2(r, s) − atan2(B, A)`.
//!
//! **Wrist.** `R_36 = R_03ᵀ R_06` and, from rows 4-6 of the table,
//! `R_36 = RotX(−π/2) RotZ(q4) RotX(π/2) RotZ(q5) RotX(−π/2) RotZ(q6) RotZ(π)`.
//! Since `RotX(π/2) RotZ(q5) RotX(−π/2) = RotY(−q5)`,
//! `M = RotX(π/2) R_36 RotZ(−π) = RotZ(q4) RotY(−q5) RotZ(q6)`: ZYZ Euler
//! angles (a, b, c) = (q4, −q5, q6). With `sb = ±√(M13² + M23²)`:
//! `b = atan2(sb, M33)`, `a = atan2(±M23, ±M13)`, `c = atan2(±M32, ∓M31)`
//! (both signs: the wrist flip). When `sb ≈ 0` (q5 ≈ 0, the wrist
//! singularity) only `q4 + q6 = atan2(M21, M11)` is determined: q4 is kept
//! from the reference and q6 follows.
//!
//! Every solution is checked by forward kinematics before it is returned.
//!
//! **Joint wrapping.** The URDF limits let q4 (±300°) and q6 (±360°) take
//! several values 2π apart; [`Kinematics::ik_nearest`] picks, per joint, the
//! equivalent value inside the limits nearest to the reference.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::{Isometry3, Matrix3, Rotation3, Vector3};

use crate::error::MillError;
use crate::mdh::ArmGeometry;

/// Tolerance of the limit checks \[rad\] (rounding only).
const LIMIT_TOL: f64 = 1e-12;
/// Below this |sin q5| the wrist is treated as singular.
const WRIST_SINGULAR: f64 = 1e-10;
/// Below this distance \[m\] the wrist centre is on the joint-1 axis.
const SHOULDER_SINGULAR: f64 = 1e-12;
/// Self-check tolerance of every IK solution (position \[m\], angle \[rad\]).
const VERIFY_TOL: f64 = 1e-8;

/// Name and position limits of one joint \[rad\].
#[derive(Debug, Clone, PartialEq)]
pub struct JointRange {
    /// Joint name (URDF).
    pub name: String,
    /// Lower limit \[rad\].
    pub lower: f64,
    /// Upper limit \[rad\].
    pub upper: f64,
}

/// One closed-form IK solution, before limits are applied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    /// Joint angles \[rad\], each wrapped to (−π, π].
    pub q: [f64; 6],
    /// Shoulder back: q1 = atan2(p_wy, p_wx) + π.
    pub shoulder_back: bool,
    /// Elbow down: q3 = β − π + asin(c).
    pub elbow_down: bool,
    /// Wrist flipped: the negative root of sin(−q5).
    pub wrist_flipped: bool,
}

/// A joint step along a path above the branch-jump threshold.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchJump {
    /// Index of the pose reached by the jump (the step is from `index − 1`).
    pub index: usize,
    /// The joint with the largest step.
    pub joint: String,
    /// Its step \[rad\] (absolute value).
    pub step: f64,
}

/// The result of [`Kinematics::ik_path`]: one joint vector per pose and
/// every branch jump found (nothing is hidden).
#[derive(Debug, Clone, PartialEq)]
pub struct IkPath {
    /// Joint vectors \[rad\], one per pose.
    pub joints: Vec<[f64; 6]>,
    /// Steps above the threshold, in path order.
    pub jumps: Vec<BranchJump>,
}

/// The IRB-6660 kinematics: geometry, joint limits, TCP offset and the
/// weights of the joint distance used to choose among IK solutions.
#[derive(Debug, Clone, PartialEq)]
pub struct Kinematics {
    geometry: ArmGeometry,
    joints: [JointRange; 6],
    tcp: Isometry3<f64>,
    weights: [f64; 6],
}

impl Kinematics {
    /// Builds the model.
    ///
    /// # Arguments
    /// * `geometry` - the arm lengths (e.g. [`ArmGeometry::IRB6660`]);
    /// * `joints` - names and limits, joint 1 first;
    /// * `tcp` - the tool tip in the `tool0` (flange) frame (identity = the
    ///   flange, the paper's model);
    /// * `weights` - weights w_i > 0 of the joint distance
    ///   `√(Σ w_i (q_i − r_i)²)`.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] for a bad length, limit, weight or a
    /// non-finite TCP offset.
    pub fn new(
        geometry: ArmGeometry,
        joints: [JointRange; 6],
        tcp: Isometry3<f64>,
        weights: [f64; 6],
    ) -> Result<Self, MillError> {
        geometry.validate()?;
        for j in &joints {
            crate::error::check_finite(&format!("{} lower limit [rad]", j.name), j.lower)?;
            crate::error::check_finite(&format!("{} upper limit [rad]", j.name), j.upper)?;
            if j.upper <= j.lower {
                return Err(MillError::InvalidParameter {
                    name: format!("{} upper limit [rad]", j.name),
                    value: j.upper,
                    reason: format!("must exceed the lower limit {}", j.lower),
                });
            }
        }
        for (i, w) in weights.iter().enumerate() {
            crate::error::check_positive(&format!("joint weight {}", i + 1), *w)?;
        }
        if tcp.translation.vector.iter().any(|v| !v.is_finite())
            || tcp.rotation.coords.iter().any(|v| !v.is_finite())
        {
            return Err(MillError::NonFinite {
                what: "TCP offset".to_string(),
            });
        }
        Ok(Self {
            geometry,
            joints,
            tcp,
            weights,
        })
    }

    /// The IRB-6660 geometry with the limits of a loaded robot model (the
    /// URDF `urdf/irb6660.urdf`).
    ///
    /// # Errors
    /// [`MillError::InvalidConfig`] unless the model has 6 joints, and the
    /// errors of [`Kinematics::new`].
    pub fn from_robot(
        robot: &kerf_robot::RobotModel,
        tcp: Isometry3<f64>,
        weights: [f64; 6],
    ) -> Result<Self, MillError> {
        let specs = robot.joints();
        let ranges: Vec<JointRange> = specs
            .iter()
            .map(|j| JointRange {
                name: j.name.clone(),
                lower: j.min_position,
                upper: j.max_position,
            })
            .collect();
        let joints: [JointRange; 6] =
            ranges
                .try_into()
                .map_err(|v: Vec<JointRange>| MillError::InvalidConfig {
                    name: "robot".to_string(),
                    reason: format!("expected 6 joints, the model has {}", v.len()),
                })?;
        Self::new(ArmGeometry::IRB6660, joints, tcp, weights)
    }

    /// The arm geometry.
    pub fn geometry(&self) -> &ArmGeometry {
        &self.geometry
    }

    /// Joint names and limits.
    pub fn joints(&self) -> &[JointRange; 6] {
        &self.joints
    }

    /// The TCP offset (tool tip in the `tool0` frame).
    pub fn tcp(&self) -> &Isometry3<f64> {
        &self.tcp
    }

    /// The joint-distance weights.
    pub fn weights(&self) -> &[f64; 6] {
        &self.weights
    }

    /// Weighted joint distance `√(Σ w_i (a_i − b_i)²)` \[rad\].
    pub fn joint_distance(&self, a: &[f64; 6], b: &[f64; 6]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.weights)
            .map(|((x, y), w)| w * (x - y) * (x - y))
            .sum::<f64>()
            .sqrt()
    }

    /// Pose of `tool0` (the flange) in the base frame.
    ///
    /// # Errors
    /// [`MillError::NonFinite`] for a NaN/infinite joint value.
    pub fn flange_pose(&self, q: &[f64; 6]) -> Result<Isometry3<f64>, MillError> {
        check_q(q)?;
        Ok(self.geometry.flange_pose(q))
    }

    /// Pose of the tool tip (TCP) in the base frame: `flange · tcp`.
    ///
    /// # Errors
    /// [`MillError::NonFinite`] for a NaN/infinite joint value.
    pub fn tcp_pose(&self, q: &[f64; 6]) -> Result<Isometry3<f64>, MillError> {
        Ok(self.flange_pose(q)? * self.tcp)
    }

    /// Checks q against the joint limits.
    ///
    /// # Errors
    /// [`MillError::JointLimit`] for the joint farthest outside its limits
    /// (no segment context), [`MillError::NonFinite`].
    pub fn check_limits(&self, q: &[f64; 6]) -> Result<(), MillError> {
        check_q(q)?;
        let mut worst: Option<MillError> = None;
        let mut worst_excess = 0.0;
        for (j, &v) in self.joints.iter().zip(q) {
            let excess = (j.lower - v).max(v - j.upper);
            if excess > LIMIT_TOL && excess > worst_excess {
                worst_excess = excess;
                worst = Some(limit_error(j, v, excess));
            }
        }
        worst.map_or(Ok(()), Err)
    }

    /// All closed-form IK solutions (up to 8: shoulder front/back × elbow
    /// up/down × wrist flip) for a flange (`tool0`) pose, limits not applied.
    ///
    /// # Arguments
    /// * `flange` - the `tool0` pose in the base frame;
    /// * `reference` - used only at singularities: q1 when the wrist centre
    ///   is on the joint-1 axis, q4 when q5 ≈ 0.
    ///
    /// # Returns
    /// The solutions, each reproducing `flange` by forward kinematics
    /// (checked to 1e-8), angles wrapped to (−π, π].
    ///
    /// # Errors
    /// [`MillError::Unreachable`] (no segment context) with the distance of
    /// the wrist centre beyond the reach; [`MillError::NonFinite`].
    ///
    /// # Performance
    /// O(1), a few µs; allocates the result vector.
    pub fn ik_flange_all(
        &self,
        flange: &Isometry3<f64>,
        reference: &[f64; 6],
    ) -> Result<Vec<IkSolution>, MillError> {
        check_pose(flange)?;
        check_q(reference)?;
        let g = &self.geometry;
        let rot = flange.rotation.to_rotation_matrix().into_inner();
        let z = rot.column(2).into_owned();
        let pw = flange.translation.vector - g.d6 * z;
        let rho = pw.x.hypot(pw.y);
        let q1_front = if rho < SHOULDER_SINGULAR {
            reference[0]
        } else {
            pw.y.atan2(pw.x)
        };
        let l = g.d4.hypot(g.a3);
        let beta = g.a3.atan2(g.d4);
        let mut out = Vec::with_capacity(8);
        let mut best_miss = f64::INFINITY;
        for shoulder_back in [false, true] {
            let q1 = if shoulder_back {
                wrap(q1_front + PI)
            } else {
                wrap(q1_front)
            };
            let r = pw.x * q1.cos() + pw.y * q1.sin() - g.a1;
            let s = pw.z - g.d1;
            let d2 = r * r + s * s;
            let c = (d2 - g.a2 * g.a2 - l * l) / (2.0 * g.a2 * l);
            if !c.is_finite() {
                return Err(MillError::NonFinite {
                    what: "IK law of cosines".to_string(),
                });
            }
            if c.abs() > 1.0 + 1e-12 {
                let dist = d2.sqrt();
                let miss = if c > 0.0 {
                    dist - (g.a2 + l)
                } else {
                    (g.a2 - l).abs() - dist
                };
                best_miss = best_miss.min(miss.max(0.0));
                continue;
            }
            let asin_c = c.clamp(-1.0, 1.0).asin();
            for elbow_down in [false, true] {
                let q3 = if elbow_down {
                    beta - PI + asin_c
                } else {
                    beta - asin_c
                };
                let phi = q3 - beta;
                let a = g.a2 - l * phi.sin();
                let b = l * phi.cos();
                let q2 = r.atan2(s) - b.atan2(a);
                let r03 = g.r03(q1, q2, q3);
                let r36 = r03.transpose() * rot;
                let m = Rotation3::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2).into_inner()
                    * r36
                    * Rotation3::from_axis_angle(&Vector3::z_axis(), -PI).into_inner();
                for (q4, q5, q6, wrist_flipped) in wrist_solutions(&m, reference[3]) {
                    let q = [q1, q2, q3, q4, q5, q6].map(wrap);
                    if verify(&g.flange_pose(&q), flange) {
                        out.push(IkSolution {
                            q,
                            shoulder_back,
                            elbow_down,
                            wrist_flipped,
                        });
                    } else {
                        log::debug!("IK candidate {q:?} failed the FK check; dropped");
                    }
                }
            }
        }
        if out.is_empty() {
            return Err(MillError::Unreachable {
                segment: None,
                g: None,
                distance_beyond_reach: if best_miss.is_finite() {
                    best_miss
                } else {
                    0.0
                },
            });
        }
        Ok(out)
    }

    /// All IK solutions for a tool-tip (TCP) pose: [`Kinematics::ik_flange_all`]
    /// of `tcp_pose · tcp⁻¹`.
    ///
    /// # Errors
    /// As [`Kinematics::ik_flange_all`].
    pub fn ik_all(
        &self,
        tcp_pose: &Isometry3<f64>,
        reference: &[f64; 6],
    ) -> Result<Vec<IkSolution>, MillError> {
        self.ik_flange_all(&(tcp_pose * self.tcp.inverse()), reference)
    }

    /// The IK solution within the joint limits nearest to `reference`
    /// (weighted joint distance), with q4 and q6 (and any joint whose range
    /// allows it) moved by multiples of 2π to the equivalent value nearest
    /// to the reference.
    ///
    /// # Arguments
    /// * `tcp_pose` - the tool-tip pose in the base frame;
    /// * `reference` - the previous joint vector (branch continuity).
    ///
    /// # Errors
    /// [`MillError::Unreachable`]; [`MillError::JointLimit`] when every
    /// solution violates a limit (the solution with the smallest violation
    /// is reported: its worst joint, value, limits and excess);
    /// [`MillError::NonFinite`]. No segment context (see
    /// [`MillError::with_context`]).
    pub fn ik_nearest(
        &self,
        tcp_pose: &Isometry3<f64>,
        reference: &[f64; 6],
    ) -> Result<[f64; 6], MillError> {
        let sols = self.ik_all(tcp_pose, reference)?;
        let mut best: Option<([f64; 6], f64)> = None;
        let mut least_bad: Option<(MillError, f64)> = None;
        for sol in &sols {
            let mut q = [0.0; 6];
            let mut violation: Option<(usize, f64, f64)> = None;
            for (i, ((j, &v), &r)) in self.joints.iter().zip(&sol.q).zip(reference).enumerate() {
                match nearest_equivalent(v, r, j.lower, j.upper) {
                    Some(x) => q[i] = x,
                    None => {
                        let (val, ex) = smallest_excess(v, j.lower, j.upper);
                        if violation.is_none_or(|(_, _, e)| ex > e) {
                            violation = Some((i, val, ex));
                        }
                    }
                }
            }
            match violation {
                None => {
                    let d = self.joint_distance(&q, reference);
                    if best.is_none_or(|(_, bd)| d < bd) {
                        best = Some((q, d));
                    }
                }
                Some((i, val, ex)) => {
                    if least_bad.as_ref().is_none_or(|(_, e)| ex < *e) {
                        let j = &self.joints[i];
                        least_bad = Some((limit_error(j, val, ex), ex));
                    }
                }
            }
        }
        match (best, least_bad) {
            (Some((q, _)), _) => Ok(q),
            (None, Some((e, _))) => Err(e),
            (None, None) => Err(MillError::Unreachable {
                segment: None,
                g: None,
                distance_beyond_reach: 0.0,
            }),
        }
    }

    /// IK along a sequence of tool-tip poses, each solution the nearest to
    /// the previous one ([`Kinematics::ik_nearest`]).
    ///
    /// # Arguments
    /// * `poses` - tool-tip poses, in path order;
    /// * `reference` - the joint vector the first pose is chosen against;
    /// * `jump_threshold` - a step of any joint above this \[rad\] between
    ///   consecutive poses is reported as a [`BranchJump`] (the reference
    ///   itself is not a path pose: its step to pose 0 is not checked).
    ///
    /// # Errors
    /// The first pose that fails, with its index as `segment`.
    pub fn ik_path(
        &self,
        poses: &[Isometry3<f64>],
        reference: &[f64; 6],
        jump_threshold: f64,
    ) -> Result<IkPath, MillError> {
        crate::error::check_positive("branch jump threshold [rad]", jump_threshold)?;
        let mut joints = Vec::with_capacity(poses.len());
        let mut jumps = Vec::new();
        let mut prev = *reference;
        for (i, pose) in poses.iter().enumerate() {
            let q = self
                .ik_nearest(pose, &prev)
                .map_err(|e| e.with_context(Some(i), None))?;
            if i > 0 {
                let (k, step) = q
                    .iter()
                    .zip(&prev)
                    .map(|(a, b)| (a - b).abs())
                    .enumerate()
                    .fold((0, 0.0), |acc, (k, s)| if s > acc.1 { (k, s) } else { acc });
                if step > jump_threshold {
                    jumps.push(BranchJump {
                        index: i,
                        joint: self.joints[k].name.clone(),
                        step,
                    });
                }
            }
            joints.push(q);
            prev = q;
        }
        Ok(IkPath { joints, jumps })
    }
}

/// The wrist solutions (q4, q5, q6, flipped) of `M = RotZ(q4) RotY(−q5) RotZ(q6)`.
fn wrist_solutions(m: &Matrix3<f64>, q4_ref: f64) -> Vec<(f64, f64, f64, bool)> {
    let sb = m[(0, 2)].hypot(m[(1, 2)]);
    if sb < WRIST_SINGULAR {
        // b = 0 (M = RotZ(a + c)) or b = π (M = RotZ(a − c) RotY(π)).
        if m[(2, 2)] > 0.0 {
            let sum = m[(1, 0)].atan2(m[(0, 0)]);
            vec![(q4_ref, 0.0, sum - q4_ref, false)]
        } else {
            let diff = (-m[(1, 0)]).atan2(-m[(0, 0)]);
            vec![(q4_ref, -PI, q4_ref - diff, false)]
        }
    } else {
        let mut out = Vec::with_capacity(2);
        for (sign, flipped) in [(1.0, false), (-1.0, true)] {
            let b = (sign * sb).atan2(m[(2, 2)]);
            let a = (sign * m[(1, 2)]).atan2(sign * m[(0, 2)]);
            let c = (sign * m[(2, 1)]).atan2(-sign * m[(2, 0)]);
            out.push((a, -b, c, flipped));
        }
        out
    }
}

/// Wraps an angle to (−π, π].
pub fn wrap(a: f64) -> f64 {
    let w = a - TAU * (a / TAU).round();
    if w <= -PI {
        w + TAU
    } else {
        w
    }
}

/// The value `v + 2πk` inside `[lower, upper]` nearest to `reference`, if
/// any (1e-12 rad slack, clamped to the limits).
pub fn nearest_equivalent(v: f64, reference: f64, lower: f64, upper: f64) -> Option<f64> {
    let kmin = ((lower - LIMIT_TOL - v) / TAU).ceil() as i64;
    let kmax = ((upper + LIMIT_TOL - v) / TAU).floor() as i64;
    (kmin..=kmax)
        .map(|k| (v + TAU * k as f64).clamp(lower, upper))
        .min_by(|a, b| (a - reference).abs().total_cmp(&(b - reference).abs()))
}

/// The equivalent `v + 2πk` closest to `[lower, upper]` and its distance
/// outside it \[rad\].
fn smallest_excess(v: f64, lower: f64, upper: f64) -> (f64, f64) {
    let w = wrap(v);
    [-TAU, 0.0, TAU]
        .iter()
        .map(|k| {
            let x = w + k;
            (x, (lower - x).max(x - upper).max(0.0))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((w, (lower - w).max(w - upper)))
}

fn limit_error(j: &JointRange, value: f64, excess: f64) -> MillError {
    MillError::JointLimit {
        segment: None,
        g: None,
        joint: j.name.clone(),
        value,
        lower: j.lower,
        upper: j.upper,
        excess,
    }
}

fn check_q(q: &[f64; 6]) -> Result<(), MillError> {
    match q.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(MillError::NonFinite {
            what: format!("joint {} value {}", i + 1, q[i]),
        }),
        None => Ok(()),
    }
}

fn check_pose(p: &Isometry3<f64>) -> Result<(), MillError> {
    if p.translation.vector.iter().all(|v| v.is_finite())
        && p.rotation.coords.iter().all(|v| v.is_finite())
    {
        Ok(())
    } else {
        Err(MillError::NonFinite {
            what: "target pose".to_string(),
        })
    }
}

fn verify(a: &Isometry3<f64>, b: &Isometry3<f64>) -> bool {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let da = (a.rotation.to_rotation_matrix().into_inner()
        - b.rotation.to_rotation_matrix().into_inner())
    .norm();
    dp <= VERIFY_TOL && da <= VERIFY_TOL
}
