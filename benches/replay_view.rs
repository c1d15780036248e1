//! Issue 16's figure: one-hour bags at 100 Hz (360,000 joint states of the bundled arm) replayed
//! with the output bag as before (`/collisions` only), with the markers, `/tf` and
//! `/robot_description` for viewers, and with those and `--plot`, interleaved round after round
//! so the ratios are taken under the same load. Two bags: random states checked each on its own
//! (the cheapest checks, so the view's share is largest, and every link flickers: the worst case
//! for the timeline), and a smooth sweep replayed with the default parameters (motions checked),
//! as an hour of robot work is. Prints a table per bag, the SVG's size and element count.
//!
//! `cargo bench --bench replay_view` (`ROUNDS=n` to change the 3 rounds; `BAGS=random` or
//! `BAGS=sweep` for one of the two; `KEEP_BAG=DIR` only writes the bags into DIR, for profiling)

#[path = "common/joint_state_bag.rs"]
mod joint_state_bag;
// Only the scratch folder: the rest of the tests' scaffolding is unused here.
#[allow(dead_code)]
#[path = "../tests/common/scaffold.rs"]
mod scaffold;

use joint_state_bag::write_joint_state_bag;
use oorandom::Rand64;
use std::path::Path;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::model::Params;
use thickness_collision::replay::{replay, ReplayOptions};

const STATES: usize = 360_000;
const PERIOD_NS: i64 = 10_000_000;

/// The hour: random states within the limits, or the path of scripts/example_recording.sh.
fn write_bag(dir: &Path, checker: &Checker, sweep: bool) {
    let joints: Vec<_> = checker.robot().joints.iter().filter(|j| j.is_actuated()).collect();
    let names: Vec<String> = joints.iter().map(|j| j.name.clone()).collect();
    let mut rng = Rand64::new(42);
    let states = (0..STATES).map(|k| {
        let s = k as f64 / 100.0 * 1.5;
        // The path of scripts/example_recording.sh, fingers closed.
        let path = [1.2 * (0.9 * s).sin(), 0.7 + 0.6 * (2.1 * s).sin(), 0.3 + 0.6 * (1.3 * s + 0.5).sin(), 0.8 * (1.7 * s).sin(), 0.5 * (1.1 * s).cos(), 0.0];
        let position = joints
            .iter()
            .enumerate()
            .map(|(i, j)| {
                let (lo, hi) = (j.limits[0].max(-3.0), j.limits[1].min(3.0));
                if sweep {
                    path.get(i).copied().unwrap_or(lo.max(0.0).min(hi))
                } else {
                    lo + (hi - lo) * rng.rand_float()
                }
            })
            .collect();
        (names.clone(), position)
    });
    let _ = write_joint_state_bag(dir, "hour", PERIOD_NS, states);
}

fn dir_size(d: &Path) -> u64 {
    std::fs::read_dir(d).map(|r| r.filter_map(|e| e.ok()?.metadata().ok()).map(|m| m.len()).sum()).unwrap_or(0)
}

/// CPU seconds of this process so far, every thread (the bag writer's too).
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes one rusage into the zeroed struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    let _ = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let rounds: usize = std::env::var("ROUNDS").ok().and_then(|v| v.parse().ok()).unwrap_or(3);
    let bags = std::env::var("BAGS").unwrap_or_default();
    let checker = Checker::from_params(Params::default()).unwrap();
    let root = scaffold::emptied(scaffold::scratch_dir("bench_replay_view"));
    if bags != "sweep" {
        scenario(&root, &checker, false, rounds);
    }
    if bags != "random" {
        scenario(&root, &checker, true, rounds);
    }
    let _ = std::fs::remove_dir_all(&root);
}

fn scenario(root: &Path, checker: &Checker, sweep: bool, rounds: usize) {
    let bag = root.join(if sweep { "sweep" } else { "random" });
    write_bag(&bag, checker, sweep);
    // `KEEP_BAG=DIR`: the bag is moved there and nothing is timed, to profile `replay` on it.
    if let Ok(keep) = std::env::var("KEEP_BAG") {
        let to = Path::new(&keep).join(if sweep { "sweep" } else { "random" });
        let _ = std::fs::remove_dir_all(&to);
        std::fs::create_dir_all(&keep).unwrap();
        std::fs::rename(&bag, &to).or_else(|_| std::process::Command::new("cp").arg("-r").arg(&bag).arg(&to).status().map(|_| ())).unwrap();
        println!("bag kept in {}", to.display());
        return;
    }
    let what = if sweep { "a smooth sweep, motions checked (the default parameters)" } else { "random joint states, each checked on its own" };
    println!("\none hour at 100 Hz: {STATES} states of the bundled arm, {what} ({:.1} MB MCAP)", dir_size(&bag) as f64 / 1e6);
    let configs =
        [("output bag, /collisions only (as before)", false, false), ("+ markers, /tf, /robot_description", true, false), ("+ markers and --plot", true, true)];
    // The sweep's checks take long: the middle row is left out there.
    let configs: Vec<_> = configs.into_iter().enumerate().filter(|(i, _)| !sweep || *i != 1).map(|(_, c)| c).collect();
    let last = configs.len() - 1;
    let mut seconds = vec![Vec::new(); configs.len()];
    let mut cpu = vec![Vec::new(); configs.len()];
    let mut sizes = vec![0u64; configs.len()];
    let (mut svg_bytes, mut svg_elements, mut in_collision) = (0, 0, 0);
    for round in 0..rounds {
        for (c, (label, markers, plot)) in configs.iter().enumerate() {
            let out = root.join("out");
            let svg = root.join("timeline.svg");
            let _ = std::fs::remove_dir_all(&out);
            let opts = ReplayOptions {
                bag: bag.clone(),
                out_dir: Some(out.clone()),
                plot: plot.then(|| svg.clone()),
                no_markers: !markers,
                motion: Some(sweep),
                ..Default::default()
            };
            let (started, cpu0) = (Instant::now(), cpu_seconds());
            let summary = replay(Params::default(), &opts, &mut thickness_collision::replay::Quiet).unwrap();
            let secs = started.elapsed().as_secs_f64();
            cpu[c].push(cpu_seconds() - cpu0);
            assert_eq!(summary.states, STATES);
            in_collision = summary.in_collision;
            seconds[c].push(secs);
            sizes[c] = dir_size(&out);
            if *plot {
                let text = std::fs::read_to_string(&svg).unwrap();
                let name = format!("tc_bench_replay_view_{}.svg", if sweep { "sweep" } else { "random" });
                let _ = std::fs::copy(&svg, std::env::temp_dir().join(name));
                svg_bytes = text.len();
                svg_elements =
                    text.matches("<rect").count() + text.matches("<line").count() + text.matches("<text").count() + text.matches("<polyline").count();
            }
            eprintln!("round {round}: {label}: {secs:.2} s, {:.2} s CPU", cpu[c][round]);
        }
    }
    println!("({in_collision} of {STATES} states in collision; {rounds} rounds, interleaved)");
    println!("{:<42} {:>9} {:>9} {:>10} {:>10} {:>11} {:>10}", "outputs", "median s", "states/s", "rate ratio", "CPU s", "CPU ratio", "output MB");
    let (base, base_cpu) = (median(&mut seconds[0].clone()), median(&mut cpu[0].clone()));
    for (c, (label, ..)) in configs.iter().enumerate() {
        let (m, mc) = (median(&mut seconds[c].clone()), median(&mut cpu[c].clone()));
        println!("{label:<42} {m:>9.2} {:>9.0} {:>10.3} {mc:>10.2} {:>11.3} {:>10.1}", STATES as f64 / m, base / m, mc / base_cpu, sizes[c] as f64 / 1e6);
    }
    let per_round: Vec<String> = (0..rounds).map(|r| format!("{:.3}", seconds[0][r] / seconds[last][r])).collect();
    println!("rate with markers and --plot / rate before, per round: {}", per_round.join(", "));
    println!("load average at the end: {}", std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim());
    println!("timeline SVG: {:.1} kB, {svg_elements} elements (rect, line, text)", svg_bytes as f64 / 1e3);
    let _ = std::fs::remove_dir_all(&bag);
}
