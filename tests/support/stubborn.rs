//! A planning service whose `spin-*` requests never check their budget (only stopping the
//! worker ends them): the harness's guarantees against a planner that misbehaves, for the
//! planning-action tests and the cancel bench.

use std::time::Duration;

use kerf_msgs::{msg::GcodePlan, std_msgs::StringMsg};
use kerf_ros::planner::{AnswerKey, AnswerSize, Failure, PlanningService, Topics};

/// A planning service whose `spin-*` requests never check their budget (only stopping the
/// worker ends them); anything else is answered at once (PROGRAM_ERROR: it plans nothing)
/// with the worker's pid.
pub struct Stubborn;

fn stubborn_answer(id: &str, status: u8, message: String) -> GcodePlan {
    GcodePlan {
        request_id: id.to_string(),
        status,
        message,
        ..GcodePlan::default()
    }
}

impl PlanningService for Stubborn {
    type RequestMsg = StringMsg;
    type Request = String;
    type Answer = GcodePlan;

    fn topics(&self) -> Topics {
        Topics::new("fake")
    }
    fn request_from_msg(&self, msg: &StringMsg) -> Result<String, Box<GcodePlan>> {
        Ok(msg.data.clone())
    }
    fn msg_key(&self, msg: &StringMsg) -> AnswerKey {
        AnswerKey {
            request_id: msg.data.clone(),
            label: String::new(),
        }
    }
    fn request_from_text(&self, text: &str) -> Result<String, Box<GcodePlan>> {
        Ok(text.to_string())
    }
    fn key(&self, request: &String) -> AnswerKey {
        AnswerKey {
            request_id: request.clone(),
            label: String::new(),
        }
    }
    fn describe(&self, request: &String) -> String {
        request.clone()
    }
    fn answer_size(&self, _: &String) -> Option<AnswerSize> {
        None
    }
    fn requested_budget(&self, _: &String) -> Option<Duration> {
        None
    }
    fn plan(&self, request: String, _: &kerf_budget::Budget) -> GcodePlan {
        if request.starts_with("spin") {
            let mut x = 0u64;
            loop {
                x = std::hint::black_box(x.wrapping_add(1));
            }
        }
        stubborn_answer(
            &request,
            GcodePlan::PROGRAM_ERROR,
            format!("planned in pid {}", std::process::id()),
        )
    }
    fn failure(&self, key: &AnswerKey, failure: Failure, message: String) -> GcodePlan {
        let status = match failure {
            Failure::Busy => GcodePlan::QUEUE_FULL,
            Failure::Stopped | Failure::Canceled | Failure::Panicked => GcodePlan::INTERNAL_ERROR,
            _ => GcodePlan::INVALID_REQUEST,
        };
        stubborn_answer(&key.request_id, status, message)
    }
    fn joint_limits(&self) -> &[kerf_executor::JointLimits] {
        &[]
    }
    fn start_of(&self, _: &String) -> kerf_approach::StartSpec {
        kerf_approach::StartSpec::None
    }
    fn approach_limits(&self) -> &[kerf_approach::JointLimit] {
        &[]
    }
    fn surroundings(
        &self,
        request: &String,
    ) -> Result<Box<dyn kerf_approach::Surroundings>, Box<GcodePlan>> {
        Err(Box::new(stubborn_answer(
            request,
            GcodePlan::INVALID_REQUEST,
            "this service has no robot".into(),
        )))
    }
    fn startup_note(&self) -> String {
        "never checks its budget on purpose".into()
    }
}
