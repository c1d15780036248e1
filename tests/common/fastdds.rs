//! The Fast DDS peer (`tests/peers/fastdds/peer.cpp`): built once by `tests/peers/fastdds/build.sh`
//! (fastddsgen and g++ into `target/fastdds/`, cached by a hash of its inputs: a rerun builds
//! nothing), started with a command wrapper and an environment of the caller's choosing (the
//! two-host test runs it under `ip netns exec`), and driven by JSON lines on its standard input.
//! A missing tool (fastddsgen, g++, Fast DDS headers, `TC_PYTHON`) is a failure with the reason.
#![allow(dead_code)]

use serde_json::Value;
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::OnceLock;

/// Builds the peer (or finds it built) and returns its path; panics with build.sh's error.
pub fn peer_binary() -> PathBuf {
    static BIN: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    BIN.get_or_init(|| {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        let dir = root.join("tests/peers/fastdds");
        let out = Command::new("bash")
            .arg(dir.join("build.sh"))
            .arg("peer")
            .arg(dir.join("peer.cpp"))
            .env("TC_PYTHON", super::python())
            .output()
            .map_err(|e| format!("cannot run build.sh: {e}"))?;
        if !out.status.success() {
            return Err(format!("building the Fast DDS peer failed ({}):\n{}", out.status, String::from_utf8_lossy(&out.stderr)));
        }
        let path = PathBuf::from(String::from_utf8_lossy(&out.stdout).lines().last().unwrap_or_default().trim());
        if path.is_file() {
            Ok(path)
        } else {
            Err(format!("build.sh printed no binary: {}", String::from_utf8_lossy(&out.stdout)))
        }
    })
    .clone()
    .unwrap_or_else(|e| panic!("{e}"))
}

/// How to start a peer: the command wrapper (empty: none; e.g. `["ip", "netns", "exec", "tc-b-1"]`),
/// the DDS domain, the interface its UDPv4 transport may use and its initial peers (both
/// 127.0.0.1 unless set), and extra environment variables.
#[derive(Clone, Debug)]
pub struct PeerOptions {
    pub wrapper: Vec<String>,
    pub domain: u32,
    pub interface: String,
    pub peers: Vec<String>,
    pub env: Vec<(String, String)>,
}

impl PeerOptions {
    /// Loopback only (the network rule): interface and peer 127.0.0.1.
    pub fn loopback(domain: u32) -> PeerOptions {
        PeerOptions { wrapper: vec![], domain, interface: "127.0.0.1".into(), peers: vec!["127.0.0.1".into()], env: vec![] }
    }
}

/// A running peer. Dropping it closes its input and kills it if it has not exited.
pub struct FastDdsPeer {
    child: Child,
    input: Option<ChildStdin>,
    output: BufReader<ChildStdout>,
}

impl FastDdsPeer {
    /// Starts the peer and waits for its answer to `hello`.
    pub fn start(opts: &PeerOptions) -> FastDdsPeer {
        let bin = peer_binary();
        let mut command = match opts.wrapper.split_first() {
            Some((first, rest)) => {
                let mut c = Command::new(first);
                let _ = c.args(rest).arg(&bin);
                c
            }
            None => Command::new(&bin),
        };
        let _ = command.args(["--domain", &opts.domain.to_string(), "--interface", &opts.interface]);
        for p in &opts.peers {
            let _ = command.args(["--peer", p]);
        }
        for (k, v) in &opts.env {
            let _ = command.env(k, v);
        }
        // The peer ends with the test thread that started it (as the node does in start_node).
        // SAFETY: prctl is async-signal-safe; nothing else runs between fork and exec here.
        unsafe {
            let _ = std::os::unix::process::CommandExt::pre_exec(&mut command, || {
                let _ = libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
                Ok(())
            });
        }
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start the Fast DDS peer {}: {e}", bin.display()));
        let input = child.stdin.take();
        let output = BufReader::new(child.stdout.take().expect("piped stdout"));
        let mut peer = FastDdsPeer { child, input, output };
        let hello = peer.send(&serde_json::json!({"cmd": "hello"}));
        assert_eq!(hello["ok"], true, "the Fast DDS peer did not start: {hello}");
        peer
    }

    /// Sends one command and returns the peer's JSON answer; a command the peer refused (an
    /// `error` field) or a peer that died is a test failure.
    pub fn send(&mut self, command: &Value) -> Value {
        let input = self.input.as_mut().expect("peer input open");
        writeln!(input, "{command}").and_then(|_| input.flush()).unwrap_or_else(|e| panic!("the Fast DDS peer is gone: {e}"));
        let mut line = String::new();
        let n = self.output.read_line(&mut line).unwrap_or_else(|e| panic!("reading the Fast DDS peer: {e}"));
        assert!(n > 0, "the Fast DDS peer exited (status {:?}) on {command}", self.child.try_wait());
        let answer: Value = serde_json::from_str(&line).unwrap_or_else(|e| panic!("the Fast DDS peer answered no JSON ({e}): {line}"));
        assert!(answer.get("error").is_none(), "the Fast DDS peer refused {command}: {answer}");
        answer
    }

    /// One service call per request, each from its own client (rmw_fastrtps_cpp's correlation);
    /// returns the answers, one per request.
    pub fn call(&mut self, service: &str, ty: &str, requests: Vec<Value>, timeout: f64) -> Vec<Value> {
        let n = requests.len();
        let a = self.send(&serde_json::json!({"cmd": "call", "service": service, "type": ty, "requests": requests, "timeout": timeout}));
        assert_eq!(a["matched"], true, "{service}: the node's request reader or reply writer never matched the Fast DDS client");
        let answers = a["answers"].as_array().cloned().unwrap_or_default();
        assert_eq!(answers.len(), n, "{service}: {a}");
        answers
    }

    /// Asks the peer to quit and waits for it.
    pub fn quit(mut self) {
        let _ = self.send_no_answer(&serde_json::json!({"cmd": "quit"}));
        drop(self.input.take());
        let status = self.child.wait().expect("wait for the Fast DDS peer");
        assert!(status.success(), "the Fast DDS peer exited with {status}");
    }

    fn send_no_answer(&mut self, command: &Value) -> std::io::Result<()> {
        let input = self.input.as_mut().expect("peer input open");
        writeln!(input, "{command}")?;
        input.flush()
    }
}

impl Drop for FastDdsPeer {
    fn drop(&mut self) {
        drop(self.input.take());
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}
