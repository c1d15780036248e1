//! Build benchmark: the thickness cells of a 1,000,000-triangle wavy wall, stage by stage, and the
//! whole build up to a queryable cell tree.
//!
//! `cargo bench --bench build` (about 2 minutes). The wall is `benches/query.rs`'s: 708 x 708
//! quads, 1,002,528 triangles over 7 x 7 m, amplitude 5 cm, wavelength 50 cm, t = 2 cm, `back`.
//! Stages, each timed on its own (criterion's median, reported as triangles/s):
//! - `weld`: `mesh::weld` (hash-grid vertex welding, degenerate and duplicate triangles);
//! - `topology`: `MeshTopology::from_welded` (edge adjacency, orientation, normals);
//! - `cells`: `ThicknessArea::build` given the `MeshTopology`;
//! - `tree`: `collision::CellTree::build` (boxes, normal cones, median splits; cells put in leaf
//!   order), given the cells;
//! - `whole`: all of the above from the indexed triangle soup, as `Scene::add_surface` does it.
//!
//! `benches/run_build_comparison.sh` runs this beside coal's `BVHModelOBBRSS` build of the same
//! triangles (`benches/coal_build.py`) and prints the ratio.

#[path = "wall_1m.rs"]
mod wall_1m;

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, SamplingMode, Throughput};
use std::time::{Duration, Instant};
use thickness_collision::collision::CellTree;
use thickness_collision::math::Vector;
use thickness_collision::mesh::{weld, MeshTopology, TopologySettings};
use thickness_collision::thickness::{ThicknessArea, ThicknessCell, ThicknessSettings};
use wall_1m::{checksum, wall};

fn whole(v: &[Vector], t: &[[u32; 3]], topo: &TopologySettings, cells: &ThicknessSettings) -> (ThicknessArea, CellTree) {
    let welded = weld(v, t, topo).expect("weld");
    let mesh = MeshTopology::from_welded(welded);
    let mut area = ThicknessArea::build(&mesh, cells).expect("cells");
    let tree = CellTree::build(&mut area.cells);
    (area, tree)
}

fn bench_build(c: &mut Criterion) {
    let (v, t) = wall(708, 708);
    let topo = TopologySettings::default();
    let settings = ThicknessSettings { thickness: 0.02, ..Default::default() };
    let (cv, ct) = checksum(&v, &t);
    eprintln!("wall: {} vertices, {} triangles", v.len(), t.len());
    eprintln!("checksum: vertices={cv:016x} triangles={ct:016x}");

    // One untimed pass: the inputs of the stage benchmarks, a first timing and the memory figures.
    let s = Instant::now();
    let welded = weld(&v, &t, &topo).expect("weld");
    let t_weld = s.elapsed();
    let s = Instant::now();
    let mesh = MeshTopology::from_welded(welded.clone());
    let t_topo = s.elapsed();
    let s = Instant::now();
    let area = ThicknessArea::build(&mesh, &settings).expect("cells");
    let t_cells = s.elapsed();
    let s = Instant::now();
    let mut sorted = area.cells.clone();
    let tree = CellTree::build(&mut sorted);
    let t_tree = s.elapsed();
    drop(sorted);
    eprintln!("first pass: weld {t_weld:.2?}, topology {t_topo:.2?}, cells {t_cells:.2?}, tree {t_tree:.2?}");
    let r = &area.report;
    eprintln!(
        "cells: {} (tetrahedra {}, ratioed {}, prisms {}, diverging {}, skipped {}); boundary edges {}",
        r.cells, r.tetrahedra, r.ratioed, r.prisms, r.diverging, r.degenerate_skipped, r.boundary_edges
    );
    assert_eq!(r.cells, t.len());
    let n = area.cells.len() as f64;
    let cell_bytes = std::mem::size_of::<ThicknessCell>();
    let cells_heap = area.cells.capacity() * cell_bytes;
    let bvh_bytes = tree.memory();
    eprintln!(
        "memory per cell: ThicknessCell {} B (Vec: {:.1} B/cell) + tree {:.1} B/cell ({:.1} MiB in all) = {:.1} B/cell",
        cell_bytes,
        cells_heap as f64 / n,
        bvh_bytes as f64 / n,
        bvh_bytes as f64 / (1024.0 * 1024.0),
        (cells_heap + bvh_bytes) as f64 / n
    );
    // One line for benches/run_build_comparison.sh.
    println!(
        "BUILD_MEMORY cells={} cell_bytes={} bvh_bytes={} bytes_per_cell={:.1}",
        area.cells.len(),
        cell_bytes,
        bvh_bytes,
        (cells_heap + bvh_bytes) as f64 / n
    );
    drop(tree);

    let mut g = c.benchmark_group("build_1M_wall");
    g.sample_size(10).sampling_mode(SamplingMode::Flat).warm_up_time(Duration::from_millis(500)).throughput(Throughput::Elements(t.len() as u64));
    // Measurement times: 10 iterations of each stage on this machine (2 cores, noisy), the whole
    // benchmark under 2 minutes.
    g.measurement_time(Duration::from_secs(6));
    g.bench_function("weld", |b| b.iter_batched(|| (), |()| weld(black_box(&v), black_box(&t), &topo).expect("weld"), BatchSize::PerIteration));
    g.measurement_time(Duration::from_secs(4));
    g.bench_function("topology", |b| b.iter_batched(|| welded.clone(), MeshTopology::from_welded, BatchSize::PerIteration));
    g.bench_function("cells", |b| b.iter_batched(|| (), |()| ThicknessArea::build(black_box(&mesh), &settings).expect("cells"), BatchSize::PerIteration));
    g.measurement_time(Duration::from_secs(7));
    g.bench_function("tree", |b| b.iter_batched(|| area.cells.clone(), |mut cells| CellTree::build(black_box(&mut cells)), BatchSize::PerIteration));
    g.measurement_time(Duration::from_secs(20));
    g.bench_function("whole", |b| b.iter_batched(|| (), |()| whole(black_box(&v), black_box(&t), &topo, &settings), BatchSize::PerIteration));
    g.finish();
}

criterion_group!(benches, bench_build);
criterion_main!(benches);
