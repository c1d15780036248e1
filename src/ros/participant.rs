//! The DDS participant: `ROS_DOMAIN_ID`, and the discovery range and static peers the
//! environment asks for ([`DiscoverySettings`]).

use super::discovery_range::DiscoverySettings;
use anyhow::{anyhow, Context as _, Result};
use ros2_client::dds::rustdds::{DomainParticipant, DomainParticipantBuilder};

/// The largest domain id: RTPS ports are `7400 + 250 * domain + ...`, and above 232 they pass
/// 65535 and wrap (the limit the ROS 2 "Domain ID" article gives).
const MAX_DOMAIN_ID: u16 = 232;

/// The participant, its domain and the discovery settings it was built with.
pub(super) fn participant() -> Result<(DomainParticipant, u16, DiscoverySettings)> {
    let domain = domain_id(std::env::var("ROS_DOMAIN_ID").ok().as_deref())?;
    let discovery = DiscoverySettings::from_env()?;
    let builder = discovery.apply(DomainParticipantBuilder::new(domain));
    Ok((builder.build().context("cannot create the DDS participant")?, domain, discovery))
}

/// `ROS_DOMAIN_ID` (`None` or blank: domain 0), refused outside 0-232.
fn domain_id(value: Option<&str>) -> Result<u16> {
    let Some(text) = value.map(str::trim).filter(|t| !t.is_empty()) else {
        return Ok(0);
    };
    match text.parse::<u64>() {
        Ok(d) if d <= u64::from(MAX_DOMAIN_ID) => Ok(d as u16),
        _ => Err(anyhow!("ROS_DOMAIN_ID='{text}' is not a domain id: an integer from 0 to {MAX_DOMAIN_ID} is allowed")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn domain_id_is_0_to_232() {
        assert_eq!(domain_id(None).unwrap(), 0);
        assert_eq!(domain_id(Some("  ")).unwrap(), 0);
        assert_eq!(domain_id(Some("0")).unwrap(), 0);
        assert_eq!(domain_id(Some(" 42 ")).unwrap(), 42);
        assert_eq!(domain_id(Some("232")).unwrap(), 232);
        for bad in ["233", "65535", "65536", "-1", "1.5", "one", "99999999999999999999999"] {
            let e = domain_id(Some(bad)).unwrap_err().to_string();
            assert!(e.contains("ROS_DOMAIN_ID") && e.contains(&format!("'{bad}'")) && e.contains("0 to 232") && !e.contains('\n'), "{bad}: {e}");
        }
    }
}
