//! The supervisor against real worker processes: answers, a job that ignores its deadline, a
//! job that outgrows its memory, panics, aborts and cancellation.

use std::{sync::Arc, time::Duration};

use kerf_budget::Budget;
use kerf_isolate::{resident_bytes, Outcome, Supervisor, SupervisorSettings, Work};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Serialize, Deserialize)]
enum Job {
    /// Answers `x + 1` and the worker's pid.
    Add(u64),
    /// Spins without ever checking its budget.
    Spin,
    /// Checks its budget every millisecond until it stops.
    Cooperate,
    /// Touches `n` bytes, 1 MiB at a time, without checking anything.
    Grow(u64),
    /// Panics.
    Panic,
    /// Aborts the process.
    Abort,
    /// Reports the budget's memory limit.
    MemoryLimit,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
enum Answer {
    Sum { value: u64, pid: u32 },
    Interrupted(String),
    Limit(Option<u64>),
}

struct Test;

impl Work for Test {
    type Job = Job;
    type Answer = Answer;

    fn run(&self, job: Job, budget: &Budget) -> Answer {
        match job {
            Job::Add(x) => Answer::Sum {
                value: x + 1,
                pid: std::process::id(),
            },
            Job::Spin => loop {
                std::hint::spin_loop();
            },
            Job::Cooperate => loop {
                if let Err(e) = budget.check("cooperating") {
                    return Answer::Interrupted(e.to_string());
                }
                std::thread::sleep(Duration::from_millis(1));
            },
            Job::Grow(n) => {
                let mut keep: Vec<Vec<u8>> = Vec::new();
                let mut total = 0;
                while total < n {
                    keep.push(vec![1u8; 1 << 20]);
                    total += 1 << 20;
                }
                Answer::Sum {
                    value: keep.len() as u64,
                    pid: std::process::id(),
                }
            }
            Job::Panic => panic!("job panicked on purpose"),
            Job::Abort => std::process::abort(),
            Job::MemoryLimit => Answer::Limit(budget.memory_limit()),
        }
    }
}

fn supervisor(memory: u64) -> Supervisor<Test> {
    Supervisor::new(Arc::new(Test), SupervisorSettings::new(memory))
}

/// Polls until the job ends (a hang guard of 20 s, never a timing assertion).
fn wait(s: &mut Supervisor<Test>) -> (u64, Outcome<Answer>) {
    let start = std::time::Instant::now();
    loop {
        if let Some(done) = s.poll() {
            return done;
        }
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "no outcome in 20 s"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn process_exists(pid: u32) -> bool {
    std::path::Path::new(&format!("/proc/{pid}")).exists()
}

#[test]
fn answers_come_back_from_one_reused_worker() {
    let mut s = supervisor(256 << 20);
    s.warm().unwrap();
    let worker = s.worker_pid().unwrap();
    assert_ne!(worker, std::process::id());
    for k in 0..5 {
        s.submit(k, &Job::Add(k * 10), Duration::from_secs(5))
            .unwrap();
        assert!(
            s.submit(99, &Job::Add(0), Duration::from_secs(1)).is_err(),
            "one at a time"
        );
        let (id, outcome) = wait(&mut s);
        assert_eq!(id, k);
        assert_eq!(
            outcome,
            Outcome::Answered(Answer::Sum {
                value: k * 10 + 1,
                pid: worker
            })
        );
    }
    assert_eq!(s.forks(), 1);
    s.submit(7, &Job::MemoryLimit, Duration::from_secs(5))
        .unwrap();
    assert_eq!(
        wait(&mut s).1,
        Outcome::Answered(Answer::Limit(Some(256 << 20)))
    );
    drop(s);
    std::thread::sleep(Duration::from_millis(50));
    assert!(
        !process_exists(worker),
        "the worker is reaped when the supervisor goes"
    );
}

#[test]
fn a_job_that_ignores_its_deadline_is_stopped_and_the_next_gets_a_fresh_worker() {
    let mut s = supervisor(256 << 20);
    s.submit(1, &Job::Spin, Duration::from_millis(300)).unwrap();
    let stuck = s.worker_pid().unwrap();
    let (id, outcome) = wait(&mut s);
    assert_eq!(id, 1);
    match outcome {
        Outcome::TimedOut { limit, elapsed } => {
            assert_eq!(limit, Duration::from_millis(300));
            assert!(elapsed >= limit + s.settings().grace, "{elapsed:?}");
        }
        other => panic!("{other:?}"),
    }
    assert!(
        !process_exists(stuck),
        "the stuck worker is killed and reaped"
    );
    s.submit(2, &Job::Add(1), Duration::from_secs(5)).unwrap();
    match wait(&mut s) {
        (2, Outcome::Answered(Answer::Sum { value: 2, pid })) => assert_ne!(pid, stuck),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_job_that_outgrows_its_memory_is_stopped_and_the_node_does_not_grow() {
    let before = resident_bytes(std::process::id()).unwrap();
    let mut s = supervisor(64 << 20);
    s.submit(1, &Job::Grow(8 << 30), Duration::from_secs(30))
        .unwrap();
    match wait(&mut s) {
        (1, Outcome::OverMemory { limit, grown }) => {
            assert_eq!(limit, 64 << 20);
            assert!(grown > limit && grown < limit + (512 << 20), "{grown}");
        }
        other => panic!("{other:?}"),
    }
    let after = resident_bytes(std::process::id()).unwrap();
    assert!(after < before + (64 << 20), "{before} -> {after}");
    // Within the budget, the same job answers.
    s.submit(2, &Job::Grow(16 << 20), Duration::from_secs(30))
        .unwrap();
    assert!(matches!(wait(&mut s), (2, Outcome::Answered(_))));
}

#[test]
fn panics_are_answered_and_aborts_are_contained() {
    let mut s = supervisor(256 << 20);
    s.submit(1, &Job::Panic, Duration::from_secs(5)).unwrap();
    let worker = s.worker_pid().unwrap();
    match wait(&mut s) {
        (1, Outcome::Panicked { message }) => assert!(message.contains("on purpose")),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        s.worker_pid(),
        Some(worker),
        "a panic does not end the worker"
    );
    s.submit(2, &Job::Abort, Duration::from_secs(5)).unwrap();
    match wait(&mut s) {
        (2, Outcome::Crashed { reason }) => assert!(reason.contains("signal 6"), "{reason}"),
        other => panic!("{other:?}"),
    }
    s.submit(3, &Job::Add(3), Duration::from_secs(5)).unwrap();
    assert!(matches!(
        wait(&mut s),
        (3, Outcome::Answered(Answer::Sum { value: 4, .. }))
    ));
}

#[test]
fn cancelled_jobs_answer_at_their_next_check_or_are_stopped() {
    let mut s = supervisor(256 << 20);
    s.submit(1, &Job::Cooperate, Duration::from_secs(30))
        .unwrap();
    std::thread::sleep(Duration::from_millis(100));
    s.cancel();
    match wait(&mut s) {
        (1, Outcome::Answered(Answer::Interrupted(text))) => {
            assert!(text.contains("cancelled"), "{text}")
        }
        other => panic!("{other:?}"),
    }
    s.submit(2, &Job::Spin, Duration::from_secs(30)).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    s.cancel();
    assert_eq!(wait(&mut s), (2, Outcome::Stopped));
}
