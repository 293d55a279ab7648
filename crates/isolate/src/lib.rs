//! Plans in a supervised worker process (issue 33, items 2 and 3).
//!
//! A planner that stops checking its [`kerf_budget::Budget`] (an endless loop, a stage that
//! allocates without estimating) cannot be stopped from inside its process: a thread cannot be
//! killed, and an allocation failure aborts the whole process. So every plan runs in a
//! **worker process** forked from the node, and the node supervises it:
//!
//! ```text
//!  node (parent)                                     worker (child, forked on demand)
//!  Supervisor::submit(id, job, limit) ── Job ──────► Work::run(job, budget)
//!  Supervisor::poll() every loop:        ◄─ Answer ─   budget: limit + cancel + plan memory
//!    answer → Outcome::Answered
//!    now > start + limit + grace → SIGKILL, reap → Outcome::TimedOut
//!    RSS growth > memory          → SIGKILL, reap → Outcome::OverMemory
//!    worker died (signal, exit)   → reap          → Outcome::Crashed
//!  Supervisor::cancel()                ── Cancel ──► the job's CancelToken
//! ```
//!
//! The worker is kept between jobs (caches a planner builds, such as the milling planner's
//! per-path indicator caches, survive), and replaced by a fresh fork after it was killed or when
//! its resident memory has grown by more than [`SupervisorSettings::recycle_growth`]. The node
//! process itself never plans, so its memory does not grow with the requests it serves.
//!
//! What the worker inherits and what it must not touch: it is forked from the node's thread, so
//! it holds a copy of the node's memory (the planner, its models and caches) but none of its
//! other threads. It only runs [`Work::run`], reads jobs from and writes answers to its socket,
//! and leaves with `_exit` (no destructor of the node runs in it: no DDS traffic, no log line).
//! It ignores SIGINT (Ctrl-C reaches the whole process group; the node decides), dies with the
//! node's thread (`PR_SET_PDEATHSIG`), and its address space is limited (`RLIMIT_AS`) as a
//! backstop behind the supervisor's resident-memory bound.

mod child;
mod error;
mod frame;
mod proc_stat;
mod supervisor;

pub use error::IsolateError;
pub use proc_stat::{resident_bytes, virtual_bytes};
pub use supervisor::{
    Outcome, Supervisor, SupervisorSettings, Work, DEFAULT_CANCEL_GRACE, DEFAULT_GRACE,
};
