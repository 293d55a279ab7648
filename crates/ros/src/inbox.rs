//! [`Inbox`]: a subscription read on its own thread.
//!
//! Taking a sample deserializes it; a large message (a 5000-point trajectory is about 1 MB)
//! costs milliseconds, more than a control period. The inbox thread takes and deserializes
//! samples and hands them over through a channel, so a control loop only moves them.
//!
//! The channel holds at most [`INBOX_CAPACITY`] samples. While it is full the thread stops
//! taking, so unread samples wait in the subscription's keep-last history, which drops the
//! oldest: a reader that falls behind holds at most capacity + depth samples, never an
//! unbounded backlog of deserialized messages (issue 11, item 5).

use std::{
    sync::{
        atomic::{AtomicBool, Ordering},
        mpsc::{sync_channel, Receiver, TrySendError},
        Arc,
    },
    thread::JoinHandle,
    time::Duration,
};

use ros2_client::Subscription;
use serde::de::DeserializeOwned;

/// How often the inbox thread looks for new samples when it found none.
pub const INBOX_POLL: Duration = Duration::from_millis(1);

/// Most deserialized samples waiting in an inbox for the caller to take them.
pub const INBOX_CAPACITY: usize = 4;

/// A received sample and its source timestamp (ns since the epoch, the writer's clock), when
/// the writer gave one.
type Stamped<M> = (M, Option<i64>);

/// A subscription drained by a background thread.
pub struct Inbox<M> {
    rx: Receiver<Result<Stamped<M>, String>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl<M: DeserializeOwned + Send + 'static> Inbox<M> {
    /// Moves `sub` to a thread named `name`.
    pub fn new(sub: Subscription<M>, name: &str) -> std::io::Result<Self> {
        let (tx, rx) = sync_channel(INBOX_CAPACITY);
        let stop = Arc::new(AtomicBool::new(false));
        let stop_t = Arc::clone(&stop);
        let thread = std::thread::Builder::new()
            .name(format!("in-{name}"))
            .spawn(move || {
                // Hands `item` over, waiting while the channel is full; false once the inbox
                // is dropped or stopped.
                let hand_over = |mut item: Result<Stamped<M>, String>| loop {
                    match tx.try_send(item) {
                        Ok(()) => return true,
                        Err(TrySendError::Disconnected(_)) => return false,
                        Err(TrySendError::Full(back)) => {
                            if stop_t.load(Ordering::Relaxed) {
                                return false;
                            }
                            item = back;
                            std::thread::sleep(INBOX_POLL);
                        }
                    }
                };
                while !stop_t.load(Ordering::Relaxed) {
                    match sub.take() {
                        Ok(Some((m, info))) => {
                            let stamp = info.source_timestamp().map(|t| t.to_nanos());
                            if !hand_over(Ok((m, stamp))) {
                                return;
                            }
                        }
                        Ok(None) => std::thread::sleep(INBOX_POLL),
                        Err(e) => {
                            if !hand_over(Err(format!("{e:?}"))) {
                                return;
                            }
                            std::thread::sleep(INBOX_POLL);
                        }
                    }
                }
            })?;
        Ok(Self {
            rx,
            stop,
            thread: Some(thread),
        })
    }

    /// The next received sample (or read error, e.g. a sample that did not deserialize), if
    /// any. Never blocks.
    pub fn try_recv(&self) -> Option<Result<M, String>> {
        self.try_recv_stamped().map(|r| r.map(|(m, _)| m))
    }

    /// As [`Self::try_recv`], with the sample's source timestamp (ns since the Unix epoch, the
    /// writer's clock; `None` when the writer gave none).
    pub fn try_recv_stamped(&self) -> Option<Result<(M, Option<i64>), String>> {
        self.rx.try_recv().ok()
    }
}

impl<M> Drop for Inbox<M> {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
