//! The node's resident memory under a stream of large planning-scene objects: 100,000-triangle thin
//! meshes sent to the running node through `apply_planning_scene` by the Fast DDS peer (C++, the
//! enhanced service mapping), four ids, then the same ids again twice with other geometry, and
//! the node's `VmRSS` read from `/proc` after each reply. Its growth over the node's own start
//! stays within 2.5 times the cells' own size (cells and trees of the objects in force, measured
//! on an in-process pipeline given the same requests) plus 150 MiB: the cells of replaced objects
//! are freed, and no sample, reassembly buffer or copy of a scene is kept per request. Each reply
//! says `success` (sent once the object is in force). Default parameters (markers on) but the
//! service mapping. Loopback only; domain 174.

mod common;

#[path = "../benches/wall_1m.rs"]
mod wall_1m;

use common::fastdds::{FastDdsPeer, PeerOptions};
use common::start_node;
use thickness_collision::fuzz_access::{apply_planning_scene_cdr, collision_object_cdr};
use thickness_collision::model::Params;
use thickness_collision::pipeline::Pipeline;

#[test]
fn the_nodes_memory_stays_bounded_by_its_cells_under_large_adds() {
    let dir = common::scratch_subdir("scene_node_memory", "requests");
    let domain = 174;
    let (mut node, _out, banner) = start_node(&["--ros-args", "-p", "service_mapping:=enhanced"], domain);
    assert!(banner.contains("planning scene"), "{banner}");
    let pid = node.id();
    let mut peer = FastDdsPeer::start(&PeerOptions::loopback(domain));
    let mut mirror = Pipeline::new(Params::default()).unwrap();
    let (h, mib) = (std::f64::consts::FRAC_1_SQRT_2, 1024.0 * 1024.0);
    // The node's own start: matched, warmed up (an empty difference), nothing built yet.
    let warm = peer.send(&serde_json::json!({"cmd": "apply", "service": "apply_planning_scene", "files": [], "timeout": 30}));
    assert_eq!(warm["matched"], true, "{warm}");
    std::thread::sleep(std::time::Duration::from_millis(300));
    let base = common::resident_bytes(&pid.to_string());
    assert!(base > 0, "no VmRSS for the node (pid {pid})");
    let (mut worst, mut peak_cells, mut seconds, mut after_round) = (0.0f64, 0u64, Vec::new(), Vec::new());
    for round in 0..3 {
        for k in 0..4 {
            // Other geometry for every request (cells are cached by content: equal meshes share them).
            let (mut v, t) = wall_1m::wall(224, 224);
            for q in &mut v {
                q.z += 0.01 * round as f64 + 0.002 * k as f64;
            }
            let id = format!("scan_{k}");
            let pose = [0.6 + 0.3 * k as f64, -3.5, 3.5, 0.0, h, 0.0, h];
            let file = dir.join("request.cdr");
            std::fs::write(&file, apply_planning_scene_cdr(&id, 0, pose, Some((&v, &t)))).unwrap();
            let a = peer.send(&serde_json::json!({"cmd": "apply", "service": "apply_planning_scene", "files": [file], "timeout": 60}));
            let answer = &a["answers"][0];
            assert_eq!(answer["success"], true, "round {round}, {id}: {a}");
            seconds.push(answer["seconds"].as_f64().unwrap_or(f64::NAN));
            thickness_collision::fuzz_access::apply_collision_object_cdr(&mut mirror, &collision_object_cdr(&id, 0, pose, Some((&v, &t)))).unwrap();
            let (grown, cells) = (common::resident_bytes(&pid.to_string()).saturating_sub(base), common::cells_bytes(&mirror));
            peak_cells = peak_cells.max(cells);
            let bound = 2.5 * cells as f64 + 150.0 * mib;
            worst = worst.max(grown as f64 / bound);
            eprintln!("round {round}, {id}: node RSS +{:.0} MiB, cells {:.0} MiB, bound {:.0} MiB", grown as f64 / mib, cells as f64 / mib, bound / mib);
            assert!(grown as f64 <= bound, "the node's RSS grew by {:.0} MiB, past 2.5 x {:.0} MiB of cells + 150 MiB", grown as f64 / mib, cells as f64 / mib);
        }
        after_round.push(common::resident_bytes(&pid.to_string()));
    }
    // The bound above leaves room for a leak of a few objects; replaced cells must really go: two
    // more rounds of four 27 MiB objects add at most 64 MiB (a kept copy per request adds 216).
    let later = after_round[2].saturating_sub(after_round[0]) as f64 / mib;
    assert!(later <= 64.0, "the node's RSS grew by {later:.0} MiB over two rounds that replaced every object: replaced cells are kept");
    assert!(peak_cells as f64 > 50.0 * mib, "the objects must be large: {:.0} MiB of cells", peak_cells as f64 / mib);
    eprintln!("worst RSS growth / bound: {worst:.2}; request to reply (s): {seconds:.3?}");
    peer.quit();
    let _ = std::process::Command::new("kill").args(["-TERM", &pid.to_string()]).status();
    let status = node.wait().unwrap();
    assert!(status.success(), "node exit {status:?}");
}
