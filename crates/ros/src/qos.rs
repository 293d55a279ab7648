//! Named QoS profiles. Every kerf endpoint uses one of these; none relies on ros2-client's
//! defaults (publisher keep-last 1, subscription best-effort), which lose samples.
//!
//! # No reader can stall a stream (issue 33, item 6)
//!
//! A reliable RustDDS (0.15) writer keeps every sample that a matched reliable reader has not
//! acknowledged, whatever its keep-last depth, up to a send window of `ResourceLimits::
//! max_samples` samples (8192 when none is set: [`RUSTDDS_DEFAULT_WINDOW`]); then each write
//! waits `when_full` and fails. A reader whose process died (`kerf echo /joint_states | head
//! -1`, a SIGKILL) or is stopped never acknowledges again, and stays matched until its
//! participant's lease ends: RustDDS participants announce 50 s (5 × their 10 s SPDP period,
//! not configurable) and check leases every 2 s; Cyclone DDS announces 10 s and Fast DDS 20 s.
//! At 250 Hz the default window is full after 32.8 s, before a RustDDS reader's lease can end,
//! and every other subscriber then saw /joint_states stop (the stall the issue measured).
//!
//! What RustDDS offers, and what each does to the other readers:
//! * `WhenFull::Fail` or a shorter `when_full`: the write still fails, for every reader.
//! * A smaller `max_samples`: the window fills sooner (it is flow control, not keep-last).
//! * Keep-last overwriting unacknowledged samples: not offered by RustDDS 0.15 for a reliable
//!   writer with a matched reliable reader.
//! * A shorter lease: RustDDS's is a constant, and it is the remote's announced lease that
//!   counts.
//! * Dropping one matched reader from the writer: no public API.
//!
//! So kerf sizes the window by time: a stream's writer gets a window of
//! [`send_window`]`(rate)` = rate × [`READER_LEASE_HORIZON`] samples (at least RustDDS's
//! default), longer than any lease a ROS 2 DDS announces by default. A reader that stops
//! acknowledging is dropped by its lease before the window fills, and the other readers see
//! nothing of it. The price is memory while such a reader lingers: the samples it has not
//! acknowledged, at most one window (at 250 Hz, 16 000 samples of /joint_states, about 6 MB),
//! given back when the lease ends. A remote announcing a lease longer than the horizon still
//! fills the window; [`crate::Streamer`] then counts the writes that fail.

use std::time::Duration;

use ros2_client::{
    action::ActionServerQosPolicies,
    qos::{Durability, History, Reliability, WhenFull},
    QosProfile,
};

/// Depth of every keep-last history kerf creates, unless a profile says otherwise.
pub const DEFAULT_DEPTH: usize = 10;

/// The send window RustDDS gives a writer without `ResourceLimits` (samples).
pub const RUSTDDS_DEFAULT_WINDOW: usize = 8192;

/// How long a stream's writer goes on publishing without an acknowledgement from one reader:
/// longer than the 52 s after which RustDDS drops a silent participant announcing its 50 s
/// lease (checked every 2 s), with a margin for the SPDP period.
pub const READER_LEASE_HORIZON: Duration = Duration::from_secs(64);

/// The largest stream rate [`send_window`] accepts (Hz): a window of 64 × 10⁴ samples.
pub const MAX_STREAM_RATE_HZ: f64 = 10_000.0;

/// The send window (samples) of a reliable stream published at `rate_hz`: enough samples for
/// [`READER_LEASE_HORIZON`], at least [`RUSTDDS_DEFAULT_WINDOW`].
///
/// # Arguments
/// * `rate_hz` – how often the stream is published (Hz), in (0, [`MAX_STREAM_RATE_HZ`]].
///
/// # Errors
/// A message naming `rate_hz` when it is not finite or outside that range.
pub fn send_window(rate_hz: f64) -> Result<usize, String> {
    if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= MAX_STREAM_RATE_HZ) {
        return Err(format!(
            "rate_hz = {rate_hz} Hz: a stream's rate must be finite, > 0 and at most {MAX_STREAM_RATE_HZ} Hz"
        ));
    }
    let samples = (rate_hz * READER_LEASE_HORIZON.as_secs_f64()).ceil();
    // In range: at most 6.4·10⁵ by the check above.
    Ok((samples as usize).max(RUSTDDS_DEFAULT_WINDOW))
}

/// Reliable, volatile, keep-last `depth`: ROS 2's default topic profile (`rmw_qos_profile_default`).
///
/// A reliable `publish` waits up to 100 ms for window space before reporting `WouldBlock`.
pub fn reliable(depth: usize) -> QosProfile {
    QosProfile::publisher_default()
        .reliability(Reliability::Reliable {
            when_full: WhenFull::DEFAULT,
        })
        .durability(Durability::Volatile)
        .history(History::KeepLast {
            depth: depth.max(1),
        })
}

/// The profile for commands and results: reliable, volatile, keep-last 10.
pub fn commands() -> QosProfile {
    reliable(DEFAULT_DEPTH)
}

/// The profile for high-rate state streams (`/joint_states`, controller state): reliable,
/// volatile, keep-last 10, like `joint_state_broadcaster`. Best-effort subscribers match it too.
/// Published through [`crate::KerfNode::streamer`], whose writer has the [`send_window`] of the
/// stream's rate, so that no reader can stall it (module docs).
pub fn state() -> QosProfile {
    reliable(DEFAULT_DEPTH)
}

/// Latched status: reliable, transient-local, keep-last 10, so a late subscriber still sees
/// the most recent results.
pub fn latched() -> QosProfile {
    reliable(DEFAULT_DEPTH).durability(Durability::TransientLocal)
}

/// Services: reliable, volatile, keep-last 10 (`rmw_qos_profile_services_default`).
pub fn services() -> QosProfile {
    reliable(DEFAULT_DEPTH)
}

/// The QoS of an action server's endpoints, as rcl_action sets them: services and feedback
/// reliable/volatile, status reliable/transient-local keep-last 1.
pub fn action_server() -> ActionServerQosPolicies {
    ActionServerQosPolicies {
        goal_service: services(),
        result_service: services(),
        cancel_service: services(),
        // Feedback is periodic: a stalled client must not block the server, so a full send
        // window drops the sample at once instead of waiting.
        feedback_publisher: reliable(DEFAULT_DEPTH).reliability(Reliability::Reliable {
            when_full: WhenFull::Fail,
        }),
        status_publisher: reliable(1).durability(Durability::TransientLocal),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_are_reliable_with_depth() {
        for p in [commands(), state(), latched(), services()] {
            assert!(matches!(p.reliability, Reliability::Reliable { .. }));
            assert_eq!(
                p.history,
                History::KeepLast {
                    depth: DEFAULT_DEPTH
                }
            );
        }
        assert_eq!(latched().durability, Durability::TransientLocal);
        assert_eq!(commands().durability, Durability::Volatile);
    }

    #[test]
    fn the_window_outlasts_every_default_lease() {
        // 250 Hz: 16 000 samples, 64 s; RustDDS's 8192 would last 32.8 s.
        assert_eq!(send_window(250.0).unwrap(), 16_000);
        assert_eq!(send_window(1000.0).unwrap(), 64_000);
        // Slow streams keep at least RustDDS's default.
        assert_eq!(send_window(20.0).unwrap(), RUSTDDS_DEFAULT_WINDOW);
        assert_eq!(
            send_window(MAX_STREAM_RATE_HZ).unwrap(),
            640_000,
            "the largest window"
        );
        for rate in [0.0, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e308] {
            let e = send_window(rate).unwrap_err();
            assert!(e.contains("rate_hz"), "{e}");
        }
        // A window of rate × horizon outlasts RustDDS's 50 s lease checked every 2 s.
        for rate in [1.0, 20.0, 250.0, 1000.0] {
            let lasts = send_window(rate).unwrap() as f64 / rate;
            assert!(lasts >= 52.0 + 10.0, "{rate} Hz: {lasts} s");
        }
    }
}
