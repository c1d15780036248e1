//! Planning-scene benchmark: a 100,000-triangle thin mesh added to the bundled workcell as a
//! `moveit_msgs/CollisionObject` (decode, cells, tree, the checker swapped in), then moved (`MOVE`)
//! and added again with the same geometry at a new pose (`ADD`, as `move_group` re-sends an
//! object after a move), each timed from the message's bytes to the change in force inside the
//! pipeline the node runs.
//!
//! `cargo bench --bench scene_update [-- NX NY REPEAT]` (default 224 x 224 quads: 100,352
//! triangles of the build benchmark's wavy wall, 7 repeats, medians). `benches/run_scene_comparison.sh`
//! runs it beside coal's BVH build of the same triangles (`benches/coal_build.py`) and prints the
//! ratio. The last line is machine-readable: `SCENE_UPDATE {json}`.

#[path = "wall_1m.rs"]
mod wall_1m;

use std::time::Instant;
use thickness_collision::fuzz_access::{apply_collision_object_cdr, collision_object_cdr};
use thickness_collision::model::Params;
use thickness_collision::pipeline::Pipeline;
use wall_1m::{median, scene_bench_wall};

fn main() {
    let ((v, t), repeat) = scene_bench_wall();
    // The wall upright in front of the arm, 0.6 m away (a quarter turn about y).
    let (h, id) = (std::f64::consts::FRAC_1_SQRT_2, "scan");
    let at = |x: f64| [x, -3.5, 3.5, 0.0, h, 0.0, h];
    let add = collision_object_cdr(id, 0, at(0.6), Some((&v, &t)));
    let moved = collision_object_cdr(id, 3, at(0.7), None);
    let readd = collision_object_cdr(id, 0, at(0.65), Some((&v, &t)));
    let remove = collision_object_cdr(id, 1, at(0.0), None);
    eprintln!("message: {:.1} MB", add.len() as f64 / 1e6);
    let mut pipeline = Pipeline::new(Params::default()).expect("the bundled workcell");
    let (mut t_add, mut t_move, mut t_readd) = (Vec::new(), Vec::new(), Vec::new());
    let time = |p: &mut Pipeline, bytes: &[u8], out: &mut Vec<f64>| {
        let s = Instant::now();
        apply_collision_object_cdr(p, bytes).expect("applied");
        out.push(s.elapsed().as_secs_f64());
    };
    for _ in 0..repeat {
        // Removed first: the cells are forgotten, so the ADD builds them.
        apply_collision_object_cdr(&mut pipeline, &remove).ok();
        time(&mut pipeline, &add, &mut t_add);
        time(&mut pipeline, &moved, &mut t_move);
        time(&mut pipeline, &readd, &mut t_readd);
    }
    let (add_s, move_s, readd_s) = (median(t_add.clone()), median(t_move), median(t_readd));
    eprintln!(
        "ADD (decode, cells, tree, swap): median {:.1} ms (runs: {:?} ms)",
        add_s * 1e3,
        t_add.iter().map(|s| (s * 1e4).round() / 10.0).collect::<Vec<_>>()
    );
    eprintln!("MOVE: median {:.2} ms; re-ADD of the same geometry at a new pose: median {:.2} ms", move_s * 1e3, readd_s * 1e3);
    println!(
        "SCENE_UPDATE {{\"triangles\": {}, \"add_s\": {add_s:.6}, \"move_s\": {move_s:.6}, \"readd_s\": {readd_s:.6}, \"repeat\": {repeat}, \"bytes\": {}}}",
        t.len(),
        add.len()
    );
}
