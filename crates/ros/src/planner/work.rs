//! What the worker process runs for the harness: a request (as received) to its answer.

use std::{sync::Arc, time::Duration};

use kerf_budget::{Budget, CancelToken};
use serde::{Deserialize, Serialize};

use super::{check_points, check_trajectory_msg, Failure, PlanAnswer, PlanningService};

/// A request as it was received, sent to the worker process (which converts it again: a
/// converted request need not cross a process boundary).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum RawRequest<M> {
    /// A request message.
    Msg(M),
    /// The `data` of a text request.
    Text(String),
}

/// Work for the planner thread. Failed requests travel through it too, so that every answer
/// leaves in arrival order.
pub enum Job<R, A> {
    /// Plan this request.
    Plan(Box<R>),
    /// Already answered (conversion or parse error): pass the answer through.
    Answer(Box<A>),
}

/// Plans a converted request under `budget` and checks the answer as the harness publishes
/// it: a successful plan whose trajectory the executor would refuse
/// ([`check_trajectory_msg`]) becomes [`Failure::NotExecutable`], one with too many points
/// [`Failure::TooLarge`].
pub fn plan_checked<S: PlanningService>(
    service: &S,
    request: S::Request,
    budget: &Budget,
) -> S::Answer {
    let key = service.key(&request);
    let answer = service.plan(request, budget);
    if !answer.is_success() {
        return answer;
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
    plan_checked(service, *request, &budget)
}

/// The harness's work in the worker process: convert the request as received, plan it under
/// the budget the supervisor gives (the request's time limit, the cancel token, `plan_memory`)
/// and check the answer ([`plan_checked`]).
pub struct HarnessWork<S> {
    /// The planning service (the worker's copy of the node's).
    pub service: Arc<S>,
}

impl<S: PlanningService> kerf_isolate::Work for HarnessWork<S> {
    type Job = RawRequest<S::RequestMsg>;
    type Answer = S::Answer;

    fn run(&self, job: Self::Job, budget: &Budget) -> S::Answer {
        let converted = match &job {
            RawRequest::Msg(m) => self.service.request_from_msg(m),
            RawRequest::Text(t) => self.service.request_from_text(t),
        };
        drop(job);
        match converted {
            Ok(request) => plan_checked(&*self.service, request, budget),
            Err(answer) => *answer,
        }
    }
}
