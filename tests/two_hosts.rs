//! Two hosts (issue 14, part 2): the node in network namespace A, the peers in B, joined by one
//! veth pair (192.0.2.1 and 192.0.2.2, nothing else reachable: `tests/common/netns.rs`). The node
//! runs without `ROS_LOCALHOST_ONLY`, with its own `ROS_AUTOMATIC_DISCOVERY_RANGE`; everything
//! else in the test suite stays on loopback.
//!
//! - `subnet_multicast_cyclone_and_fastdds`: range SUBNET, multicast on the link, the Cyclone DDS peer bound
//!   to 192.0.2.2: discovery, topics (reports equal `check --json`), `check_states`, and the
//!   parameter services (get, a refused set, a set, get) across the link.
//! - `static_peers_without_multicast_cyclone_and_fastdds`: multicast off on both veth ends and no multicast
//!   route; the node names host B in `ROS_STATIC_PEERS`, the Cyclone peer names no one: the same
//!   exchange, found only by the node's unicast announcement.
//! - `range_off_keeps_the_node_alone`: range OFF; the Cyclone and Fast DDS peers in B, with
//!   multicast on and host A named as their peer, get no match, no report and no service answer
//!   while the node runs.
//!
//! Namespaces need root (CI runs as root): without it these tests fail with the reason.

mod common;

use common::fastdds::{FastDdsPeer, PeerOptions};
use common::netns::{TwoHosts, HOST_A, HOST_B};
use serde_json::{json, Value};
use std::io::Read;
use std::process::{Child, Command};
use std::time::Instant;

/// The Cyclone DDS peer in host B: its veth address only, multicast as asked, `peers` as unicast
/// discovery peers, well-known ports (participant index auto) so unicast SPDP can find it.
fn cyclone_config(multicast: bool, peers: &[&str]) -> String {
    let peers: String = peers.iter().map(|p| format!(r#"<Peer address="{p}"/>"#)).collect();
    format!(
        r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="{HOST_B}"/></Interfaces><AllowMulticast>{multicast}</AllowMulticast></General><Discovery><Peers>{peers}</Peers><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>20</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>"#
    )
}

/// Runs `tests/peers/dds_peer.py` in host B with `config`; returns its JSON answer.
fn run_peer_in_b(hosts: &TwoHosts, config: &str, request: &Value) -> Value {
    let file = scratch().join(format!("cyclone_{}.xml", request["domain"]));
    std::fs::write(&file, config).unwrap();
    common::run_cyclone_peer_in(&hosts.in_b(), "dds_peer.py", &file, &request.to_string())
}

fn scratch() -> std::path::PathBuf {
    common::scratch_dir("two_hosts")
}

/// A state of the bundled arm (the same walk as `tests/ros_node.rs`: some collide, some not).
fn state(k: usize) -> (Vec<&'static str>, Vec<f64>) {
    let names = vec!["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];
    let x = k as f64;
    let pos = vec![(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02];
    (names, pos)
}

fn params_file() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config/params.yaml")
}

/// [`params_file`] keyed for the node renamed `tc_two` (a parameters file applies by the node's
/// full name).
fn renamed_params_file() -> std::path::PathBuf {
    let text = std::fs::read_to_string(params_file()).unwrap();
    assert!(text.contains("/**/thickness_collision:"), "config/params.yaml changed its key");
    let out = scratch().join("params_tc_two.yaml");
    std::fs::write(&out, text.replace("/**/thickness_collision:", "/**/tc_two:")).unwrap();
    out
}

/// `check --json` on `states` with the node's parameters after the set to 0.2 m.
fn reference(states: &[(Vec<&str>, Vec<f64>)]) -> Vec<Value> {
    let dir = scratch();
    let lines: Vec<String> = states.iter().map(|(n, p)| json!({"name": n, "position": p}).to_string()).collect();
    let file = dir.join("states.jsonl");
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let after = dir.join("params_after.yaml");
    let text = std::fs::read_to_string(params_file()).unwrap();
    assert!(text.contains("default_thickness: 0.02"), "config/params.yaml changed: this test sets default_thickness from 0.02 to 0.2");
    std::fs::write(&after, text.replace("default_thickness: 0.02", "default_thickness: 0.2")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
        .args(["check", "--params-file", after.to_str().unwrap(), "--states", file.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "check: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

/// The node in host A with `env` (on top of removing `ROS_LOCALHOST_ONLY`).
fn start_node_in_a(hosts: &TwoHosts, domain: u32, env: &[(&str, Option<&str>)]) -> (Child, std::io::BufReader<std::process::ChildStdout>, String) {
    let wrapper = hosts.in_a();
    let wrapper: Vec<&str> = wrapper.iter().map(String::as_str).collect();
    let mut all = vec![("ROS_LOCALHOST_ONLY", None)];
    all.extend_from_slice(env);
    common::start_node_env(
        &wrapper,
        &[
            "--ros-args",
            "-r",
            "__node:=tc_two",
            "--params-file",
            renamed_params_file().to_str().unwrap(),
            "-p",
            "check_motion:=false",
            "-p",
            "service_mapping:=enhanced",
        ],
        domain,
        &all,
    )
}

/// SIGTERM, then the node's exit status, and its remaining stdout and stderr.
fn stop(mut node: Child, mut out: std::io::BufReader<std::process::ChildStdout>) -> (std::process::ExitStatus, String, String) {
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let status = node.wait().unwrap();
    let mut rest = String::new();
    let _ = out.read_to_string(&mut rest);
    let mut err = String::new();
    let _ = node.stderr.take().unwrap().read_to_string(&mut err);
    (status, rest, err)
}

/// The exchange across the link, with the Cyclone peer and then the Fast DDS peer in host B
/// (`fast_peers`: the Fast DDS peer's initial peers): states on `joint_states`, reports on
/// `collisions`, a `check_states` call and the parameter services; every answer checked.
fn exchange_across_the_link(hosts: &TwoHosts, domain: u32, node_env: &[(&str, Option<&str>)], cyclone: &str, fast_peers: &[&str], banner_says: &str) {
    let states: Vec<(Vec<&str>, Vec<f64>)> = (0..12).map(state).collect();
    let want = reference(&states);
    assert!(want.iter().any(|r| r["in_collision"] == true) && want.iter().any(|r| r["in_collision"] == false), "the states must include both answers");

    let (node, out, banner) = start_node_in_a(hosts, domain, node_env);
    assert!(!banner.contains("loopback only"), "the node in host A must not be on loopback: {banner}");
    assert!(banner.contains(banner_says), "banner lacks '{banner_says}': {banner}");
    let request = json!({
        "domain": domain,
        "states": states.iter().enumerate().map(|(k, (n, p))| json!({"name": n, "position": p, "stamp": 1_000_000_000 + k})).collect::<Vec<_>>(),
        "service_states": states[..4].iter().map(|(n, p)| json!({"name": n, "position": p, "stamp": 7})).collect::<Vec<_>>(),
        "timeout": 30,
        "node": "tc_two",
        "set_thickness": 0.2,
        "service_mapping": "enhanced",
    });
    let t = Instant::now();
    let answer = run_peer_in_b(hosts, cyclone, &request);
    eprintln!("Cyclone peer in host B done in {:.1} s", t.elapsed().as_secs_f64());
    assert_eq!(answer["matched"], true, "no DDS match across the link: {answer}");
    // Parameters first (the peer set default_thickness to 0.2 before sending the states).
    assert_eq!(answer["get_before"], json!([0.02, "world"]), "{answer}");
    assert_eq!(answer["set_results"][0][0], false, "a negative thickness is refused: {}", answer["set_results"]);
    assert_eq!(answer["set_results"][1][0], true, "{}", answer["set_results"]);
    assert_eq!(answer["get_after"], json!(0.2));
    let reports = answer["reports"].as_array().unwrap();
    assert_eq!(reports.len(), states.len(), "one report per state, across the link");
    for (k, (got, w)) in reports.iter().zip(&want).enumerate() {
        common::same_report(got, w, &format!("topic, state {k}"));
        assert_eq!(got["stamp"].as_i64().unwrap(), 1_000_000_000 + k as i64, "stamped with the input's stamp");
        assert_eq!(got["error"], "");
    }
    let service = answer["service"].as_array().unwrap();
    assert_eq!(service.len(), 4, "check_states answers every state: {answer}");
    for (k, (got, w)) in service.iter().zip(&want).enumerate() {
        common::same_report(got, w, &format!("service, state {k}"));
    }

    let t = Instant::now();
    let fast = fastdds_in_b(hosts, domain, fast_peers, &states, &want);
    eprintln!("Fast DDS peer in host B done in {:.1} s", t.elapsed().as_secs_f64());
    let (status, rest, err) = stop(node, out);
    if let Err(e) = fast {
        panic!("Fast DDS peer in host B: {e}; node stderr: {err}");
    }
    assert!(status.success(), "node exit {status:?}; stderr: {err}");
    assert!(rest.contains("shutting down"), "{rest}");
}

/// The Fast DDS peer in host B (UDPv4 only, on 192.0.2.2, initial peers `peers`, none: multicast
/// discovery), against the node after the Cyclone peer set `default_thickness` to 0.2: the same
/// states and reports, `check_states`, then get, a refused set, a set to 0.3 and get.
fn fastdds_in_b(hosts: &TwoHosts, domain: u32, peers: &[&str], states: &[(Vec<&str>, Vec<f64>)], want: &[Value]) -> Result<(), String> {
    let opts = PeerOptions { wrapper: hosts.in_b(), domain, interface: HOST_B.into(), peers: peers.iter().map(|p| p.to_string()).collect(), env: vec![] };
    let mut peer = FastDdsPeer::start(&opts);
    let js: Vec<Value> = states.iter().enumerate().map(|(k, (n, p))| json!({"name": n, "position": p, "stamp": 2_000_000_000 + k})).collect();
    let a = peer.send(&json!({"cmd": "states", "states": js, "warm": common::whole_arm_warm_up(), "timeout": 30}));
    if a["matched"] != true {
        return Err(format!("no match on joint_states/collisions: {a}"));
    }
    let reports = a["reports"].as_array().cloned().unwrap_or_default();
    if reports.len() != states.len() {
        return Err(format!("{} reports for {} states: {a}", reports.len(), states.len()));
    }
    for (k, (got, w)) in reports.iter().zip(want).enumerate() {
        common::same_report(got, w, &format!("Fast DDS topic, state {k}"));
        assert_eq!(got["stamp"].as_i64(), Some(2_000_000_000 + k as i64), "stamped with the input's stamp");
    }
    let answers = peer.call("check_states", "check_states", vec![json!({"states": js[..4].to_vec()})], 20.0);
    let got = answers[0]["response"]["reports"].as_array().cloned().ok_or_else(|| format!("check_states: no answer: {}", answers[0]))?;
    assert_eq!(got.len(), 4, "Fast DDS check_states: {}", answers[0]);
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        common::same_report(g, w, &format!("Fast DDS check_states, state {k}"));
    }
    let get = |peer: &mut FastDdsPeer| -> Result<Value, String> {
        let a = peer.call("tc_two/get_parameters", "get_parameters", vec![json!({"names": ["default_thickness"]})], 20.0);
        a[0]["response"]["values"][0].get("double").cloned().ok_or_else(|| format!("get_parameters: no answer: {}", a[0]))
    };
    let set = |peer: &mut FastDdsPeer, x: f64| -> Value {
        let a = peer.call(
            "tc_two/set_parameters",
            "set_parameters",
            vec![json!({"parameters": [{"name": "default_thickness", "value": {"type": 3, "double": x}}]})],
            20.0,
        );
        a[0]["response"]["results"][0]["successful"].clone()
    };
    assert_eq!(get(&mut peer)?, json!(0.2), "Fast DDS get_parameters sees the Cyclone peer's set");
    assert_eq!(set(&mut peer, -1.0), json!(false), "a negative thickness is refused");
    assert_eq!(set(&mut peer, 0.3), json!(true));
    assert_eq!(get(&mut peer)?, json!(0.3));
    peer.quit();
    Ok(())
}

#[test]
fn subnet_multicast_cyclone_and_fastdds() {
    let hosts = TwoHosts::new();
    exchange_across_the_link(
        &hosts,
        170,
        &[("ROS_AUTOMATIC_DISCOVERY_RANGE", Some("SUBNET")), ("ROS_STATIC_PEERS", None)],
        &cyclone_config(true, &[]),
        &[],
        "discovery range SUBNET (all interfaces, multicast)",
    );
}

#[test]
fn static_peers_without_multicast_cyclone_and_fastdds() {
    let hosts = TwoHosts::new();
    hosts.multicast_off();
    // The peers name no one: only the node's unicast announcement to host B can start discovery.
    exchange_across_the_link(
        &hosts,
        171,
        &[("ROS_AUTOMATIC_DISCOVERY_RANGE", Some("SUBNET")), ("ROS_STATIC_PEERS", Some(HOST_B))],
        &cyclone_config(false, &[]),
        &[],
        &format!("static peers {HOST_B}"),
    );
}

#[test]
fn range_off_keeps_the_node_alone() {
    let hosts = TwoHosts::new();
    let domain = 172;
    let (mut node, out, banner) = start_node_in_a(&hosts, domain, &[("ROS_AUTOMATIC_DISCOVERY_RANGE", Some("OFF")), ("ROS_STATIC_PEERS", Some(HOST_B))]);
    assert!(banner.contains("discovery range OFF"), "{banner}");
    // The peers do all they can: multicast on the link and host A named as a unicast peer. Both
    // run at once (a bounded wait each, about 20 s).
    let states: Vec<Value> = (0..2).map(state).map(|(n, p)| json!({"name": n, "position": p, "stamp": 5})).collect();
    let request = json!({"domain": domain, "states": states, "service_states": states, "timeout": 8, "warmup": 4, "service_wait": 5});
    let t = Instant::now();
    let (answer, fast, call) = std::thread::scope(|scope| {
        let cyclone = scope.spawn(|| run_peer_in_b(&hosts, &cyclone_config(true, &[HOST_A]), &request));
        let opts = PeerOptions { wrapper: hosts.in_b(), domain, interface: HOST_B.into(), peers: vec![HOST_A.into()], env: vec![] };
        let mut peer = FastDdsPeer::start(&opts);
        let fast = peer.send(&json!({"cmd": "states", "states": states[..1].to_vec(), "warm": states[0], "timeout": 8}));
        let call = peer.send(&json!({"cmd": "call", "service": "check_states", "type": "check_states", "requests": [{"states": states}], "timeout": 5}));
        peer.quit();
        (cyclone.join().unwrap_or_else(|e| std::panic::resume_unwind(e)), fast, call)
    });
    eprintln!("peers in host B done in {:.1} s", t.elapsed().as_secs_f64());
    assert!(node.try_wait().unwrap().is_none(), "the node must run while the peers try");
    let (status, _rest, err) = stop(node, out);
    assert!(status.success(), "node exit {status:?}; stderr: {err}");
    assert_eq!(answer["matched"], false, "OFF: the peer in host B matched the node: {answer}");
    assert_eq!(answer["reports"], json!([]), "OFF: reports reached host B: {answer}");
    assert_eq!(answer["service"], json!([]), "OFF: check_states answered across the link: {answer}");
    assert_eq!((&fast["matched"], &fast["warm_reports"], &fast["reports"]), (&json!(false), &json!(0), &json!([])), "OFF: Fast DDS: {fast}");
    assert_eq!(call["matched"], false, "OFF: Fast DDS's check_states client matched the node: {call}");
    assert!(call["answers"].as_array().is_none_or(|a| a.iter().all(|x| x["response"].is_null())), "OFF: Fast DDS got an answer: {call}");
}
