//! The Python layer's cost (issue 35): the Panda (example-robot-data, with its SRDF) in the
//! bundled workcell, the same random states checked by the Rust API and through the Python
//! package, in turns (Rust, then Python, `ROUNDS` times), on this machine's cores.
//!
//!   cargo bench --bench python_layer        # STATES=20000 ROUNDS=3 by default
//!
//! Builds the package into the test venv first (maturin develop --release, target/python), as
//! tests/python_package.rs does. Prints a markdown table: per `check` call, Rust
//! (`check_joints`) beside Python (`Checker.check`, reading `in_collision`), and the difference
//! (goal: at most 2 µs); per batch, Rust (`check_joints_batch`: full checks on every core) beside
//! `check_batch(Q, depths=True)` (the same full checks) and `check_batch(Q)` (flags only). The Python side runs with `OPENBLAS_NUM_THREADS=1`.

#[path = "peer_compare_core.rs"]
mod peer_compare_core;

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::model::{LoadedParams, Params, DEFAULT_NODE_FQN};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let n = env_usize("STATES", 20_000);
    let rounds = env_usize("ROUNDS", 3);
    let py = peer_compare_core::python();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    peer_compare_core::scaffold::develop_python_package(&py);
    let (_, map) = peer_compare_core::panda(&py);
    let erd = map[0].split_once('=').unwrap().1.to_owned();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("python_layer");
    std::fs::create_dir_all(&dir).unwrap();
    let params_path = dir.join("panda.yaml");
    std::fs::write(
        &params_path,
        format!(
            "/**/thickness_collision:\n  ros__parameters:\n    robot_description_file: {erd}/robots/panda_description/urdf/panda.urdf\n    environment_file: {}\n    robot_semantic_file: {erd}/robots/panda_description/srdf/panda.srdf\n    robot_base_pose: [0.0, 0.0, 0.005, 0.0, 0.0, 0.0]\n    package_map: [\"{}\"]\n",
            root.join("config/example_workcell/environment.urdf").display(),
            map[0]
        ),
    )
    .unwrap();
    let LoadedParams { params, .. } = Params::from_files_for_node(std::slice::from_ref(&params_path), DEFAULT_NODE_FQN).unwrap();
    let checker = Checker::from_params(params).unwrap();
    let robot = checker.robot();
    let names: Vec<String> = robot.joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
    let mut rng = oorandom::Rand64::new(35);
    let rows: Vec<Vec<f64>> = (0..n)
        .map(|_| {
            names
                .iter()
                .map(|name| {
                    let [lo, hi] = robot.joints[robot.joint(name).unwrap()].limits;
                    lo + (hi - lo) * rng.rand_float()
                })
                .collect()
        })
        .collect();
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let states_path = dir.join("states.f64");
    peer_compare_core::scaffold::write_le(&states_path, &flat);

    let (mut rust_check, mut rust_batch, mut python) = (Vec::new(), Vec::new(), Vec::new());
    let batch: Vec<(&[String], &[f64])> = rows.iter().map(|r| (&names[..], &r[..])).collect();
    for _ in 0..rounds {
        let started = Instant::now();
        let mut colliding = 0;
        for r in &rows {
            colliding += checker.check_joints(&names, r).unwrap().in_collision as usize;
        }
        rust_check.push(started.elapsed().as_secs_f64() / n as f64);
        let started = Instant::now();
        let reports = checker.check_joints_batch(&batch);
        rust_batch.push(started.elapsed().as_secs_f64());
        assert_eq!(reports.iter().filter(|r| r.as_ref().unwrap().in_collision).count(), colliding);
        // NumPy's OpenBLAS threads spin on this machine's two cores after import (5.9 % of a
        // profile of the loop): one thread, as for any single-threaded timing.
        let out = Command::new(&py)
            .env("OPENBLAS_NUM_THREADS", "1")
            .arg(root.join("benches/python_layer.py"))
            .arg(&params_path)
            .arg(&states_path)
            .arg("3")
            .output()
            .unwrap();
        assert!(out.status.success(), "python_layer.py: {}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["colliding"].as_u64().unwrap() as usize, colliding, "Python and Rust disagree");
        python.push(v);
    }
    let pick = |key: &str| median(python.iter().flat_map(|v| v[key].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>()).collect());
    let (rc, pc, ri) = (median(rust_check.clone()), pick("check"), pick("rust_in_process"));
    let diffs: Vec<f64> = python
        .iter()
        .flat_map(|v| {
            v["check"]
                .as_array()
                .unwrap()
                .iter()
                .zip(v["rust_in_process"].as_array().unwrap())
                .map(|(p, r)| p.as_f64().unwrap() - r.as_f64().unwrap())
                .collect::<Vec<_>>()
        })
        .collect();
    let (rb, pd, pf) = (median(rust_batch.clone()), pick("batch_depths"), pick("batch_flags"));
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    println!(
        "Panda (with its SRDF) in the bundled workcell, {n} random states, {cores} cores, medians of {rounds} rounds (the Python process: 3 loops each):\n"
    );
    println!("| measure | Rust | Python | Python − Rust, or Python / Rust |");
    println!("|---|---|---|---|");
    println!("| one `check` at a time, per call; Rust in this bench's process | {:.2} µs | {:.2} µs | {:+.2} µs |", rc * 1e6, pc * 1e6, (pc - rc) * 1e6);
    println!(
        "| the same, Rust's loop inside the Python process, just before each Python loop | {:.2} µs | {:.2} µs | **{:+.2} µs** (median of the {} paired differences; goal ≤ 2 µs) |",
        ri * 1e6,
        pc * 1e6,
        median(diffs.clone()) * 1e6,
        diffs.len()
    );
    println!(
        "| a batch of {n}, full checks (`check_joints_batch`; `check_batch(Q, depths=True)`) | {:.1} ms | {:.1} ms | **{:.3}** (goal ≤ 1.10) |",
        rb * 1e3,
        pd * 1e3,
        pd / rb
    );
    println!("| a batch, flags only (`check_batch(Q)`) | | {:.1} ms | {:.3} of the Rust full batch |", pf * 1e3, pf / rb);
    println!("\nPaired differences, Python − Rust in its process (µs): {}", diffs.iter().map(|d| format!("{:+.2}", d * 1e6)).collect::<Vec<_>>().join(", "));
}
