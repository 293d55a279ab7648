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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_is_refused() {
        assert!(set_realtime_priority(0).is_err());
        assert!(set_realtime_priority(100).is_err());
    }
}
