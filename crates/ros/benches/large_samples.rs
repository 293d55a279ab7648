//! Large reliable samples over loopback DDS between two kerf nodes in two processes (issue 11,
//! items 5–6): delivery latency and throughput per sample size, and the receiving process's
//! memory (VmRSS / VmHWM) over a sequence of large samples.
//!
//! `cargo bench -p kerf_ros --bench large_samples -- [options]`
//!
//! * `--msg string|traj` – `std_msgs/String` of N bytes, or a six-joint `JointTrajectory` with
//!   positions, velocities and accelerations sized to about N bytes (default `string`).
//! * `--sizes 65536,262144,…` – throughput phase: sample sizes in bytes (default 64 KiB … 16 MiB).
//! * `--repeat R` – samples per size (default 3; the table gives the median and the worst).
//! * `--depth D` – keep-last depth of both endpoints (default 10, `qos::reliable(D)`).
//! * `--best-effort` – best-effort writer and reader.
//! * `--mem-count K --mem-size N` – memory phase: K samples of N bytes, one after another
//!   (default 24 × 4 MiB; `--mem-count 0` skips it).
//! * `--timeout S` – give up on one sample after S seconds (default 60).
//! * `--domain D` – ROS domain (default 121; only 120–129 are for this bench).
//!
//! Both processes keep DDS on loopback (`DiscoveryRange::Localhost`). The publisher is this
//! process; the subscriber is the same binary started again with `KERF_LS_ROLE=sub`, reading
//! through `KerfNode::inbox` like the nodes do, and reporting each arrival (with its memory
//! after the sample was dropped) on stdout.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::{
    io::{BufRead, BufReader, Write},
    process::{Child, ChildStdin, Command, Stdio},
    sync::mpsc::{channel, Receiver, RecvTimeoutError},
    time::{Duration, Instant},
};

use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    std_msgs::StringMsg,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};
use kerf_ros::{qos, ros2_client::qos::Reliability, DiscoveryRange, KerfNode, RosEnv};
use serde::{de::DeserializeOwned, Serialize};

const TOPIC: &str = "/kerf_bench/large_samples";

#[derive(Debug, Clone)]
struct Opts {
    msg: String,
    sizes: Vec<usize>,
    repeat: usize,
    depth: usize,
    best_effort: bool,
    mem_count: usize,
    mem_size: usize,
    timeout: Duration,
    domain: u16,
}

fn parse_opts() -> Opts {
    let mut o = Opts {
        msg: "string".into(),
        sizes: vec![64 << 10, 256 << 10, 1 << 20, 4 << 20, 16 << 20],
        repeat: 3,
        depth: qos::DEFAULT_DEPTH,
        best_effort: false,
        mem_count: 24,
        mem_size: 4 << 20,
        timeout: Duration::from_secs(60),
        domain: 121,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    let val = |i: usize| args.get(i + 1).cloned().expect("option value");
    while i < args.len() {
        match args[i].as_str() {
            "--msg" => o.msg = val(i),
            "--sizes" => {
                o.sizes = val(i)
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(|s| s.parse().expect("size"))
                    .collect()
            }
            "--repeat" => o.repeat = val(i).parse().expect("repeat"),
            "--depth" => o.depth = val(i).parse().expect("depth"),
            "--best-effort" => {
                o.best_effort = true;
                i += 1;
                continue;
            }
            "--mem-count" => o.mem_count = val(i).parse().expect("count"),
            "--mem-size" => o.mem_size = val(i).parse().expect("size"),
            "--timeout" => o.timeout = Duration::from_secs(val(i).parse().expect("seconds")),
            "--domain" => o.domain = val(i).parse().expect("domain"),
            // `cargo bench` passes --bench; ignore anything else that is not ours.
            _ => {
                i += 1;
                continue;
            }
        }
        i += 2;
    }
    assert!(
        (120..=129).contains(&o.domain),
        "this bench uses domains 120–129"
    );
    o
}

fn env(domain: u16) -> RosEnv {
    RosEnv {
        domain_id: domain,
        range: DiscoveryRange::Localhost,
        ..RosEnv::default()
    }
}

fn node(name: &str, domain: u16) -> KerfNode {
    KerfNode::client(name, &env(domain)).expect("node")
}

fn profile(o: &Opts) -> kerf_ros::ros2_client::QosProfile {
    let p = qos::reliable(o.depth);
    if o.best_effort {
        p.reliability(Reliability::BestEffort)
    } else {
        p
    }
}

/// (VmRSS, VmHWM) of this process in KiB.
fn memory_kib() -> (u64, u64) {
    let field = |name: &str| kerf_ros::memory::status_kib(name).unwrap_or(0);
    (field("VmRSS:"), field("VmHWM:"))
}

/// Serialized (CDR) size of `m` in bytes, as RustDDS sends it (without the 4-byte header).
fn cdr_size<M: Serialize>(m: &M) -> usize {
    struct Count(usize);
    impl Write for Count {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0 += b.len();
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let mut c = Count(0);
    kerf_ros::ros2_client::dds::rustdds::serialization::to_writer_with_rep_id(
        &mut c,
        m,
        kerf_ros::ros2_client::dds::rustdds::RepresentationIdentifier::CDR_LE,
    )
    .expect("serialize");
    c.0
}

/// A message of about `bytes` serialized bytes whose first field tags it with `seq`.
trait Sample: Serialize + DeserializeOwned + Send + 'static {
    const ROS_TYPE: &'static str;
    fn make(seq: u64, bytes: usize) -> Self;
    fn seq(&self) -> u64;
    /// What one unit of the sample costs serialized, for the answer-size limit.
    fn describe(&self) -> String {
        String::new()
    }
}

impl Sample for StringMsg {
    const ROS_TYPE: &'static str = "std_msgs/msg/String";
    fn make(seq: u64, bytes: usize) -> Self {
        let mut data = format!("{seq:020}");
        data.extend(std::iter::repeat_n('x', bytes.saturating_sub(28)));
        Self { data }
    }
    fn seq(&self) -> u64 {
        self.data
            .get(..20)
            .and_then(|s| s.parse().ok())
            .unwrap_or(0)
    }
}

/// Serialized bytes of one six-joint point with positions, velocities, accelerations.
const TRAJ_POINT_BYTES: usize = 3 * (4 + 6 * 8) + 4 + 8;

impl Sample for JointTrajectory {
    const ROS_TYPE: &'static str = "trajectory_msgs/msg/JointTrajectory";
    fn make(seq: u64, bytes: usize) -> Self {
        let n = (bytes / TRAJ_POINT_BYTES).max(1);
        let mut t = JointTrajectory {
            joint_names: (1..=6).map(|j| format!("joint_{j}")).collect(),
            ..Default::default()
        };
        t.header.frame_id = format!("{seq:020}");
        t.points = (0..n)
            .map(|i| {
                let s = i as f64 * 1e-3;
                JointTrajectoryPoint {
                    positions: vec![s.sin(); 6],
                    velocities: vec![s.cos(); 6],
                    accelerations: vec![-s.sin(); 6],
                    effort: Vec::new(),
                    time_from_start: RosDuration {
                        sec: (i / 250) as i32,
                        nanosec: ((i % 250) * 4_000_000) as u32,
                    },
                }
            })
            .collect();
        t
    }
    fn seq(&self) -> u64 {
        self.header.frame_id.parse().unwrap_or(0)
    }
    fn describe(&self) -> String {
        let n = self.points.len() as f64;
        let yaml = serde_yaml_ng::to_string(self).map_or(0, |t| t.len());
        format!(
            "# six-joint point (positions, velocities, accelerations): {:.1} CDR bytes; as YAML (serde_yaml_ng, as on *_plan_text) {:.1} bytes",
            cdr_size(self) as f64 / n,
            yaml as f64 / n
        )
    }
}

// ---------------------------------------------------------------- subscriber process

fn subscriber<M: Sample>(o: &Opts) {
    let mut n = node("large_samples_sub", o.domain);
    let inbox = n.inbox::<M>(TOPIC, M::ROS_TYPE, profile(o)).expect("inbox");
    let out = std::io::stdout();
    let (rss, hwm) = memory_kib();
    writeln!(out.lock(), "ready {rss} {hwm}").unwrap();
    // Commands from the parent: `rss` (report memory now), `quit`.
    let (tx, rx) = channel::<String>();
    std::thread::spawn(move || {
        for line in std::io::stdin().lock().lines() {
            let Ok(l) = line else { break };
            if tx.send(l).is_err() {
                break;
            }
        }
    });
    loop {
        while let Some(r) = inbox.try_recv() {
            let seq = match r {
                Ok(m) => m.seq(),
                Err(e) => {
                    writeln!(out.lock(), "error {e}").unwrap();
                    continue;
                }
            }; // the message is dropped here
            let (rss, hwm) = memory_kib();
            writeln!(out.lock(), "got {seq} {rss} {hwm}").unwrap();
        }
        match rx.try_recv() {
            Ok(c) if c == "rss" => {
                let (rss, hwm) = memory_kib();
                writeln!(out.lock(), "rss {rss} {hwm}").unwrap();
            }
            Ok(c) if c == "quit" => break,
            Ok(_) => {}
            Err(std::sync::mpsc::TryRecvError::Empty) => {
                std::thread::sleep(Duration::from_millis(1))
            }
            Err(_) => break,
        }
    }
    drop(inbox);
    drop(n);
}

// ---------------------------------------------------------------- publisher process

struct Sub {
    child: Child,
    stdin: ChildStdin,
    lines: Receiver<String>,
}

impl Sub {
    fn start(o: &Opts) -> Self {
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args(std::env::args().skip(1))
            .env("KERF_LS_ROLE", "sub")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("subscriber process");
        let stdin = child.stdin.take().unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for l in BufReader::new(stdout).lines() {
                let Ok(l) = l else { break };
                if tx.send(l).is_err() {
                    break;
                }
            }
        });
        let _ = o;
        Self {
            child,
            stdin,
            lines,
        }
    }

    /// The next line starting with `word`, split into its numbers, within `timeout`.
    fn expect(&self, word: &str, timeout: Duration) -> Option<Vec<u64>> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(l) => {
                    let mut it = l.split_whitespace();
                    if it.next() == Some(word) {
                        return Some(it.filter_map(|v| v.parse().ok()).collect());
                    }
                    if l.starts_with("error") {
                        eprintln!("subscriber: {l}");
                    }
                }
                Err(RecvTimeoutError::Timeout) => return None,
                Err(RecvTimeoutError::Disconnected) => return None,
            }
        }
    }

    fn rss(&mut self) -> (u64, u64) {
        writeln!(self.stdin, "rss").unwrap();
        let v = self.expect("rss", Duration::from_secs(10)).unwrap();
        (v[0], v[1])
    }

    fn quit(mut self) {
        let _ = writeln!(self.stdin, "quit");
        let _ = self.child.wait();
    }
}

fn mib(kib: u64) -> f64 {
    kib as f64 / 1024.0
}

fn publisher<M: Sample>(o: &Opts) {
    let mut n = node("large_samples_pub", o.domain);
    let publisher = n
        .publisher::<M>(TOPIC, M::ROS_TYPE, profile(o))
        .expect("publisher");
    let mut sub = Sub::start(o);
    let ready = sub
        .expect("ready", Duration::from_secs(30))
        .expect("subscriber started");
    assert!(
        n.wait_for_subscriber(&publisher, Duration::from_secs(30)),
        "subscriber not matched"
    );
    // Matching is seen by the writer first; give the reader a moment to match back.
    std::thread::sleep(Duration::from_millis(500));
    println!(
        "# {} samples, {}, keep-last {}; subscriber at start: VmRSS {:.1} MiB",
        o.msg,
        if o.best_effort {
            "best-effort"
        } else {
            "reliable"
        },
        o.depth,
        mib(ready[0])
    );
    let d = M::make(0, 1 << 20).describe();
    if !d.is_empty() {
        println!("{d}");
    }
    let mut seq = 1_u64;
    if !o.sizes.is_empty() {
        println!("| sample | CDR bytes | publish call | delivered (median) | worst | MB/s (median) | lost |");
        println!("|---|---|---|---|---|---|---|");
    }
    for &size in &o.sizes {
        let mut lat = Vec::new();
        let mut pub_call = Vec::new();
        let mut lost = 0;
        let mut bytes = 0;
        for _ in 0..o.repeat {
            let m = M::make(seq, size);
            bytes = cdr_size(&m);
            let t0 = Instant::now();
            let r = publisher.publish(m);
            pub_call.push(t0.elapsed());
            if let Err(e) = r {
                eprintln!("publish of {bytes} bytes: {e}");
            }
            match wait_for(&sub, seq, o.timeout) {
                Some(_) => lat.push(t0.elapsed()),
                None => lost += 1,
            }
            seq += 1;
        }
        lat.sort();
        pub_call.sort();
        let med = lat.get(lat.len() / 2).copied();
        println!(
            "| {} | {} | {:.1} ms | {} | {} | {} | {}/{} |",
            human(size),
            bytes,
            pub_call[pub_call.len() / 2].as_secs_f64() * 1e3,
            med.map_or("—".into(), |d| format!("{:.3} s", d.as_secs_f64())),
            lat.last()
                .map_or("—".into(), |d| format!("{:.3} s", d.as_secs_f64())),
            med.map_or("—".into(), |d| format!(
                "{:.1}",
                bytes as f64 / 1e6 / d.as_secs_f64()
            )),
            lost,
            o.repeat
        );
    }
    if o.mem_count > 0 {
        let (rss0, _) = sub.rss();
        let (prss0, _) = memory_kib();
        println!(
            "\n# memory: {} samples of {} one after another; VmRSS before: subscriber {:.1} MiB, publisher {:.1} MiB",
            o.mem_count,
            human(o.mem_size),
            mib(rss0),
            mib(prss0)
        );
        println!("| after sample | subscriber VmRSS | VmHWM | publisher VmRSS | delivered in |");
        println!("|---|---|---|---|---|");
        for k in 1..=o.mem_count {
            let m = M::make(seq, o.mem_size);
            let t0 = Instant::now();
            if let Err(e) = publisher.publish(m) {
                eprintln!("publish: {e}");
            }
            let got = wait_for(&sub, seq, o.timeout);
            seq += 1;
            let (prss, _) = memory_kib();
            match got {
                Some(v) => {
                    if k <= 3 || k % 4 == 0 || k == o.mem_count {
                        println!(
                            "| {k} | {:.1} MiB | {:.1} MiB | {:.1} MiB | {:.2} s |",
                            mib(v[0]),
                            mib(v[1]),
                            mib(prss),
                            t0.elapsed().as_secs_f64()
                        )
                    }
                }
                None => println!("| {k} | not delivered in {:?} | | | |", o.timeout),
            }
        }
        std::thread::sleep(Duration::from_secs(8));
        let (rss, hwm) = sub.rss();
        let (prss, _) = memory_kib();
        println!(
            "| 8 s later | {:.1} MiB | {:.1} MiB | {:.1} MiB | |",
            mib(rss),
            mib(hwm),
            mib(prss)
        );
    }
    sub.quit();
    drop(publisher);
    drop(n);
}

fn wait_for(sub: &Sub, seq: u64, timeout: Duration) -> Option<Vec<u64>> {
    let deadline = Instant::now() + timeout;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let v = sub.expect("got", left)?;
        if v.first() == Some(&seq) {
            return Some(v[1..].to_vec());
        }
    }
}

fn human(b: usize) -> String {
    if b >= 1 << 20 && b.is_multiple_of(1 << 20) {
        format!("{} MiB", b >> 20)
    } else if b.is_multiple_of(1 << 10) {
        format!("{} KiB", b >> 10)
    } else {
        format!("{:.1} MB", b as f64 / 1e6)
    }
}

fn main() {
    let o = parse_opts();
    let sub = std::env::var("KERF_LS_ROLE").as_deref() == Ok("sub");
    match (o.msg.as_str(), sub) {
        ("string", true) => subscriber::<StringMsg>(&o),
        ("string", false) => publisher::<StringMsg>(&o),
        ("traj", true) => subscriber::<JointTrajectory>(&o),
        ("traj", false) => publisher::<JointTrajectory>(&o),
        (m, _) => panic!("--msg string|traj, not {m}"),
    }
}
