//! Planning-scene benchmark end to end: the release node running, a C++ client on Fast DDS
//! (`tests/peers/fastdds/peer.cpp`, as a MoveIt application on rmw_fastrtps_cpp calls it) sends
//! `apply_planning_scene` with the 100,000-triangle wavy wall of `scene_update` as an `ADD`, and
//! the time from just before its `write()` to the reply's take is recorded (the reply is sent
//! only once the object is in force). A `REMOVE` follows each `ADD` (timed too), so every `ADD`
//! builds its cells. Loopback only (`ROS_LOCALHOST_ONLY=1`, the peer's UDPv4 transport on
//! 127.0.0.1), DDS domain 175.
//!
//! `cargo bench --bench scene_apply [-- NX NY REPEAT]` (default 224 x 224 quads, 7 repeats;
//! needs `TC_PYTHON` for the peer's type generation, as the tests do; `TC_NODE_LOG=FILE` keeps
//! the node's log). `benches/run_scene_comparison.sh`
//! runs it beside coal's build of the same triangles. The last line is machine-readable:
//! `SCENE_APPLY {json}`.

#[path = "wall_1m.rs"]
mod wall_1m;

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, Stdio};
use thickness_collision::fuzz_access::apply_planning_scene_cdr;
use wall_1m::{median, scene_bench_wall};

const DOMAIN: &str = "175";

/// `command` killed with this process: a benchmark that panics leaves no node serving its
/// domain (a second node there would answer, and build, every request too).
fn dies_with_us(mut command: Command) -> Command {
    // SAFETY: prctl is async-signal-safe; nothing else runs between fork and exec here.
    unsafe {
        let _ = std::os::unix::process::CommandExt::pre_exec(&mut command, || {
            let _ = libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            Ok(())
        });
    }
    command
}

/// The release node on the bundled workcell, past its banner.
fn start_node() -> Child {
    let mut node = dies_with_us(Command::new(env!("CARGO_BIN_EXE_thickness_collision")))
        .args(["run", "--ros-args", "-p", "service_mapping:=enhanced"])
        .env("ROS_DOMAIN_ID", DOMAIN)
        .env("ROS_LOCALHOST_ONLY", "1")
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .stdout(Stdio::piped())
        .stderr(std::env::var_os("TC_NODE_LOG").map_or_else(Stdio::null, |p| Stdio::from(std::fs::File::create(p).expect("the node log"))))
        .spawn()
        .expect("start the node");
    let mut out = BufReader::new(node.stdout.take().expect("piped"));
    let mut line = String::new();
    while out.read_line(&mut line).map(|n| n > 0).unwrap_or(false) && !line.contains("serves") {}
    // Keep reading (and dropping) its reports' log so it never blocks on a full pipe.
    std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    node
}

/// The Fast DDS peer, built by its build script.
fn start_peer() -> Child {
    let root = env!("CARGO_MANIFEST_DIR");
    let built = Command::new("bash")
        .arg(format!("{root}/tests/peers/fastdds/build.sh"))
        .arg("peer")
        .arg(format!("{root}/tests/peers/fastdds/peer.cpp"))
        .stderr(Stdio::inherit())
        .output()
        .expect("run build.sh");
    assert!(built.status.success(), "building the Fast DDS peer failed (TC_PYTHON set? fastddsgen installed?)");
    let bin = String::from_utf8_lossy(&built.stdout).lines().last().unwrap_or_default().trim().to_owned();
    dies_with_us(Command::new(bin))
        .args(["--domain", DOMAIN, "--interface", "127.0.0.1", "--peer", "127.0.0.1"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start the Fast DDS peer")
}

fn main() {
    let ((v, t), repeat) = scene_bench_wall();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let pose = [0.6, -3.5, 3.5, 0.0, h, 0.0, h];
    let dir = std::env::temp_dir().join(format!("tc_scene_apply_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    let (add, remove) = (dir.join("add.cdr"), dir.join("remove.cdr"));
    let add_bytes = apply_planning_scene_cdr("scan", 0, pose, Some((&v, &t)));
    std::fs::write(&add, &add_bytes).expect("write the request");
    std::fs::write(&remove, apply_planning_scene_cdr("scan", 1, pose, None)).expect("write the request");
    eprintln!("request: {:.1} MB", add_bytes.len() as f64 / 1e6);

    let mut node = start_node();
    let mut peer = start_peer();
    let mut input = peer.stdin.take().expect("piped");
    let mut output = BufReader::new(peer.stdout.take().expect("piped"));
    let mut send = |cmd: Value| -> Value {
        writeln!(input, "{cmd}").and_then(|_| input.flush()).expect("the peer is gone");
        let mut line = String::new();
        let _ = output.read_line(&mut line).expect("read the peer");
        serde_json::from_str(&line).unwrap_or(Value::Null)
    };
    let hello = send(json!({"cmd": "hello"}));
    assert_eq!(hello["ok"], true, "the peer did not start: {:?}", peer.try_wait());
    let files: Vec<_> = (0..repeat).flat_map(|_| [add.clone(), remove.clone()]).collect();
    let a = send(json!({"cmd": "apply", "service": "apply_planning_scene", "files": files, "timeout": 60}));
    let _ = send(json!({"cmd": "quit"}));
    let _ = peer.wait();
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let _ = node.wait();
    let _ = std::fs::remove_dir_all(&dir);
    let answers = a["answers"].as_array().unwrap_or_else(|| panic!("no answers: {a}"));
    assert!(answers.iter().all(|x| x["success"] == true), "a request failed: {a}");
    let seconds = |parity: usize| answers.iter().skip(parity).step_by(2).map(|x| x["seconds"].as_f64().unwrap_or(f64::NAN)).collect::<Vec<f64>>();
    let (adds, removes) = (seconds(0), seconds(1));
    let ms = |v: &[f64]| v.iter().map(|x| format!("{:.0}", x * 1e3)).collect::<Vec<_>>().join(", ");
    eprintln!("apply_planning_scene ADD, request to reply: median {:.1} ms (runs: {} ms)", median(adds.clone()) * 1e3, ms(&adds));
    eprintln!("apply_planning_scene REMOVE, request to reply: median {:.1} ms (runs: {} ms)", median(removes.clone()) * 1e3, ms(&removes));
    println!(
        "SCENE_APPLY {}",
        json!({"triangles": t.len(), "repeat": repeat, "request_bytes": add_bytes.len(), "add_s": median(adds.clone()), "add_runs_s": adds, "remove_s": median(removes)})
    );
}
