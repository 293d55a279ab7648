//! Ctrl-C (SIGINT) for the offline commands (`kerf plan`, `lobes`, `demo`, `train`): the
//! command ends at once with exit code [`EXIT_INTERRUPTED`] (130, the shell's 128 + SIGINT)
//! and one line on stderr saying so, whatever it is computing. The DDS commands (`launch`,
//! `echo`, `pub`) keep `kerf_ros`'s handler, which stops their nodes cleanly.

use std::sync::OnceLock;

/// Exit code of an offline command ended by Ctrl-C (SIGINT).
pub const EXIT_INTERRUPTED: i32 = 130;

/// The line written on SIGINT (set once, before the handler is installed).
static MESSAGE: OnceLock<Vec<u8>> = OnceLock::new();

extern "C" fn on_sigint(_: libc::c_int) {
    if let Some(m) = MESSAGE.get() {
        // SAFETY: write(2) and _exit(2) are async-signal-safe; `m` is never freed or changed
        // after it was set.
        unsafe {
            libc::write(libc::STDERR_FILENO, m.as_ptr().cast(), m.len());
        }
    }
    // SAFETY: as above.
    unsafe { libc::_exit(EXIT_INTERRUPTED) }
}

/// Makes Ctrl-C end `command` (e.g. `kerf lobes`) with [`EXIT_INTERRUPTED`] and the line
/// `kerf lobes: interrupted (Ctrl-C); exit code 130, output files may be incomplete`.
///
/// # Errors
/// The OS refused the handler.
pub fn exit_on_sigint(command: &str) -> Result<(), String> {
    let _ = MESSAGE.set(
        format!(
            "\nkerf {command}: interrupted (Ctrl-C); exit code {EXIT_INTERRUPTED}, output files \
             may be incomplete\n"
        )
        .into_bytes(),
    );
    // SAFETY: sigaction(2) with a handler that only calls async-signal-safe functions.
    let installed = unsafe {
        let mut action: libc::sigaction = std::mem::zeroed();
        action.sa_sigaction = on_sigint as extern "C" fn(libc::c_int) as libc::sighandler_t;
        libc::sigemptyset(&mut action.sa_mask);
        libc::sigaction(libc::SIGINT, &action, std::ptr::null_mut())
    };
    if installed == 0 {
        Ok(())
    } else {
        Err(format!(
            "cannot install the Ctrl-C handler: {}",
            std::io::Error::last_os_error()
        ))
    }
}
