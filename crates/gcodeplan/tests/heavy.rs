//! The probe's heavy programs (issue 33, items 2 and 3): each ends within 15 s (a hang guard,
//! not a timing assertion) with a named refusal of its time or memory budget, and the test
//! process's peak resident memory grows by less than the memory budget plus a slack.
//!
//! One test function runs the cases one after the other: the peak (VmHWM) is the process's,
//! and a case running beside another would blur it.
#![allow(clippy::unwrap_used)]

use std::fmt::Write;
use std::time::{Duration, Instant};

use kerf_budget::{Budget, CancelToken, Interrupt};
use kerf_gcodeplan::{plan_program, GcodePlanError, LaserSheet, PlanSettings};

/// The memory budget of every case (bytes).
const MEMORY: u64 = 256 << 20;

/// What the process may grow past the budget: the allocator's and the reader's overheads.
const SLACK: u64 = 128 << 20;

/// The process's peak resident memory (bytes), from /proc/self/status.
fn peak_rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .unwrap()
        .to_string();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024
}

fn helix(turns: &str) -> String {
    format!("G21 G90 G17\nG1 X10 Y0 F3000\nG2 X10 Y0 Z-5 I-10 J0 P{turns}\n")
}

fn full_circles(lines: usize) -> String {
    let mut s = String::from("G21 G90 G17\nM3\nG1 X10 Y0 F3000\n");
    for _ in 0..lines {
        s.push_str("G2 X10 Y0 I-5 J0\n");
    }
    s.push_str("M5\n");
    s
}

fn zig_zag(lines: usize) -> String {
    let mut s = String::from("G21 G90\nM3\nF3000\n");
    for k in 0..lines {
        let x = if k % 2 == 0 { 20.0 } else { 0.0 };
        let _ = writeln!(s, "G1 X{x} Y{:.3}", 0.001 * k as f64);
    }
    s.push_str("M5\n");
    s
}

/// A staircase of `corners` right-angle corners (1 mm steps).
fn staircase(corners: usize) -> String {
    let mut s = String::from("G21 G90\nM3\nF3000\n");
    let (mut x, mut y) = (0, 0);
    for k in 0..corners {
        if k % 2 == 0 {
            x += 1;
        } else {
            y += 1;
        }
        let _ = writeln!(s, "G1 X{x} Y{y}");
    }
    s.push_str("M5\n");
    s
}

/// What a case must end with.
enum Expect {
    /// The time or the memory budget, whichever the machine reaches first.
    Budget,
    /// The memory budget, naming this.
    OverMemory(&'static str),
    /// The reader's refusal, naming this.
    Program(&'static str),
}

#[test]
fn heavy_programs_end_in_a_named_refusal_within_their_budgets() {
    let laser = LaserSheet::default_sheet().unwrap();
    let nurbs = PlanSettings::laser_cutter()
        .with_corner_method(kerf_toolpath::CornerMethod::Nurbs(Default::default()));
    let laser_settings = PlanSettings::laser_cutter();
    let cases: Vec<(&str, String, &PlanSettings, Option<u64>, Expect)> = vec![
        // The 60-byte helix: 10⁴ turns of 70 chords, its path samples far over the budget.
        (
            "helix P10000",
            helix("10000"),
            &laser_settings,
            Some(MEMORY),
            Expect::OverMemory("the run from line 2: smoothed path: 702425 vertices"),
        ),
        // Under a 16 MiB budget its chords alone do not fit: refused by their estimate.
        (
            "helix P10000 in 16 MiB",
            helix("10000"),
            &laser_settings,
            Some(16 << 20),
            Expect::OverMemory("10000 turns"),
        ),
        (
            "helix P1e9",
            helix("1000000000"),
            &laser_settings,
            Some(MEMORY),
            Expect::Program("an integer in [1, 1000000]"),
        ),
        (
            "1e5 full circles",
            full_circles(100_000),
            &laser_settings,
            Some(MEMORY),
            Expect::Budget,
        ),
        (
            "1e5-line zig-zag",
            zig_zag(100_000),
            &laser_settings,
            Some(MEMORY),
            Expect::Budget,
        ),
        (
            "1500 NURBS corners",
            staircase(1500),
            &nurbs,
            Some(MEMORY),
            Expect::Budget,
        ),
    ];
    let start_peak = peak_rss();
    for (name, program, settings, memory, expect) in cases {
        let budget =
            Budget::new(Some(Duration::from_secs(2)), CancelToken::new()).with_memory(memory);
        let started = Instant::now();
        let result = plan_program(program.as_bytes(), &laser, settings, &budget);
        let took = started.elapsed();
        let grown = peak_rss().saturating_sub(start_peak);
        let e = result.err().unwrap_or_else(|| panic!("{name}: planned"));
        eprintln!(
            "{name}: {:.3} s, peak RSS +{} MiB: {e}",
            took.as_secs_f64(),
            grown >> 20
        );
        assert!(took < Duration::from_secs(15), "{name}: hang guard");
        assert!(
            grown < MEMORY + SLACK,
            "{name}: the process grew by {grown} bytes"
        );
        let text = e.to_string();
        match expect {
            Expect::Budget => match &e {
                GcodePlanError::Interrupted(Interrupt::TimedOut { stage, .. }) => {
                    assert!(text.contains(stage), "{name}: {text}")
                }
                GcodePlanError::Interrupted(Interrupt::OverMemory { what, .. }) => {
                    assert!(!what.is_empty(), "{name}: {text}")
                }
                other => panic!("{name}: {other:?}"),
            },
            Expect::OverMemory(what) => {
                assert!(
                    matches!(
                        &e,
                        GcodePlanError::Interrupted(Interrupt::OverMemory { .. })
                    ),
                    "{name}: {e:?}"
                );
                assert!(text.contains(what), "{name}: {text}");
            }
            Expect::Program(what) => {
                assert!(matches!(&e, GcodePlanError::Program(_)), "{name}: {e:?}");
                assert!(text.contains(what), "{name}: {text}");
            }
        }
        assert_eq!(
            budget.memory_used(),
            0,
            "{name}: everything held is given back"
        );
    }
}
