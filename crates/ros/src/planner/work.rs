//! What the worker process runs for the harness: a request (as received) to its answer.

use std::{sync::Arc, time::Duration};

use kerf_budget::{Budget, CancelToken};
use serde::{Deserialize, Serialize};

use kerf_approach::FrameSettings;

use super::{
    check_points, check_trajectory_msg,
    framing::{frame_trajectory, unframed},
    start::{resolve_start, CurrentState},
    Failure, PlanAnswer, PlanningService,
};

/// A request as it was received, sent to the worker process (which converts it again: a
/// converted request need not cross a process boundary).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum RawRequest<M> {
    /// A request message.
    Msg(M),
    /// The `data` of a text request.
    Text(String),
}

/// What the harness hands its worker process: the request as received, and the robot's
/// joint state when the plan was handed over (for a request that starts where the robot is).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PlanJob<M> {
    /// The request.
    pub raw: RawRequest<M>,
    /// The robot's latest joint state, if the node has received one.
    pub current: Option<CurrentState>,
}

/// Work for the planner thread. Failed requests travel through it too, so that every answer
/// leaves in arrival order.
pub enum Job<R, A> {
    /// Plan this request.
    Plan(Box<R>),
    /// Already answered (conversion or parse error): pass the answer through.
    Answer(Box<A>),
}

/// Plans a converted request under `budget`, frames it with an approach and a retract when it
/// has a start, and checks the answer as the harness publishes it.
///
/// 1. The request's start ([`PlanningService::start_of`]) is resolved against `current`
///    ([`resolve_start`]); a start that cannot be used is [`Failure::BadStart`].
/// 2. With a start, the service's [`PlanningService::surroundings`] are built and the start
///    checked against them before planning: closer than the approach clearance is
///    [`Failure::NoApproach`], naming the obstacle.
/// 3. The plan; a failure is the answer.
/// 4. With a start, the plan is framed ([`super::framing::frame_trajectory`]): no
///    collision-free approach or retract is [`Failure::NoApproach`]. The answer's
///    `stretches` say where the trajectory starts and where the process starts and ends.
/// 5. A successful answer whose trajectory the executor would refuse
///    ([`check_trajectory_msg`]) becomes [`Failure::NotExecutable`], one with too many points
///    [`Failure::TooLarge`].
pub fn plan_checked<S: PlanningService>(
    service: &S,
    request: S::Request,
    budget: &Budget,
    framing: &FrameSettings,
    current: Option<&CurrentState>,
) -> S::Answer {
    let key = service.key(&request);
    let start = match resolve_start(&service.start_of(&request), current, service.joint_limits()) {
        Ok(s) => s,
        Err(reason) => return service.failure(&key, Failure::BadStart, reason),
    };
    let world = match &start {
        None => None,
        Some((_, q)) => {
            let world = match service.surroundings(&request) {
                Ok(w) => w,
                Err(answer) => return *answer,
            };
            let c = world.clearance(q, false);
            // NaN is not clear either.
            if !matches!(
                c.distance.partial_cmp(&framing.clearance()),
                Some(std::cmp::Ordering::Greater | std::cmp::Ordering::Equal)
            ) {
                return service.failure(
                    &key,
                    Failure::NoApproach,
                    format!(
                        "the start configuration {q:?} is {} m from '{}', inside the approach \
                         clearance {} m: move the robot clear of it first",
                        c.distance,
                        c.obstacle,
                        framing.clearance()
                    ),
                );
            }
            Some(world)
        }
    };
    let mut answer = service.plan(request, budget);
    if !answer.is_success() {
        return answer;
    }
    match (&start, &world) {
        (Some((kind, q)), Some(world)) => {
            match frame_trajectory(
                *kind,
                q,
                answer.trajectory(),
                service.approach_limits(),
                world.as_ref(),
                framing,
            ) {
                Ok((trajectory, stretches)) => {
                    answer.set_trajectory(trajectory);
                    answer.set_stretches(stretches);
                }
                Err((reason, blocked)) => {
                    let failure = if blocked {
                        Failure::NoApproach
                    } else {
                        Failure::NotExecutable
                    };
                    return service.failure(&key, failure, reason);
                }
            }
        }
        _ => {
            let stretches = unframed(answer.trajectory());
            answer.set_stretches(stretches);
        }
    }
    // Checked before anything renders the answer (its YAML text would be ~6× its size).
    let trajectory = answer.trajectory();
    if let Err(reason) = check_points(trajectory.points.len(), trajectory.joint_names.len()) {
        return service.failure(&key, Failure::TooLarge, reason);
    }
    match check_trajectory_msg(service.joint_limits(), answer.trajectory()) {
        Ok(()) => answer,
        Err(reason) => service.failure(
            &key,
            Failure::NotExecutable,
            format!(
                "the planned trajectory would be refused by the trajectory executor ({reason}); \
                 it is not published (a planner bug)"
            ),
        ),
    }
}

/// Runs one job in the calling thread: an already-answered job passes through; a job queued
/// after the node began to stop is answered [`Failure::Stopped`] without planning; a plan
/// runs under a budget of `plan_timeout` (tightened by the request's own, started now, and
/// cancelled by `cancel`) and is checked ([`plan_checked`]).
///
/// The node runs its plans in a worker process ([`HarnessWork`]); this is the same work
/// in-process, for tools and tests.
pub fn work<S: PlanningService>(
    service: &S,
    cancel: &CancelToken,
    plan_timeout: Duration,
    job: Job<S::Request, S::Answer>,
) -> S::Answer {
    let request = match job {
        Job::Answer(m) => return *m,
        Job::Plan(r) => r,
    };
    if cancel.is_cancelled() {
        // Queued when the node stopped: skipped, so that shutdown waits for one plan at most.
        return service.failure(
            &service.key(&request),
            Failure::Stopped,
            "the planner node stopped before planning this request".into(),
        );
    }
    let budget = Budget::new(Some(plan_timeout), cancel.clone())
        .tightened(service.requested_budget(&request));
    // No robot state in-process: a request plans from its given start, or from its first
    // point.
    plan_checked(service, *request, &budget, &FrameSettings::default(), None)
}

/// The harness's work in the worker process: convert the request as received, plan it under
/// the budget the supervisor gives (the request's time limit, the cancel token, `plan_memory`)
/// and check the answer ([`plan_checked`]).
pub struct HarnessWork<S> {
    /// The planning service (the worker's copy of the node's).
    pub service: Arc<S>,
    /// How plans with a start are framed (the node's `approach.*` and `retract.*`).
    pub framing: FrameSettings,
}

impl<S: PlanningService> kerf_isolate::Work for HarnessWork<S> {
    type Job = PlanJob<S::RequestMsg>;
    type Answer = S::Answer;

    fn run(&self, job: Self::Job, budget: &Budget) -> S::Answer {
        let PlanJob { raw, current } = job;
        let converted = match &raw {
            RawRequest::Msg(m) => self.service.request_from_msg(m),
            RawRequest::Text(t) => self.service.request_from_text(t),
        };
        drop(raw);
        match converted {
            Ok(request) => plan_checked(
                &*self.service,
                request,
                budget,
                &self.framing,
                current.as_ref(),
            ),
            Err(answer) => *answer,
        }
    }
}
