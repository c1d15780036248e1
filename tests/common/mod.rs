//! Shared by the integration tests that talk to the Python peers (coal, yourdfpy, rosbags, ...).
#![allow(dead_code)]

/// The Fast DDS peer (C++): built, started and driven (`tests/fastdds_interop.rs`, the two-host test).
pub mod fastdds;

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};

mod bundled_arm;
pub mod near_miss;
pub mod netns;
mod scaffold;
mod scene_memory;

// Each test binary uses some of these.
#[allow(unused_imports)]
pub use self::bundled_arm::{arm_srdfs, arm_with_tray, random_arm_states};
#[allow(unused_imports)]
pub use self::scaffold::{develop_python_package, emptied, mesh_area, scratch_dir, scratch_subdir, thin_area, topology, topology_area, write_le, LeBytes};
#[allow(unused_imports)]
pub use self::scene_memory::{cells_bytes, resident_bytes};

/// A Cyclone DDS configuration that keeps a peer on loopback: `NetworkInterface 127.0.0.1`, no
/// multicast, the peer 127.0.0.1 (the network rule in the design notes).
pub const CYCLONE_LOOPBACK: &str = r#"<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><Peers><Peer address="127.0.0.1"/></Peers><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>"#;

/// Starts the node (`run` with `args`) with loopback-only DDS on `domain` and waits for its
/// banner; returns the process, its standard output after the banner, and the banner.
pub fn start_node(args: &[&str], domain: u32) -> (Child, BufReader<ChildStdout>, String) {
    start_node_wrapped(&[], args, domain)
}

/// [`start_node`] through `wrapper`, a command that ends by exec'ing the node (for example
/// `unshare -n sh -c 'ip link set lo up && exec "$0" "$@"'`), so the process returned is the node.
pub fn start_node_wrapped(wrapper: &[&str], args: &[&str], domain: u32) -> (Child, BufReader<ChildStdout>, String) {
    start_node_env(wrapper, args, domain, &[])
}

/// [`start_node_wrapped`] with `env` applied after the loopback defaults: `(name, Some(value))`
/// sets a variable, `(name, None)` removes it (the two-host test removes `ROS_LOCALHOST_ONLY` and
/// sets its own `ROS_AUTOMATIC_DISCOVERY_RANGE`, inside its own network namespaces only).
pub fn start_node_env(wrapper: &[&str], args: &[&str], domain: u32, env: &[(&str, Option<&str>)]) -> (Child, BufReader<ChildStdout>, String) {
    let bin = env!("CARGO_BIN_EXE_thickness_collision");
    let mut command = match wrapper.split_first() {
        Some((first, rest)) => {
            let mut c = Command::new(first);
            let _ = c.args(rest).arg(bin);
            c
        }
        None => Command::new(bin),
    };
    // The node ends with the test thread that started it: a test that fails before its own
    // SIGTERM must not leave a node running on its domain (it would answer the next test's peer).
    // SAFETY: prctl is async-signal-safe; nothing else runs between fork and exec here.
    unsafe {
        let _ = std::os::unix::process::CommandExt::pre_exec(&mut command, || {
            let _ = libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
            Ok(())
        });
    }
    let _ =
        command.arg("run").args(args).env("ROS_DOMAIN_ID", domain.to_string()).env("ROS_LOCALHOST_ONLY", "1").env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST");
    for (name, value) in env {
        let _ = match value {
            Some(v) => command.env(name, v),
            None => command.env_remove(name),
        };
    }
    let mut node = command.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut out = BufReader::new(node.stdout.take().unwrap());
    let mut banner = String::new();
    while !banner.contains("serves") {
        let mut line = String::new();
        assert!(out.read_line(&mut line).unwrap() > 0, "the node exited early: {banner}");
        banner += &line;
    }
    (node, out, banner)
}

/// The peers' interpreter: `$TC_PYTHON`, set by `.ci/run` (`scripts/setup_venv.sh`). A missing
/// peer is a failure, never a skip.
pub fn python() -> PathBuf {
    match std::env::var_os("TC_PYTHON") {
        Some(p) => PathBuf::from(p),
        None => panic!("TC_PYTHON is not set: run the tests with `bash .ci/run` (it installs the Python peers)"),
    }
}

/// Runs a peer script from `tests/peers/` with a JSON request on stdin; returns its JSON answer.
pub fn run_peer(script: &str, request: &serde_json::Value) -> serde_json::Value {
    run_peer_env(script, &[], &request.to_string())
}

/// A Cyclone DDS peer from `tests/peers/` configured by the file `cyclone` (`CYCLONEDDS_URI`),
/// with `request` (JSON text: it may hold bare `NaN`s) on stdin; returns its JSON answer.
pub fn run_cyclone_peer(script: &str, cyclone: &Path, request: &str) -> serde_json::Value {
    run_peer_env(script, &[("CYCLONEDDS_URI", format!("file://{}", cyclone.display()))], request)
}

fn run_peer_env(script: &str, env: &[(&str, String)], request: &str) -> serde_json::Value {
    run_peer_wrapped(&[], script, env, request)
}

/// [`run_cyclone_peer`] through `wrapper` (e.g. `ip netns exec <ns>`: a test's own host).
pub fn run_cyclone_peer_in(wrapper: &[String], script: &str, cyclone: &Path, request: &str) -> serde_json::Value {
    run_peer_wrapped(wrapper, script, &[("CYCLONEDDS_URI", format!("file://{}", cyclone.display()))], request)
}

fn run_peer_wrapped(wrapper: &[String], script: &str, env: &[(&str, String)], request: &str) -> serde_json::Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/peers").join(script);
    let mut command = match wrapper.split_first() {
        Some((first, rest)) => {
            let mut c = Command::new(first);
            let _ = c.args(rest).arg(python());
            c
        }
        None => Command::new(python()),
    };
    let _ = command.arg(&path).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped());
    for (k, v) in env {
        let _ = command.env(k, v);
    }
    let mut child = command.spawn().expect("start the Python peer");
    child.stdin.take().unwrap().write_all(request.as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{script} failed: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{script} answered no JSON: {e}"))
}

/// [`CYCLONE_LOOPBACK`] written to `dir/cyclone.xml`, for a peer's `CYCLONEDDS_URI`.
pub fn cyclone_loopback_file(dir: &Path) -> PathBuf {
    let file = dir.join("cyclone.xml");
    std::fs::write(&file, CYCLONE_LOOPBACK).unwrap();
    file
}

/// Stops a node with SIGTERM, asserts that it exited cleanly, and returns its standard error.
pub fn stop_node(mut node: Child) -> String {
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let status = node.wait().unwrap();
    let mut err = String::new();
    let _ = std::io::Read::read_to_string(&mut node.stderr.take().unwrap(), &mut err);
    assert!(status.success(), "node exit {status:?}: {err}");
    err
}

/// `<site-packages>/cmeel.prefix/share/example-robot-data`, where example-robot-data installs.
pub fn example_robot_data() -> PathBuf {
    let out = Command::new(python()).args(["-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).output().unwrap();
    let site = String::from_utf8(out.stdout).unwrap();
    let dir = PathBuf::from(site.trim()).join("cmeel.prefix/share/example-robot-data");
    assert!(dir.is_dir(), "example-robot-data is not installed in the peers' venv ({})", dir.display());
    dir
}

/// The Panda from example-robot-data without an environment, raised 5 mm off the table it stands
/// on (a link resting on the table collides with it).
pub fn panda_params() -> thickness_collision::model::Params {
    let erd = example_robot_data();
    thickness_collision::model::Params {
        package_map: vec![format!("example-robot-data={}", erd.display())],
        robot_base_pose: vec![0.0, 0.0, 0.005, 0.0, 0.0, 0.0],
        input_files: thickness_collision::model::InputFiles { robot: Some(erd.join("robots/panda_description/urdf/panda.urdf")), environment: None },
        ..thickness_collision::model::Params::default()
    }
}

/// The robot URDF at `rel` inside example-robot-data, with the package map that resolves it.
pub fn erd_robot(rel: &str) -> (PathBuf, Vec<String>) {
    let root = example_robot_data();
    (root.join("robots").join(rel), vec![format!("example-robot-data={}", root.display())])
}

/// The bundled arm with a fat forearm (capsule radius 0.3 instead of 0.04), as URDF text that can
/// travel as a `robot_description` (its mesh path absolute): it reaches walls the arm does not.
pub fn fat_arm_urdf() -> String {
    let config = thickness_collision::model::bundled_config_dir();
    let gripper = config.join("example_workcell/gripper.obj");
    std::fs::read_to_string(config.join("example_workcell/robot.urdf"))
        .unwrap()
        .replace("filename=\"gripper.obj\"", &format!("filename=\"file://{}\"", gripper.display()))
        .replace("<capsule radius=\"0.04\"", "<capsule radius=\"0.3\"")
}

/// Numbers within 1e-9 (metres, here), arrays element by element.
pub fn close(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => (x - y).abs() <= 1e-9,
        _ => a.as_array().zip(b.as_array()).is_some_and(|(x, y)| x.len() == y.len() && x.iter().zip(y).all(|(p, q)| close(p, q))),
    }
}

/// `check --states <dir>/<name>.jsonl --json` plus `extra` on `lines`: the reference reports, one
/// per line.
pub fn check_json(dir: &Path, name: &str, lines: &[serde_json::Value], extra: &[&str]) -> Vec<serde_json::Value> {
    let file = dir.join(format!("{name}.jsonl"));
    let text: Vec<String> = lines.iter().map(serde_json::Value::to_string).collect();
    std::fs::write(&file, text.join("\n") + "\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_thickness_collision")).args(["check", "--states", file.to_str().unwrap(), "--json"]).args(extra).output().unwrap();
    assert!(o.status.success(), "check: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

/// A report the node sent (topic or `check_states`, as a peer printed it) equals `check`'s:
/// collision, and each contact's link, object and triangle, its depth, point and normal to 1e-9 m.
pub fn same_report(got: &serde_json::Value, want: &serde_json::Value, what: &str) {
    assert_eq!(got["in_collision"], want["in_collision"], "{what}: {got} vs {want}");
    let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
    assert_eq!(g.len(), w.len(), "{what}: colliding links, {got} vs {want}");
    for (a, b) in g.iter().zip(w) {
        for k in ["link_name", "object_name", "triangle"] {
            assert_eq!(a[k], b[k], "{what}: {k}");
        }
        for k in ["depth", "position", "normal"] {
            assert!(close(&a[k], &b[k]), "{what}: {k}: {a} vs {b}");
        }
    }
}

/// A warm-up state for a node on the bundled arm: every actuated joint at 0 (under the default
/// `missing_joint: last` nothing is reported before each has been received), stamped 1 ns.
pub fn whole_arm_warm_up() -> serde_json::Value {
    let name = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];
    serde_json::json!({"name": name, "position": vec![0.0; 7], "stamp": 1})
}
