//! Replays every input saved under `fuzz/regressions/<target>/` (crashes the fuzzer found, and a
//! few small seeds) through the same entry function its `cargo fuzz` target calls
//! (`thickness_collision::fuzz_entry`), on stable: none may panic. See docs/fuzzing.md.
//!
//! `examples/fuzz_seeds.rs` writes the generated seed corpus for `scripts/fuzz_campaign.sh`.

use std::path::{Path, PathBuf};
use thickness_collision::fuzz_entry::{seeds, TARGETS};

fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz").join("regressions")
}

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(entries) => entries.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.is_file()).collect(),
        Err(_) => Vec::new(),
    };
    files.sort();
    files
}

#[test]
fn every_saved_input_replays_without_panic() {
    let dir = regressions_dir();
    // A folder that names no target would be skipped silently: refuse it.
    for entry in std::fs::read_dir(&dir).expect("fuzz/regressions exists") {
        let name = entry.expect("readable entry").file_name().to_string_lossy().into_owned();
        assert!(
            TARGETS.iter().any(|(t, _)| *t == name),
            "fuzz/regressions/{name} is not a fuzz target (targets: {:?})",
            TARGETS.iter().map(|t| t.0).collect::<Vec<_>>()
        );
    }
    let mut failed = Vec::new();
    let mut replayed = 0;
    for (target, entry) in TARGETS {
        for file in files_in(&dir.join(target)) {
            let bytes = std::fs::read(&file).expect("readable input");
            let started = std::time::Instant::now();
            if std::panic::catch_unwind(|| entry(&bytes)).is_err() {
                failed.push(format!("{target}/{}", file.file_name().unwrap_or_default().to_string_lossy()));
            }
            replayed += 1;
            println!("{target}/{}: {:.1} ms", file.file_name().unwrap_or_default().to_string_lossy(), started.elapsed().as_secs_f64() * 1e3);
        }
    }
    println!("{replayed} inputs replayed");
    assert!(replayed > 0, "no inputs under {}", dir.display());
    assert!(failed.is_empty(), "{} of {replayed} saved fuzz inputs panic: {failed:?}", failed.len());
}

#[test]
fn generated_seeds_run_without_panic() {
    let seeds = seeds();
    for (target, _) in TARGETS.iter().filter(|(t, _)| !t.starts_with("bag_")) {
        assert!(seeds.iter().any(|(t, _, _)| t == target), "no generated seed for {target}");
    }
    for (target, name, bytes) in &seeds {
        assert!(!bytes.is_empty(), "seed {target}/{name} is empty");
        let entry = TARGETS.iter().find(|(t, _)| t == target).map(|(_, e)| *e).expect("a known target");
        entry(bytes);
    }
}

/// The seeds reach past the decoders: the CDR joint state and `/tf` seeds give states the
/// bundled robot can check, and the state-line seeds are checked without an error.
#[test]
fn seeds_reach_checked_states() {
    use thickness_collision::fuzz_entry::{split_records, CdrKind};
    use thickness_collision::model::Params;
    use thickness_collision::msgs::{JointState, TfMessage};
    use thickness_collision::pipeline::{parse_state_line, Pipeline};
    use thickness_collision::replay::decode_cdr;
    let seeds = seeds();
    let seed = |target: &str, name: &str| seeds.iter().find(|(t, n, _)| *t == target && n == name).map(|s| s.2.clone()).expect("a seed");
    let mut pipeline = Pipeline::new(Params::default()).expect("the bundled workcell");

    let input = seed("cdr", "joint_state.cdr");
    let records = split_records(&input);
    assert_eq!(records[0].0, CdrKind::JointStates);
    let state = pipeline.joint_state(&decode_cdr::<JointState>(records[0].1).expect("decodes")).expect("a state");
    assert!(pipeline.check(&state).report.error.is_empty());

    let input = seed("cdr", "tf.cdr");
    let records = split_records(&input);
    assert_eq!((records[0].0, records[1].0), (CdrKind::TfStatic, CdrKind::Tf));
    pipeline.tf_static(&decode_cdr::<TfMessage>(records[0].1).expect("decodes")).expect("applied");
    let state = pipeline.tf(&decode_cdr::<TfMessage>(records[1].1).expect("decodes")).expect("a state");
    assert!(pipeline.check(&state).report.error.is_empty());

    for name in ["joints.json", "transforms.json"] {
        let line = seed("state_line", name);
        let checked = pipeline.check_line(parse_state_line(std::str::from_utf8(&line).expect("UTF-8")).expect("a state line"));
        assert!(checked.report.error.is_empty(), "{name}: {}", checked.report.error);
    }
}
