//! The `sim_driver` binary over real DDS on loopback (domains 180-183), driven by a
//! ros2-client node in the test: commands and their delay, faults, the action.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;

use std::time::{Duration, Instant};

use kerf_msgs::{
    builtin_interfaces::{Duration as RosDuration, Time},
    control_msgs::{FollowJointTrajectoryGoal, FollowJointTrajectoryResult},
    sensor_msgs::JointState,
    std_msgs::{Float64MultiArray, StringMsg},
    trajectory_msgs::JointTrajectoryPoint,
};
use ros2_client::{
    action::{GoalId, GoalStatusEnum},
    action_msgs::CancelGoalResponseEnum,
};
use support::{collect_for, drain, until, Client, DriverProcess, Fjt, TIMEOUT};

const JOINTS: [&str; 6] = ["q1", "q2", "q3", "q4", "q5", "q6"];
const INITIAL: [f64; 6] = [0.8, 0.7, 1.5, 0.0, 0.0, -0.05];
const INITIAL_ARG: &str = "0.8,0.7,1.5,0,0,-0.05";

fn args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["--joints", "q1,q2,q3,q4,q5,q6", "--initial", INITIAL_ARG];
    a.extend_from_slice(extra);
    a
}

fn plus(p: &[f64], d: f64) -> Vec<f64> {
    p.iter().map(|x| x + d).collect()
}

fn secs(t: Time) -> f64 {
    t.as_secs_f64()
}

fn fault(p: &ros2_client::Publisher<StringMsg>, text: &str) {
    p.publish(StringMsg { data: text.into() }).unwrap();
}

#[test]
fn a_command_is_measured_after_the_delay_exactly() {
    let mut driver = DriverProcess::start(180, &args(&["--delay", "0.05", "--noise", "0"]));
    let mut client = Client::new(180, "commander");
    let states = client.subscription::<JointState>("/driver/joint_states", 1000);
    let commands = client.publisher::<Float64MultiArray>("/driver/commands");
    client.wait_for_subscriber(&commands);
    let first = until(&states, "a first state", |_| true).pop().unwrap();
    assert_eq!(first.name, JOINTS);
    assert_eq!(first.position, INITIAL, "noise 0: exact");
    assert_eq!(first.velocity, [0.0; 6]);
    let now = secs(Time::now().unwrap());
    assert!(
        (secs(first.header.stamp) - now).abs() < 1.0,
        "wall-clock stamps"
    );

    // A malformed command (5 values) is ignored; a good one is measured 0.05 s later.
    let send = |data: Vec<f64>| {
        commands
            .publish(Float64MultiArray {
                data,
                ..Default::default()
            })
            .unwrap()
    };
    send(vec![0.0; 5]);
    let target = plus(&INITIAL, 0.1);
    drain(&states);
    let sent = secs(Time::now().unwrap());
    send(target.clone());
    let seen = until(&states, "the commanded position", |s| s.position == target);
    let before = &seen[..seen.len() - 1];
    assert!(
        before.iter().all(|s| s.position == INITIAL),
        "only the good command moves"
    );
    let hit = seen.last().unwrap();
    let late = secs(hit.header.stamp) - sent;
    assert!(
        (0.05..0.05 + 0.1).contains(&late),
        "measured {late:.4} s after the command (delay 0.05 s)"
    );
    // The velocity is the finite difference of the noise-free position: a step, then 0.
    assert!(hit.velocity.iter().all(|v| *v > 1.0), "{:?}", hit.velocity);
    let next = until(&states, "the next state", |_| true).pop().unwrap();
    assert_eq!((next.position, next.velocity), (target, vec![0.0; 6]));

    drop(commands);
    drop(states);
    drop(client);
    let status = driver.terminate();
    assert_eq!(status.code(), Some(0), "SIGTERM stops cleanly");
    let err = driver.stderr();
    assert!(
        err.contains("ignored malformed command 1: 5 values for 6 joints"),
        "{err}"
    );
    assert!(err.contains("1 applied, 1 malformed"), "{err}");
}

#[test]
fn faults_change_the_state_stream() {
    let mut driver = DriverProcess::start(181, &args(&["--delay", "0", "--rate", "100"]));
    let mut client = Client::new(181, "injector");
    let states = client.subscription::<JointState>("/driver/joint_states", 1000);
    let faults = client.publisher::<StringMsg>("/driver/fault");
    client.wait_for_subscriber(&faults);
    until(&states, "a first state", |_| true);

    // drop: nothing after the samples in flight; resume: the stream again.
    fault(&faults, "drop");
    std::thread::sleep(Duration::from_millis(100));
    drain(&states);
    assert!(
        collect_for(&states, Duration::from_millis(500)).is_empty(),
        "dropped"
    );
    fault(&faults, "resume");
    until(&states, "states after resume", |_| true);

    // Each one-shot fault gives exactly one such state among normal ones.
    fault(&faults, "nan");
    let got = collect_for(&states, Duration::from_millis(400));
    let nan = got.iter().filter(|s| s.position[0].is_nan()).count();
    assert_eq!(nan, 1, "{} states", got.len());
    assert!(got
        .iter()
        .flat_map(|s| &s.position[1..])
        .all(|x| x.is_finite()));

    fault(&faults, "fewer_joints");
    let got = collect_for(&states, Duration::from_millis(400));
    let fewer: Vec<&JointState> = got.iter().filter(|s| s.name.len() != 6).collect();
    assert_eq!(fewer.len(), 1, "{} states", got.len());
    assert_eq!(fewer[0].name, JOINTS[..5]);
    assert_eq!(fewer[0].position.len(), 5);

    // The state before the fault too: the older stamp is the very next one.
    let mut got = until(&states, "a state before stamp_back", |_| true);
    fault(&faults, "stamp_back");
    got.extend(collect_for(&states, Duration::from_millis(400)));
    let steps: Vec<i64> = got
        .windows(2)
        .map(|w| w[1].header.stamp.as_nanos() - w[0].header.stamp.as_nanos())
        .collect();
    let back: Vec<&i64> = steps.iter().filter(|d| **d < 0).collect();
    assert_eq!(
        back,
        [&-1_000_000_000],
        "one state 1 s older than the one before"
    );

    fault(&faults, "explode");
    std::thread::sleep(Duration::from_millis(100));
    assert!(
        driver.stderr().contains("unknown fault 'explode'"),
        "{}",
        driver.stderr()
    );

    fault(&faults, "die");
    let status = driver
        .wait(Duration::from_secs(5))
        .expect("die ends the process");
    assert_eq!(status.code(), Some(3));
}

/// One goal point: positions, velocities if any, time from start (s).
type Point = (Vec<f64>, Option<Vec<f64>>, f64);

/// A goal over the six joints through `points`.
fn goal(points: &[Point]) -> FollowJointTrajectoryGoal {
    let mut g = FollowJointTrajectoryGoal::default();
    g.trajectory.joint_names = JOINTS.iter().map(|s| s.to_string()).collect();
    g.trajectory.points = points
        .iter()
        .map(|(p, v, t)| JointTrajectoryPoint {
            positions: p.clone(),
            velocities: v.clone().unwrap_or_default(),
            time_from_start: RosDuration::from_secs_f64(*t).unwrap(),
            ..Default::default()
        })
        .collect();
    g
}

/// Sends a goal; its id if accepted.
fn send(action: &Fjt, g: FollowJointTrajectoryGoal) -> Option<GoalId> {
    let (req, id) = action.send_goal(g).unwrap();
    let deadline = Instant::now() + TIMEOUT;
    loop {
        if let Some(r) = action.receive_goal_response(req).unwrap() {
            return r.accepted.then_some(id);
        }
        assert!(Instant::now() < deadline, "no goal response");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn result(action: &Fjt, id: GoalId) -> (GoalStatusEnum, FollowJointTrajectoryResult) {
    let req = action.request_result(id).unwrap();
    let deadline = Instant::now() + TIMEOUT;
    loop {
        if let Some(r) = action.receive_result(req).unwrap() {
            return r;
        }
        assert!(Instant::now() < deadline, "no result for {id:?}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn latest(states: &ros2_client::Subscription<JointState>) -> JointState {
    drain(states);
    until(states, "a fresh state", |_| true).pop().unwrap()
}

#[test]
fn goals_succeed_cancel_preempt_and_are_rejected() {
    let driver = DriverProcess::start(182, &args(&[]));
    let mut client = Client::new(182, "cell");
    let states = client.subscription::<JointState>("/driver/joint_states", 1000);
    let commands = client.publisher::<Float64MultiArray>("/driver/commands");
    let faults = client.publisher::<StringMsg>("/driver/fault");
    let action = client.action_client("/driver/follow_joint_trajectory");
    client.wait_for_subscriber(&commands);
    client.wait_for_subscriber(&faults);
    client.wait_for_action_server(&action);
    until(&states, "a first state", |_| true);

    // Success: Hermite through a moving middle point; a command during the goal is ignored.
    let (mid, end) = (plus(&INITIAL, 0.1), plus(&INITIAL, 0.2));
    let id = send(
        &action,
        goal(&[
            (INITIAL.to_vec(), None, 0.0),
            (mid, Some(vec![0.2; 6]), 0.4),
            (end.clone(), Some(vec![0.0; 6]), 0.8),
        ]),
    )
    .expect("accepted");
    commands
        .publish(Float64MultiArray {
            data: vec![0.0; 6],
            ..Default::default()
        })
        .unwrap();
    let (status, res) = result(&action, id);
    assert_eq!(
        (status, res.error_code),
        (GoalStatusEnum::Succeeded, 0),
        "{res:?}"
    );
    assert_eq!(
        latest(&states).position,
        end,
        "the final state is the last point"
    );
    let feedback = std::iter::from_fn(|| action.receive_feedback(id).unwrap()).count();
    assert!(feedback >= 5, "{feedback} feedback samples in 0.8 s");

    // Cancel: stops where it is and holds.
    let far = plus(&end, 0.5);
    let id = send(&action, goal(&[(end.clone(), None, 0.0), (far, None, 3.0)])).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let req = action.cancel_goal(id).unwrap();
    let deadline = Instant::now() + TIMEOUT;
    let answer = loop {
        if let Some(a) = action.receive_cancel_response(req).unwrap() {
            break a;
        }
        assert!(Instant::now() < deadline, "no cancel response");
        std::thread::sleep(Duration::from_millis(2));
    };
    assert_eq!(answer.return_code, CancelGoalResponseEnum::None);
    let (status, res) = result(&action, id);
    assert_eq!(
        (status, res.error_code),
        (GoalStatusEnum::Canceled, 0),
        "{res:?}"
    );
    std::thread::sleep(Duration::from_millis(50));
    let held = latest(&states).position;
    assert!(
        held[0] > end[0] + 0.01 && held[0] < end[0] + 0.4,
        "{held:?}"
    );
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(latest(&states).position, held, "holds after cancel");

    // Preemption: the slow goal A gives way to B, which starts where A was.
    let a = send(
        &action,
        goal(&[(held.clone(), None, 0.0), (plus(&held, 0.06), None, 3.0)]),
    )
    .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let here = latest(&states).position;
    let b_end = plus(&here, 0.01);
    let b = send(
        &action,
        goal(&[(here, None, 0.0), (b_end.clone(), None, 0.2)]),
    )
    .unwrap();
    let (status, res) = result(&action, a);
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert!(res.error_string.contains("preempted"), "{res:?}");
    let (status, res) = result(&action, b);
    assert_eq!(
        (status, res.error_code),
        (GoalStatusEnum::Succeeded, 0),
        "{res:?}"
    );
    assert_eq!(latest(&states).position, b_end);

    // A first point away from the current position: accepted, then aborted (-4).
    let id = send(&action, goal(&[(plus(&b_end, 0.1), None, 0.5)])).unwrap();
    let (status, res) = result(&action, id);
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(
        res.error_code,
        FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED
    );

    // Rejections: other joint names; any goal under reject_goals; accepted again after.
    let mut wrong = goal(&[(b_end.clone(), None, 0.1)]);
    wrong.trajectory.joint_names[5] = "q7".into();
    assert_eq!(send(&action, wrong), None, "wrong joint names");
    fault(&faults, "reject_goals");
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(send(&action, goal(&[(b_end.clone(), None, 0.1)])), None);
    fault(&faults, "accept_goals");
    std::thread::sleep(Duration::from_millis(100));
    let id = send(&action, goal(&[(b_end, None, 0.1)])).expect("accepted again");
    assert_eq!(result(&action, id).0, GoalStatusEnum::Succeeded);

    let err = driver.stderr();
    for needle in [
        "ignored command 1 received while a goal runs",
        "must be exactly the driver's joints",
        "goals are rejected (fault reject_goals)",
    ] {
        assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    }
}

#[test]
fn joint_state_commands_and_a_scheduled_fault() {
    let driver = DriverProcess::start(
        183,
        &args(&[
            "--namespace",
            "/robot",
            "--command-type",
            "joint_state",
            "--delay",
            "0",
            "--fault",
            "0.3:drop",
        ]),
    );
    let mut client = Client::new(183, "commander");
    let states = client.subscription::<JointState>("/robot/joint_states", 1000);
    let commands = client.publisher::<JointState>("/robot/commands");
    client.wait_for_subscriber(&commands);
    until(&states, "a first state", |_| true);

    let command = |names: &[&str], position: Vec<f64>| JointState {
        name: names.iter().map(|s| s.to_string()).collect(),
        position,
        ..Default::default()
    };
    // Unknown joint: ignored (and no clock start). Reversed names: applied in joint order.
    let mut unknown = JOINTS.to_vec();
    unknown[0] = "q0";
    commands.publish(command(&unknown, vec![0.0; 6])).unwrap();
    let target = plus(&INITIAL, -0.2);
    let reversed: Vec<&str> = JOINTS.iter().rev().copied().collect();
    let sent = secs(Time::now().unwrap());
    commands
        .publish(command(&reversed, target.iter().rev().copied().collect()))
        .unwrap();
    until(&states, "the commanded position", |s| s.position == target);
    // The scheduled drop: the stream stops 0.3 s after that command.
    let got = collect_for(&states, Duration::from_millis(800));
    let last = got.last().expect("states before the drop");
    let stopped = secs(last.header.stamp) - sent;
    assert!(
        (0.25..0.45).contains(&stopped),
        "last state {stopped:.3} s after the command"
    );
    assert!(collect_for(&states, Duration::from_millis(200)).is_empty());
    let err = driver.stderr();
    assert!(err.contains("unknown joint 'q0'"), "{err}");
    assert!(err.contains("fault drop (scheduled)"), "{err}");
}
