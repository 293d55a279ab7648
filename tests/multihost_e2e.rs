//! The cell's nodes on two hosts of one DDS domain (issue 15, item 4).
//!
//! Two Linux network namespaces joined by a veth pair stand for two hosts of a cell network
//! (`support/netns.rs`: private addresses that exist only inside them, created and deleted by
//! the test). Every node uses `ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`, Jazzy's default.
//!
//! * Host A runs the cell: the trajectory executor of the laser cutter (the simulated cell, `hardware:=sim`, kinematic) and
//!   the cell controller, a client node that sends the cut request and watches
//!   `/joint_states` and the trajectory status.
//! * Host B runs the MJTO planner, its trajectory remapped to the executor's input.
//!
//! Case 1 of seed 001 goes request (A) → planner (B) → plan and trajectory (B → A) →
//! executor (A), which runs it to its last point; the veth's counters show the plan crossed
//! the link. A second test shows what happens on a network that blocks multicast: the hosts
//! never discover each other, and `ROS_STATIC_PEERS`, which would be Jazzy's answer, is
//! refused at start-up because RustDDS cannot honour it (README, "Across hosts").
//!
//! Namespaces need root; without them the tests fail with the reason unless
//! `KERF_SKIP_NETNS=1` is set. Domains 130 and 131.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::Path,
    time::{Duration, Instant},
};

use kerf_msgs::{
    msg::{CutPlan, TrajectoryStatus},
    std_msgs::StringMsg,
    RosType,
};
use kerf_ros::{qos, DiscoveryRange, KerfNode, RosEnv, RosError};
use ros2_client::ServiceMapping;

#[path = "support/netns.rs"]
mod netns;
#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use netns::{Host, HostPair, Link};
use support::{expect, take, QUICK};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
/// Waiting for the plan (the planner plans case 1 in well under a second in release builds;
/// debug builds and a busy machine are slower).
const PLANNING: Duration = Duration::from_secs(120);
/// Waiting for the cut to run (case 1 lasts a few seconds of robot time).
const RUNNING: Duration = Duration::from_secs(60);

/// The environment of every node: one domain, discovery over the subnet (Jazzy's default).
fn subnet(domain: u16) -> RosEnv {
    RosEnv {
        domain_id: domain,
        range: DiscoveryRange::Subnet,
        service_mapping: ServiceMapping::Enhanced,
    }
}

/// The executor's hardware parameters on host A: the simulated cell (`kerf_cell`, kinematic,
/// the laser cutter with the B-pillar of case 1), so the cut runs against the cell's robot and
/// its contact checks.
fn cell_hardware() -> Vec<String> {
    vec![
        "hardware:=sim".into(),
        format!("sim_cell:={ROOT}/urdf/cells/laser_bpillar.yaml"),
        "sim_mode:=kinematic".into(),
    ]
}

/// Case 1's request file as text, and its request.
fn case1() -> (String, kerf_mjto::CutRequest) {
    let path = Path::new(ROOT).join("crates/mjto/cases/case1.yaml");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{} is missing or unreadable ({e})", path.display()));
    let request = kerf_mjto::CutRequest::from_yaml(&text).expect("case 1 parses");
    (text, request)
}

/// Bytes received and sent on `host`'s veth end (`ip -s -j link`).
fn veth_bytes(hosts: &HostPair, host: Host) -> (u64, u64) {
    let json = hosts
        .ip_on(host, &["-s", "-j", "link", "show", "type", "veth"])
        .expect("veth statistics");
    let links: serde_json::Value = serde_json::from_str(&json).expect("ip's JSON");
    let stats = &links[0]["stats64"];
    let n = |dir: &str| stats[dir]["bytes"].as_u64().expect("byte counter");
    (n("rx"), n("tx"))
}

#[test]
fn case1_planned_on_one_host_runs_on_another() {
    let Some(hosts) = HostPair::create(Link::Switched) else {
        return;
    };
    let env = subnet(130);
    let (text, request) = case1();
    // The cell starts at the laser cutter's start pose (launch_scripts/params/laser_cutter.yaml);
    // the planner on host B plans from the robot's joint state on host A (issue 27).
    let home = vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05];
    let offline =
        kerf_mjto::planner::Planner::new(kerf_mjto::LaserMachine::default_machine().unwrap())
            .unwrap()
            .plan(&request)
            .unwrap_or_else(|e| panic!("case 1 does not plan offline: {e}"));

    // Host B: the planner, its trajectory going to the executor on host A.
    let (planner_stop, planner) = hosts.on(Host::B, {
        let env = env.clone();
        move || {
            let words = [
                "--ros-args",
                "--disable-rosout-logs",
                "-r",
                "~/joint_trajectory:=/trajectory_executor/joint_trajectory",
            ];
            support::spawn_node(&env, words.map(String::from).to_vec(), |a, e, s| {
                kerf_mjto_planner::run(a, e, s).map_err(|e| e.to_string())
            })
        }
    });

    let before = veth_bytes(&hosts, Host::A);
    // Host A: the cell (executor and controller); everything below runs there.
    let a = {
        let env = env.clone();
        move || {
            let started = Instant::now();
            let mut params = vec![support::initial_positions(&home)];
            params.extend(cell_hardware());
            let (exec_stop, executor) =
                support::spawn_robot_executor(&env, "laser_cutter", &params);
            let mut controller = KerfNode::client("cell_controller", &env).expect("client node");
            let requests = controller
                .publisher(
                    "/mjto_planner/cut_request_text",
                    StringMsg::ROS_TYPE,
                    qos::commands(),
                )
                .expect("request publisher");
            let plans = controller
                .subscription::<CutPlan>(
                    "/mjto_planner/cut_plan",
                    CutPlan::ROS_TYPE,
                    qos::latched(),
                )
                .expect("plan subscription");
            // Discovery across the link, both ways: the planner on B matches the request
            // publisher on A, and A sees the planner's remapped trajectory writer.
            assert!(
                controller.wait_for_subscriber(&requests, 3 * QUICK),
                "the planner on host B was not discovered from host A"
            );
            let (watch, states, statuses) = support::watch_cell(&env, "cut_watch", &home);
            let discovery = started.elapsed();

            requests
                .publish(StringMsg { data: text })
                .expect("publish the request");
            let plan = take(&plans, PLANNING, "cut plan");
            expect(&plan, &request.request_id, CutPlan::SUCCESS, &["planned"]);
            let points = &plan.trajectory.points;
            // It starts where the robot on host A is, and its process stretch is the cut.
            assert_eq!(plan.stretches.start, "current", "{:?}", plan.stretches);
            assert_eq!(points[0].positions, home);
            let at = points
                .iter()
                .position(|p| {
                    (p.time_from_start.as_secs_f64() - plan.stretches.process_start_time).abs()
                        < 1e-9
                })
                .expect("a point at process_start_time");
            for (k, q) in offline.positions.iter().enumerate() {
                for (a, b) in points[at + k].positions.iter().zip(q) {
                    assert!((a - b).abs() < 1e-9, "process point {k} differs");
                }
            }
            let planned: Vec<Vec<f64>> = points.iter().map(|p| p.positions.clone()).collect();
            let largest_step = support::largest_step(&planned);
            let last = planned.last().expect("a planned point").clone();

            // The executor on A runs the trajectory that came from B, to its end.
            let deadline = Instant::now() + RUNNING;
            let mut succeeded = false;
            let mut states_seen = 0;
            let mut moved = 0.0_f64;
            while Instant::now() < deadline && !succeeded {
                succeeded |= support::drain_statuses(&statuses, "case 1")
                    .contains(&TrajectoryStatus::SUCCEEDED);
                while let Ok(Some((s, _))) = states.take() {
                    let off = support::off_plan(&planned, &s.position);
                    assert!(
                        off <= largest_step + 1e-6,
                        "state {:?} is {off} off the plan",
                        s.position
                    );
                    moved = moved.max((s.position[0] - home[0]).abs());
                    states_seen += 1;
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            assert!(
                succeeded,
                "the executor did not finish the cut within {RUNNING:?}"
            );
            let cut_start = &offline.positions[0];
            assert!(
                moved > 0.5 * (cut_start[0] - home[0]).abs(),
                "q1 moved only {moved} m"
            );
            assert!(
                states_seen > 100,
                "{states_seen} joint states during the cut"
            );
            support::assert_rests_at(&states, &last, 1e-4, "case 1");
            println!(
                "discovery across the veth (executor and controller start → planner matched, \
                 trajectory writer seen): {:.2} s; plan of {} points",
                discovery.as_secs_f64(),
                points.len()
            );

            drop((requests, plans, controller, states, statuses, watch));
            exec_stop.stop();
            executor
                .join()
                .expect("executor thread")
                .expect("executor ends cleanly");
            // The serialized trajectory: 3 arrays of 6 doubles per point.
            points.len() * 3 * 6 * 8
        }
    };
    let trajectory_bytes = hosts.on(Host::A, a);
    let after = veth_bytes(&hosts, Host::A);

    // The plan and the trajectory (each carrying every point) came in over the veth.
    let received = after.0 - before.0;
    println!(
        "host A's veth received {received} B during the run ({trajectory_bytes} B of \
         trajectory arrays per message)"
    );
    assert!(
        received as usize > 2 * trajectory_bytes,
        "host A's veth received {received} B, less than the plan and trajectory ({} B each)",
        trajectory_bytes
    );
    planner_stop.stop();
    planner
        .join()
        .expect("planner thread")
        .expect("planner ends cleanly");
}

/// A network that blocks multicast (the hosts on two subnets, joined by a router that
/// forwards unicast only): the hosts reach each other by unicast, but SUBNET discovery, which
/// starts with multicast, does not cross; and `ROS_STATIC_PEERS`, Jazzy's answer for such
/// networks, is refused at start-up with the reason and the workaround, not silently ignored.
#[test]
fn without_multicast_hosts_stay_apart_and_static_peers_are_refused() {
    let Some(hosts) = HostPair::create(Link::Routed) else {
        return;
    };
    let env = subnet(131);
    // Unicast crosses the router: a datagram from A reaches B's address.
    let b = hosts.address(Host::B);
    let receiver = hosts.on(Host::B, move || {
        let socket = std::net::UdpSocket::bind((b, 0)).expect("bind on host B");
        socket.set_read_timeout(Some(QUICK)).expect("read timeout");
        socket
    });
    let to = receiver.local_addr().expect("receiver address");
    hosts.on(Host::A, move || {
        let socket = std::net::UdpSocket::bind(("0.0.0.0", 0)).expect("bind on host A");
        socket.send_to(b"unicast", to).expect("send to host B");
    });
    let mut buf = [0u8; 16];
    let (n, from) = receiver
        .recv_from(&mut buf)
        .expect("host B receives A's datagram");
    assert_eq!(
        (&buf[..n], from.ip()),
        (
            &b"unicast"[..],
            std::net::IpAddr::from(hosts.address(Host::A))
        )
    );

    // Host B: a subscriber, kept until `release` is dropped.
    let (ready_tx, ready) = std::sync::mpsc::channel();
    let (release, held) = std::sync::mpsc::channel::<()>();
    let listener = hosts.spawn_on(Host::B, {
        let env = env.clone();
        move || {
            let mut node = KerfNode::client("listener", &env).expect("client node");
            let sub = node
                .subscription::<StringMsg>("/hello", StringMsg::ROS_TYPE, qos::commands())
                .expect("subscription");
            ready_tx.send(()).expect("signal ready");
            let _ = held.recv();
            drop((sub, node));
        }
    });
    ready
        .recv_timeout(QUICK)
        .expect("the listener on host B started");
    let matched = hosts.on(Host::A, {
        let env = env.clone();
        move || {
            let mut node = KerfNode::client("talker", &env).expect("client node");
            let publisher = node
                .publisher::<StringMsg>("/hello", StringMsg::ROS_TYPE, qos::commands())
                .expect("publisher");
            node.wait_for_subscriber(&publisher, Duration::from_secs(5))
        }
    });
    assert!(
        !matched,
        "the hosts discovered each other without multicast: RustDDS now reaches peers by \
         unicast, so ROS_STATIC_PEERS may be implementable (update README, 'Across hosts')"
    );
    drop(release);
    listener.join().expect("listener thread");

    // What a user on such a network would set, refused with the reason and the workaround.
    let peer = hosts.address(Host::B).to_string();
    let err = RosEnv::from_vars(|k| (k == "ROS_STATIC_PEERS").then(|| peer.clone()))
        .expect_err("ROS_STATIC_PEERS is refused");
    assert!(matches!(err, RosError::UnsupportedEnv { .. }), "{err}");
    let text = err.to_string();
    for needle in ["ROS_STATIC_PEERS", "10.213.2.1", "multicast", "SUBNET"] {
        assert!(text.contains(needle), "{text:?} lacks {needle:?}");
    }
}
