//! The driver's loop: reads faults, commands, goals, cancel and result requests as they
//! come (every millisecond at most), integrates and publishes the state at the configured
//! rate, and answers the action.

use std::{
    io::Write,
    sync::atomic::{AtomicBool, Ordering},
    time::{Duration, Instant},
};

use kerf_msgs::builtin_interfaces::Time;
use ros2_client::action::{GoalId, GoalStatusEnum};

use crate::{
    cli::Config,
    driver::{Counters, Driver, Ignored},
    faults::{Fault, Schedule},
    goals::GoalBook,
    node::Endpoints,
};

/// The longest the loop sleeps before it looks at its inputs again.
const POLL: Duration = Duration::from_millis(1);
/// Most samples of one input taken per loop pass, so that one flooded input cannot starve
/// the state.
pub(crate) const MAX_PER_PASS: usize = 64;
/// Feedback rate of a running goal (Hz, about).
const FEEDBACK_HZ: f64 = 20.0;

/// Prints one log line to stderr.
pub fn log(msg: &str) {
    eprintln!("sim_driver: {msg}");
}

/// Whether the `n`-th repeat of a log line is printed: the first 10, then every 100th.
fn worth_logging(n: u64) -> bool {
    n <= 10 || n.is_multiple_of(100)
}

/// The wall clock as a ROS time.
pub(crate) fn wall_clock() -> Time {
    Time::now().unwrap_or(Time::ZERO)
}

/// The loop's state.
pub(crate) struct Loop<'a> {
    cfg: &'a Config,
    pub(crate) ep: &'a Endpoints,
    pub(crate) driver: Driver,
    pub(crate) book: GoalBook,
    pub(crate) schedule: Schedule,
    /// The goal the driver is running.
    pub(crate) running: Option<GoalId>,
    start: Instant,
    ticks: u64,
    feedback_every: u64,
    publish_failures: u64,
}

/// Runs the driver until `stop` is set; prints the ready line first.
///
/// # Returns
/// The counters, for the summary. A `die` fault exits the process with code 3 from here.
pub fn serve(cfg: &Config, ep: &Endpoints, stop: &AtomicBool) -> Counters {
    let mut l = Loop {
        cfg,
        ep,
        driver: Driver::new(cfg),
        book: GoalBook::default(),
        schedule: Schedule::new(&cfg.faults),
        running: None,
        start: Instant::now(),
        ticks: 0,
        feedback_every: ((cfg.rate / FEEDBACK_HZ).round() as u64).max(1),
        publish_failures: 0,
    };
    println!(
        "sim_driver ready: {} joints, namespace {}",
        cfg.joints.len(),
        cfg.namespace
    );
    let _ = std::io::stdout().flush();
    let period = 1.0 / cfg.rate;
    let mut next_tick = 0.0;
    while !stop.load(Ordering::SeqCst) {
        let now = l.now();
        l.poll_faults();
        l.poll_commands();
        l.poll_goals(now);
        l.poll_cancels();
        l.poll_result_requests();
        for f in l.schedule.due(now) {
            l.fault(f, "scheduled");
        }
        if now >= next_tick {
            l.tick(now);
            next_tick += period;
            if next_tick <= now {
                next_tick = now + period;
            }
        }
        l.answer_results();
        l.publish_statuses();
        let wait = (next_tick - l.now()).clamp(0.0, POLL.as_secs_f64());
        if wait > 0.0 {
            std::thread::sleep(Duration::from_secs_f64(wait));
        }
    }
    l.driver.counters
}

impl Loop<'_> {
    fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    fn fault(&mut self, fault: Fault, source: &str) {
        log(&format!("fault {fault} ({source})"));
        if fault == Fault::Die {
            log("dying (exit code 3)");
            std::process::exit(3);
        }
        self.driver.apply(fault);
    }

    fn poll_faults(&mut self) {
        for _ in 0..MAX_PER_PASS {
            match self.ep.next_fault() {
                None => break,
                Some(Ok(text)) => match text.parse::<Fault>() {
                    Ok(f) => self.fault(f, &self.cfg.topic("fault")),
                    Err(e) => log(&format!("ignored on {}: {e}", self.cfg.topic("fault"))),
                },
                Some(Err(e)) => log(&format!("ignored on {}: {e}", self.cfg.topic("fault"))),
            }
        }
    }

    fn poll_commands(&mut self) {
        for _ in 0..MAX_PER_PASS {
            let Some(cmd) = self.ep.commands.next(self.driver.joints()) else {
                break;
            };
            // Taken now: the delay counts from when the command was read, not from the pass.
            let now = self.now();
            match cmd.map(|p| self.driver.command(now, p)) {
                Ok(Ok(())) => self.schedule.start(now),
                Ok(Err(Ignored::DuringGoal)) => {
                    let n = self.driver.counters.commands_during_goal;
                    if worth_logging(n) {
                        log(&format!(
                            "ignored command {n} received while a goal runs (commands and \
                             goals are not mixed)"
                        ));
                    }
                }
                Err(reason) => {
                    let n = self.driver.count_invalid();
                    if worth_logging(n) {
                        log(&format!("ignored malformed command {n}: {reason}"));
                    }
                }
            }
        }
    }

    fn tick(&mut self, now: f64) {
        let wall = wall_clock();
        let (state, end) = self.driver.tick(now, wall);
        if let Some(s) = state {
            if let Err(e) = self.ep.states.publish(s) {
                self.publish_failures += 1;
                if worth_logging(self.publish_failures) {
                    log(&format!(
                        "joint state {} not published: {e:?}",
                        self.publish_failures
                    ));
                }
            }
        }
        if let Some(end) = end {
            if let Some(id) = self.running.take() {
                let (status, word) = if end.succeeded {
                    (GoalStatusEnum::Succeeded, "succeeded")
                } else {
                    (GoalStatusEnum::Aborted, "aborted")
                };
                log(&format!("goal {id:?} {word} {}", end.result.error_string));
                self.book.finish(&id, status, end.result);
            }
        }
        self.ticks += 1;
        if let Some(id) = self.running {
            if self.ticks.is_multiple_of(self.feedback_every) {
                if let Some(fb) = self.driver.feedback(wall) {
                    // A lost feedback sample is harmless; a full window drops it.
                    let _ = self.ep.action.send_feedback(id, fb);
                }
            }
        }
    }
}
