//! The platform's own timer jitter, as a baseline for `joint_states_jitter`: a thread sleeping
//! to absolute 4 ms deadlines (as the executor's control loop does) for 2500 periods, and how
//! late it wakes. `KERF_JITTER_RT=N` runs it with `SCHED_FIFO` priority N.
//!
//! Run: `cargo bench --bench sleep_baseline`. Reported, never asserted.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::{Duration, Instant};

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    if let Some(p) = std::env::var("KERF_JITTER_RT")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        if p > 0 {
            kerf_ros::set_realtime_priority(p).expect("SCHED_FIFO");
        }
    }
    let period = Duration::from_millis(4);
    let mut late = Vec::with_capacity(2500);
    let mut next = Instant::now();
    for _ in 0..2500 {
        next += period;
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        }
        late.push(Instant::now().saturating_duration_since(next).as_secs_f64());
    }
    late.sort_by(f64::total_cmp);
    println!(
        "sleep to 4 ms deadlines, {} periods: wake-up lateness p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        late.len(),
        late[late.len() / 2] * 1e6,
        late[late.len() * 99 / 100] * 1e6,
        late[late.len() - 1] * 1e6
    );
}
