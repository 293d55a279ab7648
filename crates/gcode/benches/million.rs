//! The reader on a 10⁶-line G01 program generated on the fly (`tests/support`: a serpentine
//! raster, about 21 MB of text, never held in memory), read through `Program` from a 64 KiB
//! `BufReader`. Prints lines/s, total time, the peak live heap while reading (this binary's
//! counting allocator) and the process's peak resident set (VmHWM in /proc/self/status) before
//! and after. `KERF_MILLION_LINES=N` changes the count.
//!
//! ```sh
//! cargo bench -p kerf_gcode --bench million
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

#[path = "../tests/support/mod.rs"]
mod support;
use support::{live_bytes, peak_bytes, reset_peak, status_kb, Counting, Generated};

use std::time::Instant;

use kerf_gcode::{Motion, Program, ReaderSettings};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn main() {
    let lines: usize = std::env::var("KERF_MILLION_LINES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let hwm_before = status_kb("VmHWM");
    let live_before = live_bytes();
    reset_peak();
    let start = Instant::now();
    let mut program = Program::new(
        std::io::BufReader::with_capacity(64 * 1024, Generated::new(lines)),
        ReaderSettings::default(),
    )
    .unwrap();
    let (mut moves, mut length) = (0usize, 0.0);
    for m in program.by_ref() {
        if let Motion::Line { start, end, .. } = m.unwrap() {
            moves += 1;
            length += (end[0] - start[0]).hypot(end[1] - start[1]);
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    let heap = peak_bytes() - live_before;
    let hwm_after = status_kb("VmHWM");
    assert_eq!(program.lines_read(), lines);
    println!("lines read          {lines}");
    println!("G1 motions          {moves} (path length {length:.3} m)");
    println!("total time          {elapsed:.3} s");
    println!("lines/s             {:.0}", lines as f64 / elapsed);
    let generation = Instant::now();
    let bytes = program_bytes(lines);
    let generation = generation.elapsed().as_secs_f64();
    println!("MB/s                {:.1}", bytes as f64 / elapsed / 1e6);
    println!(
        "of which generating {generation:.3} s ({bytes} bytes of text alone); reading alone {:.0} lines/s",
        lines as f64 / (elapsed - generation)
    );
    println!("peak live heap      {heap} bytes above the start (64 KiB BufReader included)");
    match (hwm_before, hwm_after) {
        (Some(b), Some(a)) => println!("VmHWM               {b} kB before, {a} kB after"),
        _ => println!("VmHWM               not available"),
    }
}

/// The size of the generated text (generated again, not stored).
fn program_bytes(lines: usize) -> usize {
    let mut g = Generated::new(lines);
    std::io::copy(&mut g, &mut std::io::sink()).unwrap() as usize
}
