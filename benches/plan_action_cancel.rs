//! Cancel latency of the planning action (issue 27, item 3): the time from a cancel request
//! to the CANCELED result at the client, for a queued goal and for a plan in progress.
//!
//! Starts `mjto_planner` in this process and a client node, both on loopback (own Contexts,
//! ROS domain 209). Each of `KERF_CANCEL_RUNS` rounds (default 10) sends a long cut goal (case
//! 1 with a 25 × 25 × 15 GFD and an RTO every 2 cm: over a minute of planning), waits until
//! it is being planned plus 50-500 ms (a different point of the plan each round), sends a short
//! goal that queues behind it, then cancels the queued goal and the plan in progress, each
//! measured from `cancel_goal` to the CANCELED result. Prints both distributions and how often
//! the worker had to be stopped (the plan did not answer its cancel within 80 ms).
//!
//! Then the same for a plan that never checks its budget (a planning service whose plan spins,
//! on its own node `stubborn_planner`): the harness stops its worker process 80 ms after the
//! cancel and replaces it; measured from `cancel_goal` to the CANCELED result, and the next
//! goal is answered by a fresh worker.
//!
//! Run: `cargo bench --bench plan_action_cancel`. Timings are reported, never asserted.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::{
    path::Path,
    time::{Duration, Instant},
};

use kerf_mjto::CutRequest;
use kerf_msgs::{
    geometry_msgs::{Point, Pose, Quaternion, Vector3},
    msg::{self, CutPlan},
};
use kerf_msgs::{msg::GcodePlan, std_msgs::StringMsg};
use kerf_ros::{
    planner::{
        self,
        goal_msgs::{PlanFeedback, PlanGoal, PlanResult, Stage},
        HarnessSettings,
    },
    ros2_client::{
        action::{ActionClient, GoalId, GoalStatusEnum},
        RmwRequestId, ServiceMapping,
    },
};

// Shared with the end-to-end tests; the executor helpers are not used here.
#[allow(dead_code)]
#[path = "../tests/support/mod.rs"]
mod support;

type PlanCut = ActionClient<PlanGoal<msg::CutRequest>, PlanResult<CutPlan>, PlanFeedback>;

const TIMEOUT: Duration = Duration::from_secs(30);

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f64 * p).round() as usize]
}

/// Case 1 (message form) with the largest GFD grid and an RTO every 2 cm, or its first nine
/// points (planned in milliseconds).
fn request(id: &str, long: bool) -> msg::CutRequest {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/mjto/cases/case1.yaml");
    let mut r = CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap();
    r.request_id = id.into();
    if long {
        r.options.gfd.q4_steps = 25;
        r.options.gfd.q5_steps = 25;
        r.options.gfd.q6_steps = 15;
        r.options.rto_indices.clear();
        r.options.rto_spacing = 0.02;
    } else {
        r.points.truncate(9);
        r.axes.truncate(9);
        r.options.rto_indices = vec![0, 8];
    }
    let o = &r.options;
    let [px, py, pz] = r.workpiece_pose.position;
    let [qx, qy, qz, qw] = r.workpiece_pose.orientation;
    msg::CutRequest {
        request_id: r.request_id.clone(),
        points: r
            .points
            .iter()
            .map(|p| Point {
                x: p[0],
                y: p[1],
                z: p[2],
            })
            .collect(),
        axes: r
            .axes
            .iter()
            .map(|a| Vector3 {
                x: a[0],
                y: a[1],
                z: a[2],
            })
            .collect(),
        feedrate: r.feedrate,
        sample_period: r.sample_period,
        max_lead_angle: r.max_lead_angle,
        max_tilt_angle: r.max_tilt_angle,
        mesh: r.mesh.clone(),
        workpiece_pose: Pose {
            position: Point {
                x: px,
                y: py,
                z: pz,
            },
            orientation: Quaternion {
                x: qx,
                y: qy,
                z: qz,
                w: qw,
            },
        },
        gfd_q4_steps: o.gfd.q4_steps as u32,
        gfd_q5_steps: o.gfd.q5_steps as u32,
        gfd_q6_steps: o.gfd.q6_steps as u32,
        gfd_q4_half_range: o.gfd.q4_half_range,
        gfd_q5_half_range: o.gfd.q5_half_range,
        rto_indices: o.rto_indices.iter().map(|&i| i as u32).collect(),
        rto_spacing: o.rto_spacing,
        rto_angle: o.rto_angle,
        has_reference_standoff: true,
        reference_standoff: o.reference_standoff,
        ..msg::CutRequest::default()
    }
}

/// Sends a goal, waits for its acceptance and asks for its result.
fn send(client: &PlanCut, request: msg::CutRequest) -> (GoalId, RmwRequestId) {
    let (req, id) = client
        .send_goal(PlanGoal {
            request,
            execute: false,
        })
        .expect("send goal");
    let deadline = Instant::now() + TIMEOUT;
    while client
        .receive_goal_response(req)
        .expect("goal response")
        .is_none()
    {
        assert!(Instant::now() < deadline, "no goal response");
        std::thread::sleep(Duration::from_millis(1));
    }
    (id, client.request_result(id).expect("request result"))
}

/// Waits for a feedback of `goal` at `stage` (other goals' feedback is dropped).
fn wait_stage(client: &PlanCut, goal: GoalId, stage: Stage) {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        while let Ok(Some((m, _))) = client.feedback_subscription().take() {
            if m.goal_id == goal && m.feedback.stage == stage.as_str() {
                return;
            }
        }
        assert!(Instant::now() < deadline, "no {stage:?} feedback");
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Cancels `goal`: the latency (ms) to its CANCELED result, and the result's plan message.
fn cancel<G, A>(
    client: &ActionClient<G, PlanResult<A>, impl kerf_ros::ros2_client::Message>,
    goal: GoalId,
    result: RmwRequestId,
) -> (f64, String)
where
    G: kerf_ros::ros2_client::Message + Clone + 'static,
    A: planner::PlanAnswer,
{
    let at = Instant::now();
    client.cancel_goal(goal).expect("cancel");
    loop {
        if let Some((status, r)) = client.receive_result(result).expect("result") {
            let ms = at.elapsed().as_secs_f64() * 1e3;
            assert_eq!(status, GoalStatusEnum::Canceled, "{}", r.plan.message());
            return (ms, r.plan.message().to_string());
        }
        assert!(at.elapsed() < TIMEOUT, "no result after the cancel");
        std::thread::sleep(Duration::from_micros(200));
    }
}

fn main() {
    let runs: usize = std::env::var("KERF_CANCEL_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10);
    let env = support::loopback(209, ServiceMapping::Enhanced);
    let words = vec![
        "--ros-args".to_string(),
        "--disable-rosout-logs".to_string(),
    ];
    let (stop, planner) = support::spawn_node(&env, words, |a, e, s| {
        kerf_mjto_planner::run(a, e, s).map_err(|e| e.to_string())
    });
    let mut node = support::client_node("plan_action_cancel", &env);
    let client: PlanCut = node
        .action_client("/mjto_planner/plan_cut", "kerf_msgs/action/PlanCut")
        .expect("action client");
    assert!(
        node.wait_for_action_server(&client, TIMEOUT),
        "plan_cut not discovered"
    );

    let (mut queued, mut running) = (Vec::new(), Vec::new());
    let mut stopped = 0;
    println!("| round | planning before the cancel (ms) | queued goal (ms) | plan in progress (ms) | how the plan stopped |");
    println!("|---:|---:|---:|---:|---|");
    for k in 0..runs {
        let (long, long_result) = send(&client, request(&format!("long-{k}"), true));
        wait_stage(&client, long, Stage::Planning);
        let into = 50 + 450 * k as u64 / runs.max(2).saturating_sub(1) as u64;
        std::thread::sleep(Duration::from_millis(into));
        let (short, short_result) = send(&client, request(&format!("short-{k}"), false));
        wait_stage(&client, short, Stage::Queued);
        let (q, _) = cancel(&client, short, short_result);
        let (r, message) = cancel(&client, long, long_result);
        let killed = message.contains("worker process was stopped");
        stopped += usize::from(killed);
        println!(
            "| {k} | {into} | {q:.1} | {r:.1} | {} |",
            if killed {
                "worker stopped after 80 ms"
            } else {
                "answered its cancel"
            }
        );
        queued.push(q);
        running.push(r);
    }
    println!(
        "cancel → CANCELED over loopback DDS, {runs} rounds: queued goal p50 {:.1} ms, max {:.1} \
         ms; plan in progress p50 {:.1} ms, max {:.1} ms; worker stopped in {stopped} of {runs}",
        percentile(&mut queued, 0.5),
        percentile(&mut queued, 1.0),
        percentile(&mut running, 0.5),
        percentile(&mut running, 1.0),
    );
    drop(client);
    drop(node);
    stop.stop();
    let _ = planner.join();
    stubborn(runs);
}

type PlanFake = ActionClient<PlanGoal<StringMsg>, PlanResult<GcodePlan>, PlanFeedback>;

/// The cancel of a plan that never checks its budget, `runs` times.
fn stubborn(runs: usize) {
    let env = support::loopback(208, ServiceMapping::Enhanced);
    let words = vec!["--ros-args".to_string(), "--disable-rosout-logs".into()];
    let (stop, node) = support::spawn_node(&env, words, |args, env, stop| {
        planner::run("stubborn_planner", &[], args, env, stop, |node| {
            let settings = HarnessSettings::from_params(node.params())?;
            Ok::<_, kerf_ros::RosError>((support::stubborn::Stubborn, settings))
        })
        .map_err(|e| e.to_string())
    });
    let mut client_node = support::client_node("stubborn_client", &env);
    let client: PlanFake = client_node
        .action_client("/stubborn_planner/plan_fake", "kerf_msgs/action/PlanFake")
        .expect("action client");
    assert!(client_node.wait_for_action_server(&client, TIMEOUT));
    let mut latency = Vec::new();
    for k in 0..runs {
        let (req, id) = client
            .send_goal(PlanGoal {
                request: StringMsg {
                    data: format!("spin-{k}"),
                },
                execute: false,
            })
            .expect("send goal");
        let deadline = Instant::now() + TIMEOUT;
        while client
            .receive_goal_response(req)
            .expect("goal response")
            .is_none()
        {
            assert!(Instant::now() < deadline, "no goal response");
            std::thread::sleep(Duration::from_millis(1));
        }
        let result = client.request_result(id).expect("request result");
        std::thread::sleep(Duration::from_millis(200));
        let (ms, message) = cancel(&client, id, result);
        assert!(message.contains("worker process was stopped"), "{message}");
        latency.push(ms);
    }
    println!(
        "cancel → CANCELED of a plan that never checks its budget, {runs} rounds: p50 {:.1} \
         ms, max {:.1} ms (worker stopped 80 ms after the cancel, every time)",
        percentile(&mut latency, 0.5),
        percentile(&mut latency, 1.0),
    );
    drop(client);
    drop(client_node);
    stop.stop();
    let _ = node.join();
}
