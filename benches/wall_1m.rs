//! The 1M-triangle wavy wall of the build and query benchmarks, and the checksum that shows a
//! peer builds from the very same triangles. Shared by `benches/build.rs`, `benches/query.rs` and
//! `examples/dump_wall.rs` (through `#[path]`).
#![allow(dead_code)]

use thickness_collision::math::{Real, Vector};
use thickness_collision::mesh::generate;

/// Wave amplitude and wavelength (metres).
pub const AMPLITUDE: Real = 0.05;
pub const WAVELENGTH: Real = 0.5;

/// `nx` x `ny` quads over 7 x 7 m (708 x 708: 1,002,528 triangles of about 1 cm).
pub fn wall(nx: usize, ny: usize) -> generate::Soup {
    generate::wavy_sheet(nx, ny, 7.0, 7.0, AMPLITUDE, WAVELENGTH)
}

/// Over the flattened arrays, `sum_k bits(coord_k) * (2k + 1)` and `sum_k index_k * (2k + 1)`,
/// both wrapping mod 2^64 (`benches/coal_build.py` recomputes it).
pub fn checksum(v: &[Vector], t: &[[u32; 3]]) -> (u64, u64) {
    let cv = v.iter().flat_map(|p| [p.x, p.y, p.z]).enumerate().fold(0u64, |s, (k, x)| s.wrapping_add(x.to_bits().wrapping_mul(2 * k as u64 + 1)));
    let ct = t.iter().flatten().enumerate().fold(0u64, |s, (k, &i)| s.wrapping_add((i as u64).wrapping_mul(2 * k as u64 + 1)));
    (cv, ct)
}

/// The planning-scene benchmarks' wall and repeat count from `[NX NY REPEAT]` on the command line
/// (default 224 x 224 quads, 7 repeats), its size and checksum printed for
/// `benches/run_scene_comparison.sh` to compare with coal's.
pub fn scene_bench_wall() -> (generate::Soup, usize) {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let nx = args.first().copied().unwrap_or(224);
    let ny = args.get(1).copied().unwrap_or(nx);
    let repeat = args.get(2).copied().unwrap_or(7);
    let (v, t) = wall(nx, ny);
    let (cv, ct) = checksum(&v, &t);
    eprintln!("wall: {} vertices, {} triangles", v.len(), t.len());
    eprintln!("checksum: vertices={cv:016x} triangles={ct:016x}");
    ((v, t), repeat)
}

/// The median of `v` (not empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
