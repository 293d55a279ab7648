//! Received samples are bounded (issue 11, item 5): a sequence of large samples through
//! `KerfNode::inbox` leaves the process's memory on a plateau (the keep-last depth of
//! samples), not growing by one sample each. Loopback DDS, domain 124. No timing is asserted.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::time::{Duration, Instant};

use kerf_msgs::{std_msgs::StringMsg, RosType};
use kerf_ros::{qos, DiscoveryRange, KerfNode, RosEnv};

/// VmRSS of this process in MiB.
fn rss_mib() -> f64 {
    kerf_ros::memory::status_kib("VmRSS:").unwrap() as f64 / 1024.0
}

#[test]
fn large_samples_reach_a_plateau() {
    const SAMPLE: usize = 2 << 20;
    const COUNT: usize = 40;
    let env = RosEnv {
        domain_id: 124,
        range: DiscoveryRange::Localhost,
        ..RosEnv::default()
    };
    let mut rx = KerfNode::client("bounded_memory_rx", &env).expect("node");
    let mut tx = KerfNode::client("bounded_memory_tx", &env).expect("node");
    let inbox = rx
        .inbox::<StringMsg>("/bounded_memory", StringMsg::ROS_TYPE, qos::commands())
        .unwrap();
    let publisher = tx
        .publisher::<StringMsg>("/bounded_memory", StringMsg::ROS_TYPE, qos::commands())
        .unwrap();
    assert!(tx.wait_for_subscriber(&publisher, Duration::from_secs(30)));
    std::thread::sleep(Duration::from_millis(500));

    let before = rss_mib();
    let mut received = 0;
    for i in 0..COUNT {
        let mut data = format!("{i:08}");
        data.extend(std::iter::repeat_n('x', SAMPLE - 8));
        publisher.publish(StringMsg { data }).unwrap();
        // One at a time, so the writer's history does not grow either.
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            if let Some(m) = inbox.try_recv() {
                let m = m.unwrap();
                assert_eq!(m.data.len(), SAMPLE);
                received += 1;
                break;
            }
            assert!(Instant::now() < deadline, "sample {i} not delivered");
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    let last = rss_mib();
    // RustDDS's writer frees acknowledged samples beyond its depth in a cache cleaning every
    // 6 s; until then the writer side holds every sample published since the last one.
    std::thread::sleep(Duration::from_secs(8));
    let after = rss_mib();
    eprintln!(
        "{COUNT} samples of {} MiB: VmRSS {before:.1} → {last:.1} MiB after the last, {after:.1} MiB 8 s later",
        SAMPLE >> 20
    );
    assert_eq!(received, COUNT);
    // Both ends of the topic are in this process: the writer keeps its last 10 samples, the
    // reader's topic cache its last 10 (RustDDS's default kept 64: 80 MiB here, growing by
    // 2 MiB a sample). The plateau is about 40 MiB; the bound leaves room for the allocator.
    let growth = after - before;
    assert!(
        growth < 64.0,
        "VmRSS grew by {growth:.1} MiB over {COUNT} samples of {} MiB",
        SAMPLE >> 20
    );
    drop(publisher);
    drop(inbox);
    drop(tx);
    drop(rx);
}
