//! Replays every input saved under `fuzz/regressions/<target>/` (crashes the fuzzer found, and a
//! few small seeds) through the same entry function its `cargo fuzz` target calls
//! (`fuzz_harness`, in fuzz/harness), on stable: none may panic. See docs/fuzzing.md.
//!
//! `examples/fuzz_seeds.rs` writes the generated seed corpus for `scripts/fuzz_campaign.sh`.

use fuzz_harness::{seeds, TARGETS};
use std::path::{Path, PathBuf};

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
    use fuzz_harness::{split_records, CdrKind};
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

#[test]
fn the_srdf_seed_parses_against_the_bundled_arm() {
    let seeds = seeds();
    let (_, _, bytes) = seeds.iter().find(|(t, _, _)| *t == "srdf").expect("an srdf seed");
    let text = std::str::from_utf8(bytes).unwrap();
    let model = thickness_collision::model::Srdf::parse(text, "seed", fuzz_harness::workcell().checker().robot()).unwrap();
    assert_eq!(model.group_names(), vec!["all", "arm", "hand"]);
    fuzz_harness::srdf(bytes);
}

#[test]
fn trajectory_seeds_decode_and_reach_the_check() {
    use thickness_collision::msgs::CheckTrajectoryRequest;
    use thickness_collision::replay::decode_cdr;
    let mut seen = 0;
    for (_, name, bytes) in seeds().into_iter().filter(|s| s.0 == "check_trajectory") {
        let mut request = decode_cdr::<CheckTrajectoryRequest>(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        // The seeds were written before `interpolation` and `path_tolerance` were appended: an
        // older client's request decodes with both empty (executed as the controller would).
        assert_eq!((request.interpolation.as_str(), request.path_tolerance.len()), ("", 0), "{name}");
        let a = fuzz_harness::workcell().check_trajectory(&request);
        match name.as_str() {
            "every_joint.cdr" => assert!(a.valid || a.segment >= 0 || a.segment == -2, "{name}: {a:?}"),
            "into_guard.cdr" => assert!(!a.valid && a.segment >= 0 && a.error.is_empty() && !a.contacts.is_empty(), "{name}: {a:?}"),
            "one_point.cdr" => {
                // Its point comes after 0: the approach from the current state is checked first
                // (and here crosses the guard); along the chords, the point alone.
                assert!(!a.valid && a.segment == -2 && a.error.is_empty() && !a.contacts.is_empty(), "{name}: {a:?}");
                request.interpolation = "linear".into();
                let a = fuzz_harness::workcell().check_trajectory(&request);
                assert!(!a.valid && a.segment == 0 && a.fraction == 0.0, "{name}: {a:?}");
            }
            _ => assert!(!a.valid && a.segment == -1 && !a.error.is_empty(), "{name}: {a:?}"),
        }
        seen += 1;
    }
    assert_eq!(seen, 7);
}

#[test]
fn validity_seeds_decode_and_reach_the_check() {
    use thickness_collision::fuzz_access::{GetStateValidityRequest, PipelineAccess};
    use thickness_collision::replay::decode_cdr;
    let mut seen = 0;
    for (_, name, bytes) in seeds().into_iter().filter(|s| s.0 == "check_state_validity") {
        let request = decode_cdr::<GetStateValidityRequest>(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (a, reason) = fuzz_harness::workcell().check_validity(&request);
        fuzz_harness::assert_validity_answer(&a, reason.as_deref());
        match name.as_str() {
            "every_joint.cdr" | "partial.cdr" => assert!(reason.is_none(), "{name}: {reason:?}"),
            "into_guard.cdr" | "group.cdr" => assert!(!a.valid && reason.is_none() && !a.contacts.is_empty(), "{name}: {a:?}"),
            _ => assert!(reason.is_some(), "{name}: {a:?}"),
        }
        seen += 1;
    }
    assert_eq!(seen, 9);
}

#[test]
fn records_split_back() {
    use fuzz_harness::{cdr_records, split_records, CdrKind};
    let input = cdr_records(&[(CdrKind::Tf, vec![1, 2, 3]), (CdrKind::Clock, vec![])]);
    assert_eq!(split_records(&input), vec![(CdrKind::Tf, &[1u8, 2, 3][..]), (CdrKind::Clock, &[][..])]);
    // A length past the end takes the rest; a lone kind byte is an empty record.
    assert_eq!(split_records(&[4, 9, 0, 7]), vec![(CdrKind::CheckStates, &[7u8][..])]);
    assert_eq!(split_records(&[6]), vec![(CdrKind::JointStates, &[][..])]);
}

/// The planning-scene seeds (the bytes Cyclone DDS wrote) decode as the types their first byte
/// names, and round-trip: a seed that no longer decodes would test only the refusal.
#[test]
fn planning_scene_seeds_decode() {
    let seeds: Vec<_> = seeds().into_iter().filter(|s| s.0 == "planning_scene").collect();
    assert_eq!(seeds.len(), 2);
    for (_, name, bytes) in seeds {
        assert!(thickness_collision::fuzz_access::planning_scene_round_trip(&bytes), "{name} does not decode");
    }
}
