//! The laser cutter's surroundings for the approach and retract of a cut (issue 27): the
//! cutting head against the request's workpiece mesh by exact distance
//! ([`CollisionWorld::distance_up_to`]), the tool axis by the machine's kinematics (seed 001,
//! eq. 2).

use kerf_approach::{ApproachError, Clearance, JointLimit, Surroundings};
use kerf_mjto::{
    collision::{CollisionWorld, HeadModel},
    mesh::MeshData,
    CutRequest, LaserMachine, PlanError,
};

/// Distances are exact up to this far (m); farther ones count as this far (a lower bound,
/// which keeps the certification sound). 0.25 m is more than any clearance plus the farthest
/// a head point moves in one control period at the velocity limits.
pub const EXACT_UP_TO: f64 = 0.25;

/// The head and the request's workpiece.
pub struct LaserSurroundings {
    world: CollisionWorld,
    lipschitz: Vec<f64>,
    limits: Vec<JointLimit>,
    mesh: String,
}

impl LaserSurroundings {
    /// The surroundings of `request` on `machine`: `mesh` (the request's workpiece, as loaded)
    /// at its workpiece pose.
    ///
    /// # Errors
    /// [`PlanError`] for a request that does not validate, a mesh parry cannot use, a head
    /// model the URDF does not give.
    pub fn new(
        machine: &LaserMachine,
        limits: Vec<JointLimit>,
        request: &CutRequest,
        mesh: &MeshData,
    ) -> Result<Self, PlanError> {
        let v = request.validate()?;
        let head = HeadModel::from_urdf(machine.robot().urdf())?;
        let lipschitz = head.lipschitz().to_vec();
        let world = CollisionWorld::new(head, mesh, &v.workpiece_pose, 0.0)?;
        Ok(Self {
            world,
            lipschitz,
            limits,
            mesh: request.mesh.clone(),
        })
    }
}

impl Surroundings for LaserSurroundings {
    /// The head's distance to the workpiece. The laser cuts without contact (the nozzle keeps
    /// its standoff), so the process leaves nothing out.
    fn clearance(&self, q: &[f64], _process: bool) -> Clearance {
        let Ok(q6) = <[f64; 6]>::try_from(q) else {
            return Clearance::new(f64::NAN, "a configuration of 6 joints");
        };
        let name = |link: &str| format!("workpiece {} (head link {link})", self.mesh);
        match self.world.distance_up_to(&q6, EXACT_UP_TO) {
            Ok(Some(d)) => Clearance::new(d.distance, name(d.link)),
            Ok(None) => Clearance::new(EXACT_UP_TO, format!("workpiece {}", self.mesh)),
            Err(e) => Clearance::new(f64::NAN, format!("workpiece {}: {e}", self.mesh)),
        }
    }

    fn lipschitz(&self) -> Vec<f64> {
        self.lipschitz.clone()
    }

    /// The gantry moves the rotary-axes centre `M = (q1, q2, q3)` by `distance` along the tool
    /// axis `O(q4, q5)` (seed 001 eq. 2: `C = M + q6 O`, the head above the part along `O`);
    /// the head's orientation and standoff are unchanged.
    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError> {
        kerf_mjto::kinematics::tool_axis_back_off(q, distance, &self.limits)
    }
}

/// The approach limits of the machine's axes (`names`: the joint names, in order).
pub fn approach_limits(machine: &LaserMachine, names: &[String]) -> Vec<JointLimit> {
    machine
        .limits()
        .iter()
        .zip(names)
        .map(|(l, name)| JointLimit {
            name: name.clone(),
            min_position: l.min,
            max_position: l.max,
            max_velocity: l.vel,
            max_acceleration: l.acc,
            max_jerk: l.jerk,
        })
        .collect()
}
