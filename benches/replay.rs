//! Replay rate on a 100,000-state bag of the bundled workcell, I/O included (reading the MCAP,
//! decoding CDR, checking, writing JSON lines and an output bag). Prints a table.
//!
//! `cargo bench --bench replay`

#[path = "common/joint_state_bag.rs"]
mod joint_state_bag;
// Only the scratch folder: the rest of the tests' scaffolding is unused here.
#[allow(dead_code)]
#[path = "../tests/common/scaffold.rs"]
mod scaffold;

use joint_state_bag::write_joint_state_bag;
use oorandom::Rand64;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::model::Params;
use thickness_collision::replay::{replay, Quiet, ReplayOptions};

const STATES: usize = 100_000;

fn main() {
    let checker = Checker::from_params(Params::default()).unwrap();
    let mut rng = Rand64::new(42);
    let states: Vec<(Vec<String>, Vec<f64>)> = (0..STATES)
        .map(|_| {
            let joints: Vec<_> = checker.robot().joints.iter().filter(|j| j.is_actuated()).collect();
            let names = joints.iter().map(|j| j.name.clone()).collect();
            let pos = joints
                .iter()
                .map(|j| {
                    let (lo, hi) = (j.limits[0].max(-3.0), j.limits[1].min(3.0));
                    lo + (hi - lo) * rng.rand_float()
                })
                .collect();
            (names, pos)
        })
        .collect();
    let root = scaffold::emptied(scaffold::scratch_dir("bench_replay"));
    let bag = root.join("in");
    let _ = write_joint_state_bag(&bag, "bench", 1_000_000, states);
    let size = std::fs::metadata(bag.join("bench_0.mcap")).unwrap().len();

    println!("replay of {STATES} joint states of the bundled arm against the bundled workcell ({:.1} MB MCAP)", size as f64 / 1e6);
    println!("{:<44} {:>10} {:>12} {:>12}", "outputs", "seconds", "states/s", "us/state");
    for (label, jsonl, out) in [("summary only", false, false), ("JSON lines", true, false), ("JSON lines + output bag", true, true)] {
        let opts = ReplayOptions {
            bag: bag.clone(),
            topic: None,
            pose_source: None,
            frame_prefix: None,
            out_dir: out.then(|| root.join(format!("out_{}", label.len()))),
            jsonl: jsonl.then(|| root.join("out.jsonl")),
            start: None,
            end: None,
            // States on their own, as the figures in docs/benchmarks.md were taken; motions are
            // measured in benches/motion.rs.
            motion: Some(false),
            plot: None,
            no_markers: true,
            trajectory_topic: None,
        };
        let started = Instant::now();
        let summary = replay(Params::default(), &opts, &mut Quiet).unwrap();
        let secs = started.elapsed().as_secs_f64();
        assert_eq!(summary.states, STATES);
        println!("{label:<44} {secs:>10.3} {:>12.0} {:>12.2}", STATES as f64 / secs, secs / STATES as f64 * 1e6);
        if label == "summary only" {
            println!("  ({} of {STATES} states in collision)", summary.in_collision);
        }
    }
    let _ = std::fs::remove_dir_all(&root);
}
