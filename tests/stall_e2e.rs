//! No reader can stall a publisher (issue 33, item 6).
//!
//! The executor (mock hardware, IRB 6660) runs in this process and publishes /joint_states at
//! 250 Hz. Three `kerf echo /joint_states` processes subscribe reliable, print their first
//! sample, and then:
//! * one is killed with SIGKILL (dies without leaving: its reader stays matched until its
//!   participant's 50 s lease ends);
//! * one is stopped with SIGSTOP (neither reads nor acknowledges, and stops announcing
//!   itself);
//! * one stops reading: its stdout pipe is never read again, so it blocks writing and never
//!   takes another sample (its DDS threads still acknowledge).
//!
//! A reading subscriber in this process records every /joint_states stamp for 75 s after the
//! kill: past the 32.8 s at which RustDDS's default send window (8192 samples) filled before
//! the fix, past the end of the dead readers' leases, and past the 64 s a window of
//! `kerf_ros::qos::send_window` lasts. It must see no gap over 2 control periods.
//!
//! Loopback only (`ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST` for the children, a loopback
//! `RosEnv` here), domain 156 (`KERF_STALL_DOMAIN` overrides it).

#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    io::{BufRead, BufReader},
    process::{Child, ChildStdout, Command, Stdio},
    sync::{
        atomic::{AtomicBool, AtomicUsize, Ordering},
        Arc, Mutex,
    },
    time::{Duration, Instant},
};

use kerf_msgs::{sensor_msgs::JointState, RosType};
use kerf_ros::{qos, ros2_client::ServiceMapping, RosEnv};

mod support;

const DEFAULT_DOMAIN: u16 = 156;

/// The executor's control period (s): the default 250 Hz.
const PERIOD: f64 = 0.004;

/// How long the reading subscriber records after the kill.
const RUN: Duration = Duration::from_secs(75);

fn domain() -> u16 {
    std::env::var("KERF_STALL_DOMAIN")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_DOMAIN)
}

/// Every /joint_states stamp (ns) a reading subscriber receives, and how many readers of
/// /joint_states of other participants its participant knows, read on its own thread.
struct Recorder {
    stamps: Arc<Mutex<Vec<i64>>>,
    readers: Arc<AtomicUsize>,
    running: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Recorder {
    fn start(env: &RosEnv) -> Recorder {
        let stamps = Arc::new(Mutex::new(Vec::new()));
        let readers = Arc::new(AtomicUsize::new(0));
        let running = Arc::new(AtomicBool::new(true));
        let (s, n, r) = (
            Arc::clone(&stamps),
            Arc::clone(&readers),
            Arc::clone(&running),
        );
        let env = env.clone();
        let thread = std::thread::spawn(move || {
            let mut node = support::client_node("stall_watcher", &env);
            // Deep history: a reader thread delayed by the machine must not lose samples and
            // show a false gap.
            let sub = node
                .subscription::<JointState>(
                    "/joint_states",
                    JointState::ROS_TYPE,
                    qos::reliable(10_000),
                )
                .unwrap();
            let mut counted = Instant::now();
            while r.load(Ordering::Relaxed) {
                match sub.take() {
                    Ok(Some((m, _))) => {
                        let t = m.header.stamp.as_nanos();
                        s.lock().unwrap().push(t);
                    }
                    Ok(None) => std::thread::sleep(Duration::from_millis(1)),
                    Err(e) => panic!("reading joint states: {e:?}"),
                }
                if counted.elapsed() > Duration::from_millis(250) {
                    n.store(
                        node.discovered_reader_count("/joint_states"),
                        Ordering::Relaxed,
                    );
                    counted = Instant::now();
                }
            }
            drop(sub);
            drop(node);
        });
        Recorder {
            stamps,
            readers,
            running,
            thread: Some(thread),
        }
    }

    fn count(&self) -> usize {
        self.stamps.lock().unwrap().len()
    }

    fn finish(mut self) -> Vec<i64> {
        self.stop();
        std::mem::take(&mut *self.stamps.lock().unwrap())
    }

    fn stop(&mut self) {
        self.running.store(false, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            t.join().unwrap();
        }
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        self.running.store(false, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A `kerf echo /joint_states` child on the test's loopback domain, its stdout piped, after it
/// printed its first line; the pipe is returned unread beyond that line.
fn echo_after_first_line(domain: u16) -> (support::Killed, BufReader<ChildStdout>) {
    let mut child = support::Killed(
        Command::new(env!("CARGO_BIN_EXE_kerf"))
            .args(["echo", "/joint_states"])
            .env("ROS_DOMAIN_ID", domain.to_string())
            .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start kerf echo"),
    );
    let stdout = child.0.stdout.take().expect("stdout");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut out = BufReader::new(stdout);
        let mut line = String::new();
        let read = out.read_line(&mut line);
        let _ = tx.send((read.map(|n| n > 0), out));
    });
    let (read, out) = rx
        .recv_timeout(support::QUICK)
        .expect("kerf echo printed a first line");
    assert!(matches!(read, Ok(true)), "kerf echo printed nothing");
    (child, out)
}

fn signal(child: &Child, sig: &str) {
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args([sig, &pid])
        .status()
        .expect("run kill")
        .success());
}

/// What the reading subscriber saw: its largest gap between consecutive stamps, the gaps over
/// two periods, and the samples missing, in all and at the largest gap that lost samples.
struct Gaps {
    largest: f64,
    largest_at: f64,
    over_two_periods: usize,
    missing: i64,
    /// The largest gap after which samples are missing (the publisher's gaps), and when.
    largest_lossy: f64,
    largest_lossy_at: f64,
    samples: usize,
    span: f64,
}

/// How long after a gap the control loop has caught up with its schedule (s).
const CATCH_UP: f64 = 0.5;

/// The control loop runs on an absolute schedule: a cycle that wakes late (the scheduler of a
/// loaded machine, not the publisher) is followed by quick ones until it is back on time, and
/// no sample is lost. A publisher that stalls loses the samples of the stall (the streamer's
/// queue and the DDS writer drop them). So a gap over two periods is the publisher's when the
/// samples within [`CATCH_UP`] after it are fewer than the periods elapsed.
fn gaps(stamps: &[i64]) -> Gaps {
    let (first, last) = (stamps[0], stamps[stamps.len() - 1]);
    let secs = |a: i64, b: i64| (b - a) as f64 * 1e-9;
    let mut g = Gaps {
        largest: 0.0,
        largest_at: 0.0,
        over_two_periods: 0,
        missing: 0,
        largest_lossy: 0.0,
        largest_lossy_at: 0.0,
        samples: stamps.len(),
        span: secs(first, last),
    };
    for (i, w) in stamps.windows(2).enumerate() {
        let gap = secs(w[0], w[1]);
        if gap > g.largest {
            g.largest = gap;
            g.largest_at = secs(first, w[0]);
        }
        if gap <= 2.0 * PERIOD {
            continue;
        }
        g.over_two_periods += 1;
        let end = stamps[i + 1..]
            .iter()
            .position(|&t| secs(w[1], t) >= CATCH_UP)
            .map_or(stamps.len() - 1, |k| i + 1 + k);
        let elapsed = (secs(w[0], stamps[end]) / PERIOD).round() as i64;
        let lost = elapsed - (end - i) as i64;
        if lost > 0 && gap > g.largest_lossy {
            g.largest_lossy = gap;
            g.largest_lossy_at = secs(first, w[0]);
        }
    }
    g.missing = (g.span / PERIOD).round() as i64 + 1 - stamps.len() as i64;
    g
}

#[test]
fn a_dead_or_stopped_reader_never_stalls_joint_states() {
    let domain = domain();
    let env = support::loopback(domain, ServiceMapping::Enhanced);
    // The control thread runs SCHED_FIFO where the test may (root in CI), so that the stamps
    // show the publisher, not the scheduler of a loaded machine.
    let fifo = Command::new("chrt")
        .args(["-f", "1", "true"])
        .status()
        .is_ok_and(|s| s.success());
    let params: Vec<String> = if fifo {
        vec!["realtime_priority:=80".into()]
    } else {
        Vec::new()
    };
    println!(
        "control thread: {}",
        if fifo {
            "SCHED_FIFO 80"
        } else {
            "normal scheduling"
        }
    );
    let (stop, executor) = support::spawn_executor(&env, &params);
    let mut executor = Some(executor);
    let recorder = Recorder::start(&env);
    let deadline = Instant::now() + support::QUICK;
    while recorder.count() == 0 {
        assert!(Instant::now() < deadline, "no /joint_states within 30 s");
        std::thread::sleep(Duration::from_millis(10));
    }

    let (mut killed, _killed_out) = echo_after_first_line(domain);
    let (stopped, _stopped_out) = echo_after_first_line(domain);
    // Never read again: kerf echo blocks on its full stdout pipe and stops taking samples.
    let (blocked, _blocked_out) = echo_after_first_line(domain);
    // The three echoes: every reader known before any of them dies.
    let deadline = Instant::now() + support::QUICK;
    while recorder.readers.load(Ordering::Relaxed) < 3 {
        assert!(
            Instant::now() < deadline,
            "the echoes' readers were not discovered ({} readers)",
            recorder.readers.load(Ordering::Relaxed)
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let all_readers = recorder.readers.load(Ordering::Relaxed);
    killed.0.kill().expect("SIGKILL kerf echo");
    let _ = killed.0.wait();
    signal(&stopped.0, "-STOP");
    let dead_at = Instant::now();
    let start_stamps = recorder.count();
    println!("other readers of /joint_states before the kill: {all_readers}");

    // The dead and the stopped readers leave when their participants' leases end; the reader
    // that stops reading (alive) stays.
    let mut dropped_after = None;
    let mut reported = Instant::now();
    while dead_at.elapsed() < RUN {
        let readers = recorder.readers.load(Ordering::Relaxed);
        if dropped_after.is_none() && readers <= 1 {
            dropped_after = Some(dead_at.elapsed());
            println!(
                "dead and stopped readers dropped {:.1} s after the kill",
                dead_at.elapsed().as_secs_f64()
            );
        }
        if reported.elapsed() > Duration::from_secs(10) {
            println!(
                "{:.0} s: {} samples, {readers} readers",
                dead_at.elapsed().as_secs_f64(),
                recorder.count()
            );
            reported = Instant::now();
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let stamps = recorder.finish();
    signal(&stopped.0, "-KILL");
    drop((stopped, blocked));
    support::stop_and_join(&stop, &mut executor);

    // From one second before the kill to the end.
    let from = start_stamps.saturating_sub(250);
    let g = gaps(&stamps[from..]);
    println!(
        "{} samples over {:.1} s: largest gap {:.1} ms at {:.1} s, {} gaps over 2 periods, {} \
         samples missing; largest gap that lost samples {:.1} ms at {:.1} s",
        g.samples,
        g.span,
        g.largest * 1e3,
        g.largest_at,
        g.over_two_periods,
        g.missing,
        g.largest_lossy * 1e3,
        g.largest_lossy_at
    );
    assert!(
        dropped_after.is_some(),
        "the dead and the stopped readers were never dropped ({all_readers} readers before the kill)"
    );
    assert!(
        g.span > RUN.as_secs_f64() - 1.0,
        "the stamps span only {:.1} s",
        g.span
    );
    // No sample lost between the publisher and this reader (one for a late last cycle), and no
    // gap of the publisher over two periods.
    assert!(
        g.missing <= 1 && g.largest_lossy == 0.0,
        "/joint_states stalled: {} samples missing, {:.1} ms without samples {:.1} s after the kill",
        g.missing,
        g.largest_lossy * 1e3,
        g.largest_lossy_at - 1.0
    );
}
