//! The parameters of the whole part: foot and body sections, transition,
//! spine and tessellation.

use super::section::HatSection;
use super::MIN_PIECE;
use crate::TestPartError;

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
    /// [`TestPartError::Invalid`] with the field name (`bpillar.*`) for
    /// a non-finite or non-positive length, a thickness not below every
    /// radius, a kink angle outside (0, π/2], zero segment counts, or a
    /// section whose pieces do not fit ([`HatSection::validate`]).
    pub fn validate(&self) -> Result<(), TestPartError> {
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
                return Err(TestPartError::invalid(
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
                return Err(TestPartError::invalid(
                    format!("bpillar.{name}"),
                    format!("{v} m is shorter than {MIN_PIECE} m"),
                ));
            }
        }
        if self.kink_angle > std::f64::consts::FRAC_PI_2 {
            return Err(TestPartError::invalid(
                "bpillar.kink_angle",
                format!("{} rad must be in (0, π/2]", self.kink_angle),
            ));
        }
        if self.kink_radius <= self.thickness || self.spine_radius <= self.thickness {
            return Err(TestPartError::invalid(
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
                return Err(TestPartError::invalid(
                    format!("bpillar.{name}"),
                    format!("{v} must be in [1, 1000]"),
                ));
            }
        }
        if self.curved_length / self.curved_station_spacing > 1000.0 {
            return Err(TestPartError::invalid(
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
