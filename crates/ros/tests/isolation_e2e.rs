//! The planner harness's guarantees that do not depend on the planner (issue 33, items 2, 3
//! and 5), shown with a planning service that misbehaves on purpose, over loopback DDS
//! (domain 125): a plan that never checks its budget is answered TIMEOUT by the harness and
//! the next request is planned by a fresh worker process (the stuck one reaped); a plan that
//! grows without estimating is stopped at `plan_memory` (RESOURCE_LIMIT) while the node's own
//! memory stays put; an estimate over the budget names what grew; a burst over the queue is
//! answered QUEUE_FULL in arrival order; stopping the node mid-plan answers the plan.
//! Timings are printed, never asserted (the bounds below are hang guards).

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::time::{Duration, Instant};

use kerf_budget::Budget;
use kerf_executor::JointLimits;
use kerf_msgs::{msg::GcodePlan, std_msgs::StringMsg, RosType};
use kerf_ros::{
    planner::{self, AnswerKey, AnswerSize, Failure, HarnessSettings, PlanningService, Topics},
    qos, DiscoveryRange, KerfNode, RosArgs, RosEnv, StopToken,
};

/// A service whose requests say how to misbehave: `spin-*` loops without checking its
/// budget, `grow-*` allocates without estimating, `estimate-*` asks its budget for more memory
/// than it has, `cooperate-*` checks its budget until it runs out; anything else is answered at
/// once with the worker's pid.
struct Misbehaving;

fn answer(id: &str, status: u8, message: String) -> GcodePlan {
    GcodePlan {
        request_id: id.to_string(),
        status,
        message,
        ..GcodePlan::default()
    }
}

impl PlanningService for Misbehaving {
    type RequestMsg = StringMsg;
    type Request = String;
    type Answer = GcodePlan;

    fn topics(&self) -> Topics {
        Topics::new("fake")
    }
    fn request_from_msg(&self, msg: &StringMsg) -> Result<String, Box<GcodePlan>> {
        self.request_from_text(&msg.data)
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
    fn plan(&self, request: String, budget: &Budget) -> GcodePlan {
        if request.starts_with("spin") {
            let mut x = 0u64;
            loop {
                x = std::hint::black_box(x.wrapping_add(1));
            }
        }
        if request.starts_with("grow") {
            let mut keep: Vec<Vec<u8>> = Vec::new();
            loop {
                keep.push(vec![7u8; 1 << 20]);
                std::hint::black_box(&keep);
            }
        }
        if request.starts_with("estimate") {
            return match budget.check_memory(u64::MAX / 2, "the estimated samples of 10^12 arcs") {
                Ok(()) => answer(&request, GcodePlan::SUCCESS, "fits?".into()),
                Err(e) => answer(&request, GcodePlan::RESOURCE_LIMIT, e.to_string()),
            };
        }
        if request.starts_with("cooperate") {
            loop {
                if let Err(e) = budget.check("cooperating") {
                    let status = if e.is_timeout() {
                        GcodePlan::TIMEOUT
                    } else {
                        GcodePlan::INTERNAL_ERROR
                    };
                    return answer(&request, status, e.to_string());
                }
                std::thread::sleep(Duration::from_millis(1));
            }
        }
        answer(
            &request,
            GcodePlan::PROGRAM_ERROR,
            format!("planned in pid {}", std::process::id()),
        )
    }
    fn failure(&self, key: &AnswerKey, failure: Failure, message: String) -> GcodePlan {
        let status = match failure {
            Failure::Busy => GcodePlan::QUEUE_FULL,
            Failure::Timeout => GcodePlan::TIMEOUT,
            Failure::ResourceLimit => GcodePlan::RESOURCE_LIMIT,
            Failure::Stopped | Failure::Canceled | Failure::Panicked | Failure::NotExecutable => {
                GcodePlan::INTERNAL_ERROR
            }
            _ => GcodePlan::INVALID_REQUEST,
        };
        answer(&key.request_id, status, message)
    }
    fn joint_limits(&self) -> &[JointLimits] {
        &[]
    }
    fn start_of(&self, _: &String) -> kerf_approach::StartSpec {
        // Plans without a robot: never framed.
        kerf_approach::StartSpec::None
    }
    fn approach_limits(&self) -> &[kerf_approach::JointLimit] {
        &[]
    }
    fn surroundings(
        &self,
        request: &String,
    ) -> Result<Box<dyn kerf_approach::Surroundings>, Box<GcodePlan>> {
        Err(Box::new(answer(
            request,
            GcodePlan::INVALID_REQUEST,
            "this service has no robot".into(),
        )))
    }
    fn startup_note(&self) -> String {
        "misbehaving on purpose".into()
    }
}

fn rss_mib() -> f64 {
    kerf_ros::memory::status_kib("VmRSS:").unwrap() as f64 / 1024.0
}

fn pid_of(plan: &GcodePlan) -> u32 {
    plan.message
        .rsplit(' ')
        .next()
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no pid in {:?}", plan.message))
}

#[test]
fn the_harness_bounds_plans_it_cannot_trust() {
    let env = RosEnv {
        domain_id: 125,
        range: DiscoveryRange::Localhost,
        ..RosEnv::default()
    };
    let stop = StopToken::new();
    let args = RosArgs::parse([
        "--ros-args",
        "-p",
        "plan_timeout:=1.0",
        "-p",
        "plan_memory:=67108864",
        "-p",
        "queue_depth:=2",
    ])
    .unwrap();
    let (env_n, stop_n) = (env.clone(), stop.clone());
    let node = std::thread::spawn(move || {
        planner::run("fake_planner", &[], &args, &env_n, stop_n, |node| {
            let settings = HarnessSettings::from_params(node.params())?;
            Ok::<_, kerf_ros::RosError>((Misbehaving, settings))
        })
    });
    let mut client = KerfNode::client("isolation_client", &env).unwrap();
    let answers = client
        .inbox::<GcodePlan>(
            "/fake_planner/fake_plan",
            GcodePlan::ROS_TYPE,
            qos::latched(),
        )
        .unwrap();
    let requests = client
        .publisher::<StringMsg>(
            "/fake_planner/fake_request",
            StringMsg::ROS_TYPE,
            qos::commands(),
        )
        .unwrap();
    assert!(client.wait_for_subscriber(&requests, Duration::from_secs(30)));
    std::thread::sleep(Duration::from_millis(300));
    let send = |id: &str| requests.publish(StringMsg { data: id.into() }).unwrap();
    let next = || {
        let start = Instant::now();
        loop {
            if let Some(a) = answers.try_recv() {
                return (a.unwrap(), start.elapsed());
            }
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "no answer in 20 s"
            );
            std::thread::sleep(Duration::from_millis(1));
        }
    };

    send("ok-0");
    let (first, _) = next();
    assert_eq!(first.request_id, "ok-0", "{}", first.message);
    let worker = pid_of(&first);
    assert_ne!(worker, std::process::id(), "plans run in a worker process");

    // A plan that never checks its budget: TIMEOUT from the harness at plan_timeout + 0.5 s.
    send("spin-1");
    let (timed_out, took) = next();
    eprintln!(
        "spin-1 answered after {:.3} s: {}",
        took.as_secs_f64(),
        timed_out.message
    );
    assert_eq!(
        (timed_out.request_id.as_str(), timed_out.status),
        ("spin-1", GcodePlan::TIMEOUT)
    );
    assert!(
        timed_out.message.contains("stopped"),
        "{}",
        timed_out.message
    );
    assert!(took >= Duration::from_millis(1500), "{took:?}");
    assert!(
        !std::path::Path::new(&format!("/proc/{worker}")).exists(),
        "the stuck worker is reaped"
    );
    send("ok-2");
    let (fresh, _) = next();
    assert_eq!(fresh.request_id, "ok-2");
    assert_ne!(
        pid_of(&fresh),
        worker,
        "a fresh worker plans the next request"
    );

    // A plan that grows without estimating: stopped at plan_memory; the node does not grow.
    let before = rss_mib();
    send("grow-3");
    let (grown, took) = next();
    eprintln!(
        "grow-3 answered after {:.3} s: {}",
        took.as_secs_f64(),
        grown.message
    );
    assert_eq!(
        (grown.request_id.as_str(), grown.status),
        ("grow-3", GcodePlan::RESOURCE_LIMIT)
    );
    assert!(grown.message.contains("plan_memory"), "{}", grown.message);
    let after = rss_mib();
    assert!(
        after - before < 32.0,
        "node RSS {before:.1} -> {after:.1} MiB"
    );

    // An estimate over the budget names what grew.
    send("estimate-4");
    let (estimated, _) = next();
    assert_eq!(estimated.status, GcodePlan::RESOURCE_LIMIT);
    assert!(
        estimated.message.contains("10^12 arcs"),
        "{}",
        estimated.message
    );

    // A burst over queue_depth 2: one planned, one queued, the rest QUEUE_FULL in arrival order.
    for id in ["cooperate-5", "ok-6", "ok-7", "ok-8", "ok-9"] {
        send(id);
    }
    let mut got: Vec<(String, u8)> = (0..5)
        .map(|_| {
            let (a, _) = next();
            (a.request_id, a.status)
        })
        .collect();
    let busy: Vec<&str> = got
        .iter()
        .filter(|(_, s)| *s == GcodePlan::QUEUE_FULL)
        .map(|(id, _)| id.as_str())
        .collect();
    assert_eq!(busy, ["ok-7", "ok-8", "ok-9"], "{got:?}");
    got.retain(|(_, s)| *s != GcodePlan::QUEUE_FULL);
    assert_eq!(
        got,
        [
            ("cooperate-5".to_string(), GcodePlan::TIMEOUT),
            ("ok-6".to_string(), GcodePlan::PROGRAM_ERROR)
        ]
    );

    // Stopping mid-plan (a plan that ignores cancellation): answered, and the node returns.
    send("spin-10");
    std::thread::sleep(Duration::from_millis(200));
    let stopping = Instant::now();
    stop.stop();
    let (stopped, _) = next();
    assert_eq!(
        (stopped.request_id.as_str(), stopped.status),
        ("spin-10", GcodePlan::INTERNAL_ERROR)
    );
    assert!(stopped.message.contains("stopping"), "{}", stopped.message);
    node.join().unwrap().unwrap();
    eprintln!(
        "the node returned {:.3} s after its stop token",
        stopping.elapsed().as_secs_f64()
    );
    assert!(stopping.elapsed() < Duration::from_secs(10));
    drop(requests);
    drop(answers);
    drop(client);
}
