//! The worker process's side: read jobs, plan them under their budget, write answers.

use std::{
    os::unix::{
        io::{AsRawFd, RawFd},
        net::UnixStream,
    },
    panic::{catch_unwind, AssertUnwindSafe},
    sync::{mpsc::channel, Arc, Mutex},
    time::Duration,
};

use kerf_budget::{Budget, CancelToken};

use crate::{
    frame::{decode, encode, read_frame, write_frame, Frame, ANSWER, CANCEL, JOB, PANICKED},
    Work,
};

/// Largest job a worker reads (bytes): the largest request a node accepts is far smaller.
const MAX_JOB_BYTES: u64 = 1 << 30;

/// The job running now and its token, for the cancel frames.
type Current = Arc<Mutex<Option<(u64, CancelToken)>>>;

/// Ends the worker process at once: no destructor of the node's state runs in it.
fn leave(code: i32) -> ! {
    // SAFETY: _exit ends the process; it has no preconditions.
    unsafe { libc::_exit(code) }
}

/// Closes every socket the worker inherited but its own (`keep`): the node's DDS sockets and
/// other workers' sockets stay the node's alone, so a worker never holds a port or keeps a
/// peer's socket open.
fn close_other_sockets(keep: RawFd) {
    let Ok(entries) = std::fs::read_dir("/proc/self/fd") else {
        return;
    };
    let fds: Vec<RawFd> = entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok())
        .collect();
    for fd in fds {
        if fd == keep || fd <= 2 {
            continue;
        }
        // SAFETY: fstat writes into the zeroed struct; close on a socket we will never use.
        unsafe {
            let mut st: libc::stat = std::mem::zeroed();
            if libc::fstat(fd, &mut st) == 0 && (st.st_mode & libc::S_IFMT) == libc::S_IFSOCK {
                libc::close(fd);
            }
        }
    }
}

/// Sets up the process right after `fork` (signals, parent death, address-space backstop,
/// its own rayon pool).
fn set_up(parent: libc::pid_t, address_space: Option<u64>) {
    // SAFETY: plain system calls on this process.
    unsafe {
        // Die with the node's thread that forked us; leave if it is already gone.
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
        if libc::getppid() != parent {
            leave(1);
        }
        // Ctrl-C reaches the whole process group: the node decides what happens to the plan.
        libc::signal(libc::SIGINT, libc::SIG_IGN);
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
    }
    if let Some(extra) = address_space {
        let now = crate::virtual_bytes(std::process::id()).unwrap_or(0);
        let limit = now.saturating_add(extra);
        let rl = libc::rlimit {
            rlim_cur: limit,
            rlim_max: limit,
        };
        // SAFETY: setrlimit reads the struct we pass.
        unsafe {
            libc::setrlimit(libc::RLIMIT_AS, &rl);
        }
    }
    // A panic is answered with its message; printing it would take stderr's lock, which a
    // thread of the node may have held at the fork.
    std::panic::set_hook(Box::new(|_| {}));
    // rayon's global pool, if the node had built one, has no threads in this process: build
    // ours. (Err: the node had one — planning code must then use its own pools.)
    let _ = rayon::ThreadPoolBuilder::new().build_global();
}

/// Runs the worker: serves jobs from `stream` until the node closes it, then leaves.
///
/// # Arguments
/// * `work` — what a job runs.
/// * `stream` — the worker's end of the socket.
/// * `parent` — the node's pid (the worker leaves if it is not its parent any more).
/// * `address_space` — the backstop: bytes of address space allowed beyond the worker's size
///   at its start.
pub(crate) fn serve<W: Work>(
    work: &W,
    stream: UnixStream,
    parent: libc::pid_t,
    address_space: Option<u64>,
) -> ! {
    close_other_sockets(stream.as_raw_fd());
    set_up(parent, address_space);
    let current: Current = Arc::new(Mutex::new(None));
    let (jobs_tx, jobs_rx) = channel::<Frame>();
    let Ok(mut reader) = stream.try_clone() else {
        leave(2)
    };
    let current_r = Arc::clone(&current);
    let spawned = std::thread::Builder::new()
        .name("worker-in".into())
        .spawn(move || {
            loop {
                match read_frame(&mut reader, MAX_JOB_BYTES) {
                    Ok(Some(f)) if f.kind == JOB => {
                        if jobs_tx.send(f).is_err() {
                            break;
                        }
                    }
                    Ok(Some(f)) if f.kind == CANCEL => {
                        if let Ok(c) = current_r.lock() {
                            if let Some((id, token)) = c.as_ref() {
                                if *id == f.id {
                                    token.cancel();
                                }
                            }
                        }
                    }
                    Ok(Some(_)) => {}
                    // The node closed the socket or is gone: cancel what runs and stop.
                    Ok(None) | Err(_) => break,
                }
            }
            if let Ok(c) = current_r.lock() {
                if let Some((_, token)) = c.as_ref() {
                    token.cancel();
                }
            }
        });
    if spawned.is_err() {
        leave(2);
    }
    for job in jobs_rx {
        let token = CancelToken::new();
        if let Ok(mut c) = current.lock() {
            *c = Some((job.id, token.clone()));
        }
        let budget = Budget::new(Some(Duration::from_nanos(job.a)), token).with_memory(Some(job.b));
        let answer = match decode::<W::Job>(&job.body) {
            Err(e) => Frame::new(
                PANICKED,
                job.id,
                format!("cannot decode the job: {e}").into(),
            ),
            Ok(j) => match catch_unwind(AssertUnwindSafe(|| work.run(j, &budget))) {
                Ok(a) => match encode(&a) {
                    Ok(bytes) => Frame::new(ANSWER, job.id, bytes),
                    Err(e) => Frame::new(
                        PANICKED,
                        job.id,
                        format!("cannot encode the answer: {e}").into(),
                    ),
                },
                Err(payload) => {
                    let message = payload
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| payload.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "non-string panic payload".into());
                    Frame::new(PANICKED, job.id, message.into_bytes())
                }
            },
        };
        if let Ok(mut c) = current.lock() {
            *c = None;
        }
        if write_frame(&stream, &answer).is_err() {
            break;
        }
    }
    leave(0)
}
