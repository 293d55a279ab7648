//! Giving the memory of a large trajectory back to the system once it has been served.
//!
//! A `JointTrajectory` arrives as one allocation per point and field (the deserialized
//! message, then the [`kerf_executor::TrajectoryRequest`] converted from it): 10⁶ points of
//! 6 joints are about 6·10⁶ allocations of 48 bytes, 600 MB with the vectors' headers. Each is
//! below glibc's mmap threshold, so it comes from a malloc heap (of the inbox thread for the
//! message, of the preparation thread for the request). [`kerf_ros::memory`] makes freed
//! blocks merge at once, so that the free top of each heap goes back to the system; what is
//! left free inside a heap, between blocks still in use, is returned by `malloc_trim(0)`,
//! called here after a large request. Before, the executor kept 529 MB of a 10⁶-point
//! trajectory after serving it (issue 33).
//!
//! The prepared trajectory itself ([`kerf_executor::PreparedTrajectory`]) is a few large
//! vectors, served by `mmap` and unmapped when freed.

/// Requests with at least this many points are followed by [`give_back_freed_memory`]
/// (6.0 MB of freed allocations for 6 joints). Smaller ones leave at most that much in the
/// heaps, where the next request reuses it.
pub const TRIM_AFTER_POINTS: usize = 10_000;

/// Returns the free pages of every malloc arena to the system ([`kerf_ros::memory`]; called on
/// the preparation thread, never on the control thread).
pub use kerf_ros::memory::give_back_freed_memory;

#[cfg(test)]
mod tests {
    /// Many small blocks of another thread's arena, freed here, come back to the system, as
    /// a message deserialized on the inbox thread and freed on the preparation thread.
    #[test]
    fn freed_small_blocks_are_given_back() {
        if !cfg!(all(target_os = "linux", target_env = "gnu")) {
            return;
        }
        kerf_ros::memory::release_large_allocations();
        let rss = || kerf_ros::memory::status_kib("VmRSS:").unwrap();
        let before = rss();
        // 2·10⁶ blocks of 48 bytes (the positions of one point of 6 joints), about 128 MB,
        // in this thread's arena, kept alive past the allocation of the next ones.
        let blocks: Vec<Vec<f64>> =
            std::thread::spawn(|| (0..2_000_000).map(|i| vec![i as f64; 6]).collect())
                .join()
                .unwrap();
        let held = rss();
        assert!(held > before + 100_000, "{before} → {held} KiB");
        drop(blocks);
        super::give_back_freed_memory();
        let after = rss();
        assert!(
            after < before + 20_000,
            "after the trim: {after} KiB, {before} KiB before the blocks, {held} KiB with them"
        );
    }
}
