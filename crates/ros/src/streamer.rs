//! [`Streamer`]: publishing that never blocks the caller.
//!
//! A reliable DDS writer blocks `publish` when a matched reliable reader stops acknowledging
//! and the send window fills (RustDDS: `ResourceLimits::max_samples`, 8192 by default, then
//! up to `when_full` per sample). A control loop must not stall because a remote tool is
//! slow, so high-rate streams are handed to a thread through a bounded queue: when the queue
//! is full the newest sample is dropped and counted, and the control loop goes on.
//!
//! The queue protects the caller; the window protects the other readers:
//! [`crate::KerfNode::streamer`] gives the writer a window of [`crate::qos::send_window`]
//! samples, longer than the lease after which a reader that stopped acknowledging (a dead or
//! stopped process) is dropped, so that such a reader never fills it ([`crate::qos`]).

use std::{
    sync::{
        atomic::{AtomicU64, Ordering},
        mpsc::{sync_channel, SyncSender, TrySendError},
        Arc,
    },
    thread::JoinHandle,
};

use ros2_client::Publisher;
use serde::Serialize;

/// A publisher running on its own thread behind a bounded queue.
pub struct Streamer<M> {
    tx: Option<SyncSender<M>>,
    thread: Option<JoinHandle<()>>,
    dropped: Arc<AtomicU64>,
    failed: Arc<AtomicU64>,
}

impl<M: Serialize + Send + 'static> Streamer<M> {
    /// Moves `publisher` to a thread named `name` with a queue of `capacity` samples.
    pub fn new(publisher: Publisher<M>, capacity: usize, name: &str) -> std::io::Result<Self> {
        let (tx, rx) = sync_channel::<M>(capacity.max(1));
        let failed = Arc::new(AtomicU64::new(0));
        let failed_t = Arc::clone(&failed);
        let thread = std::thread::Builder::new()
            .name(format!("pub-{name}"))
            .spawn(move || {
                for msg in rx {
                    if publisher.publish(msg).is_err() {
                        failed_t.fetch_add(1, Ordering::Relaxed);
                    }
                }
            })?;
        Ok(Self {
            tx: Some(tx),
            thread: Some(thread),
            dropped: Arc::new(AtomicU64::new(0)),
            failed,
        })
    }

    /// Queues `msg` without blocking.
    ///
    /// # Returns
    /// `false` if the queue was full and the sample was dropped.
    pub fn publish(&self, msg: M) -> bool {
        match self.tx.as_ref().map(|tx| tx.try_send(msg)) {
            Some(Ok(())) => true,
            Some(Err(TrySendError::Full(_) | TrySendError::Disconnected(_))) | None => {
                self.dropped.fetch_add(1, Ordering::Relaxed);
                false
            }
        }
    }

    /// Samples dropped because the queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// Samples the DDS writer refused (send window full past `when_full`: a reader has not
    /// acknowledged for the whole window, longer than any default lease).
    pub fn failed(&self) -> u64 {
        self.failed.load(Ordering::Relaxed)
    }
}

impl<M> Drop for Streamer<M> {
    fn drop(&mut self) {
        self.tx = None; // ends the thread's loop once the queue is drained
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
