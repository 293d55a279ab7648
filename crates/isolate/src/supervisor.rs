//! [`Supervisor`]: the node's side of its worker process.

use std::{
    os::unix::net::UnixStream,
    sync::{
        mpsc::{channel, Receiver, TryRecvError},
        Arc,
    },
    time::{Duration, Instant},
};

use kerf_budget::Budget;
use serde::{de::DeserializeOwned, Serialize};

use crate::{
    child,
    frame::{decode, encode, read_frame, write_frame, Frame, ANSWER, CANCEL, JOB, PANICKED},
    resident_bytes, IsolateError,
};

/// How long after its deadline a job that has not answered is stopped: the planner's own
/// budget check answers TIMEOUT at the deadline; this is the hard limit behind it.
pub const DEFAULT_GRACE: Duration = Duration::from_millis(500);

/// How long a cancelled job may take to answer before it is stopped: short, because a node
/// that stops (Ctrl-C) must answer and leave within 2 s.
pub const DEFAULT_CANCEL_GRACE: Duration = Duration::from_millis(200);

/// Largest answer read from a worker (bytes). Answers are published far smaller (4 MiB).
const MAX_ANSWER_BYTES: u64 = 256 << 20;

/// What a worker process runs: one job under a budget, to one answer.
///
/// Jobs and answers cross the process boundary as CDR (`cdr_encoding`), so they must
/// round-trip through serde.
pub trait Work: Send + Sync + 'static {
    /// A job, as sent to the worker.
    type Job: Serialize + DeserializeOwned;
    /// Its answer.
    type Answer: Serialize + DeserializeOwned + Send + 'static;

    /// Runs one job (in the worker process) under `budget`: the job's time limit, a token the
    /// supervisor cancels, and the memory limit ([`Budget::memory_limit`]).
    fn run(&self, job: Self::Job, budget: &Budget) -> Self::Answer;
}

/// The supervisor's limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SupervisorSettings {
    /// Memory one job may add to the worker's resident memory (bytes); also the budget's
    /// memory limit given to the job.
    pub memory: u64,
    /// How long past its time limit a job may run before it is stopped.
    pub grace: Duration,
    /// How long a cancelled job ([`Supervisor::cancel`]) may take to answer before it is
    /// stopped.
    pub cancel_grace: Duration,
    /// The worker is replaced after a job when its resident memory has grown by more than
    /// this since it started (bytes): what a planner keeps between jobs stays bounded.
    pub recycle_growth: u64,
    /// Address space the worker may add beyond its size at start (bytes; `RLIMIT_AS`): the
    /// backstop against a single huge allocation between two memory polls. `None`: no limit.
    pub address_space: Option<u64>,
}

impl SupervisorSettings {
    /// The settings for a memory budget of `memory` bytes: [`DEFAULT_GRACE`],
    /// [`DEFAULT_CANCEL_GRACE`], recycling past
    /// half the budget, an address-space backstop of four budgets plus 4 GiB (thread stacks
    /// and allocator arenas reserve address space they never touch).
    pub fn new(memory: u64) -> Self {
        Self {
            memory,
            grace: DEFAULT_GRACE,
            cancel_grace: DEFAULT_CANCEL_GRACE,
            recycle_growth: memory / 2,
            address_space: Some(memory.saturating_mul(4).saturating_add(4 << 30)),
        }
    }
}

/// How a job ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome<A> {
    /// The worker answered.
    Answered(A),
    /// The job panicked in the worker (the worker goes on serving).
    Panicked {
        /// The panic message.
        message: String,
    },
    /// The job had not answered at its time limit plus the grace: the worker was stopped.
    TimedOut {
        /// The job's time limit.
        limit: Duration,
        /// When it was stopped, from the job's start.
        elapsed: Duration,
    },
    /// The worker's resident memory grew past the job's memory limit: it was stopped.
    OverMemory {
        /// The limit (bytes).
        limit: u64,
        /// The growth seen when it was stopped (bytes).
        grown: u64,
    },
    /// The worker died or could not be read; what happened.
    Crashed {
        /// The cause ("killed by signal 6 (SIGABRT)", "exited with code 1", …).
        reason: String,
    },
    /// The job was cancelled ([`Supervisor::cancel`]) and had not answered within the grace:
    /// the worker was stopped.
    Stopped,
}

/// A worker process.
struct Child {
    pid: libc::pid_t,
    stream: UnixStream,
    /// Frames read by the reader thread; `None` when the worker closed its end (or a frame
    /// could not be read).
    frames: Receiver<Option<Frame>>,
    /// Resident memory right after the fork.
    start_rss: u64,
}

/// The job that runs.
struct Running {
    id: u64,
    started: Instant,
    limit: Duration,
    start_rss: u64,
    /// Set by [`Supervisor::cancel`]: the job is stopped when it has not answered in time.
    cancelled_at: Option<Instant>,
}

/// Runs jobs, one at a time, in a worker process forked from this one, and stops a job that
/// outlives its deadline or outgrows its memory (module docs).
pub struct Supervisor<W: Work> {
    work: Arc<W>,
    settings: SupervisorSettings,
    child: Option<Child>,
    running: Option<Running>,
    forks: u64,
}

impl<W: Work> Supervisor<W> {
    /// A supervisor for `work`; no worker runs until [`Self::warm`] or the first job.
    pub fn new(work: Arc<W>, settings: SupervisorSettings) -> Self {
        Self {
            work,
            settings,
            child: None,
            running: None,
            forks: 0,
        }
    }

    /// The settings.
    pub fn settings(&self) -> SupervisorSettings {
        self.settings
    }

    /// How many worker processes were started so far.
    pub fn forks(&self) -> u64 {
        self.forks
    }

    /// The worker's pid, if one runs.
    pub fn worker_pid(&self) -> Option<u32> {
        self.child.as_ref().and_then(|c| u32::try_from(c.pid).ok())
    }

    /// Whether a job runs.
    pub fn is_busy(&self) -> bool {
        self.running.is_some()
    }

    /// Starts a worker now if none runs, so the first job does not wait for the fork.
    ///
    /// # Errors
    /// [`IsolateError::System`] when the fork fails.
    pub fn warm(&mut self) -> Result<(), IsolateError> {
        if self.child.is_none() {
            self.child = Some(self.spawn()?);
        }
        Ok(())
    }

    /// Hands job `id` to the worker (starting one if needed) with a time limit of `limit`.
    ///
    /// # Errors
    /// [`IsolateError::Busy`] while another job runs; [`IsolateError::Encoding`] for a job
    /// that does not encode; [`IsolateError::System`] when no worker can be started or
    /// reached.
    pub fn submit(&mut self, id: u64, job: &W::Job, limit: Duration) -> Result<(), IsolateError> {
        if let Some(r) = &self.running {
            return Err(IsolateError::Busy { running: r.id });
        }
        let body = encode(job).map_err(|reason| IsolateError::Encoding {
            what: "encode the job",
            reason,
        })?;
        let frame = Frame {
            kind: JOB,
            id,
            a: u64::try_from(limit.as_nanos()).unwrap_or(u64::MAX),
            b: self.settings.memory,
            body,
        };
        // A worker that died while idle (or was never started) is replaced once.
        for attempt in 0..2 {
            self.warm()?;
            let Some(child) = &self.child else { continue };
            let start_rss = resident_bytes(child.pid as u32).unwrap_or(0);
            match write_frame(&child.stream, &frame) {
                Ok(()) => {
                    self.running = Some(Running {
                        id,
                        started: Instant::now(),
                        limit,
                        start_rss,
                        cancelled_at: None,
                    });
                    return Ok(());
                }
                Err(e) => {
                    self.retire();
                    if attempt == 1 {
                        return Err(IsolateError::System {
                            call: "send",
                            reason: e.to_string(),
                        });
                    }
                }
            }
        }
        Err(IsolateError::System {
            call: "fork",
            reason: "no worker process".into(),
        })
    }

    /// Asks the running job to stop at its next budget check. If it has not answered
    /// [`SupervisorSettings::cancel_grace`] later, [`Self::poll`] stops the worker
    /// ([`Outcome::Stopped`]).
    pub fn cancel(&mut self) {
        let (Some(r), Some(c)) = (self.running.as_mut(), self.child.as_ref()) else {
            return;
        };
        if r.cancelled_at.is_none() {
            r.cancelled_at = Some(Instant::now());
            // A worker that cannot be written to is stopped by the grace.
            let _ = write_frame(&c.stream, &Frame::new(CANCEL, r.id, Vec::new()));
        }
    }

    /// How the running job ended, if it has; never blocks (one `/proc` read for the worker's
    /// memory).
    ///
    /// # Returns
    /// The job's id and outcome, once.
    pub fn poll(&mut self) -> Option<(u64, Outcome<W::Answer>)> {
        let run = self.running.as_ref()?;
        let id = run.id;
        let Some(child) = self.child.as_ref() else {
            self.running = None;
            return Some((
                id,
                Outcome::Crashed {
                    reason: "no worker process".into(),
                },
            ));
        };
        loop {
            match child.frames.try_recv() {
                Ok(Some(f)) if f.id != id => continue,
                Ok(Some(f)) => {
                    let outcome = match f.kind {
                        ANSWER => match decode::<W::Answer>(&f.body) {
                            Ok(a) => Outcome::Answered(a),
                            Err(reason) => Outcome::Crashed {
                                reason: format!("the answer did not decode: {reason}"),
                            },
                        },
                        PANICKED => Outcome::Panicked {
                            message: String::from_utf8_lossy(&f.body).into_owned(),
                        },
                        other => Outcome::Crashed {
                            reason: format!("unexpected frame kind {other}"),
                        },
                    };
                    self.running = None;
                    self.recycle_if_grown();
                    return Some((id, outcome));
                }
                Ok(None) | Err(TryRecvError::Disconnected) => {
                    let reason = self.reap_dead();
                    self.running = None;
                    return Some((id, Outcome::Crashed { reason }));
                }
                Err(TryRecvError::Empty) => break,
            }
        }
        let elapsed = run.started.elapsed();
        if let Some(at) = run.cancelled_at {
            if at.elapsed() > self.settings.cancel_grace {
                self.retire();
                self.running = None;
                return Some((id, Outcome::Stopped));
            }
        }
        if elapsed > run.limit.saturating_add(self.settings.grace) {
            let limit = run.limit;
            self.retire();
            self.running = None;
            return Some((id, Outcome::TimedOut { limit, elapsed }));
        }
        if let Some(rss) = resident_bytes(child.pid as u32) {
            let grown = rss.saturating_sub(run.start_rss);
            if grown > self.settings.memory {
                self.retire();
                self.running = None;
                return Some((
                    id,
                    Outcome::OverMemory {
                        limit: self.settings.memory,
                        grown,
                    },
                ));
            }
        }
        None
    }

    /// Forks a worker.
    fn spawn(&mut self) -> Result<Child, IsolateError> {
        let (parent_end, child_end) = UnixStream::pair().map_err(|e| IsolateError::System {
            call: "socketpair",
            reason: e.to_string(),
        })?;
        let mut reader = parent_end.try_clone().map_err(|e| IsolateError::System {
            call: "dup",
            reason: e.to_string(),
        })?;
        // SAFETY: getpid has no preconditions.
        let parent = unsafe { libc::getpid() };
        // SAFETY: after fork the child runs only `child::serve`, which never returns: it reads
        // jobs, runs `Work::run` and leaves with `_exit` (module docs: what it inherits).
        let pid = unsafe { libc::fork() };
        if pid < 0 {
            return Err(IsolateError::last_os("fork"));
        }
        if pid == 0 {
            drop(parent_end);
            drop(reader);
            child::serve(&*self.work, child_end, parent, self.settings.address_space);
        }
        drop(child_end);
        self.forks += 1;
        let (tx, frames) = channel();
        let spawned = std::thread::Builder::new()
            .name(format!("worker-{pid}"))
            .spawn(move || loop {
                match read_frame(&mut reader, MAX_ANSWER_BYTES) {
                    Ok(Some(f)) => {
                        if tx.send(Some(f)).is_err() {
                            return;
                        }
                    }
                    Ok(None) | Err(_) => {
                        let _ = tx.send(None);
                        return;
                    }
                }
            });
        let child = Child {
            pid,
            stream: parent_end,
            frames,
            start_rss: resident_bytes(pid as u32).unwrap_or(0),
        };
        if let Err(e) = spawned {
            kill_and_reap(child.pid);
            return Err(IsolateError::System {
                call: "spawn the reader thread",
                reason: e.to_string(),
            });
        }
        Ok(child)
    }

    /// Replaces the worker after a job when it has grown past the recycle limit.
    fn recycle_if_grown(&mut self) {
        let grown = self
            .child
            .as_ref()
            .and_then(|c| resident_bytes(c.pid as u32).map(|rss| rss.saturating_sub(c.start_rss)));
        if grown.is_some_and(|g| g > self.settings.recycle_growth) {
            self.retire();
        }
    }

    /// Stops and reaps the worker (if any).
    fn retire(&mut self) {
        if let Some(c) = self.child.take() {
            let _ = c.stream.shutdown(std::net::Shutdown::Both);
            kill_and_reap(c.pid);
        }
    }

    /// The worker closed its socket: reaps it and says how it ended.
    fn reap_dead(&mut self) -> String {
        let Some(c) = self.child.take() else {
            return "no worker process".into();
        };
        let mut status = 0;
        // The socket closed because the process is exiting; wait for it briefly, then stop it.
        let deadline = Instant::now() + Duration::from_millis(200);
        loop {
            // SAFETY: waitpid on our own child with a valid status pointer.
            let r = unsafe { libc::waitpid(c.pid, &mut status, libc::WNOHANG) };
            if r == c.pid {
                return describe(status);
            }
            if r < 0 || Instant::now() > deadline {
                kill_and_reap(c.pid);
                return "the worker closed its socket".into();
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

impl<W: Work> Drop for Supervisor<W> {
    fn drop(&mut self) {
        self.retire();
    }
}

/// SIGKILL and wait: the worker is gone and reaped when this returns.
fn kill_and_reap(pid: libc::pid_t) {
    let mut status = 0;
    // SAFETY: signalling and waiting for our own child.
    unsafe {
        libc::kill(pid, libc::SIGKILL);
        while libc::waitpid(pid, &mut status, 0) < 0 {
            if std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted {
                break;
            }
        }
    }
}

/// A wait status as text.
fn describe(status: libc::c_int) -> String {
    if libc::WIFSIGNALED(status) {
        let sig = libc::WTERMSIG(status);
        let name = match sig {
            libc::SIGABRT => {
                " (SIGABRT: an allocation failed past the address-space backstop, or an abort)"
            }
            libc::SIGKILL => " (SIGKILL: stopped from outside, e.g. by the kernel's OOM killer)",
            libc::SIGSEGV => " (SIGSEGV)",
            _ => "",
        };
        format!("the worker process was killed by signal {sig}{name}")
    } else if libc::WIFEXITED(status) {
        format!(
            "the worker process exited with code {}",
            libc::WEXITSTATUS(status)
        )
    } else {
        format!("the worker process ended (wait status {status})")
    }
}
