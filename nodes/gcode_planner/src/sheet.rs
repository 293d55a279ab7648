//! The laser cutter's surroundings for the approach and retract of a G-code program (issue
//! 27): the cutting head ([`HeadModel`]) against the sheet the program cuts, by exact distance
//! ([`CollisionWorld::distance_up_to`]); the tool axis by the machine's kinematics (seed 001
//! eq. 2).
//!
//! # The sheet model
//! A G-code request names no workpiece mesh: the program is cut in its own XY plane, placed
//! at the request's `origin` (default [`kerf_gcodeplan::machine::laser::DEFAULT_SHEET_ORIGIN`],
//! on the sheet surface: `kerf_gcodeplan::LaserSheet`, the CL point `C = origin + p`). The
//! sheet is modelled as the closed surface of a box:
//!
//! * its top face in the program's plane z = 0 (machine z = `origin.z`),
//!   [`SHEET_THICKNESS`] thick below it;
//! * in x and y, the extent of every point of the program (each run's polyline and the
//!   program's start, [`kerf_gcodeplan::read_steps`]) grown by [`SHEET_MARGIN`] on each side.
//!
//! So the head keeps its clearance from the part being cut and from the sheet around it; a
//! sheet larger than the program (and the table under it) is not modelled. The nozzle cuts
//! without contact (1 mm standoff, `urdf/laser_cutter.urdf`), so the process leaves nothing
//! out.

use kerf_approach::{ApproachError, Clearance, JointLimit, Surroundings};
use kerf_gcodeplan::{GcodePlanError, GcodeRequest, ProgramSource, Step};
use kerf_mjto::{
    collision::{CollisionWorld, HeadModel},
    mesh::MeshData,
};
use nalgebra::Isometry3;

/// Distances are exact up to this far (m); farther ones count as this far (a lower bound,
/// which keeps the certification sound). 0.25 m is more than any clearance plus the farthest
/// a head point moves in one control period at the velocity limits.
pub const EXACT_UP_TO: f64 = 0.25;

/// How far the modelled sheet reaches beyond the program's points in x and y (m): more than
/// the nozzle body's radius (25 mm, `urdf/laser_cutter.urdf`), so the sheet is under the whole
/// nozzle wherever it cuts.
pub const SHEET_MARGIN: f64 = 0.05;

/// Thickness of the modelled sheet below the program's plane (m): a typical laser-cut sheet
/// (the distance is to the box's surface, so it only places the bottom face).
pub const SHEET_THICKNESS: f64 = 0.01;

/// The head and the sheet of one request.
pub struct SheetSurroundings {
    world: CollisionWorld,
    lipschitz: Vec<f64>,
    limits: Vec<JointLimit>,
    name: String,
}

/// The machine-frame box `[min, max]` of the sheet of `request` (module documentation).
///
/// # Errors
/// The request's own errors ([`GcodeRequest::settings`], [`GcodeRequest::source`], a
/// program file that cannot be opened) and the program reader's
/// ([`kerf_gcodeplan::read_steps`]): the planner would refuse the request the same way.
pub fn sheet_box(request: &GcodeRequest) -> Result<([f64; 3], [f64; 3]), GcodePlanError> {
    let settings = request.settings()?;
    let reading = match request.source()? {
        ProgramSource::Text(text) => kerf_gcodeplan::read_steps(text.as_bytes(), &settings)?,
        ProgramSource::File(path) => {
            kerf_gcodeplan::read_steps(kerf_gcodeplan::open_program(&path)?, &settings)?
        }
    };
    let points = reading
        .steps
        .iter()
        .filter_map(|s| match s {
            Step::Run(run) => Some(run.points.iter()),
            _ => None,
        })
        .flatten()
        .chain(std::iter::once(&reading.start));
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let origin = request
        .origin
        .unwrap_or(kerf_gcodeplan::machine::laser::DEFAULT_SHEET_ORIGIN);
    let min = [
        origin[0] + lo[0] - SHEET_MARGIN,
        origin[1] + lo[1] - SHEET_MARGIN,
        origin[2] - SHEET_THICKNESS,
    ];
    let max = [
        origin[0] + hi[0] + SHEET_MARGIN,
        origin[1] + hi[1] + SHEET_MARGIN,
        origin[2],
    ];
    if min.iter().chain(&max).any(|v| !v.is_finite()) {
        return Err(GcodePlanError::InvalidRequest {
            field: "program".into(),
            reason: format!("the sheet under the program is not finite: {min:?} to {max:?}"),
        });
    }
    Ok((min, max))
}

impl SheetSurroundings {
    /// The head over the sheet of `request` ([`sheet_box`]).
    ///
    /// # Errors
    /// As [`sheet_box`]; [`GcodePlanError::InvalidRequest`] naming `machine` when the
    /// collision world cannot be built.
    pub fn new(
        head: HeadModel,
        limits: Vec<JointLimit>,
        request: &GcodeRequest,
    ) -> Result<Self, GcodePlanError> {
        let (min, max) = sheet_box(request)?;
        let lipschitz = head.lipschitz().to_vec();
        let world = CollisionWorld::new(
            head,
            &MeshData::cuboid(min, max),
            &Isometry3::identity(),
            0.0,
        )
        .map_err(|e| GcodePlanError::InvalidRequest {
            field: "machine".into(),
            reason: format!("the head over the sheet: {e}"),
        })?;
        let name = format!(
            "sheet (x {:.3}..{:.3}, y {:.3}..{:.3}, top z {:.3} m)",
            min[0], max[0], min[1], max[1], max[2]
        );
        Ok(Self {
            world,
            lipschitz,
            limits,
            name,
        })
    }
}

impl Surroundings for SheetSurroundings {
    /// The head's distance to the sheet (0 touching or through its surface). The laser cuts
    /// without contact, so the process leaves nothing out.
    fn clearance(&self, q: &[f64], _process: bool) -> Clearance {
        let Ok(q6) = <[f64; 6]>::try_from(q) else {
            return Clearance::new(f64::NAN, "no distance: a configuration has 6 joints");
        };
        match self.world.distance_up_to(&q6, EXACT_UP_TO) {
            Ok(Some(d)) => {
                Clearance::new(d.distance, format!("{} (head link {})", self.name, d.link))
            }
            Ok(None) => Clearance::new(EXACT_UP_TO, self.name.clone()),
            Err(e) => Clearance::new(f64::NAN, format!("{}: {e}", self.name)),
        }
    }

    /// The head's per-joint bounds ([`HeadModel::lipschitz`], with their proof).
    fn lipschitz(&self) -> Vec<f64> {
        self.lipschitz.clone()
    }

    /// The gantry moves the rotary-axes centre `M = (q1, q2, q3)` by `distance` along the tool
    /// axis `O(q4, q5)` (seed 001 eq. 2: `C = M + q6 O`, the head above the part along `O`);
    /// the head's orientation and standoff are unchanged.
    ///
    /// # Errors
    /// [`ApproachError::JointCount`]; the limit errors of
    /// [`kerf_approach::limits::check_configuration`] naming the joint out of its stroke.
    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError> {
        kerf_mjto::kinematics::tool_axis_back_off(q, distance, &self.limits)
    }
}
