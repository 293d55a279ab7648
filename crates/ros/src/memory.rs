//! [`release_large_allocations`] and [`give_back_freed_memory`]: memory freed by a node goes
//! back to the system.
//!
//! glibc serves allocations above its mmap threshold (128 KiB) with `mmap` and returns them
//! with `munmap` on free, but it raises that threshold to the size of every such block freed
//! (up to 32 MiB): after the first multi-megabyte DDS sample, later ones come from the heap
//! and stay resident when freed. The soak test measured it (BENCHMARKS.md, "Soak"): 300 mixed
//! requests grew a milling planner's RSS by 90–186 MiB with glibc's default, and by nothing
//! with the threshold fixed.
//!
//! Small blocks (a message's per-point vectors: a 10⁶-point trajectory is 3·10⁶ blocks of
//! 48 bytes) go to glibc's fastbins when freed, which never merge with their neighbours until
//! something consolidates them; and even `malloc_trim` does not return the free top of a
//! thread's arena (only the main arena's), where a message deserialized on an inbox thread
//! lives. So the executor kept 58 MB of a 10⁶-point trajectory after serving it (measured
//! with `cargo run --release -p kerf_executor --example trajectory_memory`, the request built
//! on another thread). Fastbins are turned off as well (`M_MXFAST` 0): a freed block merges at
//! once, and a free top of a thread's heap is returned as soon as it passes the trim threshold
//! (128 KiB). Small allocations are still served by each thread's cache (tcache).

/// `M_MMAP_THRESHOLD` of glibc's `mallopt` (malloc.h).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const M_MMAP_THRESHOLD: std::os::raw::c_int = -3;

/// `M_MXFAST` of glibc's `mallopt` (malloc.h): the largest block size kept in fastbins.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const M_MXFAST: std::os::raw::c_int = 1;

/// The fixed mmap threshold (bytes): glibc's default, without its dynamic increase.
pub const MMAP_THRESHOLD_BYTES: i32 = 128 * 1024;

#[cfg(all(target_os = "linux", target_env = "gnu"))]
extern "C" {
    /// glibc's `int mallopt(int param, int value)`; returns 1 on success.
    fn mallopt(param: std::os::raw::c_int, value: std::os::raw::c_int) -> std::os::raw::c_int;
}

/// Fixes glibc's mmap threshold at [`MMAP_THRESHOLD_BYTES`] for the whole process, so that
/// large buffers (received samples, request texts, answers) are returned to the system when
/// freed, and turns fastbins off, so that many small freed blocks merge and are returned too
/// (module docs). Called by every node binary and by `kerf` at start-up.
///
/// # Returns
/// Whether the settings were applied (false where the C library is not glibc).
pub fn release_large_allocations() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only changes allocator tunables; it is thread-safe in glibc.
        unsafe {
            let threshold = mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1;
            let no_fastbins = mallopt(M_MXFAST, 0) == 1;
            threshold && no_fastbins
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
extern "C" {
    /// glibc's `int malloc_trim(size_t pad)`: returns free memory of every arena to the
    /// system; 1 if some was released.
    fn malloc_trim(pad: usize) -> std::os::raw::c_int;
}

/// Returns the free pages of every malloc arena to the system: what is left free inside a
/// heap between blocks still in use (module docs). The executor calls it after a large
/// trajectory, the planner harness when it is idle after answering.
///
/// # Returns
/// Whether some memory was released (always false where the C library is not glibc).
///
/// # Performance
/// Walks the free chunks of every arena: about a millisecond per 100 MB of heap, taking each
/// arena's lock in turn. Not for a control thread.
pub fn give_back_freed_memory() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: malloc_trim only releases free pages of glibc's arenas; it is thread-safe.
        unsafe { malloc_trim(0) == 1 }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

/// A field of this process's `/proc/self/status` in KiB (`"VmRSS:"`, `"VmHWM:"`).
///
/// # Returns
/// `None` where the file or the field does not exist (not Linux).
pub fn status_kib(field: &str) -> Option<u64> {
    read_status_kib("/proc/self/status", field)
}

/// A field of process `pid`'s `/proc/<pid>/status` in KiB, as [`status_kib`] reads its own
/// (a node's memory read by the test or bench that started it).
///
/// # Returns
/// `None` where the process, the file or the field does not exist.
pub fn status_kib_of(pid: u32, field: &str) -> Option<u64> {
    read_status_kib(&format!("/proc/{pid}/status"), field)
}

/// The KiB value of `field` in a `/proc/.../status` file.
fn read_status_kib(path: &str, field: &str) -> Option<u64> {
    let status = std::fs::read_to_string(path).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

#[cfg(test)]
mod tests {
    #[test]
    fn resident_memory_is_read() {
        let rss = super::status_kib("VmRSS:").unwrap();
        assert!(rss > 0 && rss <= super::status_kib("VmHWM:").unwrap());
        assert_eq!(super::status_kib("NoSuchField:"), None);
        assert_eq!(
            super::status_kib_of(std::process::id(), "VmHWM:").is_some(),
            super::status_kib("VmHWM:").is_some()
        );
    }

    #[test]
    fn the_threshold_is_set_on_glibc() {
        let applied = super::release_large_allocations();
        assert_eq!(applied, cfg!(all(target_os = "linux", target_env = "gnu")));
    }
}
