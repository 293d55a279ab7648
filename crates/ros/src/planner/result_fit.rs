//! What a planning-action result can carry: one datagram (issue 27, item 3).
//!
//! RustDDS 0.15.1 writes a malformed `DATA_FRAG` submessage for every fragmented sample that
//! carries inline QoS (`DataFrag::write_to` writes the `Option<ParameterList>` with speedy's
//! one-byte `Some` tag that `content_length` does not count and no reader expects). Every
//! service reply carries inline QoS (the related sample identity, with either service
//! mapping), so a reply larger than one datagram never arrives (in debug builds the writer's
//! `debug_assert` panics its participant's event loop instead). An action result is a service
//! reply: the harness therefore sends only results that fit one datagram, leaving out what
//! does not fit — the full answer is always on the latched `~/<noun>_plan` topic, under the
//! same `request_id`:
//!
//! 1. the whole result;
//! 2. the plan without its trajectory's points (the joint names, stretches, metrics stay);
//! 3. only the plan's request id, status and message;
//! 4. that message cut to fit.
//!
//! The datagram a writer fills is what RustDDS allows for the reader's locators: the
//! loopback interface's (about 64 KiB) when every participant is on 127.0.0.1
//! (`ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`), else 1452 bytes (an Ethernet MTU).

use super::{cdr_bytes, goal_msgs::PlanResult, PlanAnswer};
use crate::DiscoveryRange;

/// The largest result (CDR bytes) sent when every participant is on the loopback interface.
pub const LOOPBACK_RESULT_BYTES: usize = 60_000;

/// The largest result (CDR bytes) sent when participants may be on other interfaces (1452
/// bytes of datagram, less the RTPS headers, the related sample identity and a heartbeat).
pub const NETWORK_RESULT_BYTES: usize = 1_200;

/// The largest result sent under a discovery range.
pub fn result_limit(range: DiscoveryRange) -> usize {
    match range {
        DiscoveryRange::Localhost => LOOPBACK_RESULT_BYTES,
        DiscoveryRange::Subnet | DiscoveryRange::SystemDefault => NETWORK_RESULT_BYTES,
    }
}

/// Bytes of the reply around the result (the goal status, the request/reply header).
const REPLY_OVERHEAD: usize = 64;

fn fits<A: PlanAnswer>(result: &PlanResult<A>, limit: usize) -> bool {
    cdr_bytes(result).is_some_and(|n| n + REPLY_OVERHEAD <= limit)
}

/// The result as sent: `result`, or less of it (module docs) so that it fits `limit` bytes.
/// `plan_topic` names where the full answer is.
pub fn fit_result<A: PlanAnswer>(
    result: PlanResult<A>,
    limit: usize,
    plan_topic: &str,
) -> PlanResult<A> {
    if fits(&result, limit) {
        return result;
    }
    let full = cdr_bytes(&result).unwrap_or(0);
    let original = result.plan.message().to_string();
    let note = |what: &str| {
        format!(
            " [{what} left out of this action result ({full} bytes, over the {limit} bytes one \
             datagram carries): the full answer is on {plan_topic}]"
        )
    };
    let mut without_points = result.clone();
    let mut trajectory = result.plan.trajectory().clone();
    trajectory.points = Vec::new();
    without_points.plan.set_trajectory(trajectory);
    without_points
        .plan
        .set_message(format!("{original}{}", note("the trajectory's points")));
    if fits(&without_points, limit) {
        return without_points;
    }
    let mut summary = PlanResult {
        plan: result.plan.summary(),
        ..result
    };
    let note = note("everything but the status and this message");
    summary.plan.set_message(format!("{original}{note}"));
    if fits(&summary, limit) {
        return summary;
    }
    // Cut the messages until the result fits.
    summary.execution_message = shorten(&summary.execution_message, 200);
    let tail = format!(" [cut to fit one datagram: the full answer is on {plan_topic}]");
    let mut keep = original.len();
    loop {
        summary
            .plan
            .set_message(format!("{}{tail}", shorten(&original, keep)));
        if keep == 0 || fits(&summary, limit) {
            return summary;
        }
        keep = keep.saturating_sub(keep / 4 + 16);
    }
}

/// The first `max` bytes of `text` (at a character boundary), with " …" when cut.
fn shorten(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_string();
    }
    let mut end = max;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{} …", text.get(..end).unwrap_or(""))
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_msgs::{
        msg::CutPlan,
        trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    };

    fn result(points: usize, message: &str) -> PlanResult<CutPlan> {
        PlanResult {
            plan: CutPlan {
                request_id: "job".into(),
                message: message.into(),
                trajectory: JointTrajectory {
                    joint_names: vec!["q1".into(); 6],
                    points: vec![
                        JointTrajectoryPoint {
                            positions: vec![0.5; 6],
                            velocities: vec![0.5; 6],
                            accelerations: vec![0.5; 6],
                            ..JointTrajectoryPoint::default()
                        };
                        points
                    ],
                    ..JointTrajectory::default()
                },
                ..CutPlan::default()
            },
            executed: true,
            execution_error_code: 0,
            execution_message: "SUCCEEDED".into(),
        }
    }

    #[test]
    fn small_results_go_whole() {
        let r = result(3, "planned");
        assert_eq!(fit_result(r.clone(), LOOPBACK_RESULT_BYTES, "/p"), r);
    }

    #[test]
    fn large_results_lose_their_points_then_everything_but_the_message() {
        let r = result(1000, "planned");
        let fitted = fit_result(r.clone(), LOOPBACK_RESULT_BYTES, "/mjto_planner/cut_plan");
        assert!(fitted.plan.trajectory.points.is_empty());
        assert_eq!(fitted.plan.trajectory.joint_names.len(), 6);
        assert!(
            fitted.plan.message.starts_with("planned ["),
            "{}",
            fitted.plan.message
        );
        assert!(fitted.plan.message.contains("/mjto_planner/cut_plan"));
        assert!(fitted.executed);
        assert!(fits(&fitted, LOOPBACK_RESULT_BYTES));

        let mut big = result(10, "planned");
        big.plan.rtos = vec![Default::default(); 200];
        let fitted = fit_result(big, NETWORK_RESULT_BYTES, "/p");
        assert!(fitted.plan.rtos.is_empty());
        assert!(fitted.plan.trajectory.joint_names.is_empty());
        assert_eq!(fitted.plan.request_id, "job");
        assert!(fits(&fitted, NETWORK_RESULT_BYTES));

        let long = result(10, &"é".repeat(5000));
        let fitted = fit_result(long, NETWORK_RESULT_BYTES, "/p");
        assert!(fits(&fitted, NETWORK_RESULT_BYTES));
        assert!(
            fitted.plan.message.contains(" … [cut to fit"),
            "{}",
            fitted.plan.message
        );
        assert!(fitted.plan.message.starts_with("éé"));
    }
}
