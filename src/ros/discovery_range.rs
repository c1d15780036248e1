//! How far the node looks for peers: `ROS_AUTOMATIC_DISCOVERY_RANGE`, `ROS_STATIC_PEERS` and the
//! older `ROS_LOCALHOST_ONLY`, read as rcl reads them since ROS 2 Iron, and turned into the DDS
//! participant's settings (ros2-client reads none of them, so the node builds the participant).
//!
//! | environment | participant |
//! |---|---|
//! | `ROS_LOCALHOST_ONLY=1` | loopback only (`with_only_networks(127.0.0.1)`: the patched RustDDS then binds every socket to 127.0.0.1, opens no multicast socket and drops datagrams from other addresses); the range and the static peers are ignored, as rcl ignores them (deprecated, still honoured) |
//! | range `LOCALHOST` | loopback only; static peers are refused (see below) |
//! | range `SUBNET` (the default when unset, as in rcl) | all interfaces, multicast discovery, plus unicast discovery to each static peer |
//! | range `SYSTEM_DEFAULT` | RustDDS's own defaults (the same as `SUBNET`), plus the static peers |
//! | range `OFF` | loopback only, no SPDP announcement sent, every other participant's ignored: the node discovers nothing, even on the same host; static peers ignored (OFF wins, as in the ROS 2 docs) |
//!
//! A static peer is announced to by unicast SPDP at the well-known discovery ports of the first
//! 12 participant ids of the domain (the patched RustDDS, `vendor/rustdds/PATCHES.md`, "Static SPDP peers");
//! once it answers, it is matched like any multicast-discovered participant. `LOCALHOST` with
//! static peers (rmw: loopback plus those hosts, no multicast) is refused at start: RustDDS
//! cannot keep multicast off while advertising a non-loopback address, and advertising only
//! loopback would make the peer unreachable.

use anyhow::{anyhow, bail, Result};
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use std::net::{IpAddr, Ipv4Addr, ToSocketAddrs};

/// `ROS_AUTOMATIC_DISCOVERY_RANGE`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DiscoveryRange {
    /// No discovery of any other participant.
    Off,
    /// Other participants on this host only.
    Localhost,
    /// Anything multicast reaches (the rcl default).
    Subnet,
    /// The middleware's defaults.
    SystemDefault,
}

impl DiscoveryRange {
    fn name(self) -> &'static str {
        match self {
            DiscoveryRange::Off => "OFF",
            DiscoveryRange::Localhost => "LOCALHOST",
            DiscoveryRange::Subnet => "SUBNET",
            DiscoveryRange::SystemDefault => "SYSTEM_DEFAULT",
        }
    }
}

/// The discovery settings the environment asks for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct DiscoverySettings {
    /// The range in effect.
    pub(crate) range: DiscoveryRange,
    /// The static peers in effect (IPv4: RustDDS sends UDPv4).
    pub(crate) static_peers: Vec<IpAddr>,
    /// `ROS_LOCALHOST_ONLY=1` decided the range.
    legacy_localhost_only: bool,
    /// What was set but is not in effect, for the banner.
    ignored: Option<String>,
}

impl DiscoverySettings {
    /// Reads the three variables; an unset or empty variable takes its default.
    pub(crate) fn from_env() -> Result<DiscoverySettings> {
        let var = |name: &str| std::env::var(name).ok();
        DiscoverySettings::parse(
            var("ROS_AUTOMATIC_DISCOVERY_RANGE").as_deref(),
            var("ROS_STATIC_PEERS").as_deref(),
            var("ROS_LOCALHOST_ONLY").as_deref(),
            &resolve,
        )
    }

    /// The settings from the variables' values; `resolve` turns one static peer into addresses.
    fn parse(
        range: Option<&str>,
        peers: Option<&str>,
        localhost_only: Option<&str>,
        resolve: &dyn Fn(&str) -> Result<Vec<IpAddr>>,
    ) -> Result<DiscoverySettings> {
        let range_value = range.map(str::trim).filter(|v| !v.is_empty());
        let parsed_range = match range_value {
            None => DiscoveryRange::Subnet,
            Some(v) => match v.to_ascii_uppercase().as_str() {
                "OFF" => DiscoveryRange::Off,
                "LOCALHOST" => DiscoveryRange::Localhost,
                "SUBNET" => DiscoveryRange::Subnet,
                "SYSTEM_DEFAULT" => DiscoveryRange::SystemDefault,
                _ => {
                    bail!("ROS_AUTOMATIC_DISCOVERY_RANGE='{v}' is not a discovery range (allowed: OFF, LOCALHOST, SUBNET, SYSTEM_DEFAULT; unset means SUBNET)")
                }
            },
        };
        let legacy = match localhost_only.map(str::trim).unwrap_or("") {
            "1" => true,
            "" | "0" => false,
            v => bail!("ROS_LOCALHOST_ONLY='{v}' is not 0 or 1 (1 keeps DDS on loopback; unset or 0 leaves it to ROS_AUTOMATIC_DISCOVERY_RANGE)"),
        };
        let peers_value = peers.unwrap_or("");
        let mut static_peers = Vec::new();
        for entry in peers_value.split(';').map(str::trim).filter(|e| !e.is_empty()) {
            let addrs = resolve(entry)
                .map_err(|e| anyhow!("ROS_STATIC_PEERS='{peers_value}': '{entry}' {e} (allowed: IPv4 addresses or host names, separated by ';')"))?;
            for a in addrs {
                if !static_peers.contains(&a) {
                    static_peers.push(a);
                }
            }
        }
        if legacy {
            let ignored = (range_value.is_some_and(|_| parsed_range != DiscoveryRange::Localhost) || !static_peers.is_empty())
                .then(|| "ROS_LOCALHOST_ONLY=1 overrides ROS_AUTOMATIC_DISCOVERY_RANGE and ROS_STATIC_PEERS".to_owned());
            return Ok(DiscoverySettings { range: DiscoveryRange::Localhost, static_peers: Vec::new(), legacy_localhost_only: true, ignored });
        }
        match parsed_range {
            DiscoveryRange::Localhost if !static_peers.is_empty() => bail!(
                "ROS_STATIC_PEERS='{peers_value}' with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST is not supported by this node (allowed: static peers with SUBNET or SYSTEM_DEFAULT; LOCALHOST without them)"
            ),
            DiscoveryRange::Off if !static_peers.is_empty() => Ok(DiscoverySettings {
                range: DiscoveryRange::Off,
                static_peers: Vec::new(),
                legacy_localhost_only: false,
                ignored: Some("ROS_STATIC_PEERS ignored: the range is OFF".to_owned()),
            }),
            range => Ok(DiscoverySettings { range, static_peers, legacy_localhost_only: false, ignored: None }),
        }
    }

    /// The participant builder with these settings.
    pub(crate) fn apply(&self, builder: DomainParticipantBuilder) -> DomainParticipantBuilder {
        let loopback = [IpAddr::from(Ipv4Addr::LOCALHOST)];
        match self.range {
            DiscoveryRange::Localhost => builder.with_only_networks(loopback),
            DiscoveryRange::Off => builder.with_only_networks(loopback).same_host_loopback(false).isolated_discovery(true),
            DiscoveryRange::Subnet | DiscoveryRange::SystemDefault if !self.static_peers.is_empty() => builder.with_static_peers(self.static_peers.clone()),
            DiscoveryRange::Subnet | DiscoveryRange::SystemDefault => builder,
        }
    }

    /// For the banner: the range in effect and what it means, e.g. `SUBNET (all interfaces,
    /// multicast, static peers 192.0.2.2)`.
    pub(crate) fn describe(&self) -> String {
        let what = match self.range {
            DiscoveryRange::Localhost if self.legacy_localhost_only => "from ROS_LOCALHOST_ONLY=1, loopback only".to_owned(),
            DiscoveryRange::Localhost => "loopback only".to_owned(),
            DiscoveryRange::Off => "loopback only, discovers no other participant".to_owned(),
            DiscoveryRange::Subnet | DiscoveryRange::SystemDefault => {
                let mut s = "all interfaces, multicast".to_owned();
                if !self.static_peers.is_empty() {
                    let peers: Vec<String> = self.static_peers.iter().map(ToString::to_string).collect();
                    s += &format!(", static peers {}", peers.join(" "));
                }
                s
            }
        };
        match &self.ignored {
            Some(note) => format!("{} ({what}; {note})", self.range.name()),
            None => format!("{} ({what})", self.range.name()),
        }
    }
}

/// One `ROS_STATIC_PEERS` entry as IPv4 addresses: an address, or a name the resolver knows.
fn resolve(entry: &str) -> Result<Vec<IpAddr>> {
    if let Ok(ip) = entry.parse::<IpAddr>() {
        return match ip {
            IpAddr::V4(_) => Ok(vec![ip]),
            IpAddr::V6(_) => Err(anyhow!("is an IPv6 address (the node's DDS speaks UDPv4 only)")),
        };
    }
    let addrs: Vec<IpAddr> = (entry, 0u16).to_socket_addrs().map_err(|e| anyhow!("cannot be resolved: {e}"))?.map(|a| a.ip()).filter(IpAddr::is_ipv4).collect();
    if addrs.is_empty() {
        return Err(anyhow!("has no IPv4 address"));
    }
    Ok(addrs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_names(entry: &str) -> Result<Vec<IpAddr>> {
        match entry.parse::<IpAddr>() {
            Ok(ip) if ip.is_ipv4() => Ok(vec![ip]),
            _ => Err(anyhow!("cannot be resolved: test")),
        }
    }

    fn parse(range: Option<&str>, peers: Option<&str>, legacy: Option<&str>) -> Result<DiscoverySettings> {
        DiscoverySettings::parse(range, peers, legacy, &no_names)
    }

    #[test]
    fn unset_is_subnet_and_values_are_case_blind() {
        assert_eq!(parse(None, None, None).unwrap().range, DiscoveryRange::Subnet);
        assert_eq!(parse(Some(""), Some(""), Some("")).unwrap().range, DiscoveryRange::Subnet);
        assert_eq!(parse(Some("localhost"), None, None).unwrap().range, DiscoveryRange::Localhost);
        assert_eq!(parse(Some("OFF"), None, Some("0")).unwrap().range, DiscoveryRange::Off);
        assert_eq!(parse(Some("SYSTEM_DEFAULT"), None, None).unwrap().range, DiscoveryRange::SystemDefault);
        assert_eq!(parse(Some("SUBNET"), None, None).unwrap().describe(), "SUBNET (all interfaces, multicast)");
        assert_eq!(parse(Some("LOCALHOST"), None, None).unwrap().describe(), "LOCALHOST (loopback only)");
    }

    #[test]
    fn static_peers_are_split_on_semicolons() {
        let s = parse(Some("SUBNET"), Some("192.0.2.2; 192.0.2.3;;192.0.2.2;"), None).unwrap();
        assert_eq!(s.static_peers, vec![IpAddr::from([192, 0, 2, 2]), IpAddr::from([192, 0, 2, 3])]);
        assert_eq!(s.describe(), "SUBNET (all interfaces, multicast, static peers 192.0.2.2 192.0.2.3)");
    }

    #[test]
    fn legacy_localhost_only_wins() {
        let s = parse(Some("SUBNET"), Some("192.0.2.2"), Some("1")).unwrap();
        assert_eq!(s.range, DiscoveryRange::Localhost);
        assert!(s.static_peers.is_empty());
        assert!(s.describe().contains("loopback only") && s.describe().contains("overrides"), "{}", s.describe());
        let plain = parse(Some("LOCALHOST"), None, Some("1")).unwrap();
        assert_eq!(plain.describe(), "LOCALHOST (from ROS_LOCALHOST_ONLY=1, loopback only)");
    }

    #[test]
    fn off_ignores_static_peers() {
        let s = parse(Some("OFF"), Some("192.0.2.2"), None).unwrap();
        assert!(s.static_peers.is_empty());
        assert!(s.describe().starts_with("OFF (loopback only, discovers no other participant; ROS_STATIC_PEERS ignored"), "{}", s.describe());
    }

    #[test]
    fn errors_name_the_variable_the_value_and_what_is_allowed() {
        let e = parse(Some("LAN"), None, None).unwrap_err().to_string();
        assert!(e.contains("ROS_AUTOMATIC_DISCOVERY_RANGE='LAN'") && e.contains("SUBNET") && !e.contains('\n'), "{e}");
        let e = parse(None, None, Some("yes")).unwrap_err().to_string();
        assert!(e.contains("ROS_LOCALHOST_ONLY='yes'") && e.contains("0 or 1"), "{e}");
        let e = parse(Some("SUBNET"), Some("192.0.2.2;no such host"), None).unwrap_err().to_string();
        assert!(e.contains("ROS_STATIC_PEERS='192.0.2.2;no such host'") && e.contains("'no such host'") && e.contains("separated by ';'"), "{e}");
        let e = parse(Some("LOCALHOST"), Some("192.0.2.2"), None).unwrap_err().to_string();
        assert!(e.contains("ROS_STATIC_PEERS='192.0.2.2'") && e.contains("LOCALHOST"), "{e}");
        let e = resolve("::1").unwrap_err().to_string();
        assert!(e.contains("IPv6"), "{e}");
    }
}
