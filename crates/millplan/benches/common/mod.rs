//! Shared by the kerf_millplan benches: CPU clocks, so that figures taken on
//! the shared machine can be read as what an idle core would take; the paths
//! the planners are compared on.

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

/// The default path of seed 004 and the ten held-out paths of
/// `kerf_millplan::path_distribution` (`HELD_OUT_SEEDS`), in that order: a label
/// (`default`, or `seed (length m)`), the points, and whether the path is held out.
pub fn default_and_held_out_paths() -> Vec<(String, Vec<[f64; 3]>, bool)> {
    use kerf_mill::MillCell;
    use kerf_millplan::path_distribution::{held_out_paths, PathDistribution};
    let base = MillCell::default_cell().expect("the default cell loads");
    let mut paths = vec![(
        "default".to_string(),
        kerf_millplan::MillRequest::default().points,
        false,
    )];
    for p in held_out_paths(&base, &PathDistribution::default()).expect("held-out paths") {
        paths.push((
            format!("{} ({:.2} m)", p.seed, p.cell.path().total_length()),
            p.spec.points.clone(),
            true,
        ));
    }
    paths
}
