//! Real-time scheduling of the calling thread (Linux `SCHED_FIFO`), for control loops.

/// Gives the calling thread `SCHED_FIFO` priority `priority` (1–99).
///
/// # Returns
/// An error naming the cause when the priority is out of range or the OS refuses it (the
/// process needs `CAP_SYS_NICE` or an `rtprio` limit, e.g. `ulimit -r 99`).
pub fn set_realtime_priority(priority: i64) -> Result<(), String> {
    if !(1..=99).contains(&priority) {
        return Err(format!("real-time priority must be 1..=99, got {priority}"));
    }
    let param = libc::sched_param {
        sched_priority: priority as libc::c_int,
    };
    // SAFETY: `param` is a valid, initialized sched_param; pid 0 is the calling thread.
    let rc = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if rc == 0 {
        Ok(())
    } else {
        Err(format!(
            "SCHED_FIFO priority {priority} refused: {} (needs CAP_SYS_NICE or an rtprio limit)",
            std::io::Error::last_os_error()
        ))
    }
}

/// Locks every page the process has mapped now into RAM (`mlockall(MCL_CURRENT)`), so that a
/// real-time thread never takes a major page fault on code or data that was mapped but not
/// yet read (a first-time code path of the control loop read from disk costs milliseconds).
///
/// Later mappings are not locked: with `MCL_FUTURE` an allocation beyond `RLIMIT_MEMLOCK`
/// would fail, and a large request would abort the process.
///
/// # Returns
/// An error naming the cause when the OS refuses (the process needs `CAP_IPC_LOCK` or a
/// large enough `RLIMIT_MEMLOCK`, e.g. `ulimit -l unlimited`).
pub fn lock_memory() -> Result<(), String> {
    // SAFETY: mlockall takes only flags and has no memory-safety preconditions.
    let rc = unsafe { libc::mlockall(libc::MCL_CURRENT) };
    if rc == 0 {
        Ok(())
    } else {
        Err(format!(
            "mlockall(MCL_CURRENT) refused: {} (needs CAP_IPC_LOCK or a larger memlock limit)",
            std::io::Error::last_os_error()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_is_refused() {
        assert!(set_realtime_priority(0).is_err());
        assert!(set_realtime_priority(100).is_err());
    }
}
