//! A restarted planner never answers a request that was already answered (issue 33, item 5):
//! requests are not durable. A cut planner answers five requests sent by a cell controller
//! whose writer is transient-local (as a latched `ros2 topic pub` or a controller that wants
//! late joiners served), is stopped and started again while the controller keeps running; the
//! writer still holds the five and replays them to the new reader. The restarted node answers
//! none of them, and answers the next request once. Loopback DDS, domain 78.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::time::Duration;

use kerf_msgs::{msg::CutPlan, std_msgs::StringMsg, RosType};
use kerf_ros::qos;
use ros2_client::ServiceMapping;

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::{planner::mjto, PlannerClient};

/// Answers come fast: these requests are refused before planning.
const ANSWER: Duration = Duration::from_secs(30);

/// A cut request in the line format that the node refuses before planning (one CL point).
fn request(id: &str) -> String {
    format!(
        "request_id: {id}\nfeedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
         max_tilt_angle: 0.1\nmesh: m.stl\n0.6 0.2 0.1 0 0 1\n"
    )
}

#[test]
fn a_restarted_planner_answers_no_request_twice() {
    let env = support::loopback(78, ServiceMapping::Enhanced);
    let planner = mjto();
    let mut client = PlannerClient::start(&planner, &env, &[]);
    let mut controller = support::client_node("cell_controller", &env);
    let latched = controller
        .publisher::<StringMsg>(
            "/mjto_planner/cut_request_text",
            StringMsg::ROS_TYPE,
            qos::latched(),
        )
        .unwrap();
    assert!(controller.wait_for_subscriber(&latched, Duration::from_secs(60)));
    for k in 0..5 {
        latched
            .publish(StringMsg {
                data: request(&format!("before-{k}")),
            })
            .unwrap();
    }
    let mut first: Vec<String> = (0..5)
        .map(|_| client.next_plan(ANSWER).request_id)
        .collect();
    first.sort();
    assert_eq!(
        first,
        ["before-0", "before-1", "before-2", "before-3", "before-4"]
    );

    client.restart(&planner, &env, &[]);
    // Long enough for a replayed history to arrive and be answered (a refusal takes ms).
    if let Some(again) = client.try_next_plan(Duration::from_secs(4)) {
        panic!(
            "the restarted planner answered '{}' again: {}",
            again.request_id, again.message
        );
    }
    client.send_text(&request("after"));
    let after = client.next_plan(ANSWER);
    assert_eq!(after.request_id, "after");
    assert_eq!(after.status, CutPlan::INVALID_REQUEST, "{}", after.message);
    assert!(
        client.try_next_plan(Duration::from_secs(2)).is_none(),
        "one answer per request"
    );
    client.finish();
    drop(latched);
    drop(controller);
}
