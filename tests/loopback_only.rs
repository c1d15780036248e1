//! Loopback means loopback (issue 33, part 1). One host with two addresses: a network namespace
//! whose only interface is `lo`, with 127.0.0.1 and 198.51.100.7 (`tests/common/netns.rs`,
//! `LoopbackHost`). The node runs there in loopback mode, once from `ROS_LOCALHOST_ONLY=1` and
//! once from `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`:
//!
//! - `ss` lists every UDP socket of the node on 127.0.0.1 (no 0.0.0.0, so no multicast listener);
//! - a Cyclone DDS peer and a Fast DDS peer whose interface is 198.51.100.7, both naming 127.0.0.1
//!   as their discovery peer, get no match, no report and no service answer. (Cyclone binds its
//!   receiving sockets to 0.0.0.0 whatever its interface, so it hears the node's announcement to
//!   the well-known ports on 127.0.0.1; everything it sends comes from 198.51.100.7 and the node
//!   drops it unread, so nothing ever matches.) With the node as RustDDS publishes it (every
//!   socket on 0.0.0.0), the Cyclone peer got every report;
//! - then the same Cyclone peer on 127.0.0.1 gets a report for every state, each equal to
//!   `check --json`, and `check_states` answers.
//!
//! Namespaces need root (CI runs as root): without it these tests fail with the reason. Domains
//! 176-177 (inside the namespaces; nothing leaves them).

mod common;

use common::fastdds::{FastDdsPeer, PeerOptions};
use common::netns::{LoopbackHost, SECOND_ADDRESS};
use serde_json::{json, Value};

/// A Cyclone DDS configuration for interface `address`, no multicast, the peer 127.0.0.1.
fn cyclone_config(address: &str) -> String {
    common::CYCLONE_LOOPBACK.replacen(r#"NetworkInterface address="127.0.0.1""#, &format!(r#"NetworkInterface address="{address}""#), 1)
}

/// `tests/peers/dds_peer.py` in `host` with the Cyclone configuration `config`.
fn cyclone_peer(host: &LoopbackHost, dir: &std::path::Path, config: &str, request: &Value) -> Value {
    let file = dir.join(format!("cyclone_{}.xml", if config.contains(SECOND_ADDRESS) { "second" } else { "loopback" }));
    std::fs::write(&file, config).unwrap();
    common::run_cyclone_peer_in(&host.wrapper(), "dds_peer.py", &file, &request.to_string())
}

fn states() -> Vec<Value> {
    (0..8)
        .map(|k| {
            let x = k as f64;
            json!({"name": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"],
                   "position": [(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02],
                   "stamp": 1000 + k})
        })
        .collect()
}

fn loopback_mode(name: &str, domain: u32, env: &[(&str, Option<&str>)], banner_says: &str) {
    let dir = common::scratch_subdir("loopback_only", name);
    let states = states();
    let want = common::check_json(&dir, "reference", &states, &[]);
    assert!(want.iter().any(|r| r["in_collision"] == true) && want.iter().any(|r| r["in_collision"] == false), "the states must include both answers");

    let host = LoopbackHost::new();
    let wrapper = host.wrapper();
    let wrapper: Vec<&str> = wrapper.iter().map(String::as_str).collect();
    let (node, out, banner) = common::start_node_env(&wrapper, &["--ros-args", "-p", "check_motion:=false"], domain, env);
    assert!(banner.contains(banner_says), "banner lacks '{banner_says}': {banner}");

    let sockets = host.udp_sockets_of(node.id());
    assert!(sockets.len() >= 3, "the node's UDP sockets (discovery, user traffic, sender): {sockets:?}");
    assert!(sockets.iter().all(|s| s.starts_with("127.0.0.1:")), "every node socket on 127.0.0.1: {sockets:?}");

    // The strangers: same host, another address. Both at once, a bounded wait each.
    let request = json!({"domain": domain, "states": states[..2], "service_states": states[..2], "timeout": 8, "warmup": 5, "service_wait": 5});
    let (cyclone, fast, call) = std::thread::scope(|scope| {
        let cyclone = scope.spawn(|| cyclone_peer(&host, &dir, &cyclone_config(SECOND_ADDRESS), &request));
        let opts = PeerOptions { wrapper: host.wrapper(), domain, interface: SECOND_ADDRESS.into(), peers: vec!["127.0.0.1".into()], env: vec![] };
        let mut peer = FastDdsPeer::start(&opts);
        let fast = peer.send(&json!({"cmd": "states", "states": states[..1], "warm": states[0], "timeout": 8}));
        let call = peer.send(&json!({"cmd": "call", "service": "check_states", "type": "check_states", "requests": [{"states": states[..2]}], "timeout": 5}));
        peer.quit();
        (cyclone.join().unwrap_or_else(|e| std::panic::resume_unwind(e)), fast, call)
    });
    assert_eq!(cyclone["matched"], false, "the Cyclone peer on {SECOND_ADDRESS} matched the node: {cyclone}");
    assert_eq!(cyclone["reports"], json!([]), "reports reached {SECOND_ADDRESS}: {cyclone}");
    assert_eq!(cyclone["service"], json!([]), "check_states answered {SECOND_ADDRESS}: {cyclone}");
    assert_eq!((&fast["matched"], &fast["warm_reports"], &fast["reports"]), (&json!(false), &json!(0), &json!([])), "Fast DDS on {SECOND_ADDRESS}: {fast}");
    assert_eq!(call["matched"], false, "Fast DDS's check_states client on {SECOND_ADDRESS} matched the node: {call}");

    // The same Cyclone peer on 127.0.0.1: every state answered, as `check --json` answers it.
    let request = json!({"domain": domain, "states": states, "service_states": states[..3], "timeout": 30});
    let answer = cyclone_peer(&host, &dir, common::CYCLONE_LOOPBACK, &request);
    let sockets_after = host.udp_sockets_of(node.id());
    let rest = common::stop_node(node);
    drop(out);
    assert_eq!(answer["matched"], true, "the peer on 127.0.0.1 must match: {answer}; node stderr: {rest}");
    let reports = answer["reports"].as_array().unwrap();
    assert_eq!(reports.len(), states.len(), "one report per state on 127.0.0.1: {answer}");
    for (k, (got, w)) in reports.iter().zip(&want).enumerate() {
        common::same_report(got, w, &format!("topic, state {k}"));
    }
    let service = answer["service"].as_array().unwrap();
    assert_eq!(service.len(), 3, "check_states answers on 127.0.0.1: {answer}");
    for (k, (got, w)) in service.iter().zip(&want).enumerate() {
        common::same_report(got, w, &format!("service, state {k}"));
    }
    assert!(sockets_after.iter().all(|s| s.starts_with("127.0.0.1:")), "no socket opened off loopback later: {sockets_after:?}");
}

#[test]
fn ros_localhost_only_binds_loopback() {
    loopback_mode(
        "legacy",
        176,
        &[("ROS_LOCALHOST_ONLY", Some("1")), ("ROS_AUTOMATIC_DISCOVERY_RANGE", None)],
        "discovery range LOCALHOST (from ROS_LOCALHOST_ONLY=1, loopback only)",
    );
}

#[test]
fn localhost_discovery_range_binds_loopback() {
    loopback_mode("range", 177, &[("ROS_LOCALHOST_ONLY", None), ("ROS_AUTOMATIC_DISCOVERY_RANGE", Some("LOCALHOST"))], "discovery range LOCALHOST");
}
