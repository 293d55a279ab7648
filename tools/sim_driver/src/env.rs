//! The ROS 2 environment variables with their Jazzy meanings, and the DDS participant they
//! ask for.

use std::net::Ipv4Addr;

use ros2_client::{Context, ServiceMapping};

/// Largest domain id whose RTPS ports (7400 + 250·id + offsets) fit in 16 bits.
pub const MAX_DOMAIN_ID: u16 = 232;

/// What the environment asks for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RosEnv {
    /// `ROS_DOMAIN_ID`, default 0.
    pub domain_id: u16,
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST` (or `ROS_LOCALHOST_ONLY=1` when the range is
    /// unset): the participant uses only 127.0.0.1.
    pub localhost: bool,
    /// The RPC mapping of the action (`RMW_IMPLEMENTATION`).
    pub service_mapping: ServiceMapping,
}

impl RosEnv {
    /// Reads the process environment.
    ///
    /// # Errors
    /// A message naming the variable that is malformed or cannot be honoured.
    pub fn from_env() -> Result<Self, String> {
        Self::from_vars(|k| std::env::var(k).ok())
    }

    /// As [`Self::from_env`], reading the variables through `get`.
    ///
    /// # Errors
    /// As [`Self::from_env`].
    pub fn from_vars(get: impl Fn(&str) -> Option<String>) -> Result<Self, String> {
        let var = |k: &str| {
            get(k)
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
        };
        let domain_id = match var("ROS_DOMAIN_ID") {
            None => 0,
            Some(s) => match s.parse::<u16>() {
                Ok(id) if id <= MAX_DOMAIN_ID => id,
                _ => {
                    return Err(format!(
                        "ROS_DOMAIN_ID={s}: must be an integer from 0 to {MAX_DOMAIN_ID}"
                    ))
                }
            },
        };
        if let Some(peers) = var("ROS_STATIC_PEERS") {
            return Err(format!(
                "ROS_STATIC_PEERS={peers}: RustDDS has no static peer list; unset it and use \
                 a network that carries multicast"
            ));
        }
        let localhost = match var("ROS_AUTOMATIC_DISCOVERY_RANGE").as_deref() {
            None => var("ROS_LOCALHOST_ONLY").as_deref() == Some("1"),
            Some("LOCALHOST") => true,
            Some("SUBNET" | "SYSTEM_DEFAULT") => false,
            Some(other) => {
                return Err(format!(
                    "ROS_AUTOMATIC_DISCOVERY_RANGE={other}: expected SUBNET, LOCALHOST or \
                     SYSTEM_DEFAULT (OFF cannot be honoured by RustDDS)"
                ))
            }
        };
        let service_mapping = match var("RMW_IMPLEMENTATION").as_deref() {
            None | Some("rmw_fastrtps_cpp" | "rmw_fastrtps_dynamic_cpp" | "rmw_connextdds") => {
                ServiceMapping::Enhanced
            }
            Some("rmw_cyclonedds_cpp") => ServiceMapping::Cyclone,
            Some(other) => {
                return Err(format!(
                    "RMW_IMPLEMENTATION={other}: the driver speaks the RPC mappings of \
                     rmw_fastrtps_cpp, rmw_connextdds and rmw_cyclonedds_cpp"
                ))
            }
        };
        Ok(Self {
            domain_id,
            localhost,
            service_mapping,
        })
    }

    /// One DDS participant (a ros2-client [`Context`]) on the domain; with `localhost`, on
    /// 127.0.0.1 only (multicast, advertised locators, and SPDP to the loopback ports).
    ///
    /// # Errors
    /// A message with RustDDS's reason.
    pub fn context(&self) -> Result<Context, String> {
        let mut builder = ros2_client::dds::rustdds::DomainParticipantBuilder::new(self.domain_id);
        if self.localhost {
            builder = builder.with_only_networks([Ipv4Addr::LOCALHOST]);
        }
        let participant = builder
            .build()
            .map_err(|e| format!("DDS participant in domain {}: {e}", self.domain_id))?;
        Context::from_domain_participant(participant).map_err(|e| format!("ROS 2 context: {e}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn env(pairs: &[(&str, &str)]) -> Result<RosEnv, String> {
        let m: HashMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        RosEnv::from_vars(|k| m.get(k).cloned())
    }

    #[test]
    fn jazzy_meanings() {
        let e = env(&[]).unwrap();
        assert_eq!((e.domain_id, e.localhost), (0, false));
        assert_eq!(e.service_mapping, ServiceMapping::Enhanced);
        let e = env(&[
            ("ROS_DOMAIN_ID", "180"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
        ])
        .unwrap();
        assert_eq!((e.domain_id, e.localhost), (180, true));
        assert!(env(&[("ROS_LOCALHOST_ONLY", "1")]).unwrap().localhost);
        let e = env(&[
            ("ROS_LOCALHOST_ONLY", "1"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET"),
        ]);
        assert!(!e.unwrap().localhost);
        let e = env(&[("RMW_IMPLEMENTATION", "rmw_cyclonedds_cpp")]).unwrap();
        assert_eq!(e.service_mapping, ServiceMapping::Cyclone);
        for (k, v) in [
            ("ROS_DOMAIN_ID", "233"),
            ("ROS_DOMAIN_ID", "-1"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "localhost"),
            ("ROS_STATIC_PEERS", "10.0.0.1"),
            ("RMW_IMPLEMENTATION", "rmw_zenoh_cpp"),
        ] {
            let err = env(&[(k, v)]).unwrap_err();
            assert!(err.contains(k), "{err}");
        }
    }
}
