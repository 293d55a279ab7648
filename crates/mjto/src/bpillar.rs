//! A B-pillar-like stamped test workpiece and the two cut requests of
//! seed 001 section 3, built on it.
//!
//! Seed 001 demonstrates MJTO on an automotive B-pillar (Figure 7) that is
//! not published. This module generates a stand-in with the features its
//! two case studies need:
//!
//! * a **hat-section sheet** (thickness 1.5 mm): two flanges, two side walls
//!   at 77° to the flanges, a top, a concave fillet between each flange and
//!   wall and a convex fillet between each wall and the top;
//! * a **spine** along the part's length (workpiece x): straight at the
//!   foot, then gently curved (radius 8 m), then a **sharp kink** (20° with
//!   a 50 mm bend radius, like a B-pillar's upper bend), then straight;
//! * a **deep, wide foot** with generous fillets, blended smoothly into the
//!   narrower pillar body (the reason is in [`BPillarParams`]).
//!
//! The mesh ([`BPillar::mesh`]) is a closed thin solid: the outer
//! (head-side) surface, the inner surface offset by the thickness along the
//! surface normals, and the edge strips around the free edges. Triangles are
//! oriented with outward normals (positive signed volume).
//!
//! The cut paths are CL points on the outer surface with the unit outward
//! surface normal as the nominal tool axis, sampled like a G-code
//! interpolator: the CAM blocks are the mesh vertices along the cut (points
//! and vertex normals), the interpolator moves at constant spacing `f Δt`
//! along the polyline and interpolates the orientation between blocks by
//! quaternion interpolation (slerp), as seed 001 section 3.2 describes its
//! input ("a standard G-code interpolator using QI for the orientation").
//! Every CL point therefore lies exactly on the mesh.
//!
//! * [`trim_case`]: case 1 (seed 001 section 3.1, Table 1): a 0.8 m side
//!   trim along a flange near the wall, tool axis near vertical (q4 is
//!   ill-defined there, and the fork arms of the head reach the wall unless
//!   q4 turns them along the cut), six RTOs.
//! * [`corner_case`]: case 2 (section 3.2, Table 1): a cut across the hat
//!   section at the foot, flange → concave fillet → wall → convex fillet →
//!   top, 628 CL points at 1 mm, two 77° tool-axis changes between adjacent
//!   RTOs, ten RTOs.
//!
//! [`write_files`] writes `urdf/meshes/bpillar.obj` and
//! `crates/mjto/cases/case{1,2}.yaml`; `cargo run -p kerf_mjto --example
//! gen_bpillar -- --out .` calls it. The output is deterministic (no
//! randomness; coordinates rounded to 1 nm, axes to 1e-12).
//!
//! Frames: the workpiece frame has x along the spine (from the foot), y
//! across the section, z towards the head side of the flanges. All lengths
//! in metres, angles in radians.

use std::path::{Path, PathBuf};

use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::mesh::{self, MeshData};
use crate::request::{CutOptions, CutRequest, PoseSpec};
use crate::PlanError;

/// The mesh reference written into both requests.
pub const MESH_REFERENCE: &str = "package://kerf/urdf/meshes/bpillar.obj";

/// Path of the mesh file relative to the repository root.
pub const MESH_FILE: &str = "urdf/meshes/bpillar.obj";

/// Path of the case 1 request relative to the repository root.
pub const CASE1_FILE: &str = "crates/mjto/cases/case1.yaml";

/// Path of the case 2 request relative to the repository root.
pub const CASE2_FILE: &str = "crates/mjto/cases/case2.yaml";

/// The command that regenerates every generated file (run from the
/// repository root).
pub const REGENERATE_COMMAND: &str = "cargo run -p kerf_mjto --example gen_bpillar -- --out .";

/// Shortest accepted straight piece of a section (flange, wall, top) and
/// shortest spine segment (m): shorter ones would give degenerate triangles.
const MIN_PIECE: f64 = 1e-3;

/// Mesh and CL coordinates are rounded to 1 / COORD_SCALE m (1 nm).
const COORD_SCALE: f64 = 1e9;

/// Tool-axis components are rounded to 1 / AXIS_SCALE.
const AXIS_SCALE: f64 = 1e12;

/// Step of the central difference that gives the change of the section
/// along the spine in the transition (m).
const SECTION_FD_STEP: f64 = 1e-5;

/// One hat cross-section, in the section plane (y across, z towards the
/// head side; the flanges lie on z = 0, the hat is symmetric about y = 0).
///
/// Dimensions are of the outer (head-side) surface, measured at the
/// virtual sharp corners where the straight pieces would meet without
/// fillets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HatSection {
    /// Half width of the top between the virtual wall-top corners (m).
    pub top_half_width: f64,
    /// Height of the top above the flanges (m).
    pub depth: f64,
    /// Angle between each wall and the flange plane (rad), in (0, π/2].
    pub wall_angle: f64,
    /// Radius of the concave fillet between flange and wall (m).
    pub flange_fillet_radius: f64,
    /// Radius of the convex fillet between wall and top (m).
    pub top_fillet_radius: f64,
    /// Flange width from the virtual flange-wall corner to the free edge (m).
    pub flange_width: f64,
}

impl HatSection {
    /// Tangent length of the flange fillet: distance from the virtual
    /// flange-wall corner to each tangent point, `r tan(β/2)` for a fillet
    /// of radius r between two lines meeting at a deflection β.
    pub fn flange_fillet_tangent(&self) -> f64 {
        self.flange_fillet_radius * (self.wall_angle / 2.0).tan()
    }

    /// Tangent length of the top fillet, `r tan(β/2)`.
    pub fn top_fillet_tangent(&self) -> f64 {
        self.top_fillet_radius * (self.wall_angle / 2.0).tan()
    }

    /// y of the left virtual flange-wall corner, `-(b + h cot β)` (m).
    pub fn flange_corner_y(&self) -> f64 {
        -(self.top_half_width + self.depth / self.wall_angle.tan())
    }

    /// y of the left flange's free edge (m).
    pub fn flange_edge_y(&self) -> f64 {
        self.flange_corner_y() - self.flange_width
    }

    /// y where the left flange ends and its fillet starts (m).
    pub fn flange_tangent_y(&self) -> f64 {
        self.flange_corner_y() - self.flange_fillet_tangent()
    }

    /// Length of the straight part of each wall between its two fillets
    /// (m): `h / sin β` minus both tangent lengths.
    pub fn wall_straight_length(&self) -> f64 {
        self.depth / self.wall_angle.sin()
            - self.flange_fillet_tangent()
            - self.top_fillet_tangent()
    }

    /// Checks that the section is finite and its pieces fit.
    ///
    /// # Arguments
    /// * `field` - name used in errors (e.g. `bpillar.foot`).
    /// * `thickness` - sheet thickness (m); every fillet radius must exceed
    ///   it so the inner surface does not fold.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] naming the field when a value is not
    /// finite or positive, the wall angle is outside (0, π/2], a radius is
    /// not larger than the thickness, or the flange, wall or top is too
    /// short for its fillets (straight piece < 1 mm).
    pub fn validate(&self, field: &str, thickness: f64) -> Result<(), PlanError> {
        for (name, v) in [
            ("top_half_width", self.top_half_width),
            ("depth", self.depth),
            ("wall_angle", self.wall_angle),
            ("flange_fillet_radius", self.flange_fillet_radius),
            ("top_fillet_radius", self.top_fillet_radius),
            ("flange_width", self.flange_width),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::invalid(
                    format!("{field}.{name}"),
                    format!("{v} must be finite and > 0"),
                ));
            }
        }
        if self.wall_angle > std::f64::consts::FRAC_PI_2 {
            return Err(PlanError::invalid(
                format!("{field}.wall_angle"),
                format!("{} rad must be in (0, π/2]", self.wall_angle),
            ));
        }
        for (name, r) in [
            ("flange_fillet_radius", self.flange_fillet_radius),
            ("top_fillet_radius", self.top_fillet_radius),
        ] {
            if r <= thickness {
                return Err(PlanError::invalid(
                    format!("{field}.{name}"),
                    format!("{r} m must exceed the sheet thickness {thickness} m"),
                ));
            }
        }
        let pieces = [
            (
                "flange_width",
                self.flange_width - self.flange_fillet_tangent(),
            ),
            ("depth", self.wall_straight_length()),
            (
                "top_half_width",
                self.top_half_width - self.top_fillet_tangent(),
            ),
        ];
        for (name, len) in pieces {
            if len.is_nan() || len < MIN_PIECE {
                return Err(PlanError::invalid(
                    format!("{field}.{name}"),
                    format!(
                        "leaves a straight piece of {len:.6} m beside the fillets (at least \
                         {MIN_PIECE} m needed)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Blend `a (1 - w) + b w` of every dimension (exactly `a` at w = 0
    /// and `b` at w = 1).
    fn blend(a: &HatSection, b: &HatSection, w: f64) -> HatSection {
        let l = |x: f64, y: f64| x * (1.0 - w) + y * w;
        HatSection {
            top_half_width: l(a.top_half_width, b.top_half_width),
            depth: l(a.depth, b.depth),
            wall_angle: l(a.wall_angle, b.wall_angle),
            flange_fillet_radius: l(a.flange_fillet_radius, b.flange_fillet_radius),
            top_fillet_radius: l(a.top_fillet_radius, b.top_fillet_radius),
            flange_width: l(a.flange_width, b.flange_width),
        }
    }

    /// The outer profile from the left flange edge to the right flange
    /// edge: `2 (n1 + n2 + 3)` vertices with their unit head-side normals.
    ///
    /// Left half: flange edge; the concave flange fillet, centre
    /// `c1 = (y_c - r1 tan(β/2), r1)`, points `c1 + r1 (sin φ, -cos φ)`,
    /// normal `(-sin φ, cos φ)`, φ = 0 → β; the convex top fillet, centre
    /// `c2 = (-b + r2 tan(β/2), h - r2)`, points `c2 + r2 (-sin φ, cos φ)`,
    /// same normal, φ = β → 0. The right half is the mirror image. (Fillet
    /// construction: a circle tangent to both lines, its tangent points at
    /// `r tan(β/2)` from the corner.)
    fn profile(&self, n1: usize, n2: usize) -> Vec<ProfileVertex> {
        let beta = self.wall_angle;
        let (r1, r2) = (self.flange_fillet_radius, self.top_fillet_radius);
        let mut left = Vec::with_capacity(n1 + n2 + 3);
        left.push(ProfileVertex {
            y: self.flange_edge_y(),
            z: 0.0,
            ny: 0.0,
            nz: 1.0,
        });
        let c1 = (self.flange_tangent_y(), r1);
        for k in 0..=n1 {
            let phi = beta * k as f64 / n1 as f64;
            let (s, c) = phi.sin_cos();
            left.push(ProfileVertex {
                y: c1.0 + r1 * s,
                z: c1.1 - r1 * c,
                ny: -s,
                nz: c,
            });
        }
        let c2 = (
            -self.top_half_width + self.top_fillet_tangent(),
            self.depth - r2,
        );
        for k in 0..=n2 {
            let phi = beta * (n2 - k) as f64 / n2 as f64;
            let (s, c) = phi.sin_cos();
            left.push(ProfileVertex {
                y: c2.0 - r2 * s,
                z: c2.1 + r2 * c,
                ny: -s,
                nz: c,
            });
        }
        let right: Vec<ProfileVertex> = left
            .iter()
            .rev()
            .map(|v| ProfileVertex {
                y: -v.y,
                z: v.z,
                ny: -v.ny,
                nz: v.nz,
            })
            .collect();
        left.extend(right);
        left
    }
}

/// A vertex of a section profile: position (y, z) and unit head-side
/// normal (ny, nz).
#[derive(Debug, Clone, Copy, PartialEq)]
struct ProfileVertex {
    y: f64,
    z: f64,
    ny: f64,
    nz: f64,
}

/// Index of the first vertex of the left flange fillet in a profile.
const LEFT_FLANGE_FILLET_START: usize = 1;

/// Parameters of the B-pillar-like workpiece. SI units (m, rad).
///
/// The defaults are chosen for the two case studies and the head of
/// `urdf/laser_cutter.urdf`:
///
/// * **Foot** (`foot`, first `foot_length` of the spine): 0.25 m deep,
///   0.36 m wide top, **100 mm fillets**. Case 2 cuts across it with two
///   77° turns of the surface normal. Table 2 limits the rotary axes to
///   10 rad/s, 80 rad/s² and 200 rad/s³; a rest-to-rest turn of
///   77° = 1.344 rad with |jerk| ≤ J takes at least `4 (θ / 2J)^(1/3)`
///   = 0.6 s (four jerk phases of equal length τ, θ = 2 J τ³), i.e.
///   0.15 m of path at 15 m/min. With the ±15° lead tolerance of case 2
///   the rotation can start before and end after the fillet, so the
///   normal may turn over a shorter arc, but not much shorter: each 77°
///   turn is spread over a fillet of radius 0.1 m (arc 0.134 m). Sharper
///   fillets would make case 2 infeasible for any planner. The wall
///   (0.0975 m straight) separates the two turns, the depth follows from
///   two such fillets plus that wall, and the top and flange are wide
///   enough for the 0.627 m path (0.1 m on the flange, 0.16 m on the top).
/// * **Body** (`body`): a B-pillar-sized hat, 0.10 m deep, 0.14 m top,
///   12/15 mm fillets, with wide (0.14 m) trim flanges: case 1 trims the
///   left flange 75 mm from the fillet, where the fork arms of the head
///   (0.085–0.115 m off the tool axis) reach the wall unless q4 turns them
///   along the cut.
/// * **Transition** (`transition_length`): every section dimension blends
///   from foot to body with the C² smootherstep `6w⁵ - 15w⁴ + 10w³`.
/// * **Spine**: straight over foot and transition, then an arc of radius
///   `spine_radius` (8 m) over `curved_length` (0.9 m: the flange normal
///   turns 6.4° there, 5.7° along case 1), then the kink (`kink_angle`
///   20°, `kink_radius` 50 mm), then `head_length` straight. The spine
///   bends away from the head side (the outer surface is convex at the
///   kink), like a B-pillar's upper bend towards the roof.
///
/// Tessellation: every fillet has `flange_fillet_segments` /
/// `top_fillet_segments` chords (6.4° each by default: 0.16 mm chord
/// error at 100 mm radius); flanges, walls and top are single strips;
/// stations along the spine only where it or the section changes. The
/// default mesh has about 5000 triangles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BPillarParams {
    /// Sheet thickness (m). Default 1.5 mm.
    pub thickness: f64,
    /// Section of the foot (deep, generous fillets; case 2).
    pub foot: HatSection,
    /// Section of the pillar body (case 1).
    pub body: HatSection,
    /// Length of the uniform foot along the spine (m). Default 0.25.
    pub foot_length: f64,
    /// Length of the foot-to-body transition (m). Default 0.30.
    pub transition_length: f64,
    /// Mesh stations (intervals) over the transition. Default 6.
    pub transition_stations: usize,
    /// Radius of the gently curved spine part (m). Default 8.
    pub spine_radius: f64,
    /// Length of the gently curved spine part (m). Default 0.9.
    pub curved_length: f64,
    /// Largest station spacing on the curved part (m). Default 0.1.
    pub curved_station_spacing: f64,
    /// Kink angle of the spine (rad). Default 20°.
    pub kink_angle: f64,
    /// Bend radius of the spine at the kink, at the flange level (m).
    /// Default 0.05.
    pub kink_radius: f64,
    /// Mesh stations (intervals) over the kink. Default 5.
    pub kink_stations: usize,
    /// Straight length after the kink (m). Default 0.15.
    pub head_length: f64,
    /// Chords per flange fillet. Default 12.
    pub flange_fillet_segments: usize,
    /// Chords per top fillet. Default 12.
    pub top_fillet_segments: usize,
}

impl Default for BPillarParams {
    fn default() -> Self {
        let wall_angle = 77f64.to_radians();
        Self {
            thickness: 0.0015,
            foot: HatSection {
                top_half_width: 0.18,
                depth: 0.25,
                wall_angle,
                flange_fillet_radius: 0.10,
                top_fillet_radius: 0.10,
                flange_width: 0.22,
            },
            body: HatSection {
                top_half_width: 0.07,
                depth: 0.10,
                wall_angle,
                flange_fillet_radius: 0.012,
                top_fillet_radius: 0.015,
                flange_width: 0.14,
            },
            foot_length: 0.25,
            transition_length: 0.30,
            transition_stations: 6,
            spine_radius: 8.0,
            curved_length: 0.9,
            curved_station_spacing: 0.1,
            kink_angle: 20f64.to_radians(),
            kink_radius: 0.05,
            kink_stations: 5,
            head_length: 0.15,
            flange_fillet_segments: 12,
            top_fillet_segments: 12,
        }
    }
}

impl BPillarParams {
    /// Checks every parameter.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] with the field name (`bpillar.*`) for
    /// a non-finite or non-positive length, a thickness not below every
    /// radius, a kink angle outside (0, π/2], zero segment counts, or a
    /// section whose pieces do not fit ([`HatSection::validate`]).
    pub fn validate(&self) -> Result<(), PlanError> {
        for (name, v) in [
            ("thickness", self.thickness),
            ("foot_length", self.foot_length),
            ("transition_length", self.transition_length),
            ("spine_radius", self.spine_radius),
            ("curved_length", self.curved_length),
            ("curved_station_spacing", self.curved_station_spacing),
            ("kink_angle", self.kink_angle),
            ("kink_radius", self.kink_radius),
            ("head_length", self.head_length),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::invalid(
                    format!("bpillar.{name}"),
                    format!("{v} must be finite and > 0"),
                ));
            }
        }
        for (name, v) in [
            ("foot_length", self.foot_length),
            ("transition_length", self.transition_length),
            ("curved_length", self.curved_length),
            ("head_length", self.head_length),
        ] {
            if v < MIN_PIECE {
                return Err(PlanError::invalid(
                    format!("bpillar.{name}"),
                    format!("{v} m is shorter than {MIN_PIECE} m"),
                ));
            }
        }
        if self.kink_angle > std::f64::consts::FRAC_PI_2 {
            return Err(PlanError::invalid(
                "bpillar.kink_angle",
                format!("{} rad must be in (0, π/2]", self.kink_angle),
            ));
        }
        if self.kink_radius <= self.thickness || self.spine_radius <= self.thickness {
            return Err(PlanError::invalid(
                "bpillar.kink_radius",
                "the spine radii must exceed the sheet thickness",
            ));
        }
        for (name, v) in [
            ("transition_stations", self.transition_stations),
            ("kink_stations", self.kink_stations),
            ("flange_fillet_segments", self.flange_fillet_segments),
            ("top_fillet_segments", self.top_fillet_segments),
        ] {
            if v == 0 || v > 1000 {
                return Err(PlanError::invalid(
                    format!("bpillar.{name}"),
                    format!("{v} must be in [1, 1000]"),
                ));
            }
        }
        if self.curved_length / self.curved_station_spacing > 1000.0 {
            return Err(PlanError::invalid(
                "bpillar.curved_station_spacing",
                "gives more than 1000 stations",
            ));
        }
        self.foot.validate("bpillar.foot", self.thickness)?;
        self.body.validate("bpillar.body", self.thickness)?;
        // Every blended section must fit too (checked at the stations and
        // between them).
        for k in 0..=20 {
            let w = smootherstep(k as f64 / 20.0);
            HatSection::blend(&self.foot, &self.body, w)
                .validate("bpillar.transition", self.thickness)?;
        }
        Ok(())
    }

    /// Total length of the spine (m).
    pub fn spine_length(&self) -> f64 {
        self.foot_length
            + self.transition_length
            + self.curved_length
            + self.kink_radius * self.kink_angle
            + self.head_length
    }

    /// Spine arc length where the gently curved part starts (m).
    pub fn curved_start(&self) -> f64 {
        self.foot_length + self.transition_length
    }

    /// Spine arc length where the kink starts (m).
    pub fn kink_start(&self) -> f64 {
        self.curved_start() + self.curved_length
    }

    /// The section at spine arc length `s`: `foot` before the transition,
    /// `body` after it, the smootherstep blend in between.
    pub fn section_at(&self, s: f64) -> HatSection {
        let w = smootherstep((s - self.foot_length) / self.transition_length);
        HatSection::blend(&self.foot, &self.body, w)
    }
}

/// The C² smootherstep `6w⁵ - 15w⁴ + 10w³` of `w` clamped to [0, 1]
/// (exactly 0 and 1 at the ends, zero first and second derivatives there;
/// the quintic fade of Perlin, "Improving Noise", SIGGRAPH 2002).
fn smootherstep(w: f64) -> f64 {
    let w = w.clamp(0.0, 1.0);
    w * w * w * (w * (w * 6.0 - 15.0) + 10.0)
}

/// One piece of the spine, a plane curve in the workpiece x-z plane:
/// straight (`curvature` 0) or a circular arc bending away from the head
/// side (the spine angle α decreases with s).
#[derive(Debug, Clone, Copy)]
struct SpineSegment {
    s0: f64,
    curvature: f64,
    x0: f64,
    z0: f64,
    alpha0: f64,
}

/// A point of the spine: position, angle α of the tangent
/// `t = (cos α, 0, sin α)` and curvature.
#[derive(Debug, Clone, Copy)]
struct SpinePoint {
    pos: Vector3<f64>,
    alpha: f64,
    curvature: f64,
}

impl SpinePoint {
    /// Unit tangent `(cos α, 0, sin α)`.
    fn tangent(&self) -> Vector3<f64> {
        Vector3::new(self.alpha.cos(), 0.0, self.alpha.sin())
    }

    /// Unit normal of the flange plane, `u = (-sin α, 0, cos α)`; with
    /// ŷ and the tangent t, (t, ŷ, u) is right-handed.
    fn up(&self) -> Vector3<f64> {
        Vector3::new(-self.alpha.sin(), 0.0, self.alpha.cos())
    }

    /// The surface point of profile coordinates (y, z): `S + y ŷ + z u`.
    fn map(&self, y: f64, z: f64) -> Vector3<f64> {
        self.pos + Vector3::new(0.0, y, 0.0) + self.up() * z
    }

    /// A profile direction (dy, dz) in 3D: `dy ŷ + dz u`.
    fn map_dir(&self, dy: f64, dz: f64) -> Vector3<f64> {
        Vector3::new(0.0, dy, 0.0) + self.up() * dz
    }
}

impl SpineSegment {
    /// The point at arc length `s` (extrapolated outside the segment).
    ///
    /// Arc: α(s) = α0 - κ (s - s0); integrating t = (cos α, sin α) gives
    /// x = x0 - (sin α - sin α0) / κ, z = z0 + (cos α - cos α0) / κ.
    fn eval(&self, s: f64) -> SpinePoint {
        let d = s - self.s0;
        if self.curvature == 0.0 {
            SpinePoint {
                pos: Vector3::new(
                    self.x0 + d * self.alpha0.cos(),
                    0.0,
                    self.z0 + d * self.alpha0.sin(),
                ),
                alpha: self.alpha0,
                curvature: 0.0,
            }
        } else {
            let k = self.curvature;
            let alpha = self.alpha0 - k * d;
            SpinePoint {
                pos: Vector3::new(
                    self.x0 - (alpha.sin() - self.alpha0.sin()) / k,
                    0.0,
                    self.z0 + (alpha.cos() - self.alpha0.cos()) / k,
                ),
                alpha,
                curvature: k,
            }
        }
    }
}

/// The spine: consecutive segments from s = 0.
#[derive(Debug, Clone)]
struct Spine {
    segments: Vec<SpineSegment>,
}

impl Spine {
    fn new(p: &BPillarParams) -> Self {
        let pieces = [
            (p.foot_length + p.transition_length, 0.0),
            (p.curved_length, 1.0 / p.spine_radius),
            (p.kink_radius * p.kink_angle, 1.0 / p.kink_radius),
            (p.head_length, 0.0),
        ];
        let mut segments = Vec::with_capacity(pieces.len());
        let (mut s0, mut x0, mut z0, mut alpha0) = (0.0, 0.0, 0.0, 0.0);
        for (length, curvature) in pieces {
            let seg = SpineSegment {
                s0,
                curvature,
                x0,
                z0,
                alpha0,
            };
            let end = seg.eval(s0 + length);
            segments.push(seg);
            s0 += length;
            x0 = end.pos.x;
            z0 = end.pos.z;
            alpha0 = end.alpha;
        }
        Self { segments }
    }

    /// The point at arc length `s` (the last segment that starts at or
    /// before `s`; the first segment before 0).
    fn eval(&self, s: f64) -> SpinePoint {
        let seg = self
            .segments
            .iter()
            .rev()
            .find(|g| g.s0 <= s)
            .or(self.segments.first());
        match seg {
            Some(g) => g.eval(s),
            None => SpinePoint {
                pos: Vector3::zeros(),
                alpha: 0.0,
                curvature: 0.0,
            },
        }
    }
}

/// A point of the outer surface with its unit outward (head-side) normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceVertex {
    /// Position in the workpiece frame (m).
    pub point: Vector3<f64>,
    /// Unit outward normal of the outer surface.
    pub normal: Vector3<f64>,
}

/// A CL path: points on the outer surface and their nominal tool axes.
#[derive(Debug, Clone, PartialEq)]
pub struct ClPath {
    /// CL points in the workpiece frame (m), rounded to 1 nm.
    pub points: Vec<[f64; 3]>,
    /// Unit outward surface normals (nominal tool axes), rounded to 1e-12.
    pub axes: Vec<[f64; 3]>,
    /// Spacing along the path, `f Δt` (m).
    pub spacing: f64,
}

/// The generated workpiece: parameters, stations and the closed mesh.
#[derive(Debug, Clone)]
pub struct BPillar {
    params: BPillarParams,
    spine: Spine,
    stations: Vec<f64>,
    profile_len: usize,
    outer: Vec<SurfaceVertex>,
    mesh: MeshData,
}

impl BPillar {
    /// Generates the workpiece.
    ///
    /// # Arguments
    /// * `params` - the part's dimensions ([`BPillarParams::default`] for
    ///   the committed mesh).
    ///
    /// # Returns
    /// The part with its closed, outward-oriented thin-solid mesh: the
    /// outer surface (stations × profile vertices), the inner surface (each
    /// outer vertex moved by the thickness against the surface normal) and
    /// the strips closing the free edges.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] from [`BPillarParams::validate`], or
    /// when the mesh would exceed the u32 vertex indices.
    ///
    /// # Performance
    /// O(stations × profile vertices); well under a millisecond for the
    /// defaults.
    pub fn new(params: BPillarParams) -> Result<Self, PlanError> {
        params.validate()?;
        let spine = Spine::new(&params);
        let stations = station_list(&params);
        let n1 = params.flange_fillet_segments;
        let n2 = params.top_fillet_segments;
        let profile_len = 2 * (n1 + n2 + 3);
        let mut outer = Vec::with_capacity(stations.len() * profile_len);
        for &s in &stations {
            outer.extend(surface_vertices(&params, &spine, s)?);
        }
        let mesh = build_mesh(&outer, stations.len(), profile_len, params.thickness)?;
        Ok(Self {
            params,
            spine,
            stations,
            profile_len,
            outer,
            mesh,
        })
    }

    /// The parameters the part was generated from.
    pub fn params(&self) -> &BPillarParams {
        &self.params
    }

    /// The closed thin-solid mesh (workpiece frame, m).
    pub fn mesh(&self) -> &MeshData {
        &self.mesh
    }

    /// Spine arc lengths of the mesh stations (m), increasing from 0 to
    /// [`BPillarParams::spine_length`].
    pub fn stations(&self) -> &[f64] {
        &self.stations
    }

    /// Number of profile vertices per station.
    pub fn profile_len(&self) -> usize {
        self.profile_len
    }

    /// The outer-surface vertices (station-major: vertex `j` of station
    /// `i` is element `i * profile_len + j`; it is also mesh vertex
    /// `i * profile_len + j`, and its inner counterpart is mesh vertex
    /// `(stations + i) * profile_len + j`).
    pub fn outer_vertices(&self) -> &[SurfaceVertex] {
        &self.outer
    }

    /// A trim path along the left flange, parallel to the spine, at a
    /// constant distance from the flange fillet.
    ///
    /// # Arguments
    /// * `offset` - distance of the trim line from the tangent point where
    ///   the left flange meets its fillet in the section at `start`,
    ///   measured on the flange (m).
    /// * `start` - spine arc length of the first CL point (m).
    /// * `spacing` - distance between CL points along the path, `f Δt` (m).
    /// * `count` - number of CL points (≥ 2).
    ///
    /// # Returns
    /// CL points on the flange (exactly on the mesh: the flange strips are
    /// planar) with the flange normal `u(s)` as nominal axis.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] when an argument is not finite or out
    /// of range, the path leaves the part, or the trim line is not on the
    /// flange of every station it crosses.
    pub fn flange_trim_path(
        &self,
        offset: f64,
        start: f64,
        spacing: f64,
        count: usize,
    ) -> Result<ClPath, PlanError> {
        check_path_args(spacing, count)?;
        if !(offset.is_finite() && offset > 0.0) {
            return Err(PlanError::invalid(
                "trim offset",
                format!("{offset} must be finite and > 0"),
            ));
        }
        if !start.is_finite() {
            return Err(PlanError::invalid("trim start", "not finite"));
        }
        let section = self.params.section_at(start);
        let y = section.flange_tangent_y() - offset;
        let vertices: Vec<SurfaceVertex> = self
            .stations
            .iter()
            .map(|&s| {
                let sp = self.spine.eval(s);
                SurfaceVertex {
                    point: sp.map(y, 0.0),
                    normal: sp.up(),
                }
            })
            .collect();
        let line = Polyline::new(vertices)?;
        // Position of `start` on the polyline: on the chord of its station
        // interval, at the same fraction as along the spine.
        let i = self
            .stations
            .windows(2)
            .position(|w| w[0] <= start && start <= w[1])
            .ok_or_else(|| {
                PlanError::invalid(
                    "trim start",
                    format!(
                        "{start} m is outside the spine [0, {:.4}] m",
                        self.params.spine_length()
                    ),
                )
            })?;
        let (s_a, s_b) = (self.stations[i], self.stations[i + 1]);
        let l0 = line.cum[i] + (start - s_a) / (s_b - s_a) * (line.cum[i + 1] - line.cum[i]);
        let l_end = l0 + spacing * (count - 1) as f64;
        // The trim line must lie on the flange strip of every station whose
        // chords the path uses (the strip between two stations is planar:
        // both its long edges run along ŷ, so the line lies on the mesh).
        for (k, &s) in self.stations.iter().enumerate() {
            let chord_used = |a: usize| match (line.cum.get(a), line.cum.get(a + 1)) {
                (Some(&la), Some(&lb)) => la < l_end && lb > l0,
                _ => false,
            };
            let used = (k > 0 && chord_used(k - 1)) || chord_used(k);
            if !used {
                continue;
            }
            let sec = self.params.section_at(s);
            if !(y > sec.flange_edge_y() && y < sec.flange_tangent_y()) {
                return Err(PlanError::invalid(
                    "trim offset",
                    format!("y = {y:.4} m is not on the flange at station s = {s:.4} m"),
                ));
            }
        }
        line.sample(l0, spacing, count)
    }

    /// A cut across the section at spine arc length `station`, from the
    /// left flange over the flange fillet, the wall and the top fillet onto
    /// the top.
    ///
    /// # Arguments
    /// * `station` - spine arc length of the cut plane (m), inside the
    ///   uniform foot (`[0, foot_length]`, where the mesh strips are planar,
    ///   so the profile polyline lies on the mesh).
    /// * `flange_run` - path length on the flange before its fillet (m).
    /// * `spacing`, `count` - as for [`BPillar::flange_trim_path`].
    ///
    /// # Returns
    /// The path and the path lengths (m, from its first point) of the
    /// flange fillet's start and end and the top fillet's start and end.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] for arguments out of range, or when
    /// the path would not end on the top between the fillets.
    pub fn section_path(
        &self,
        station: f64,
        flange_run: f64,
        spacing: f64,
        count: usize,
    ) -> Result<(ClPath, [f64; 4]), PlanError> {
        check_path_args(spacing, count)?;
        if !(station.is_finite() && (0.0..=self.params.foot_length).contains(&station)) {
            return Err(PlanError::invalid(
                "section station",
                format!(
                    "{station} m must lie in the uniform foot [0, {}] m",
                    self.params.foot_length
                ),
            ));
        }
        let section = self.params.section_at(station);
        if !(flange_run.is_finite()
            && flange_run > 0.0
            && flange_run < section.flange_width - section.flange_fillet_tangent())
        {
            return Err(PlanError::invalid(
                "flange run",
                format!("{flange_run} m must be in (0, flange straight length)"),
            ));
        }
        let sp = self.spine.eval(station);
        let n1 = self.params.flange_fillet_segments;
        let n2 = self.params.top_fillet_segments;
        let vertices: Vec<SurfaceVertex> = section
            .profile(n1, n2)
            .iter()
            .map(|v| SurfaceVertex {
                point: sp.map(v.y, v.z),
                normal: sp.map_dir(v.ny, v.nz),
            })
            .collect();
        let line = Polyline::new(vertices)?;
        let fillet1_start = LEFT_FLANGE_FILLET_START;
        let fillet1_end = fillet1_start + n1;
        let fillet2_start = fillet1_end + 1;
        let fillet2_end = fillet2_start + n2;
        let top_end = fillet2_end + 1;
        let at = |k: usize| line.cum.get(k).copied().unwrap_or(f64::NAN);
        let l0 = at(fillet1_start) - flange_run;
        let l_end = l0 + spacing * (count - 1) as f64;
        if !(l_end > at(fillet2_end) && l_end < at(top_end)) {
            return Err(PlanError::invalid(
                "section path",
                format!(
                    "{count} points at {spacing} m end {:.4} m along the profile, not on the \
                     top ({:.4} to {:.4} m)",
                    l_end - l0,
                    at(fillet2_end) - l0,
                    at(top_end) - l0
                ),
            ));
        }
        let marks = [
            at(fillet1_start) - l0,
            at(fillet1_end) - l0,
            at(fillet2_start) - l0,
            at(fillet2_end) - l0,
        ];
        Ok((line.sample(l0, spacing, count)?, marks))
    }
}

fn check_path_args(spacing: f64, count: usize) -> Result<(), PlanError> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(PlanError::invalid(
            "path spacing",
            format!("{spacing} must be finite and > 0"),
        ));
    }
    if count < 2 {
        return Err(PlanError::invalid(
            "path points",
            format!("{count}: at least 2 are needed"),
        ));
    }
    Ok(())
}

/// Spine arc lengths of the mesh stations: the ends of the foot, the
/// transition in `transition_stations` steps, the curved part in steps of
/// at most `curved_station_spacing`, the kink in `kink_stations` steps, and
/// the end.
fn station_list(p: &BPillarParams) -> Vec<f64> {
    let mut st = vec![0.0, p.foot_length];
    let run = |from: f64, len: f64, n: usize, st: &mut Vec<f64>| {
        for k in 1..=n {
            st.push(from + len * k as f64 / n as f64);
        }
    };
    run(
        p.foot_length,
        p.transition_length,
        p.transition_stations,
        &mut st,
    );
    let n_curved = (p.curved_length / p.curved_station_spacing).ceil().max(1.0) as usize;
    run(p.curved_start(), p.curved_length, n_curved, &mut st);
    run(
        p.kink_start(),
        p.kink_radius * p.kink_angle,
        p.kink_stations,
        &mut st,
    );
    st.push(p.spine_length());
    st
}

/// The outer-surface vertices of the station at spine arc length `s`.
///
/// Surface `P(s, τ) = S(s) + y(s, τ) ŷ + z(s, τ) u(s)` (a profile swept
/// along the spine, section blended along s). Its outward normal is
/// `∂P/∂s × ∂P/∂τ` normalised, with `∂P/∂s = (1 + κ z) t + ∂y/∂s ŷ +
/// ∂z/∂s u` (u' = κ t for a spine bending away from the head side) and
/// `∂P/∂τ` along the profile tangent `(nz, -ny)`. Where the section is
/// constant (`∂y/∂s = ∂z/∂s = 0`) this is exactly the profile normal
/// `ny ŷ + nz u`; in the transition the section derivative is a central
/// difference.
fn surface_vertices(
    p: &BPillarParams,
    spine: &Spine,
    s: f64,
) -> Result<Vec<SurfaceVertex>, PlanError> {
    let n1 = p.flange_fillet_segments;
    let n2 = p.top_fillet_segments;
    let sp = spine.eval(s);
    let here = p.section_at(s).profile(n1, n2);
    let h = SECTION_FD_STEP;
    let ahead = p.section_at(s + h).profile(n1, n2);
    let behind = p.section_at(s - h).profile(n1, n2);
    let t = sp.tangent();
    here.iter()
        .zip(ahead.iter().zip(&behind))
        .map(|(v, (a, b))| {
            let dy = (a.y - b.y) / (2.0 * h);
            let dz = (a.z - b.z) / (2.0 * h);
            let ds = t * (1.0 + sp.curvature * v.z) + sp.map_dir(dy, dz);
            let dtau = sp.map_dir(v.nz, -v.ny);
            let n = ds.cross(&dtau);
            let norm = n.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(PlanError::invalid(
                    "bpillar",
                    format!("degenerate surface normal at s = {s} m"),
                ));
            }
            Ok(SurfaceVertex {
                point: sp.map(v.y, v.z),
                normal: n / norm,
            })
        })
        .collect()
}

/// The closed mesh: outer grid (normals outward = head side), inner grid
/// (reversed), and a strip on every boundary edge of the outer grid.
///
/// Outer quad (i, j): a = (i, j), b = (i+1, j), c = (i+1, j+1),
/// d = (i, j+1), triangles (a, b, c), (a, c, d): their normal is
/// `∂P/∂s × ∂P/∂τ`, the outward normal. A boundary edge a → b of the outer
/// grid (directed as in its triangle) gets the strip (b, a, a'), (b, a', b')
/// with a', b' the inner vertices: every edge of the closed surface is then
/// used once in each direction.
fn build_mesh(
    outer: &[SurfaceVertex],
    n_stations: usize,
    n_profile: usize,
    thickness: f64,
) -> Result<MeshData, PlanError> {
    let n_outer = n_stations * n_profile;
    if u32::try_from(2 * n_outer).is_err() {
        return Err(PlanError::invalid(
            "bpillar",
            "too many vertices for u32 indices",
        ));
    }
    let mut vertices = Vec::with_capacity(2 * n_outer);
    vertices.extend(outer.iter().map(|v| round_vec(&v.point, COORD_SCALE)));
    vertices.extend(
        outer
            .iter()
            .map(|v| round_vec(&(v.point - v.normal * thickness), COORD_SCALE)),
    );
    let o = |i: usize, j: usize| (i * n_profile + j) as u32;
    let inn = |i: usize, j: usize| (n_outer + i * n_profile + j) as u32;
    let mut triangles = Vec::with_capacity(4 * n_outer + 4 * (n_stations + n_profile));
    for i in 0..n_stations.saturating_sub(1) {
        for j in 0..n_profile.saturating_sub(1) {
            let (a, b, c, d) = (o(i, j), o(i + 1, j), o(i + 1, j + 1), o(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
            let (a, b, c, d) = (inn(i, j), inn(i + 1, j), inn(i + 1, j + 1), inn(i, j + 1));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    let last_i = n_stations.saturating_sub(1);
    let last_j = n_profile.saturating_sub(1);
    let mut boundary: Vec<((usize, usize), (usize, usize))> = Vec::new();
    for i in 0..last_i {
        boundary.push(((i, 0), (i + 1, 0)));
        boundary.push(((i + 1, last_j), (i, last_j)));
    }
    for j in 0..last_j {
        boundary.push(((last_i, j), (last_i, j + 1)));
        boundary.push(((0, j + 1), (0, j)));
    }
    for ((ai, aj), (bi, bj)) in boundary {
        let (a, b) = (o(ai, aj), o(bi, bj));
        let (a2, b2) = (inn(ai, aj), inn(bi, bj));
        triangles.push([b, a, a2]);
        triangles.push([b, a2, b2]);
    }
    Ok(MeshData {
        vertices,
        triangles,
    })
}

/// A polyline on the outer surface with cumulative chord lengths.
struct Polyline {
    verts: Vec<SurfaceVertex>,
    cum: Vec<f64>,
}

impl Polyline {
    fn new(verts: Vec<SurfaceVertex>) -> Result<Self, PlanError> {
        let mut cum = Vec::with_capacity(verts.len());
        let mut acc = 0.0;
        cum.push(0.0);
        for w in verts.windows(2) {
            let d = (w[1].point - w[0].point).norm();
            if !(d.is_finite() && d > 0.0) {
                return Err(PlanError::invalid(
                    "bpillar path",
                    "zero-length or non-finite polyline segment",
                ));
            }
            acc += d;
            cum.push(acc);
        }
        if verts.len() < 2 {
            return Err(PlanError::invalid(
                "bpillar path",
                "polyline with fewer than 2 vertices",
            ));
        }
        Ok(Self { verts, cum })
    }

    /// The point at length `l` and the slerp of the end normals of its
    /// segment (the G-code interpolator's QI between two blocks).
    fn at(&self, l: f64) -> Result<SurfaceVertex, PlanError> {
        let total = self.cum.last().copied().unwrap_or(0.0);
        let tol = 1e-12 * total.max(1.0);
        if !(l >= -tol && l <= total + tol) {
            return Err(PlanError::invalid(
                "bpillar path",
                format!("position {l} m is outside the polyline [0, {total}] m"),
            ));
        }
        let k = self
            .cum
            .windows(2)
            .position(|w| l <= w[1])
            .unwrap_or(self.cum.len().saturating_sub(2));
        let (Some(a), Some(b), Some(la), Some(lb)) = (
            self.verts.get(k),
            self.verts.get(k + 1),
            self.cum.get(k),
            self.cum.get(k + 1),
        ) else {
            return Err(PlanError::invalid(
                "bpillar path",
                "polyline index out of range",
            ));
        };
        let lambda = ((l - la) / (lb - la)).clamp(0.0, 1.0);
        Ok(SurfaceVertex {
            point: a.point + (b.point - a.point) * lambda,
            normal: slerp(&a.normal, &b.normal, lambda),
        })
    }

    /// `count` points at `l0 + k spacing`.
    fn sample(&self, l0: f64, spacing: f64, count: usize) -> Result<ClPath, PlanError> {
        // Check both ends before allocating (a huge count fails here).
        let last = l0 + spacing * count.saturating_sub(1) as f64;
        self.at(l0)?;
        self.at(last)?;
        let mut points = Vec::with_capacity(count);
        let mut axes = Vec::with_capacity(count);
        for k in 0..count {
            let v = self.at(l0 + spacing * k as f64)?;
            points.push(round_vec(&v.point, COORD_SCALE));
            axes.push(round_vec(&v.normal, AXIS_SCALE));
        }
        Ok(ClPath {
            points,
            axes,
            spacing,
        })
    }
}

/// Spherical linear interpolation between unit vectors `a` and `b`:
/// `(sin((1-λ)θ) a + sin(λθ) b) / sin θ`, θ = ∠(a, b) (Shoemake 1985, the
/// vector form of quaternion slerp); normalised linear interpolation when
/// θ is tiny.
fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, lambda: f64) -> Vector3<f64> {
    let theta = a.cross(b).norm().atan2(a.dot(b));
    let v = if theta < 1e-9 {
        a * (1.0 - lambda) + b * lambda
    } else {
        let s = theta.sin();
        a * (((1.0 - lambda) * theta).sin() / s) + b * ((lambda * theta).sin() / s)
    };
    v.normalize()
}

/// `x` rounded to a multiple of `1 / scale` (`scale` a power of ten, so
/// the result prints as a short decimal); negative zero becomes zero.
fn round_to(x: f64, scale: f64) -> f64 {
    let y = (x * scale).round() / scale;
    if y == 0.0 {
        0.0
    } else {
        y
    }
}

/// `v` rounded componentwise with [`round_to`].
fn round_vec(v: &Vector3<f64>, scale: f64) -> [f64; 3] {
    [
        round_to(v.x, scale),
        round_to(v.y, scale),
        round_to(v.z, scale),
    ]
}

/// Case 1 of seed 001 (section 3.1, Table 1): a long side trim along the
/// left flange of the pillar body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrimCaseParams {
    /// Feedrate f (m/s). Table 1: 20 m/min.
    pub feedrate: f64,
    /// Controller sample period Δt (s). Table 1: 0.01 s.
    pub sample_period: f64,
    /// Lead angle limit (rad). Table 1: 5°.
    pub max_lead_angle: f64,
    /// Tilt angle limit (rad). Table 1: 5°.
    pub max_tilt_angle: f64,
    /// Path length (m), rounded to a whole number of `f Δt`. Default 0.8.
    pub length: f64,
    /// Spine arc length of the first CL point (m). Default 0.6 (the
    /// path then lies on the curved body part, 0.05 m clear of both ends).
    pub start: f64,
    /// Distance of the trim line from the flange fillet (m). Default
    /// 0.075: the fork arms (0.115 m from the tool axis) reach the wall
    /// when they point across the cut, the housings (≤ 0.05 m to the
    /// side) clear it when the arms point along the cut.
    pub trim_offset: f64,
    /// Number of initial RTOs, evenly spaced (Figure 8: six).
    pub rto_count: usize,
    /// Roll of the workpiece about the machine x axis (rad), after
    /// levelling the flange at the middle of the path. Default 1°: the
    /// tool axis passes 1° from the vertical, where q4 = atan2(O_y, O_x)
    /// swings by about 140° along the path.
    pub roll: f64,
    /// Machine-frame centre of the bounding box of the nominal M points
    /// `C + 0.07 O` (m). Default (0.8, 0.7, 1.0), the middle of the q1, q2
    /// strokes.
    pub m_center: [f64; 3],
}

impl Default for TrimCaseParams {
    fn default() -> Self {
        Self {
            feedrate: 20.0 / 60.0,
            sample_period: 0.01,
            max_lead_angle: 5f64.to_radians(),
            max_tilt_angle: 5f64.to_radians(),
            length: 0.8,
            start: 0.6,
            trim_offset: 0.075,
            rto_count: 6,
            roll: 1f64.to_radians(),
            m_center: [0.8, 0.7, 1.0],
        }
    }
}

/// Case 2 of seed 001 (section 3.2, Table 1): a cut across the hat section
/// of the foot with two 77° turns of the tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerCaseParams {
    /// Feedrate f (m/s). Table 1: 15 m/min.
    pub feedrate: f64,
    /// Controller sample period Δt (s). Table 1: 4 ms.
    pub sample_period: f64,
    /// Lead angle limit (rad). Table 1: 15°.
    pub max_lead_angle: f64,
    /// Tilt angle limit (rad). Table 1: 10°.
    pub max_tilt_angle: f64,
    /// Number of CL points. Section 3.2: 628 (2.51 s at 4 ms).
    pub points: usize,
    /// Spine arc length of the cut plane (m). Default 0.125, the middle of
    /// the uniform foot (the fork arms, 0.115 m to either side, stay over
    /// the uniform section).
    pub station: f64,
    /// Path length on the flange before its fillet (m). Default 0.1.
    pub flange_run: f64,
    /// Yaw of the workpiece about the machine z axis (rad). Default 30°,
    /// so that the cut runs along no machine axis.
    pub yaw: f64,
    /// Machine-frame centre of the bounding box of the nominal M points
    /// (m). Default (0.8, 0.7, 1.0).
    pub m_center: [f64; 3],
}

impl Default for CornerCaseParams {
    fn default() -> Self {
        Self {
            feedrate: 15.0 / 60.0,
            sample_period: 0.004,
            max_lead_angle: 15f64.to_radians(),
            max_tilt_angle: 10f64.to_radians(),
            points: 628,
            station: 0.125,
            flange_run: 0.1,
            yaw: 30f64.to_radians(),
            m_center: [0.8, 0.7, 1.0],
        }
    }
}

/// Builds the case 1 request ([`TrimCaseParams`]).
///
/// The workpiece is pitched so that the flange is level at the middle of
/// the path, then rolled by `roll`; it is placed so that the nominal M
/// points (q6 = the default reference standoff) are centred on `m_center`.
/// The initial RTOs are `rto_count` evenly spaced CL points.
///
/// # Errors
/// [`PlanError::InvalidRequest`] for parameters out of range (non-finite,
/// non-positive feedrate / period / length, fewer than 2 RTOs or more than
/// points) or a path that leaves the uniform body flange.
pub fn trim_case(pillar: &BPillar, p: &TrimCaseParams) -> Result<CutRequest, PlanError> {
    let spacing = path_spacing(p.feedrate, p.sample_period)?;
    if !(p.length.is_finite() && p.length > spacing) {
        return Err(PlanError::invalid(
            "case1.length",
            format!("{} must exceed f Δt", p.length),
        ));
    }
    let steps = (p.length / spacing).round();
    if steps > 1e7 {
        return Err(PlanError::invalid(
            "case1.length",
            format!("{} m gives more than 1e7 CL points", p.length),
        ));
    }
    let count = steps as usize + 1;
    if p.rto_count < 2 || p.rto_count > count {
        return Err(PlanError::invalid(
            "case1.rto_count",
            format!("{} must be in [2, {count}]", p.rto_count),
        ));
    }
    let path = pillar.flange_trim_path(p.trim_offset, p.start, spacing, count)?;
    let mid = pillar
        .spine
        .eval(p.start + 0.5 * spacing * (count - 1) as f64);
    // R_y(α) turns the tangent (cos α, 0, sin α) onto x̂, the flange normal
    // u onto ẑ; then the roll about x.
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), p.roll)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), mid.alpha);
    let rto = (0..p.rto_count)
        .map(|k| ((k * (count - 1)) as f64 / (p.rto_count - 1) as f64).round() as usize)
        .collect();
    make_request(
        "bpillar-case1-side-trim",
        path,
        rotation,
        p.m_center,
        Process {
            feedrate: p.feedrate,
            sample_period: p.sample_period,
            max_lead_angle: p.max_lead_angle,
            max_tilt_angle: p.max_tilt_angle,
        },
        rto,
    )
}

/// Builds the case 2 request ([`CornerCaseParams`]).
///
/// Ten initial RTOs at the key waypoints: start, middle of the flange run,
/// both ends of the flange fillet, middle of the wall, both ends of the
/// top fillet, two points on the top, end. The nominal axes at the two
/// ends of each fillet differ by the wall angle (77°); every other pair of
/// adjacent RTOs has the same nominal axis.
///
/// # Errors
/// [`PlanError::InvalidRequest`] for parameters out of range or a path
/// that does not end on the top ([`BPillar::section_path`]).
pub fn corner_case(pillar: &BPillar, p: &CornerCaseParams) -> Result<CutRequest, PlanError> {
    let spacing = path_spacing(p.feedrate, p.sample_period)?;
    let (path, marks) = pillar.section_path(p.station, p.flange_run, spacing, p.points)?;
    let [f1s, f1e, f2s, f2e] = marks;
    let end = spacing * (p.points - 1) as f64;
    // Fillet starts round down and fillet ends round up to a CL point, so
    // the RTOs beside each fillet sit on the flat pieces and their nominal
    // axes differ by exactly the wall angle.
    let down = |l: f64| (l / spacing + 1e-9).floor() as usize;
    let up = |l: f64| (l / spacing - 1e-9).ceil() as usize;
    let near = |l: f64| (l / spacing).round() as usize;
    let rto = vec![
        0,
        near(0.5 * f1s),
        down(f1s),
        up(f1e),
        near(0.5 * (f1e + f2s)),
        down(f2s),
        up(f2e),
        near(f2e + (end - f2e) / 3.0),
        near(f2e + 2.0 * (end - f2e) / 3.0),
        p.points - 1,
    ];
    if rto.windows(2).any(|w| w[1] <= w[0]) {
        return Err(PlanError::invalid(
            "case2",
            format!("the key waypoints fall on the same CL points: {rto:?}"),
        ));
    }
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), p.yaw);
    make_request(
        "bpillar-case2-corner",
        path,
        rotation,
        p.m_center,
        Process {
            feedrate: p.feedrate,
            sample_period: p.sample_period,
            max_lead_angle: p.max_lead_angle,
            max_tilt_angle: p.max_tilt_angle,
        },
        rto,
    )
}

fn path_spacing(feedrate: f64, sample_period: f64) -> Result<f64, PlanError> {
    for (name, v) in [("feedrate", feedrate), ("sample_period", sample_period)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(PlanError::invalid(
                name,
                format!("{v} must be finite and > 0"),
            ));
        }
    }
    Ok(feedrate * sample_period)
}

/// The process parameters of Table 1 that go into a request unchanged.
#[derive(Debug, Clone, Copy)]
struct Process {
    feedrate: f64,
    sample_period: f64,
    max_lead_angle: f64,
    max_tilt_angle: f64,
}

/// Assembles a request: places the workpiece (rotation, then the
/// translation that centres the nominal M points `M = C - q6 O` (seed 001
/// eq. 2, C = M + q6 O), q6 = the default reference standoff, on
/// `m_center`, rounded to 1 mm).
fn make_request(
    id: &str,
    path: ClPath,
    rotation: UnitQuaternion<f64>,
    m_center: [f64; 3],
    process: Process,
    rto_indices: Vec<usize>,
) -> Result<CutRequest, PlanError> {
    if m_center.iter().any(|v| !v.is_finite()) || !rotation.coords.iter().all(|v| v.is_finite()) {
        return Err(PlanError::invalid("workpiece placement", "not finite"));
    }
    for (name, a) in [
        ("max_lead_angle", process.max_lead_angle),
        ("max_tilt_angle", process.max_tilt_angle),
    ] {
        if !(a.is_finite() && a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
            return Err(PlanError::invalid(
                name,
                format!("{a} rad must be in (0, π/2)"),
            ));
        }
    }
    let q6 = CutOptions::default().reference_standoff;
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for (c, o) in path.points.iter().zip(&path.axes) {
        let c = rotation * Point3::new(c[0], c[1], c[2]);
        let o = rotation * Vector3::new(o[0], o[1], o[2]);
        let m = c.coords - o * q6;
        lo = lo.inf(&m);
        hi = hi.sup(&m);
    }
    let centre = (lo + hi) * 0.5;
    let mm = |v: f64| round_to(v, 1e3);
    let position = [
        mm(m_center[0] - centre.x),
        mm(m_center[1] - centre.y),
        mm(m_center[2] - centre.z),
    ];
    let q = rotation.quaternion();
    let r = |v: f64| round_to(v, AXIS_SCALE);
    let workpiece_pose = PoseSpec {
        position,
        orientation: [r(q.i), r(q.j), r(q.k), r(q.w)],
    };
    Ok(CutRequest {
        request_id: id.to_owned(),
        points: path.points,
        axes: path.axes,
        feedrate: process.feedrate,
        feed_acceleration: 8.0,
        feed_jerk: 80.0,
        sample_period: process.sample_period,
        max_lead_angle: process.max_lead_angle,
        max_tilt_angle: process.max_tilt_angle,
        mesh: MESH_REFERENCE.to_owned(),
        workpiece_pose,
        options: CutOptions {
            rto_indices,
            ..CutOptions::default()
        },
    })
}

/// Angles (rad) between the nominal tool axes of adjacent initial RTOs
/// (`options.rto_indices`) of a request.
///
/// # Errors
/// [`PlanError::InvalidRequest`] when an RTO index is out of range or an
/// axis is not finite.
pub fn rto_angle_changes(req: &CutRequest) -> Result<Vec<f64>, PlanError> {
    let axis = |i: usize| -> Result<Vector3<f64>, PlanError> {
        let a = req.axes.get(i).ok_or_else(|| {
            PlanError::invalid(
                "options.rto_indices",
                format!("index {i} is beyond the {} axes", req.axes.len()),
            )
        })?;
        let v = Vector3::new(a[0], a[1], a[2]);
        if v.iter().all(|c| c.is_finite()) {
            Ok(v)
        } else {
            Err(PlanError::invalid(format!("axes[{i}]"), "not finite"))
        }
    };
    req.options
        .rto_indices
        .windows(2)
        .map(|w| {
            let (a, b) = (axis(w[0])?, axis(w[1])?);
            Ok(a.cross(&b).norm().atan2(a.dot(&b)))
        })
        .collect()
}

/// A request as a YAML document with a comment header.
///
/// # Arguments
/// * `req` - the request (serialized with serde_yaml_ng, the schema of
///   [`CutRequest`]).
/// * `title` - first header line (what the request is).
///
/// # Errors
/// [`PlanError::InvalidRequest`] if serialization fails.
pub fn request_yaml(req: &CutRequest, title: &str) -> Result<String, PlanError> {
    let body =
        serde_yaml_ng::to_string(req).map_err(|e| PlanError::invalid("request", e.to_string()))?;
    Ok(format!(
        "# {title}\n\
         # Workpiece: {MESH_REFERENCE} (kerf_mjto::bpillar, a B-pillar-like hat section).\n\
         # Points and axes in the workpiece frame (m); SI units throughout.\n\
         # Generated by kerf_mjto::bpillar - do not edit. Regenerate from the repository root with\n\
         #   {REGENERATE_COMMAND}\n\
         {body}"
    ))
}

/// Everything [`generate`] builds.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The workpiece (default parameters).
    pub pillar: BPillar,
    /// Case 1 (default [`TrimCaseParams`]).
    pub case1: CutRequest,
    /// Case 2 (default [`CornerCaseParams`]).
    pub case2: CutRequest,
}

/// Builds the default workpiece and both requests.
///
/// # Errors
/// Only if the defaults were inconsistent ([`PlanError::InvalidRequest`]).
pub fn generate() -> Result<Generated, PlanError> {
    let pillar = BPillar::new(BPillarParams::default())?;
    let case1 = trim_case(&pillar, &TrimCaseParams::default())?;
    let case2 = corner_case(&pillar, &CornerCaseParams::default())?;
    Ok(Generated {
        pillar,
        case1,
        case2,
    })
}

/// Title lines of the two request files.
const CASE1_TITLE: &str = "kerf MJTO cut request, case 1 of seed 001 (section 3.1, Table 1): \
                           0.8 m side trim along the left flange, tool axis near vertical, six RTOs.";
const CASE2_TITLE: &str = "kerf MJTO cut request, case 2 of seed 001 (section 3.2, Table 1): \
                           cut across the foot (flange, fillet, wall, fillet, top), two 77 deg \
                           turns, ten RTOs.";

/// Generates and writes `urdf/meshes/bpillar.obj` and
/// `crates/mjto/cases/case{1,2}.yaml` under `root` (creating the
/// directories).
///
/// # Returns
/// What was written, and the three file paths (mesh, case 1, case 2).
///
/// # Errors
/// Any I/O error; a generation error as `ErrorKind::InvalidData`.
pub fn write_files(root: &Path) -> std::io::Result<(Generated, [PathBuf; 3])> {
    let invalid =
        |e: PlanError| std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string());
    let g = generate().map_err(invalid)?;
    let paths = [
        root.join(MESH_FILE),
        root.join(CASE1_FILE),
        root.join(CASE2_FILE),
    ];
    for p in &paths {
        if let Some(dir) = p.parent() {
            std::fs::create_dir_all(dir)?;
        }
    }
    let [mesh_path, case1_path, case2_path] = &paths;
    mesh::write_obj(mesh_path, g.pillar.mesh())?;
    std::fs::write(
        case1_path,
        request_yaml(&g.case1, CASE1_TITLE).map_err(invalid)?,
    )?;
    std::fs::write(
        case2_path,
        request_yaml(&g.case2, CASE2_TITLE).map_err(invalid)?,
    )?;
    Ok((g, paths))
}
