//! The `~/validate_trajectory` service side of the request thread: a trajectory is prepared
//! like any other (in arrival order, off the control thread; its numbers checked against their
//! declared rules, [`kerf_msgs::numbers`], by the prepare worker) and answered valid or not; a
//! number outside its rule is named as a field of the request
//! (`trajectory.points[2].positions[0]`).

use kerf_executor::SUCCESSFUL;
use kerf_msgs::srv::ValidateTrajectoryResponse;
use ros2_client::RmwRequestId;

use crate::{convert::Rejection, drain, ExecutorNode, Incoming, Job};

impl ExecutorNode {
    pub(crate) fn poll_validate(&mut self) {
        let (requests, error) = drain(|| self.validate_srv.receive_request());
        if let Some(e) = error {
            self.log
                .error(&format!("could not read a validate request: {e}"));
        }
        for (req_id, req) in requests {
            self.enqueue(Job::Validate(req_id), Incoming::Trajectory(req.trajectory));
        }
    }

    pub(crate) fn answer_validate(
        &mut self,
        req_id: RmwRequestId,
        checked: Result<f64, Rejection>,
    ) {
        let resp = match checked {
            Ok(duration) => ValidateTrajectoryResponse {
                valid: true,
                error_code: SUCCESSFUL,
                message: "valid".into(),
                duration,
            },
            Err(rej) => {
                let rej = crate::convert::number_rejection_within(rej, "trajectory.");
                ValidateTrajectoryResponse {
                    valid: false,
                    error_code: rej.code,
                    message: rej.message,
                    duration: 0.0,
                }
            }
        };
        if let Err(e) = self.validate_srv.send_response(req_id, resp) {
            self.log
                .error(&format!("could not answer a validate request: {e:?}"));
        }
    }
}
