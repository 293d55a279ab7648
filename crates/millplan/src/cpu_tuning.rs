//! The CPU settings that make small-batch training fast ([`CpuTuning`]):
//! one rayon thread, a large malloc mmap threshold, flush-to-zero.

/// `M_TRIM_THRESHOLD` of glibc's `mallopt` (malloc.h).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const M_TRIM_THRESHOLD: std::os::raw::c_int = -1;
/// `M_MMAP_THRESHOLD` of glibc's `mallopt` (malloc.h).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const M_MMAP_THRESHOLD: std::os::raw::c_int = -3;

#[cfg(all(target_os = "linux", target_env = "gnu"))]
extern "C" {
    /// glibc's `int mallopt(int param, int value)`; returns 1 on success.
    fn mallopt(param: std::os::raw::c_int, value: std::os::raw::c_int) -> std::os::raw::c_int;
}

/// The malloc mmap threshold [`CpuTuning::apply`] sets: 16 MiB (glibc's
/// maximum is 32 MiB on 64-bit targets).
pub const MMAP_THRESHOLD_BYTES: i32 = 16 << 20;

/// MXCSR bits: flush-to-zero (bit 15) and denormals-are-zero (bit 6)
/// (Intel SDM vol. 1, §10.2.3).
#[cfg(target_arch = "x86_64")]
const MXCSR_FTZ_DAZ: u32 = (1 << 15) | (1 << 6);

/// What [`CpuTuning::apply`] changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CpuTuningReport {
    /// `RAYON_NUM_THREADS` was set to 1 by this call.
    pub single_thread: bool,
    /// The MXCSR FTZ and DAZ bits were set on the calling thread (x86_64).
    pub flush_to_zero: bool,
    /// glibc's mmap and trim thresholds were raised.
    pub malloc_tuned: bool,
}

/// CPU settings that make DDPG's small matrix products about twice as fast
/// on a 2-core machine (measured in issue 5), active while the guard lives.
///
/// 1. **One thread**: sets the environment variable `RAYON_NUM_THREADS=1`,
///    which candle reads before every matrix product (`gemm` then runs
///    without its thread pool) and when it creates its element-wise pool.
///    For batch 64 × 256 the fork/join cost exceeds the gain. The variable
///    stays set after the guard is dropped (candle's pool, once created,
///    keeps its size). Call this before anything else uses candle, from the
///    main thread of a program; a caller who wants several threads sets
///    `single_thread = false` and its own `RAYON_NUM_THREADS`.
/// 2. **Flush-to-zero** (x86_64 only; no-op elsewhere): sets the FTZ and
///    DAZ bits of the calling thread's MXCSR, so denormal results and inputs
///    are treated as 0 instead of taking the slow microcode path (weights
///    and Adam moments decay into the denormal range). The previous MXCSR is
///    restored when the guard is dropped. Only the calling thread is
///    affected, which with one thread is every thread that computes. Note:
///    Rust assumes the default floating-point environment; code that
///    depends on denormals must not run on this thread while the guard
///    lives.
/// 3. **Malloc thresholds** (glibc only; no-op elsewhere): `mallopt`
///    `M_MMAP_THRESHOLD` and `M_TRIM_THRESHOLD` = [`MMAP_THRESHOLD_BYTES`].
///    A 256×256 f32 tensor (256 KiB) is above glibc's default 128 KiB
///    threshold, so every temporary of that size would be a fresh
///    `mmap`/`munmap` pair with page faults; raised, they are recycled from
///    the heap. Process-wide and not undone (it only changes which memory
///    is reused).
#[derive(Debug)]
pub struct CpuTuning {
    report: CpuTuningReport,
    #[cfg(target_arch = "x86_64")]
    saved_mxcsr: u32,
}

impl CpuTuning {
    /// Applies the settings (see the type documentation).
    ///
    /// # Arguments
    /// * `single_thread` — set `RAYON_NUM_THREADS=1`.
    pub fn apply(single_thread: bool) -> Self {
        if single_thread {
            std::env::set_var("RAYON_NUM_THREADS", "1");
        }
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: mallopt only changes allocator tuning parameters; glibc
        // takes its arena lock.
        let malloc_tuned = unsafe {
            mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1
                && mallopt(M_TRIM_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1
        };
        #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
        let malloc_tuned = false;
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: SSE is part of the x86_64 baseline; reading and
            // writing MXCSR only changes this thread's rounding/denormal
            // modes (restored on drop).
            #[allow(deprecated)]
            let saved_mxcsr = unsafe { std::arch::x86_64::_mm_getcsr() };
            #[allow(deprecated)]
            unsafe {
                std::arch::x86_64::_mm_setcsr(saved_mxcsr | MXCSR_FTZ_DAZ)
            };
            Self {
                report: CpuTuningReport {
                    single_thread,
                    flush_to_zero: true,
                    malloc_tuned,
                },
                saved_mxcsr,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Self {
                report: CpuTuningReport {
                    single_thread,
                    flush_to_zero: false,
                    malloc_tuned,
                },
            }
        }
    }

    /// What was changed.
    pub fn report(&self) -> CpuTuningReport {
        self.report
    }
}

impl Drop for CpuTuning {
    fn drop(&mut self) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: restores the MXCSR value read in `apply` on this thread.
        #[allow(deprecated)]
        unsafe {
            std::arch::x86_64::_mm_setcsr(self.saved_mxcsr)
        };
    }
}
