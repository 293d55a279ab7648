//! [`ApproachPlanner`]: the approach from the robot's current state to the first process
//! point, direct or via a safe pose, certified clear.

use crate::limits::{check_configuration, check_limits};
use crate::{
    ApproachError, ApproachSettings, Clearance, ClearanceCheck, ClosestSample, JointLimit,
    JointMove, Role, Route, Verdict, Violation, WaypointMove,
};

/// A move the planner built and certified clear.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedMove {
    /// The motion, every leg a whole number of control periods long.
    pub path: WaypointMove,
    /// Which route it takes.
    pub route: Route,
    /// The configuration that came closest to an obstacle, and how close.
    pub closest: ClosestSample,
}

/// Plans approaches (and retracts, [`ApproachPlanner::retract`]) for one robot in one
/// collision world, generic over both: the robot is its [`JointLimit`]s and Lipschitz
/// bounds, the world is a clearance function.
pub struct ApproachPlanner<'w> {
    settings: ApproachSettings,
    limits: Vec<JointLimit>,
    check: ClearanceCheck,
    world: &'w dyn Fn(&[f64]) -> Clearance,
}

impl std::fmt::Debug for ApproachPlanner<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ApproachPlanner")
            .field("settings", &self.settings)
            .field("limits", &self.limits)
            .finish_non_exhaustive()
    }
}

impl<'w> ApproachPlanner<'w> {
    /// A planner for the robot of `limits` in the world of `world`.
    ///
    /// # Arguments
    /// * `settings` – clearance, control period, Lipschitz bounds, safe poses.
    /// * `limits` – one [`JointLimit`] per joint, in the order of every configuration.
    /// * `world` – the clearance function: the signed distance (m) from the robot at a
    ///   configuration to the nearest obstacle, and that obstacle's name (see [`Clearance`]).
    ///
    /// # Returns
    /// The planner, or an error for invalid limits, a Lipschitz list of another length than
    /// the limits ([`ApproachError::JointCount`]), or a safe pose outside the position limits
    /// ([`ApproachError::OutOfLimits`] naming [`Role::SafePose`], the joint and the value).
    pub fn new(
        settings: ApproachSettings,
        limits: Vec<JointLimit>,
        world: &'w dyn Fn(&[f64]) -> Clearance,
    ) -> Result<Self, ApproachError> {
        check_limits(&limits)?;
        if settings.lipschitz().len() != limits.len() {
            return Err(ApproachError::JointCount {
                what: "lipschitz".into(),
                expected: limits.len(),
                found: settings.lipschitz().len(),
            });
        }
        for (i, pose) in settings.safe_poses().iter().enumerate() {
            check_configuration(Role::SafePose(i), pose, &limits)?;
        }
        let check = ClearanceCheck::new(
            settings.clearance(),
            settings.control_period(),
            settings.lipschitz().to_vec(),
        )?;
        Ok(Self {
            settings,
            limits,
            check,
            world,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &ApproachSettings {
        &self.settings
    }

    /// The joint limits.
    pub fn limits(&self) -> &[JointLimit] {
        &self.limits
    }

    /// The clearance check the planner applies.
    pub fn clearance_check(&self) -> &ClearanceCheck {
        &self.check
    }

    /// The approach from `start` (the robot's current joint state, at rest) to `goal` (the
    /// first process point).
    ///
    /// 1. `start` and `goal` must be inside the position limits and at least the clearance
    ///    from every obstacle.
    /// 2. The direct [`JointMove`], timed to a whole number of control periods, is checked
    ///    by [`ClearanceCheck`]; if clear, it is the answer.
    /// 3. Otherwise each safe pose in turn: `start → safe pose → goal`, both legs
    ///    rest-to-rest and checked the same way; the first clear one is the answer.
    /// 4. Otherwise [`ApproachError::NoApproach`] with the direct move's violation and each
    ///    safe pose's (obstacle, time, configuration, distance): never a move into an
    ///    obstacle.
    ///
    /// # Returns
    /// The [`CheckedMove`]; or [`ApproachError::OutOfLimits`] (and the other configuration
    /// errors) naming [`Role::Start`] or [`Role::Goal`], [`ApproachError::InCollision`],
    /// [`ApproachError::MoveTooLong`], [`ApproachError::InvalidClearance`],
    /// [`ApproachError::NoApproach`].
    ///
    /// # Performance
    /// Dominated by the clearance queries: about `duration / control_period` per route tried
    /// (see [`ClearanceCheck::check`]).
    pub fn approach(&self, start: &[f64], goal: &[f64]) -> Result<CheckedMove, ApproachError> {
        check_configuration(Role::Start, start, &self.limits)?;
        check_configuration(Role::Goal, goal, &self.limits)?;
        self.clear_endpoint(Role::Start, start)?;
        self.clear_endpoint(Role::Goal, goal)?;
        let direct = match self.checked(&[start, goal], Route::Direct)? {
            Ok(found) => return Ok(found),
            Err(v) => v,
        };
        let mut via = Vec::with_capacity(self.settings.safe_poses().len());
        for (i, pose) in self.settings.safe_poses().iter().enumerate() {
            match self.checked(&[start, pose.as_slice(), goal], Route::ViaSafePose(i))? {
                Ok(found) => return Ok(found),
                Err(v) => via.push(v),
            }
        }
        Err(ApproachError::NoApproach {
            direct: Box::new(direct),
            via,
        })
    }

    /// Refuses a configuration closer than the clearance to an obstacle.
    pub(crate) fn clear_endpoint(&self, role: Role, q: &[f64]) -> Result<(), ApproachError> {
        let c = (self.world)(q);
        if c.distance.is_nan() {
            return Err(ApproachError::InvalidClearance {
                obstacle: c.obstacle,
                configuration: q.to_vec(),
            });
        }
        if c.distance < self.settings.clearance() {
            return Err(ApproachError::InCollision {
                role,
                obstacle: c.obstacle,
                distance: c.distance,
                clearance: self.settings.clearance(),
            });
        }
        Ok(())
    }

    /// The move through `waypoints` on `route`, timed and checked: `Ok(Ok(move))` when
    /// clear, `Ok(Err(violation))` when not, `Err` for a hard error.
    pub(crate) fn checked(
        &self,
        waypoints: &[&[f64]],
        route: Route,
    ) -> Result<Result<CheckedMove, Violation>, ApproachError> {
        let path = self.timed(waypoints, route)?;
        Ok(match self.check.check(&path, route, self.world)? {
            Verdict::Clear(closest) => Ok(CheckedMove {
                path,
                route,
                closest,
            }),
            Verdict::Blocked(v) => Err(v),
        })
    }

    /// The move through `waypoints`, each leg stretched to the next whole number of control
    /// periods (only slower: every limit still holds), so that samples at the control period
    /// land on every via pose and on the end.
    fn timed(&self, waypoints: &[&[f64]], route: Route) -> Result<WaypointMove, ApproachError> {
        let fastest = WaypointMove::through(waypoints, &self.limits)?;
        let dt = self.settings.control_period();
        let max = self.settings.max_duration();
        if fastest.duration().is_nan() || fastest.duration() > max {
            return Err(ApproachError::MoveTooLong {
                route,
                duration: fastest.duration(),
                max,
            });
        }
        let legs = fastest
            .legs()
            .iter()
            .map(|leg| {
                let mut n = (leg.min_duration() / dt).ceil();
                if n * dt < leg.min_duration() {
                    n += 1.0;
                }
                leg.with_duration(n * dt)
            })
            .collect::<Result<Vec<JointMove>, ApproachError>>()?;
        let path = WaypointMove::from_legs(legs)?;
        if path.duration().is_nan() || path.duration() > max {
            return Err(ApproachError::MoveTooLong {
                route,
                duration: path.duration(),
                max,
            });
        }
        Ok(path)
    }
}
