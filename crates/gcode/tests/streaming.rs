//! `Program` reads in bounded memory: 10⁵ generated G01 lines (about 2 MB of text, never held
//! whole) are read with a live heap that grows by less than 256 KiB over its start, counted by
//! this test binary's allocator. Alone in its binary so that no other test allocates meanwhile.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // the bench uses the rest of the shared helpers
mod support;
use support::{live_bytes, peak_bytes, reset_peak, Counting, Generated};

use kerf_gcode::{Motion, Program, ReaderSettings};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn a_hundred_thousand_lines_in_bounded_memory() {
    let lines = 100_000;
    let source = std::io::BufReader::with_capacity(64 * 1024, Generated::new(lines));
    let before = live_bytes();
    reset_peak();
    let mut program = Program::new(source, ReaderSettings::default()).unwrap();
    let mut moves = 0usize;
    let mut last = [0.0; 3];
    for m in program.by_ref() {
        if let Motion::Line { end, .. } = m.unwrap() {
            moves += 1;
            last = end;
        }
    }
    let growth = peak_bytes() - before;
    assert_eq!(moves, lines - 1);
    assert_eq!(program.lines_read(), lines);
    // Line 99 999 is row 99, column 999 − 998 = 1 (odd rows run backwards): x = 0.1 + 0.0001 × 4.
    assert!(
        (last[0] - 0.1004e-3).abs() < 1e-12 && (last[1] - 9.9e-3).abs() < 1e-12,
        "{last:?}"
    );
    println!("peak live heap growth while reading {lines} lines: {growth} bytes");
    assert!(growth < 256 * 1024, "{growth} bytes");
}
