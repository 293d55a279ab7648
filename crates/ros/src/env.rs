//! The ROS 2 environment variables that choose the DDS domain and how far discovery reaches.
//!
//! ros2-client reads none of them by itself; [`RosEnv`] gives them the meanings they have in
//! ROS 2 Jazzy (REP 2005 era `rmw` behaviour):
//!
//! | variable | meaning |
//! |---|---|
//! | `ROS_DOMAIN_ID` | DDS domain, default 0. kerf accepts 0..=232, the range whose RTPS ports fit in 16 bits. |
//! | `ROS_AUTOMATIC_DISCOVERY_RANGE` | `SUBNET` (default), `LOCALHOST` (loopback only), `OFF`, `SYSTEM_DEFAULT`. |
//! | `ROS_LOCALHOST_ONLY` | deprecated in Jazzy; `1` means `LOCALHOST` when the range is not set. |
//! | `ROS_STATIC_PEERS` | not supported: refused with an error (see below). |
//! | `RMW_IMPLEMENTATION` | which RMW the *peers* use, so services and actions use their RPC mapping: unset or `rmw_fastrtps_cpp` / `rmw_fastrtps_dynamic_cpp` / `rmw_connextdds` → Enhanced (Jazzy's default), `rmw_cyclonedds_cpp` → Cyclone's mapping; anything else is refused. Topics are the same for every RMW. |
//!
//! # Why `ROS_STATIC_PEERS` is refused
//!
//! In Jazzy, `ROS_STATIC_PEERS` (addresses separated by `;`) makes the participant send its
//! SPDP announcements by unicast to each peer's well-known discovery ports of the domain
//! (7400 + 250·domain + 10 + 2·participant id), so hosts find each other where multicast is
//! blocked. RustDDS 0.15.1, which ros2-client 0.12 uses, cannot be told to do that:
//!
//! * `DomainParticipantBuilder` has no peer or initial-locator option; its only knobs are the
//!   interfaces (`with_only_networks`), `same_host_loopback` and socket buffer sizes.
//! * The SPDP writer does have fixed extra unicast destinations
//!   (`Writer::set_extra_unicast_destinations`), but the event loop fills them only with the
//!   *localhost* SPDP ports (127.0.0.1, participant ids 0–11), and the writer lives in the
//!   crate-private `rtps` module.
//! * Announcing from outside is not possible either: a user `DataWriter` cannot take the
//!   built-in SPDP writer's entity id, and `SpdpDiscoveredParticipantData`'s fields have
//!   crate-private types (locators, builtin endpoint set), so an announcement cannot be built
//!   through the public API. Writing SPDP datagrams by hand would compete with the
//!   participant's own writer for sequence numbers.
//!
//! The internal mechanism is enough: a copy of RustDDS 0.15.1 whose event loop also put each
//! peer's well-known SPDP ports (participant ids 0–11) into the SPDP writer's extra unicast
//! destinations let two participants on subnets joined by a unicast-only router match and
//! deliver within 0.44 s when each listed the other (not within 9 s when only one did). What
//! is missing is a public option to do it.
//!
//! Accepting the variable and ignoring it would leave the hosts silently apart, so it is
//! refused. The workaround is a network path that carries multicast between the cell's
//! hosts — a dedicated interface or VLAN for the cell with `ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`
//! (`tests/multihost_e2e.rs` runs a cut across such a link) — or a unicast bridge between
//! hosts that keeps DDS local on each (e.g. `zenoh-bridge-ros2dds`, not tested with kerf).

use std::net::Ipv4Addr;

use ros2_client::{Context, ServiceMapping};

use crate::RosError;

/// How far automatic discovery reaches (`ROS_AUTOMATIC_DISCOVERY_RANGE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiscoveryRange {
    /// Discover and talk to participants on the local subnet (multicast on every interface). Jazzy's default.
    Subnet,
    /// Loopback only: the DDS participant uses only 127.0.0.1, for multicast and for the
    /// unicast locators it advertises.
    Localhost,
    /// Whatever the middleware does by default; for RustDDS that is the same as [`Self::Subnet`].
    SystemDefault,
}

/// The ROS 2 environment of a process: domain id, discovery range, and the RPC mapping of
/// services and actions.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RosEnv {
    /// DDS domain id (`ROS_DOMAIN_ID`).
    pub domain_id: u16,
    /// Discovery range (`ROS_AUTOMATIC_DISCOVERY_RANGE`).
    pub range: DiscoveryRange,
    /// Request/reply mapping of services and actions (from `RMW_IMPLEMENTATION`).
    pub service_mapping: ServiceMapping,
}

impl Default for RosEnv {
    fn default() -> Self {
        Self {
            domain_id: 0,
            range: DiscoveryRange::Subnet,
            service_mapping: ServiceMapping::Enhanced,
        }
    }
}

/// Largest domain id whose RTPS port numbers (7400 + 250·id + offsets) still fit in 16 bits.
pub const MAX_DOMAIN_ID: u16 = 232;

impl RosEnv {
    /// Reads the process environment.
    ///
    /// # Returns
    /// The environment, or an error naming the variable that is malformed or cannot be honoured.
    pub fn from_env() -> Result<Self, RosError> {
        Self::from_vars(|k| std::env::var(k).ok())
    }

    /// Same as [`Self::from_env`], reading variables through `get` (for tests).
    pub fn from_vars(get: impl Fn(&str) -> Option<String>) -> Result<Self, RosError> {
        let domain_id = match get("ROS_DOMAIN_ID").map(|s| s.trim().to_string()) {
            None => 0,
            Some(s) if s.is_empty() => 0,
            Some(s) => match s.parse::<u16>() {
                Ok(id) if id <= MAX_DOMAIN_ID => id,
                Ok(_) => {
                    return Err(RosError::DomainId {
                        value: s,
                        reason: format!("must be at most {MAX_DOMAIN_ID} (RTPS port range)"),
                    })
                }
                Err(_) => {
                    return Err(RosError::DomainId {
                        value: s,
                        reason: "not a non-negative integer".into(),
                    })
                }
            },
        };
        if let Some(peers) = get("ROS_STATIC_PEERS").filter(|s| !s.trim().is_empty()) {
            return Err(RosError::UnsupportedEnv {
                variable: "ROS_STATIC_PEERS".into(),
                value: peers,
                reason: "RustDDS 0.15 has no static peer list (it announces itself by \
                         unicast only to 127.0.0.1), so these peers could not be reached \
                         without multicast; unset it and connect the hosts through a network \
                         or dedicated interface that carries multicast, with \
                         ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET (README, 'Across hosts')"
                    .into(),
            });
        }
        let range = match get("ROS_AUTOMATIC_DISCOVERY_RANGE").map(|s| s.trim().to_string()) {
            Some(s) if !s.is_empty() => match s.as_str() {
                "SUBNET" => DiscoveryRange::Subnet,
                "LOCALHOST" => DiscoveryRange::Localhost,
                "SYSTEM_DEFAULT" => DiscoveryRange::SystemDefault,
                "OFF" => {
                    return Err(RosError::DiscoveryRange {
                        value: s,
                        reason: "OFF (no discovery beyond the process) cannot be honoured by \
                                 RustDDS; use LOCALHOST"
                            .into(),
                    })
                }
                _ => {
                    return Err(RosError::DiscoveryRange {
                        value: s,
                        reason: "expected one of SUBNET, LOCALHOST, OFF, SYSTEM_DEFAULT".into(),
                    })
                }
            },
            _ => match get("ROS_LOCALHOST_ONLY")
                .map(|s| s.trim().to_string())
                .as_deref()
            {
                Some("1") => DiscoveryRange::Localhost,
                _ => DiscoveryRange::Subnet,
            },
        };
        let service_mapping = match get("RMW_IMPLEMENTATION").map(|s| s.trim().to_string()) {
            None => ServiceMapping::Enhanced,
            Some(s) => match s.as_str() {
                "" | "rmw_fastrtps_cpp" | "rmw_fastrtps_dynamic_cpp" | "rmw_connextdds" => {
                    ServiceMapping::Enhanced
                }
                "rmw_cyclonedds_cpp" => ServiceMapping::Cyclone,
                _ => {
                    return Err(RosError::UnsupportedEnv {
                        variable: "RMW_IMPLEMENTATION".into(),
                        value: s,
                        reason: "kerf speaks DDS with the service mappings of rmw_fastrtps_cpp, \
                                 rmw_connextdds and rmw_cyclonedds_cpp"
                            .into(),
                    })
                }
            },
        };
        Ok(Self {
            domain_id,
            range,
            service_mapping,
        })
    }

    /// Creates a ros2-client [`Context`] (one DDS participant) for this environment.
    ///
    /// With [`DiscoveryRange::Localhost`] the participant is restricted to 127.0.0.1
    /// (`DomainParticipantBuilder::with_only_networks`): it multicasts and advertises locators
    /// on loopback only, and announces itself to the well-known loopback ports of the domain.
    pub fn create_context(&self) -> Result<Context, RosError> {
        let mut builder = ros2_client::dds::rustdds::DomainParticipantBuilder::new(self.domain_id);
        if self.range == DiscoveryRange::Localhost {
            builder = builder.with_only_networks([Ipv4Addr::LOCALHOST]);
        }
        let participant = builder.build().map_err(|e| RosError::Dds {
            what: format!("DDS participant in domain {}", self.domain_id),
            reason: e.to_string(),
        })?;
        Context::from_domain_participant(participant).map_err(|e| RosError::Dds {
            what: "ROS 2 context".into(),
            reason: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn env(pairs: &[(&str, &str)]) -> Result<RosEnv, RosError> {
        let m: HashMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        RosEnv::from_vars(|k| m.get(k).cloned())
    }

    #[test]
    fn defaults_are_jazzy_defaults() {
        assert_eq!(env(&[]).unwrap(), RosEnv::default());
        assert_eq!(env(&[("ROS_DOMAIN_ID", "")]).unwrap().domain_id, 0);
    }

    #[test]
    fn reads_domain_and_range() {
        let e = env(&[
            ("ROS_DOMAIN_ID", "42"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
        ])
        .unwrap();
        assert_eq!(e.domain_id, 42);
        assert_eq!(e.range, DiscoveryRange::Localhost);
        let e = env(&[("ROS_AUTOMATIC_DISCOVERY_RANGE", "SYSTEM_DEFAULT")]).unwrap();
        assert_eq!(e.range, DiscoveryRange::SystemDefault);
    }

    #[test]
    fn legacy_localhost_only_applies_only_when_range_unset() {
        assert_eq!(
            env(&[("ROS_LOCALHOST_ONLY", "1")]).unwrap().range,
            DiscoveryRange::Localhost
        );
        assert_eq!(
            env(&[
                ("ROS_LOCALHOST_ONLY", "1"),
                ("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET")
            ])
            .unwrap()
            .range,
            DiscoveryRange::Subnet
        );
    }

    #[test]
    fn refuses_bad_values() {
        for bad in ["-1", "abc", "233", "1.5"] {
            let err = env(&[("ROS_DOMAIN_ID", bad)]).unwrap_err();
            assert!(matches!(err, RosError::DomainId { .. }), "{bad}: {err}");
        }
        let err = env(&[("ROS_AUTOMATIC_DISCOVERY_RANGE", "localhost")]).unwrap_err();
        assert!(err.to_string().contains("LOCALHOST"), "{err}");
        assert!(env(&[("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")]).is_err());
        let err = env(&[("ROS_STATIC_PEERS", "10.0.0.1;host-b")]).unwrap_err();
        assert!(matches!(err, RosError::UnsupportedEnv { .. }), "{err}");
        for needle in [
            "10.0.0.1;host-b",
            "no static peer list",
            "multicast",
            "SUBNET",
        ] {
            assert!(err.to_string().contains(needle), "{err} lacks {needle:?}");
        }
        // Blank means unset, as in Jazzy.
        assert!(env(&[("ROS_STATIC_PEERS", " ")]).is_ok());
        let err = env(&[("RMW_IMPLEMENTATION", "rmw_zenoh_cpp")]).unwrap_err();
        assert!(
            err.to_string().contains("rmw_fastrtps_cpp, rmw_connextdds"),
            "{err}"
        );
    }

    #[test]
    fn rmw_chooses_the_service_mapping() {
        assert_eq!(env(&[]).unwrap().service_mapping, ServiceMapping::Enhanced);
        assert_eq!(
            env(&[("RMW_IMPLEMENTATION", "rmw_cyclonedds_cpp")])
                .unwrap()
                .service_mapping,
            ServiceMapping::Cyclone
        );
        assert_eq!(
            env(&[("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")])
                .unwrap()
                .service_mapping,
            ServiceMapping::Enhanced
        );
    }
}
