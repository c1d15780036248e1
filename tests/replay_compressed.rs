//! Issue 30: compressed bags and inputs with nothing to check. rosbags writes plain bags of the
//! bundled arm's joint states (MCAP and sqlite3); `tests/peers/bag_compress.py` compresses them as
//! `ros2 bag record --compression-format zstd --compression-mode message|file` does (zstandard).
//! Replay of each compressed bag, and of the same bag compressed by rosbags' own writer, must give
//! the plain bag's reports byte for byte; rosbags' reader must read the hand-compressed bags to the
//! plain bag's messages (they are the format it knows);
//! and every input without a state to check must exit 2 with one line that says why.

mod common;

use oorandom::Rand64;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use thickness_collision::checker::Checker;
use thickness_collision::model::Params;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn dir(name: &str) -> PathBuf {
    common::emptied(common::scratch_subdir("replay_compressed", name))
}

const T0: i64 = 1_700_000_000_000_000_000;

/// Random states of the bundled arm as bag_tool.py messages, 10 ms apart.
fn joint_messages(n: usize, seed: u64) -> Vec<Value> {
    let checker = Checker::from_params(Params::default()).unwrap();
    let mut rng = Rand64::new(seed as u128);
    (0..n)
        .map(|k| {
            let (mut names, mut pos) = (Vec::new(), Vec::new());
            for j in checker.robot().joints.iter().filter(|j| j.is_actuated()) {
                let (lo, hi) = (j.limits[0].max(-3.0), j.limits[1].min(3.0));
                names.push(j.name.clone());
                pos.push(lo + (hi - lo) * rng.rand_float());
            }
            let t = T0 + k as i64 * 10_000_000;
            json!({"t": t, "stamp": t - 1234, "name": names, "position": pos})
        })
        .collect()
}

fn write_bag(path: &Path, storage: &str, messages: &[Value]) {
    let _ = common::run_peer("bag_tool.py", &json!({"op": "write", "path": path, "storage": storage, "messages": messages, "robot_description": null}));
}

fn peer(op: &str, bag: &Path, extra: Value) -> Value {
    let mut req = json!({"op": op, "path": bag});
    if let (Some(r), Some(e)) = (req.as_object_mut(), extra.as_object()) {
        r.extend(e.clone());
    }
    common::run_peer("bag_compress.py", &req)
}

fn copy_bag(from: &Path, to: &Path) {
    let _ = std::fs::remove_dir_all(to);
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let _ = std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// The bag's one storage file (ending in `ext`).
fn storage_file(bag: &Path, ext: &str) -> PathBuf {
    std::fs::read_dir(bag).unwrap().map(|e| e.unwrap().path()).find(|p| p.to_str().unwrap().ends_with(ext)).unwrap()
}

/// `replay BAG --no-motion --jsonl ...` with its own temporary folder; the JSON lines, the output,
/// and what is left in that temporary folder afterwards.
fn replay(bag: &Path, d: &Path, name: &str, extra: &[&str]) -> (Vec<String>, Output, usize) {
    let tmp = d.join(format!("tmp_{name}"));
    std::fs::create_dir_all(&tmp).unwrap();
    let jsonl = d.join(format!("{name}.jsonl"));
    let out = bin().arg("replay").arg(bag).arg("--no-motion").arg("--jsonl").arg(&jsonl).args(extra).env("TMPDIR", &tmp).output().unwrap();
    let lines = std::fs::read_to_string(&jsonl).unwrap_or_default().lines().map(str::to_owned).collect();
    let left = std::fs::read_dir(&tmp).unwrap().count();
    (lines, out, left)
}

/// The CLI's error line (there must be exactly one), after asserting exit code 2.
fn refused(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "expected exit 2: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("thickness_collision: error:")).collect();
    assert_eq!(lines.len(), 1, "one error line: {err}");
    assert!(err.lines().skip_while(|l| !l.starts_with("thickness_collision: error:")).count() == 1, "nothing after the error line: {err}");
    lines[0].to_owned()
}

fn same_lines(got: &[String], want: &[String], what: &str) {
    if let Some(i) = (0..got.len().min(want.len())).find(|&i| got[i] != want[i]) {
        panic!("{what}: line {i} differs:\n got  {}\n want {}", got[i], want[i]);
    }
    assert_eq!(got.len(), want.len(), "{what}: line count");
}

#[test]
fn message_and_file_compressed_bags_replay_like_the_plain_ones() {
    let d = dir("same");
    let msgs = joint_messages(300, 7);
    for storage in ["mcap", "sqlite3"] {
        let ext = if storage == "mcap" { ".mcap" } else { ".db3" };
        let plain = d.join(format!("plain_{storage}"));
        write_bag(&plain, storage, &msgs);
        let (want, out, _) = replay(&plain, &d, &format!("plain_{storage}"), &[]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(want.len(), 300);
        let colliding = want.iter().filter(|l| l.contains("\"in_collision\":true")).count();
        assert!(colliding > 20 && colliding < 280, "{colliding} of 300 colliding: pick another seed");
        let rosbags_plain = peer("read", &plain, json!({}));
        assert_eq!(rosbags_plain["messages"].as_array().unwrap().len(), 300);

        for mode in ["message", "file"] {
            let what = format!("{storage}, compression_mode {mode}");
            let bag = d.join(format!("{mode}_{storage}"));
            copy_bag(&plain, &bag);
            let plain_size = std::fs::metadata(storage_file(&bag, ext)).unwrap().len();
            let _ = peer(mode, &bag, json!({}));
            let meta = std::fs::read_to_string(bag.join("metadata.yaml")).unwrap();
            assert!(meta.contains("compression_format: zstd") && meta.contains(&format!("compression_mode: {}", mode.to_uppercase())), "{meta}");
            // rosbags reads the compressed bag to the very messages of the plain one.
            assert_eq!(peer("read", &bag, json!({})), rosbags_plain, "{what}: rosbags' reader");

            let (got, out, left) = replay(&bag, &d, &format!("{mode}_{storage}"), &[]);
            assert!(out.status.success(), "{what}: {}", String::from_utf8_lossy(&out.stderr));
            same_lines(&got, &want, &what);
            assert_eq!(left, 0, "{what}: the decompressed copies are removed");
            // The same bag compressed by rosbags' writer: lower-case mode, and in file mode a
            // frame that does not declare its size.
            let by_rosbags = d.join(format!("rosbags_{mode}_{storage}"));
            let _ = peer("rosbags", &plain, json!({"out": by_rosbags, "mode": mode}));
            let meta = std::fs::read_to_string(by_rosbags.join("metadata.yaml")).unwrap();
            assert!(meta.contains(&format!("compression_mode: {mode}\n")), "{meta}");
            let (got, out, left) = replay(&by_rosbags, &d, &format!("rosbags_{mode}_{storage}"), &[]);
            assert!(out.status.success(), "{what}, rosbags' writer: {}", String::from_utf8_lossy(&out.stderr));
            same_lines(&got, &want, &format!("{what}, rosbags' writer"));
            assert_eq!(left, 0);
            if mode == "file" {
                let zst = storage_file(&bag, &format!("{ext}.zstd"));
                assert!(std::fs::metadata(&zst).unwrap().len() < plain_size, "{what}: compressed");
                assert!(!meta.contains(&format!("- {}\n", zst.file_stem().unwrap().to_str().unwrap())), "{what}: the plain name is gone: {meta}");
                // The .zstd file alone, as a bare path.
                let (got, out, left) = replay(&zst, &d, &format!("bare_{storage}"), &[]);
                assert!(out.status.success(), "{what}, bare: {}", String::from_utf8_lossy(&out.stderr));
                same_lines(&got, &want, &format!("{what}, bare .zstd"));
                assert_eq!(left, 0);
                // A corrupt one: refused naming it, and nothing left behind.
                let bytes = std::fs::read(&zst).unwrap();
                std::fs::write(&zst, &bytes[..bytes.len() / 2]).unwrap();
                let (_, out, left) = replay(&bag, &d, &format!("cut_{storage}"), &[]);
                let e = refused(&out);
                assert!(e.contains(zst.file_name().unwrap().to_str().unwrap()) && e.contains("not a valid zstd file"), "{e}");
                assert_eq!(left, 0, "{what}: removed on error too");
            } else {
                // A message-compressed storage file without its metadata.yaml: payloads are zstd
                // frames, not CDR. Refused, saying so.
                let (got, out, _) = replay(&storage_file(&bag, ext), &d, &format!("bare_{mode}_{storage}"), &[]);
                let e = refused(&out);
                assert!(got.is_empty());
                assert!(e.contains("none of the 300 messages on /joint_states") && e.contains("zstd frames") && e.contains("metadata.yaml"), "{e}");
            }
        }
    }
}

#[test]
fn inputs_without_a_state_to_check_exit_2() {
    let d = dir("refused");
    let msgs = joint_messages(5, 3);
    let plain = d.join("plain");
    write_bag(&plain, "mcap", &msgs);

    // A ROS 1 channel in an MCAP file: refused up front, naming the encoding.
    let ros1 = d.join("ros1");
    copy_bag(&plain, &ros1);
    let _ = peer("encoding", &ros1, json!({"topic": "/joint_states", "encoding": "ros1"}));
    let e = refused(&replay(&ros1, &d, "ros1", &[]).1);
    assert!(e.contains("/joint_states") && e.contains("'ros1'") && e.contains("cdr"), "{e}");

    // An unknown compression format: refused, naming it and what is read.
    let lz4 = d.join("lz4");
    copy_bag(&plain, &lz4);
    let _ = peer("message", &lz4, json!({}));
    let _ = peer("format", &lz4, json!({"format": "lz4"}));
    let e = refused(&replay(&lz4, &d, "lz4", &[]).1);
    assert!(e.contains("metadata.yaml") && e.contains("compression_format 'lz4' is not supported") && e.contains("zstd"), "{e}");

    // Messages on the topic, none of which decodes (today: "0 states", exit 0).
    let junk: Vec<Value> = msgs.iter().map(|m| json!({"t": m["t"], "raw": [0, 1, 0, 0, 255, 255, 255]})).collect();
    for storage in ["mcap", "sqlite3"] {
        let bag = d.join(format!("junk_{storage}"));
        write_bag(&bag, storage, &junk);
        let (got, out, _) = replay(&bag, &d, &format!("junk_{storage}"), &[]);
        let e = refused(&out);
        assert!(got.is_empty());
        assert!(e.contains("none of the 5 messages on /joint_states") && e.contains("decodes as CDR sensor_msgs/msg/JointState"), "{e}");
        assert!(!e.contains("zstd"), "{e}");
        // One good message among them is enough: the rest are skipped and counted, as before.
        let mut mixed = junk.clone();
        mixed[2] = msgs[2].clone();
        let bag = d.join(format!("mixed_{storage}"));
        write_bag(&bag, storage, &mixed);
        let (got, out, _) = replay(&bag, &d, &format!("mixed_{storage}"), &[]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(got.len(), 1);
        assert!(String::from_utf8_lossy(&out.stdout).contains("4 x undecodable"));
    }

    let one = d.join("one_junk");
    write_bag(&one, "mcap", &junk[..1]);
    let e = refused(&replay(&one, &d, "one_junk", &[]).1);
    assert!(e.contains("the one message on /joint_states") && e.contains("does not decode as CDR"), "{e}");

    // The topic is declared but has no messages: refused, naming the topics that have some.
    let tf_only = d.join("tf_only");
    write_bag(&tf_only, "sqlite3", &[json!({"t": T0, "stamp": T0, "transforms": []})]);
    let e = refused(&replay(&tf_only, &d, "tf_only", &[]).1);
    assert!(e.contains("no messages on topic /joint_states") && e.contains("/tf (1)"), "{e}");

    // Every message outside --start/--end.
    let e = refused(&replay(&plain, &d, "window", &["--start", "100"]).1);
    assert!(e.contains("none of the 5 messages on /joint_states") && e.contains("--start 100") && e.contains("0.000 to 0.040 s"), "{e}");
    // Inside it: fine.
    let (got, out, _) = replay(&plain, &d, "window_ok", &["--start", "0.015"]);
    assert!(out.status.success() && got.len() == 3, "{}", String::from_utf8_lossy(&out.stderr));
}
