//! [`PlanAnswer`] for kerf's answer messages (implemented here: the trait and the messages
//! live in other crates than the planner nodes).

use kerf_msgs::{
    msg::{CutPlan, GcodePlan, MillPlan, PlanStretches},
    trajectory_msgs::JointTrajectory,
};

use super::{AnswerKey, PlanAnswer};

/// Implements [`PlanAnswer`] for a message with `request_id`, `status`, `message`,
/// `trajectory`, `stretches`, the `SUCCESS` constant and `status_name`; `$label` gives the key's label.
macro_rules! plan_answer {
    ($msg:ty, |$m:ident| $label:expr) => {
        impl PlanAnswer for $msg {
            fn request_id(&self) -> &str {
                &self.request_id
            }
            fn key(&self) -> AnswerKey {
                let $m = self;
                AnswerKey {
                    request_id: self.request_id.clone(),
                    label: $label,
                }
            }
            fn is_success(&self) -> bool {
                self.status == <$msg>::SUCCESS
            }
            fn status(&self) -> u8 {
                self.status
            }
            fn status_name(&self) -> &'static str {
                <$msg>::status_name(self.status).unwrap_or("?")
            }
            fn message(&self) -> &str {
                &self.message
            }
            fn set_message(&mut self, message: String) {
                self.message = message;
            }
            fn summary(&self) -> Self {
                Self {
                    request_id: self.request_id.clone(),
                    status: self.status,
                    message: self.message.clone(),
                    ..Self::default()
                }
            }
            fn trajectory(&self) -> &JointTrajectory {
                &self.trajectory
            }
            fn set_trajectory(&mut self, trajectory: JointTrajectory) {
                self.trajectory = trajectory;
            }
            fn set_stretches(&mut self, stretches: PlanStretches) {
                self.stretches = stretches;
            }
        }
    };
}

plan_answer!(CutPlan, |_m| String::new());
plan_answer!(MillPlan, |m| m.planner.clone());
plan_answer!(GcodePlan, |m| m.method.clone());
