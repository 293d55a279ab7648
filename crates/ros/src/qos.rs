//! Named QoS profiles. Every kerf endpoint uses one of these; none relies on ros2-client's
//! defaults (publisher keep-last 1, subscription best-effort), which lose samples.

use ros2_client::{
    action::ActionServerQosPolicies,
    qos::{Durability, History, Reliability, WhenFull},
    QosProfile,
};

/// Depth of every keep-last history kerf creates, unless a profile says otherwise.
pub const DEFAULT_DEPTH: usize = 10;

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
}
