//! The request/worker pattern: a node hands slow work (planning) to background threads and
//! keeps serving its topics, then collects results when they are ready.
//!
//! Requests are processed in submission order by a fixed number of threads. A panic inside
//! the work function is caught and reported as [`WorkerError::Panicked`] for that request; the
//! worker keeps serving the next ones.

use std::{
    panic::{catch_unwind, AssertUnwindSafe},
    sync::{
        mpsc::{channel, Receiver, Sender},
        Arc, Mutex,
    },
    thread::JoinHandle,
};

/// Why a request produced no result.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WorkerError {
    /// The work function panicked; the message is the panic payload if it was a string.
    #[error("request {ticket} failed inside the worker: {message}")]
    Panicked {
        /// Ticket of the request.
        ticket: u64,
        /// Panic message.
        message: String,
    },
}

type Job<Req> = (u64, Req);
type Done<Resp> = (u64, Result<Resp, WorkerError>);

/// A pool of background threads running one work function.
pub struct Worker<Req, Resp> {
    jobs: Option<Sender<Job<Req>>>,
    done: Receiver<Done<Resp>>,
    threads: Vec<JoinHandle<()>>,
    next_ticket: u64,
}

impl<Req: Send + 'static, Resp: Send + 'static> Worker<Req, Resp> {
    /// Starts `threads` (at least 1) threads named `name-N` running `work`.
    pub fn spawn<F>(name: &str, threads: usize, work: F) -> std::io::Result<Self>
    where
        F: Fn(Req) -> Resp + Send + Sync + 'static,
    {
        let (jobs_tx, jobs_rx) = channel::<Job<Req>>();
        let (done_tx, done_rx) = channel::<Done<Resp>>();
        let jobs_rx = Arc::new(Mutex::new(jobs_rx));
        let work = Arc::new(work);
        let mut handles = Vec::new();
        for n in 0..threads.max(1) {
            let jobs_rx = Arc::clone(&jobs_rx);
            let done_tx = done_tx.clone();
            let work = Arc::clone(&work);
            handles.push(
                std::thread::Builder::new()
                    .name(format!("{name}-{n}"))
                    .spawn(move || loop {
                        let job = match jobs_rx.lock() {
                            Ok(rx) => rx.recv(),
                            Err(_) => return,
                        };
                        let Ok((ticket, req)) = job else { return };
                        let result =
                            catch_unwind(AssertUnwindSafe(|| work(req))).map_err(|payload| {
                                let message = payload
                                    .downcast_ref::<&str>()
                                    .map(|s| s.to_string())
                                    .or_else(|| payload.downcast_ref::<String>().cloned())
                                    .unwrap_or_else(|| "non-string panic payload".into());
                                WorkerError::Panicked { ticket, message }
                            });
                        if done_tx.send((ticket, result)).is_err() {
                            return;
                        }
                    })?,
            );
        }
        Ok(Self {
            jobs: Some(jobs_tx),
            done: done_rx,
            threads: handles,
            next_ticket: 0,
        })
    }

    /// Queues a request.
    ///
    /// # Returns
    /// Its ticket, which comes back with its result.
    pub fn submit(&mut self, req: Req) -> u64 {
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        if let Some(tx) = &self.jobs {
            // Threads only exit when `jobs` is dropped, so the send cannot fail while we hold it.
            let _ = tx.send((ticket, req));
        }
        ticket
    }

    /// A finished result, if one is ready. Never blocks.
    pub fn try_recv(&self) -> Option<(u64, Result<Resp, WorkerError>)> {
        self.done.try_recv().ok()
    }

    /// Waits up to `timeout` for a finished result.
    pub fn recv_timeout(
        &self,
        timeout: std::time::Duration,
    ) -> Option<(u64, Result<Resp, WorkerError>)> {
        self.done.recv_timeout(timeout).ok()
    }
}

impl<Req, Resp> Drop for Worker<Req, Resp> {
    fn drop(&mut self) {
        self.jobs = None; // closes the queue: threads finish their current job and exit
        for h in self.threads.drain(..) {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn results_come_back_and_panics_are_contained() {
        let mut w = Worker::spawn("t", 2, |x: u32| {
            if x == 3 {
                panic!("three is bad");
            }
            std::thread::sleep(Duration::from_millis(5));
            x * 2
        })
        .unwrap();
        let tickets: Vec<u64> = (0..6).map(|x| w.submit(x)).collect();
        let mut got = Vec::new();
        while got.len() < tickets.len() {
            got.push(
                w.recv_timeout(Duration::from_secs(5))
                    .expect("result in time"),
            );
        }
        got.sort_by_key(|(t, _)| *t);
        for (t, r) in got {
            if t == 3 {
                assert!(
                    matches!(r, Err(WorkerError::Panicked { ref message, .. }) if message.contains("three"))
                );
            } else {
                assert_eq!(r.unwrap(), t as u32 * 2);
            }
        }
    }

    #[test]
    fn caller_keeps_running_while_work_is_slow() {
        let mut w = Worker::spawn("slow", 1, |_: ()| {
            std::thread::sleep(Duration::from_millis(200))
        })
        .unwrap();
        w.submit(());
        // The submitting thread is not blocked: nothing is ready yet.
        assert!(w.try_recv().is_none());
        assert!(w.recv_timeout(Duration::from_secs(5)).is_some());
    }
}
