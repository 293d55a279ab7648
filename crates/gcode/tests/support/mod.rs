//! Helpers shared by the streaming test and the million-line bench: a G01 program generated on
//! the fly (never held in memory) and a global allocator that counts live heap bytes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Read;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A G01 raster program of `lines` lines generated as it is read: `G21 G90 F6000`, then `G1`
/// moves over a 100 mm × 100 mm serpentine raster at 0.1 mm steps, 4 decimals, about 21 bytes a
/// line. Deterministic.
pub struct Generated {
    /// Lines still to write.
    remaining: usize,
    /// Lines written.
    written: usize,
    /// The current line's bytes not yet read.
    line: Vec<u8>,
    offset: usize,
    /// Bytes produced so far.
    pub bytes: usize,
}

impl Generated {
    /// A program of `lines` lines (the first is the preamble).
    pub fn new(lines: usize) -> Self {
        Self {
            remaining: lines,
            written: 0,
            line: Vec::with_capacity(64),
            offset: 0,
            bytes: 0,
        }
    }

    fn next_line(&mut self) {
        use std::io::Write as _;
        self.line.clear();
        self.offset = 0;
        let k = self.written;
        if k == 0 {
            self.line.extend_from_slice(b"G21 G90 F6000\n");
        } else {
            let row = (k - 1) / 1000;
            let col = (k - 1) % 1000;
            let col = if row.is_multiple_of(2) {
                col
            } else {
                999 - col
            };
            // In 0.0001 mm, written as integers (float formatting would cost as much as
            // the reading being measured).
            let x = col * 1000 + k % 7;
            let y = (row % 1000) * 1000;
            let _ = writeln!(
                self.line,
                "G1 X{}.{:04} Y{}.{:04}",
                x / 10_000,
                x % 10_000,
                y / 10_000,
                y % 10_000
            );
        }
        self.written += 1;
        self.remaining -= 1;
    }
}

impl Read for Generated {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut n = 0;
        while n < buf.len() {
            if self.offset == self.line.len() {
                if self.remaining == 0 {
                    break;
                }
                self.next_line();
            }
            let take = (self.line.len() - self.offset).min(buf.len() - n);
            buf[n..n + take].copy_from_slice(&self.line[self.offset..self.offset + take]);
            self.offset += take;
            n += take;
        }
        self.bytes += n;
        Ok(n)
    }
}

/// The system allocator, counting live bytes and their peak.
pub struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to `System` unchanged; the counters are only bookkeeping.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, forwarded.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, forwarded.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract, forwarded.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
            let live = LIVE.fetch_add(new_size, Ordering::Relaxed) + new_size;
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }
}

/// Live heap bytes now.
pub fn live_bytes() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// Sets the peak to the live bytes now (the start of a measurement).
pub fn reset_peak() {
    PEAK.store(LIVE.load(Ordering::Relaxed), Ordering::Relaxed);
}

/// The peak of live heap bytes since [`reset_peak`].
pub fn peak_bytes() -> usize {
    PEAK.load(Ordering::Relaxed)
}

/// A field of /proc/self/status in kB (`VmHWM`: peak resident set, `VmRSS`), if readable.
pub fn status_kb(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    text.lines()
        .find(|l| l.starts_with(field) && l[field.len()..].starts_with(':'))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}
