//! The side-by-side comparison with coal and python-fcl, shared by `benches/peer_compare.rs` (the
//! full run) and `tests/peer_agreement.rs` (a small version in the test suite).
#![allow(dead_code)]

/// The tests' scaffolding (scratch folders, the little-endian writer for the peers, mesh to area).
#[path = "../tests/common/scaffold.rs"]
pub mod scaffold;

use oorandom::Rand64;
use parry3d_f64::shape::ConvexPolyhedron;
use serde_json::Value;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::collision::{Scene, TargetShape};
use thickness_collision::math::{Pose, Real};
use thickness_collision::model::example_workcell::peer_environment;
use thickness_collision::model::{PackageResolver, Params, RobotModel};

pub const THICKNESS: Real = 0.02;

/// The peers' interpreter and example-robot-data.
pub fn python() -> PathBuf {
    match std::env::var_os("TC_PYTHON") {
        Some(p) => PathBuf::from(p),
        None => {
            let out = Command::new("bash").arg("scripts/setup_venv.sh").output().expect("scripts/setup_venv.sh");
            PathBuf::from(String::from_utf8_lossy(&out.stdout).lines().last().unwrap_or("python3").trim())
        }
    }
}

pub fn panda(py: &Path) -> (RobotModel, Vec<String>) {
    let out = Command::new(py).args(["-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).output().unwrap();
    let erd = PathBuf::from(String::from_utf8(out.stdout).unwrap().trim()).join("cmeel.prefix/share/example-robot-data");
    let map = vec![format!("example-robot-data={}", erd.display())];
    let urdf = erd.join("robots/panda_description/urdf/panda.urdf");
    (RobotModel::from_file(&urdf, &PackageResolver::new(&map), false).unwrap(), map)
}

/// Random joint vectors within the limits (fixed seed).
pub fn random_states(robot: &RobotModel, n: usize, seed: u64) -> Vec<(Vec<String>, Vec<f64>)> {
    let mut rng = Rand64::new(seed as u128);
    let joints: Vec<_> = robot.joints.iter().filter(|j| j.is_actuated()).collect();
    (0..n)
        .map(|_| {
            let names = joints.iter().map(|j| j.name.clone()).collect();
            let pos = joints
                .iter()
                .map(|j| {
                    let (lo, hi) = (j.limits[0].max(-3.2), j.limits[1].min(3.2));
                    lo + (hi - lo) * rng.rand_float()
                })
                .collect();
            (names, pos)
        })
        .collect()
}

/// One world: the scene and the same triangles in world coordinates for the peers.
pub struct World {
    pub scene: Scene,
    pub vertices: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub build_seconds: f64,
    pub memory_bytes: usize,
}

pub fn world(triangles: usize) -> World {
    world_from(peer_environment(triangles))
}

/// A world of thin surfaces, each with cells of `THICKNESS` behind it.
pub fn world_from(surfaces: Vec<(String, thickness_collision::mesh::generate::Soup, Pose)>) -> World {
    let mut scene = Scene::new();
    let mut vertices = Vec::new();
    let mut tris = Vec::new();
    let started = Instant::now();
    for (name, (v, t), pose) in surfaces {
        let area = scaffold::thin_area(&v, &t, THICKNESS);
        let _ = scene.add_surface(name, pose, area);
        let base = vertices.len() as u32;
        vertices.extend(v.iter().map(|p| (pose * *p).to_array()));
        tris.extend(t.iter().map(|f| f.map(|i| i + base)));
    }
    let build_seconds = started.elapsed().as_secs_f64();
    let memory_bytes = scene
        .objects()
        .iter()
        .map(|o| o.bvh_memory() + o.area().map_or(0, |a| a.cells.len() * std::mem::size_of::<thickness_collision::thickness::ThicknessCell>()))
        .sum();
    World { scene, vertices, triangles: tris, build_seconds, memory_bytes }
}

/// The result of one world.
pub struct Comparison {
    pub triangles: usize,
    pub cells: usize,
    pub build_seconds: f64,
    pub memory_bytes: usize,
    pub states: usize,
    pub ours_seconds: f64,
    pub flags_seconds: f64,
    pub batch_seconds: f64,
    pub coal_seconds: f64,
    pub fcl_seconds: f64,
    pub ours_colliding_states: usize,
    pub coal_colliding_states: usize,
    pub explained_thickness: usize,
    pub explained_touching: usize,
    pub unexplained: Vec<String>,
}

/// Runs ours and the peers on one world and compares link by link.
pub fn compare(py: &Path, robot: &RobotModel, map: &[String], states: &[(Vec<String>, Vec<f64>)], triangles: usize, dir: &Path) -> Comparison {
    let w = world(triangles);
    let (build_seconds, memory_bytes, cells) = (w.build_seconds, w.memory_bytes, w.scene.cell_count());
    // The peers check the links against the environment only: so does this side.
    let params = Params { package_map: map.to_vec(), self_collision: false, ..Params::default() };
    let checker = Checker::from_robot_and_scene(params, robot.clone(), w.scene, "panda".into()).unwrap();

    // Ours: the full check (all links, all cells, deepest contacts with depth), one core.
    let started = Instant::now();
    let mut reports = Vec::with_capacity(states.len());
    for (names, pos) in states {
        reports.push(checker.check_joints(names, pos).unwrap());
    }
    let ours_seconds = started.elapsed().as_secs_f64();
    // Like for like with the peers' boolean collide: which links collide, first cell wins.
    let started = Instant::now();
    for ((names, pos), full) in states.iter().zip(&reports) {
        let flags = checker.check_joints_flags(names, pos).unwrap();
        let (a, b): (Vec<&str>, Vec<&str>) =
            (flags.contacts.iter().map(|c| c.link_name.as_str()).collect(), full.contacts.iter().map(|c| c.link_name.as_str()).collect());
        assert_eq!(a, b, "flag-only and full checks must agree on the colliding links");
    }
    let flags_seconds = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let batch = checker.check_joints_batch(states);
    let batch_seconds = started.elapsed().as_secs_f64();
    for (a, b) in batch.iter().zip(&reports) {
        let a = a.as_ref().unwrap();
        assert!(a.in_collision == b.in_collision && a.contacts == b.contacts, "the batch API must give the same reports");
    }

    // The parts (every link's convex pieces) and their world poses per state.
    let mut parts: Vec<(usize, std::sync::Arc<thickness_collision::collision::ConvexHull>, Pose)> = Vec::new();
    for (ti, t) in checker.targets().iter().enumerate() {
        for (shape, offset) in &t.parts {
            match shape {
                TargetShape::Polytope(h) => parts.push((ti, h.clone(), *offset)),
                other => panic!("link {}: the peers get convex hulls only, not {other:?}", t.name),
            }
        }
    }
    std::fs::create_dir_all(dir).unwrap();
    scaffold::write_le(&dir.join("env_vertices.f64"), &w.vertices);
    scaffold::write_le(&dir.join("env_triangles.u32"), &w.triangles);
    for (i, (_, hull, _)) in parts.iter().enumerate() {
        let (pts, tri) = hull.vertices_and_triangles();
        scaffold::write_le(&dir.join(format!("part{i}_vertices.f64")), &pts);
        scaffold::write_le(&dir.join(format!("part{i}_triangles.u32")), &tri);
    }
    let mut poses: Vec<f64> = Vec::with_capacity(states.len() * parts.len() * 12);
    let mut link_poses = Vec::with_capacity(states.len());
    for (names, pos) in states {
        let mut q = vec![0.0; checker.robot().joints.len()];
        for (n, p) in names.iter().zip(pos) {
            q[checker.robot().joint(n).unwrap()] = *p;
        }
        let world_links: Vec<Pose> = checker
            .robot()
            .forward_kinematics(&q, &nalgebra::Isometry3::identity())
            .unwrap()
            .iter()
            .map(thickness_collision::math::pose_from_isometry)
            .collect();
        for (ti, _, offset) in &parts {
            let p = world_links[checker.targets()[*ti].link] * *offset;
            poses.extend_from_slice(&thickness_collision::math::pose_rows(&p));
        }
        link_poses.push(world_links);
    }
    scaffold::write_le(&dir.join("poses.f64"), &poses);
    let meta = serde_json::json!({"states": states.len(), "parts": parts.len()});
    std::fs::File::create(dir.join("meta.json")).unwrap().write_all(meta.to_string().as_bytes()).unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/peer_compare.py");
    let out = Command::new(py).arg(&script).arg(dir).output().unwrap();
    assert!(out.status.success(), "peer_compare.py: {}", String::from_utf8_lossy(&out.stderr));
    let peers: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("peers.json")).unwrap()).unwrap();

    // Link by link: ours against each peer.
    let mut cmp = Comparison {
        triangles: w.triangles.len(),
        cells,
        build_seconds,
        memory_bytes,
        states: states.len(),
        ours_seconds,
        flags_seconds,
        batch_seconds,
        coal_seconds: peers["coal"]["seconds"].as_f64().unwrap(),
        fcl_seconds: peers["fcl"]["seconds"].as_f64().unwrap(),
        ours_colliding_states: reports.iter().filter(|r| r.in_collision).count(),
        coal_colliding_states: 0,
        explained_thickness: 0,
        explained_touching: 0,
        unexplained: Vec::new(),
    };
    let trimesh =
        parry3d_f64::shape::TriMesh::new(w.vertices.iter().map(|p| thickness_collision::math::Vector::from_array(*p)).collect(), w.triangles.clone()).unwrap();
    for peer in ["coal", "fcl"] {
        let flags = peers[peer]["flags"].as_array().unwrap();
        for (s, report) in reports.iter().enumerate() {
            let row = flags[s].as_str().unwrap().as_bytes();
            if peer == "coal" && row.contains(&b'1') {
                cmp.coal_colliding_states += 1;
            }
            for (ti, t) in checker.targets().iter().enumerate() {
                let theirs = parts.iter().enumerate().any(|(pi, (pt, _, _))| *pt == ti && row[pi] == b'1');
                let contact = report.contacts.iter().find(|c| c.link_name == t.name);
                if contact.is_some() == theirs {
                    continue;
                }
                let link_pose = link_poses[s][t.link];
                // Distance from the link to the plain surface (parry, independent of our SAT).
                let distance = parts
                    .iter()
                    .filter(|(pt, _, _)| *pt == ti)
                    .map(|(_, hull, off)| parry3d_f64::query::distance(&(link_pose * *off), hull.as_parry(), &Pose::IDENTITY, &trimesh).unwrap().distance)
                    .fold(Real::INFINITY, |a: Real, b: Real| a.min(b));
                if distance <= 1e-6 {
                    cmp.explained_touching += 1;
                    continue;
                }
                match contact {
                    // Ours only: explained when parry's GJK confirms the link meets the reported cell.
                    Some(c) => {
                        let object = checker.scene().objects().iter().find(|o| o.name == c.object_name).unwrap();
                        let cell = object.area().unwrap().cells.iter().find(|cell| cell.triangle == c.triangle).unwrap();
                        let poly = ConvexPolyhedron::from_convex_hull(&cell.distinct_vertices()).unwrap();
                        let meets = parts.iter().filter(|(pt, _, _)| *pt == ti).any(|(_, hull, off)| {
                            parry3d_f64::query::intersection_test(&(link_pose * *off), hull.as_parry(), &object.pose, &poly).unwrap().intersecting
                        });
                        if meets && c.depth > 0.0 {
                            cmp.explained_thickness += 1;
                        } else {
                            cmp.unexplained.push(format!("{peer}: state {s}, link {}: ours {:?}, peer no, distance {distance:e}", t.name, c));
                        }
                    }
                    None => cmp.unexplained.push(format!("{peer}: state {s}, link {}: peer yes, ours no, distance {distance:e}", t.name)),
                }
            }
        }
    }
    cmp
}

/// The world's triangles and the checker's link parts (as hulls) written for
/// `benches/coal_motion.py` into `dir`; returns each part's target index and offset, in the order
/// the poses must follow.
pub fn write_coal_inputs(dir: &Path, checker: &Checker, world_vertices: &[[f64; 3]], world_triangles: &[[u32; 3]]) -> Vec<(usize, Pose)> {
    std::fs::create_dir_all(dir).unwrap();
    let mut parts = Vec::new();
    for (ti, t) in checker.targets().iter().enumerate() {
        for (shape, offset) in &t.parts {
            match shape {
                TargetShape::Polytope(h) => {
                    let (pts, tri) = h.vertices_and_triangles();
                    scaffold::write_le(&dir.join(format!("part{}_vertices.f64", parts.len())), &pts);
                    scaffold::write_le(&dir.join(format!("part{}_triangles.u32", parts.len())), &tri);
                    parts.push((ti, *offset));
                }
                other => panic!("link {}: the peers get convex hulls only, not {other:?}", t.name),
            }
        }
    }
    scaffold::write_le(&dir.join("env_vertices.f64"), world_vertices);
    scaffold::write_le(&dir.join("env_triangles.u32"), world_triangles);
    parts
}
