//! Shared by the kerf_millplan benches: CPU clocks, so that figures taken on
//! the shared machine can be read as what an idle core would take.

/// `struct timespec` of Linux (64-bit).
#[cfg(target_os = "linux")]
#[repr(C)]
struct Timespec {
    tv_sec: i64,
    tv_nsec: i64,
}

#[cfg(target_os = "linux")]
extern "C" {
    /// POSIX `clock_gettime` (libc).
    fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
}

/// `clock_gettime` of a Linux clock id in seconds; `None` off Linux or on
/// failure.
fn cpu_clock(clock: i32) -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let mut ts = Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: ts is a valid, writable timespec.
        let rc = unsafe { clock_gettime(clock, &mut ts) };
        (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = clock;
        None
    }
}

/// CPU time of the calling thread, s (`CLOCK_THREAD_CPUTIME_ID` = 3 on
/// Linux): what the work costs on an otherwise idle core, independent of
/// other jobs on the shared machine.
pub fn thread_cpu_time() -> Option<f64> {
    cpu_clock(3)
}

/// CPU time of the whole process, s (`CLOCK_PROCESS_CPUTIME_ID` = 2 on
/// Linux: all threads).
pub fn process_cpu_time() -> Option<f64> {
    cpu_clock(2)
}
