//! Side by side with the checkers planners use today: this crate's full check (all links, all
//! cells, deepest contacts with depth) against coal 3.0.3 and python-fcl 0.7 (each link's convex
//! hull against the world's OBBRSS BVH model, boolean collide, Python overhead taken off), on the
//! Panda, 10,000 random joint states (fixed seed) and worlds of 10k, 100k and 1M thin-surface
//! triangles; then the build alone at 10M triangles. Writes a table and an SVG plot to
//! `target/peer_compare/`.
//!
//! `cargo bench --bench peer_compare`   (TC_PEER_STATES, TC_PEER_SIZES to change the run)

#[path = "peer_compare_core.rs"]
mod peer_compare_core;

use peer_compare_core::*;
use std::fmt::Write as _;
use std::time::Instant;

fn main() {
    if std::env::args().any(|a| a == "--test" || a == "--list") {
        return; // `cargo test --benches` runs bench binaries with --test: nothing to do here
    }
    let n_states: usize = std::env::var("TC_PEER_STATES").ok().and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let sizes: Vec<usize> =
        std::env::var("TC_PEER_SIZES").ok().map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect()).unwrap_or(vec![10_000, 100_000, 1_000_000]);
    let py = python();
    let (robot, map) = panda(&py);
    let states = random_states(&robot, n_states, 1);
    let out = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/peer_compare");
    std::fs::create_dir_all(&out).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());

    let mut table = String::new();
    let _ = writeln!(table, "| triangles | cells | build (s) | memory (MiB) | colliding states (ours / coal) | ours µs/state | batch µs/state ({cores} cores) | ours flag-only µs/state | coal µs/state | FCL µs/state | ours/coal | ours/FCL | flag-only/coal | explained (thickness / touching) | unexplained |");
    let _ = writeln!(table, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut points = Vec::new();
    let mut unexplained_total = 0;
    for &size in &sizes {
        eprintln!("== {size} triangles");
        let c = compare(&py, &robot, &map, &states, size, &out.join(format!("world_{size}")));
        let per = |s: f64| s / c.states as f64 * 1e6;
        let (ours, coal, fcl) = (per(c.ours_seconds), per(c.coal_seconds), per(c.fcl_seconds));
        let _ = writeln!(
            table,
            "| {} | {} | {:.3} | {:.1} | {} / {} ({:.0} %) | {ours:.2} | {:.2} | {:.2} | {coal:.2} | {fcl:.2} | {:.2} | {:.2} | {:.2} | {} / {} | {} |",
            c.triangles,
            c.cells,
            c.build_seconds,
            c.memory_bytes as f64 / 1048576.0,
            c.ours_colliding_states,
            c.coal_colliding_states,
            100.0 * c.ours_colliding_states as f64 / c.states as f64,
            per(c.batch_seconds),
            per(c.flags_seconds),
            ours / coal,
            ours / fcl,
            per(c.flags_seconds) / coal,
            c.explained_thickness,
            c.explained_touching,
            c.unexplained.len()
        );
        for u in c.unexplained.iter().take(20) {
            eprintln!("UNEXPLAINED {u}");
        }
        unexplained_total += c.unexplained.len();
        points.push((c.triangles as f64, ours, coal, fcl));
    }
    // The build alone at 10M triangles.
    let started = Instant::now();
    let w = world(if std::env::var_os("TC_PEER_SKIP_10M").is_some() { 1000 } else { 10_000_000 });
    let _ = writeln!(
        table,
        "\nBuild alone at {} triangles: {:.2} s, {:.0} MiB ({} cells).",
        w.triangles.len(),
        started.elapsed().as_secs_f64(),
        w.memory_bytes as f64 / 1048576.0,
        w.scene.cell_count()
    );
    drop(w);
    println!("{n_states} random Panda states; t = {THICKNESS} m\n\n{table}");
    std::fs::write(out.join("table.md"), &table).unwrap();
    std::fs::write(out.join("time_per_state.svg"), svg(&points)).unwrap();
    println!("written: {}/table.md and time_per_state.svg", out.display());
    if unexplained_total > 0 {
        eprintln!("{unexplained_total} UNEXPLAINED disagreements");
        std::process::exit(1);
    }
}

/// Time per state against triangle count, log-log, one line per checker.
fn svg(points: &[(f64, f64, f64, f64)]) -> String {
    let (w, h, m) = (640.0, 400.0, 60.0);
    let xs: Vec<f64> = points.iter().map(|p| p.0.log10()).collect();
    let ys: Vec<f64> = points.iter().flat_map(|p| [p.1, p.2, p.3]).map(f64::log10).collect();
    let (x0, x1) = (xs.iter().cloned().fold(f64::MAX, f64::min) - 0.2, xs.iter().cloned().fold(f64::MIN, f64::max) + 0.2);
    let (y0, y1) = ((ys.iter().cloned().fold(f64::MAX, f64::min) - 0.2).floor(), (ys.iter().cloned().fold(f64::MIN, f64::max) + 0.2).ceil());
    let px = |x: f64| m + (x.log10() - x0) / (x1 - x0) * (w - 2.0 * m);
    let py = |y: f64| h - m - (y.log10() - y0) / (y1 - y0) * (h - 2.0 * m);
    let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"20\" text-anchor=\"middle\">Time per state (µs, log) against world triangles (log): Panda, 10,000 states</text>",
        w / 2.0
    );
    let _ = writeln!(
        s,
        "<line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/><line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{}\" stroke=\"black\"/>",
        h - m,
        w - m,
        h - m,
        h - m
    );
    for p in points {
        let _ = writeln!(s, "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>", px(p.0), h - m + 16.0, p.0 as u64);
    }
    let mut e = y0;
    while e <= y1 {
        let v = 10f64.powf(e);
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text><line x1=\"{m}\" y1=\"{:.1}\" x2=\"{}\" y2=\"{:.1}\" stroke=\"#ddd\"/>",
            m - 4.0,
            py(v) + 4.0,
            v,
            py(v),
            w - m,
            py(v)
        );
        e += 1.0;
    }
    for (k, (name, color)) in [("thickness_collision", "#d62728"), ("coal", "#1f77b4"), ("python-fcl", "#2ca02c")].iter().enumerate() {
        let pts: Vec<String> = points.iter().map(|p| format!("{:.1},{:.1}", px(p.0), py([p.1, p.2, p.3][k]))).collect();
        let _ = writeln!(s, "<polyline fill=\"none\" stroke=\"{color}\" stroke-width=\"2\" points=\"{}\"/>", pts.join(" "));
        let _ = writeln!(s, "<text x=\"{}\" y=\"{}\" fill=\"{color}\">{name}</text>", w - m - 120.0, m + 14.0 * k as f64);
    }
    s + "</svg>\n"
}
