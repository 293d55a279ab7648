//! Reading a subscription with a deadline.

use std::time::{Duration, Instant};

use ros2_client::Subscription;
use serde::de::DeserializeOwned;

/// The next sample of `sub`; fails the test with "no `what` within `timeout`", or on a read
/// error.
pub fn take<M: DeserializeOwned + 'static>(
    sub: &Subscription<M>,
    timeout: Duration,
    what: &str,
) -> M {
    let deadline = Instant::now() + timeout;
    while Instant::now() < deadline {
        match sub.take() {
            Ok(Some((m, _))) => return m,
            Ok(None) => std::thread::sleep(Duration::from_millis(2)),
            Err(e) => panic!("reading {what}: {e:?}"),
        }
    }
    panic!("no {what} within {timeout:?}");
}

/// The newest sample of `sub`: waits for one as [`take`] does, then reads every sample
/// already received and returns the last.
pub fn take_newest<M: DeserializeOwned + 'static>(
    sub: &Subscription<M>,
    timeout: Duration,
    what: &str,
) -> M {
    let mut newest = take(sub, timeout, what);
    while let Ok(Some((m, _))) = sub.take() {
        newest = m;
    }
    newest
}
