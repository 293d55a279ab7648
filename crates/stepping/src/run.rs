//! Running a controller over a course: the per-period loop, the bookkeeping
//! of passed points, and the run's record.

use serde::Serialize;

use crate::{
    course::Course,
    error::StepError,
    lattice::{Action, State},
};

/// What a controller sees at one period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Period index (0 = the first decision).
    pub step: usize,
    /// The axis state now.
    pub state: State,
    /// The next target not yet left behind (0-based among the targets).
    pub target: usize,
    /// Whether a sample already lay in that target's window.
    pub seen: bool,
}

/// A per-period controller: RPRO, an agent, or an agent behind a shield.
pub trait Controller {
    /// The action for this period.
    ///
    /// # Errors
    /// A controller that cannot decide (RPRO with no viable action, a
    /// network that fails).
    fn decide(&mut self, course: &Course, decision: &Decision) -> Result<Action, StepError>;
}

/// How a target was passed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pass {
    /// Index of the point (1 = the first target; 0 is the start).
    pub point: usize,
    /// Sample index of its closest sample inside the window.
    pub step: usize,
    /// Distance [m or rad] of that sample to the point.
    pub error: f64,
}

/// The record of a run: every sample, every action, every pass.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// States at the sample times, the start first (`actions.len() + 1`).
    pub states: Vec<State>,
    /// The action of each period.
    pub actions: Vec<Action>,
    /// One pass per target, in order.
    pub passes: Vec<Pass>,
}

impl Run {
    /// Number of periods (the paper's "steps").
    pub fn steps(&self) -> usize {
        self.actions.len()
    }

    /// Mean distance [m or rad] of the passes to their points (the paper's
    /// "average accuracy").
    pub fn mean_error(&self) -> f64 {
        if self.passes.is_empty() {
            return 0.0;
        }
        self.passes.iter().map(|p| p.error).sum::<f64>() / self.passes.len() as f64
    }

    /// Largest distance of a pass to its point.
    pub fn max_error(&self) -> f64 {
        self.passes.iter().map(|p| p.error).fold(0.0, f64::max)
    }
}

/// Runs `controller` from rest at the start until it rests inside the last
/// point's window.
///
/// Every action is checked against the limits ([`crate::lattice::Lattice::allows`]),
/// and every target must have a sample inside its window before the motion
/// leaves it.
///
/// # Errors
/// * the controller's own error;
/// * [`StepError::Violation`] for an action outside the limits, a target
///   stepped over, or a motion past the last point;
/// * [`StepError::StepCap`] after `max_steps` periods.
///
/// # Performance
/// One `decide` per period plus O(1) bookkeeping.
pub fn run(
    course: &Course,
    controller: &mut dyn Controller,
    max_steps: usize,
) -> Result<Run, StepError> {
    let lat = &course.lattice;
    let last = course.targets() - 1;
    let mut state = State::REST;
    let mut states = vec![state];
    let mut actions = Vec::new();
    let mut passes: Vec<Pass> = Vec::with_capacity(course.targets());
    let mut target = 0usize;
    let mut best: Option<Pass> = None;
    loop {
        let step = actions.len();
        // Leave every window behind that this sample is past.
        while target <= last && state.q > course.windows[target].1 {
            match best.take() {
                Some(p) => passes.push(p),
                None => {
                    return Err(StepError::Violation {
                        step,
                        reason: format!(
                            "point {} stepped over: sample at {:.6} after {:.6}, point at {:.6} \
                             ± {}",
                            target + 1,
                            lat.position(state),
                            lat.position(states[step.saturating_sub(1)]),
                            course.points[target + 1] - course.points[0],
                            course.precision
                        ),
                    })
                }
            }
            target += 1;
        }
        if target > last {
            return Err(StepError::Violation {
                step,
                reason: "the motion passed the last point without stopping on it".to_string(),
            });
        }
        if course.in_window(target, state.q) {
            let error = course.distance_to(target, state.q).abs();
            if best.is_none_or(|b| error < b.error) {
                best = Some(Pass {
                    point: target + 1,
                    step,
                    error,
                });
            }
            if target == last && state.at_rest() {
                if let Some(p) = best.take() {
                    passes.push(p);
                }
                return Ok(Run {
                    states,
                    actions,
                    passes,
                });
            }
        }
        if step >= max_steps {
            return Err(StepError::StepCap {
                max_steps,
                point: target + 1,
                points: course.points.len(),
            });
        }
        let decision = Decision {
            step,
            state,
            target,
            seen: best.is_some(),
        };
        let action = controller.decide(course, &decision)?;
        let u = action.sign();
        if !lat.allows(state, u) {
            let next = state.step(u);
            return Err(StepError::Violation {
                step,
                reason: format!(
                    "{} leaves the limits: v = {:.6}, a = {:.6} (settled v {:.6}; limits v ≤ {}, \
                     |a| ≤ {})",
                    action.name(),
                    lat.velocity(next),
                    lat.acceleration(next),
                    next.settled_velocity() as f64 * lat.unit_v,
                    lat.limits.velocity,
                    lat.limits.acceleration
                ),
            });
        }
        state = state.step(u);
        states.push(state);
        actions.push(action);
    }
}
