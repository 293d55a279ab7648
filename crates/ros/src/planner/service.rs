//! [`PlanningService`]: what a planner gives the planner-node harness ([`super::run`]).

use std::time::Duration;

use kerf_approach::{JointLimit as ApproachLimit, StartSpec, Surroundings};
use kerf_budget::Budget;
use kerf_executor::JointLimits;
use kerf_msgs::{numbers::NumberFields, trajectory_msgs::JointTrajectory, RosType};
use serde::{de::DeserializeOwned, Serialize};

/// The topics of one planner node, relative to the node (`~/…`), named after what it plans
/// ([`Topics::new`]).
///
/// Every planner node also publishes the planned trajectory on `~/joint_trajectory` (reliable,
/// volatile: a restarted executor must never receive an old plan).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topics {
    /// What the node plans, for log lines ("cut", "mill").
    pub noun: &'static str,
    /// The request message topic, `~/<noun>_request` (reliable, keep-last 10).
    pub request: String,
    /// The text request topic (`std_msgs/String`), `~/<noun>_request_text`.
    pub request_text: String,
    /// The answer topic, `~/<noun>_plan` (reliable, transient-local, keep-last 10).
    pub plan: String,
    /// The answer as YAML text (`std_msgs/String`), `~/<noun>_plan_text` (latched too).
    pub plan_text: String,
}

impl Topics {
    /// The topics of a node planning `noun`s: `~/<noun>_request`, `~/<noun>_request_text`,
    /// `~/<noun>_plan`, `~/<noun>_plan_text`.
    pub fn new(noun: &'static str) -> Self {
        Self {
            noun,
            request: format!("~/{noun}_request"),
            request_text: format!("~/{noun}_request_text"),
            plan: format!("~/{noun}_plan"),
            plan_text: format!("~/{noun}_plan_text"),
        }
    }
}

/// The topic every planner node publishes its successful trajectories on.
pub const TRAJECTORY_TOPIC: &str = "~/joint_trajectory";

/// Who answers a request: its id and a service-defined label (the milling planner's
/// `planner` field; empty where a service has none). Failures the harness answers carry it.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct AnswerKey {
    /// The request's `request_id` (empty when unknown).
    pub request_id: String,
    /// The service's label for the request (e.g. `"ddpg"`), passed back to
    /// [`PlanningService::failure`].
    pub label: String,
}

/// The failures the harness itself answers; the service picks the status of each
/// ([`PlanningService::failure`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Failure {
    /// A sample could not be read (deserialized) at all.
    Unreadable,
    /// `queue_depth` requests are waiting or being planned.
    Busy,
    /// The node stopped before planning the request.
    Stopped,
    /// The planner panicked.
    Panicked,
    /// The planned trajectory fails the executor's own validation
    /// ([`crate::planner::check_trajectory_msg`]): never published as a success.
    NotExecutable,
    /// The request asks for a larger time budget than the node's `plan_timeout` (a request
    /// may ask for less, never more): refused without planning, like an invalid request.
    OverBudget,
    /// The answer would be larger than what is published ([`super::MAX_ANSWER_BYTES`]):
    /// refused before planning when [`PlanningService::answer_size`] tells, else after.
    TooLarge,
    /// A numeric field is not finite, out of its declared range, or denormal where it
    /// divides (`kerf_msgs::numbers`): refused before planning, like an invalid request.
    BadNumber,
    /// The plan did not end by its deadline (`plan_timeout`, or the request's own budget) plus
    /// the harness's grace: its worker was stopped and the request answered by the harness.
    Timeout,
    /// The plan's worker went over the node's `plan_memory` and was stopped.
    ResourceLimit,
    /// The request's start cannot be used: `current` without a recent joint state, a state
    /// with missing or non-finite joints, a moving robot, given positions of the wrong count
    /// or outside the limits (issue 27). Refused like an invalid request.
    BadStart,
    /// No collision-free approach or retract exists, or the start is too close to an
    /// obstacle (issue 27): the message names the stage, obstacle, time and configuration.
    NoApproach,
    /// The request's goal of the planning action was canceled by its client (issue 27, item
    /// 3): taken out of the queue, or its plan stopped. Answered like [`Failure::Stopped`] by
    /// the answer messages that have no canceled status; the message says "canceled".
    Canceled,
}

/// An answer message (`kerf_msgs/msg/CutPlan`, `MillPlan`, …): what the harness reads of it.
pub trait PlanAnswer: RosType + Serialize + DeserializeOwned + Clone + Send + 'static {
    /// The request id it answers.
    fn request_id(&self) -> &str;
    /// The key of failures derived from this answer (request id, service label).
    fn key(&self) -> AnswerKey;
    /// Whether the status is SUCCESS.
    fn is_success(&self) -> bool;
    /// The status code.
    fn status(&self) -> u8;
    /// The status constant's name (`"SUCCESS"`, `"INVALID_REQUEST"`, …; `"?"` if unknown).
    fn status_name(&self) -> &'static str;
    /// The human-readable message.
    fn message(&self) -> &str;
    /// Replaces the message (an action result that had to leave something out says so).
    fn set_message(&mut self, message: String);
    /// Only the request id, status and message (and the service's label), every other field
    /// at its default: what an action result carries when the answer does not fit one
    /// datagram ([`super::result_fit`]).
    fn summary(&self) -> Self;
    /// The planned trajectory (empty on failure).
    fn trajectory(&self) -> &JointTrajectory;
    /// Replaces the trajectory (the harness frames it with approach and retract).
    fn set_trajectory(&mut self, trajectory: JointTrajectory);
    /// Sets where the trajectory starts and its stretches.
    fn set_stretches(&mut self, stretches: kerf_msgs::msg::PlanStretches);
}

/// A planning service: turns requests into answers; the harness ([`super::run`]) does the
/// rest (topics, queue, busy answers, panics, executability check, publishing, shutdown).
///
/// `plan` runs on the harness's worker thread; everything else on the node thread.
pub trait PlanningService: Send + Sync + 'static {
    /// The request message (`kerf_msgs/msg/CutRequest`, …).
    ///
    /// Its numbers are checked against their declared rules ([`NumberFields`]) by the harness
    /// before [`Self::request_from_msg`] sees it ([`Failure::BadNumber`]).
    /// It is also the goal's `request` of the planning action (`~/plan_<noun>`).
    type RequestMsg: RosType + NumberFields + Serialize + DeserializeOwned + Clone + Send + 'static;
    /// A request as the planner takes it (converted, not yet planned).
    type Request: Send + 'static;
    /// The answer message.
    type Answer: PlanAnswer;

    /// The node's topics.
    fn topics(&self) -> Topics;

    /// Converts a request message; a request that cannot be converted is answered with the
    /// returned answer (its status and message).
    fn request_from_msg(&self, msg: &Self::RequestMsg) -> Result<Self::Request, Box<Self::Answer>>;

    /// The key of a request message (its `request_id`, and the label where the service has
    /// one), for an answer given before it is converted (a number outside its rule).
    fn msg_key(&self, msg: &Self::RequestMsg) -> AnswerKey;

    /// Parses a text request (the `data` of a `std_msgs/String`); as [`Self::request_from_msg`].
    fn request_from_text(&self, text: &str) -> Result<Self::Request, Box<Self::Answer>>;

    /// The key of a request (for the answers the harness gives it).
    fn key(&self, request: &Self::Request) -> AnswerKey;

    /// A short description of a request for the log, e.g. `"12 CL points"`.
    fn describe(&self, request: &Self::Request) -> String;

    /// What the answer to `request` will carry (trajectory points, joints, other text that
    /// grows with the request), when it is known before planning: the harness refuses a
    /// request whose answer would be over [`super::MAX_ANSWER_BYTES`] ([`Failure::TooLarge`]).
    /// `None` when not known (the answer is checked after planning). A value the service's
    /// validation refuses may give `None`.
    fn answer_size(&self, request: &Self::Request) -> Option<super::AnswerSize>;

    /// The request's own time budget, if it asks for one (its `time_budget` field). The
    /// harness refuses one over the node's `plan_timeout` ([`Failure::OverBudget`]); a value
    /// the service's own validation refuses may be returned as `None`.
    fn requested_budget(&self, request: &Self::Request) -> Option<Duration>;

    /// Plans a request (on the worker thread) under `budget` (the node's `plan_timeout`,
    /// tightened by the request's own; cancelled when the node stops). The planner checks it
    /// cooperatively and answers TIMEOUT when it runs out. Panics are contained by the
    /// harness and answered [`Failure::Panicked`].
    fn plan(&self, request: Self::Request, budget: &Budget) -> Self::Answer;

    /// An answer carrying only a status and a message, for a failure of the harness.
    fn failure(&self, key: &AnswerKey, failure: Failure, message: String) -> Self::Answer;

    /// The robot model the executor runs plans on: the executability check's limits.
    fn joint_limits(&self) -> &[JointLimits];

    /// Where a request's trajectory starts (its `start` field; issue 27). The harness
    /// resolves it against the robot's joint state and frames the plan with an approach and a
    /// retract ([`super::framing`]).
    fn start_of(&self, request: &Self::Request) -> StartSpec;

    /// The robot's limits for the approach and retract moves (position, velocity,
    /// acceleration, jerk), in the order of [`Self::joint_limits`].
    fn approach_limits(&self) -> &[ApproachLimit];

    /// The robot's surroundings for `request`: the exact distances the approach and retract
    /// keep (the request's workpiece and the cell's objects, the process contact left out on
    /// request) and the tool axis. Called before planning, only for a request with a start.
    ///
    /// # Errors
    /// The answer to give instead (e.g. a workpiece mesh that does not load).
    fn surroundings(
        &self,
        request: &Self::Request,
    ) -> Result<Box<dyn Surroundings>, Box<Self::Answer>>;

    /// The service's part of the start-up log line (machine, cell, policies …).
    fn startup_note(&self) -> String;
}
