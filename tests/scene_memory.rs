//! Memory under a stream of large planning-scene objects: 100,000-triangle thin meshes added as
//! `moveit_msgs/CollisionObject` bytes to the pipeline the node runs (new ids, then the same ids
//! again with other geometry, then removed), the process's resident memory read after each. It
//! stays within 2.5 times the cells' own size (cells and trees of the objects in force) plus
//! 150 MiB (the test's own meshes and messages, the workcell, the allocator's slack): cells of
//! replaced objects are freed, and no copy of an object's cells is kept per scene change.

mod common;

#[path = "../benches/wall_1m.rs"]
mod wall_1m;

use thickness_collision::fuzz_access::{apply_collision_object_cdr, collision_object_cdr};
use thickness_collision::model::Params;
use thickness_collision::pipeline::Pipeline;

#[test]
fn large_objects_keep_memory_bounded_by_their_cells() {
    let mut p = Pipeline::new(Params::default()).unwrap();
    let base = common::resident_bytes("self");
    let (h, mib) = (std::f64::consts::FRAC_1_SQRT_2, 1024.0 * 1024.0);
    let mut worst: f64 = 0.0;
    let mut peak_cells = 0;
    for round in 0..3 {
        for k in 0..4 {
            // Each round another wave (other geometry: its cells are built anew).
            let (mut v, t) = wall_1m::wall(224, 224);
            for q in &mut v {
                q.z += 0.01 * round as f64;
            }
            let id = format!("scan_{k}");
            let add = collision_object_cdr(&id, 0, [0.6 + 0.3 * k as f64, -3.5, 3.5, 0.0, h, 0.0, h], Some((&v, &t)));
            apply_collision_object_cdr(&mut p, &add).unwrap();
            let (now, cells) = (common::resident_bytes("self").saturating_sub(base), common::cells_bytes(&p));
            peak_cells = peak_cells.max(cells);
            let bound = 2.5 * cells as f64 + 150.0 * mib;
            worst = worst.max(now as f64 / bound);
            eprintln!("round {round}, object {k}: RSS +{:.0} MiB, cells {:.0} MiB, bound {:.0} MiB", now as f64 / mib, cells as f64 / mib, bound / mib);
            assert!((now as f64) <= bound, "RSS grew by {:.0} MiB, past 2.5 x {:.0} MiB of cells + 150 MiB", now as f64 / mib, cells as f64 / mib);
        }
    }
    assert_eq!(p.scene_object_count(), (4, 0));
    assert!(peak_cells as f64 > 50.0 * mib, "the objects must be large: {:.0} MiB of cells", peak_cells as f64 / mib);
    eprintln!("worst RSS / bound: {worst:.2}");
}
