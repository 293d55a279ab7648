//! One job-shop case: its request, the part it cuts and the outcome the contract
//! demands of a planner.

use kerf_mjto::request::{CutOptions, CutRequest};
use nalgebra::{UnitQuaternion, Vector3};

use super::part::Part;
use super::path::{sample_curve, ClPath};
use crate::placement::workpiece_pose;
use crate::TestPartError;

/// What a planner must answer (issue 16: planned at the requested feed where a machine can
/// make the cut; else the exact refusal of "Bad input").
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Expectation {
    /// The machine can make the cut: a plan at the requested feedrate.
    Plan,
    /// The feed cannot be reached anywhere on the path: INFEASIBLE with the largest feasible
    /// feedrate (within `tolerance`, relative) and the joint that limits it named.
    Infeasible {
        /// The largest feasible feedrate (m/s).
        max_feedrate: f64,
        /// Relative tolerance on it.
        tolerance: f64,
        /// The limiting joint (q1..q6).
        joint: &'static str,
    },
    /// No collision-free orientation inside the lead/tilt allowance at some CL point:
    /// COLLISION naming the point and the reason.
    Collision,
}

/// A generated case.
#[derive(Debug, Clone)]
pub struct JobShopCase {
    /// Short name; the file is `crates/mjto/cases/jobshop/<name>.yaml`.
    pub name: &'static str,
    /// One line saying what the cut is.
    pub title: String,
    /// Name of the part it cuts (`jobshop::Part::name`).
    pub part: &'static str,
    /// True for a closed contour (first point = last point).
    pub closed: bool,
    /// The request.
    pub request: CutRequest,
    /// The answer the contract demands.
    pub expect: Expectation,
}

impl JobShopCase {
    /// A case cutting `curve` on `part` with the workpiece unturned: the curve sampled at the
    /// process's spacing ([`sample_curve`]) and the request assembled ([`make_request`]).
    ///
    /// # Errors
    /// As [`sample_curve`] and [`make_request`].
    pub(super) fn cut(
        name: &'static str,
        title: String,
        part: &Part,
        curve: &dyn Fn(f64) -> (Vector3<f64>, Vector3<f64>),
        closed: bool,
        process: Process,
        expect: Expectation,
    ) -> Result<Self, TestPartError> {
        let path = sample_curve(curve, closed, process.spacing())?;
        Ok(Self {
            name,
            title,
            part: part.name,
            closed,
            request: make_request(
                name,
                part.mesh_reference(),
                path,
                UnitQuaternion::identity(),
                process,
            )?,
            expect,
        })
    }

    /// Repository-relative path of the request file.
    pub fn file(&self) -> String {
        format!("crates/mjto/cases/jobshop/{}.yaml", self.name)
    }
}

/// Process parameters of a request.
#[derive(Debug, Clone, Copy)]
pub(super) struct Process {
    /// Feedrate (m/s).
    pub(super) feedrate: f64,
    /// Controller sample period Δt (s).
    pub(super) sample_period: f64,
    /// Lead and tilt allowances (rad).
    pub(super) lead: f64,
    pub(super) tilt: f64,
}

impl Process {
    /// From the units of a job shop: feed in m/min, Δt in ms, lead and tilt in degrees.
    pub(super) fn shop(feed_m_min: f64, dt_ms: f64, lead_deg: f64, tilt_deg: f64) -> Self {
        Self {
            feedrate: feed_m_min / 60.0,
            sample_period: dt_ms / 1000.0,
            lead: lead_deg.to_radians(),
            tilt: tilt_deg.to_radians(),
        }
    }

    /// The CL spacing `f Δt` (m).
    pub(super) fn spacing(&self) -> f64 {
        self.feedrate * self.sample_period
    }
}

/// Machine-frame centre of the nominal M points of every case (m): the middle of the q1, q2
/// strokes, 1 m up.
const M_CENTER: [f64; 3] = [0.8, 0.7, 1.0];

/// Assembles a request: the workpiece turned by `rotation` and placed so that the bounding
/// box of the nominal M points `M = C − q6 O` (seed 001 eq. 2, q6 the default reference
/// standoff) is centred on [`M_CENTER`], rounded to 1 mm. Options are the defaults
/// (automatic RTOs and control points, clearance 0).
pub(super) fn make_request(
    id: &str,
    mesh: String,
    path: ClPath,
    rotation: UnitQuaternion<f64>,
    process: Process,
) -> Result<CutRequest, TestPartError> {
    let workpiece_pose = workpiece_pose(&path.points, &path.axes, &rotation, M_CENTER);
    if !workpiece_pose.position.iter().all(|v| v.is_finite()) {
        return Err(TestPartError::invalid(id, "empty or non-finite path"));
    }
    Ok(CutRequest {
        start: Default::default(),
        request_id: format!("jobshop-{id}"),
        points: path.points,
        axes: path.axes,
        feedrate: process.feedrate,
        feed_acceleration: 8.0,
        feed_jerk: 80.0,
        sample_period: process.sample_period,
        max_lead_angle: process.lead,
        max_tilt_angle: process.tilt,
        mesh,
        workpiece_pose,
        options: CutOptions::default(),
        time_budget: 0.0,
    })
}
