//! The planning scene on the pipeline, without DDS: cells built once per geometry, frames
//! resolved as MoveIt resolves them, whole-or-nothing messages, the scene kept across a new robot
//! description, and `get_planning_scene`'s answer applied again giving the same world.

use super::{Pipeline, SkipCause};
use crate::math::{pose_from_isometry, Pose, Vector};
use crate::mesh::generate;
use crate::model::Params;
use crate::msgs::planning_scene::{CollisionObject, MeshTriangle, PlanningScene, PlanningSceneComponents, ShapeMesh, SolidPrimitive};
use crate::msgs::{Header, JointState, Point, PoseMsg, Quaternion, Time};

pub(super) const ARM: [&str; 7] =
    ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];

pub(super) fn at(x: f64, y: f64, z: f64) -> PoseMsg {
    PoseMsg { position: Point { x, y, z }, orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } }
}

fn sheet() -> ShapeMesh {
    let (v, t) = generate::flat_grid(10, 10, 0.6, 0.6);
    ShapeMesh {
        vertices: v.iter().map(|p| Point { x: p.x, y: p.y, z: p.z }).collect(),
        triangles: t.iter().map(|t| MeshTriangle { vertex_indices: *t }).collect(),
    }
}

pub(super) fn object(frame: &str, id: &str, operation: u8) -> CollisionObject {
    CollisionObject {
        header: Header { stamp: Time::default(), frame_id: frame.into() },
        id: id.into(),
        operation,
        pose: at(0.0, 0.0, 0.0),
        ..Default::default()
    }
}

fn sheet_at(x: f64, y: f64, z: f64) -> CollisionObject {
    CollisionObject { pose: at(x, y, z), meshes: vec![sheet()], ..object("world", "scan", CollisionObject::ADD) }
}

/// Random states of the bundled arm, and the pipeline's reports for them.
pub(super) fn reports(p: &Pipeline) -> Vec<(bool, Vec<(String, String)>)> {
    let names: Vec<String> = ARM.iter().map(|s| s.to_string()).collect();
    let mut rng = oorandom::Rand64::new(5);
    (0..150)
        .map(|_| {
            let q: Vec<f64> = ARM.iter().map(|_| -2.0 + 4.0 * rng.rand_float()).collect();
            let r = p.checker().check_joints(&names, &q).unwrap();
            (r.in_collision, r.contacts.into_iter().map(|c| (c.link_name, c.object_name)).collect())
        })
        .collect()
}

/// An SRDF (without its closing tag) that disables the pairs `plain`'s default reasoning allows,
/// so that a twin robot with other geometry is checked with the same pairs.
pub(super) fn explicit_srdf(plain: &crate::checker::Checker) -> String {
    use std::fmt::Write as _;
    let targets = plain.targets();
    let mut srdf = String::from("<robot name=\"tc_arm\">");
    for a in 0..targets.len() {
        for b in a + 1..targets.len() {
            if !plain.self_pairs().pairs.contains(&(a, b)) {
                let _ = write!(srdf, "<disable_collisions link1=\"{}\" link2=\"{}\" reason=\"Default\"/>", targets[a].name, targets[b].name);
            }
        }
    }
    srdf
}

/// A MOVE, and `move_group`'s full re-ADD of the same geometry at a new pose, build no cells:
/// the world is the one a fresh pipeline builds with the object added there.
#[test]
fn moving_and_re_adding_an_object_reuses_its_cells() {
    let mut p = Pipeline::new(Params::default()).unwrap();
    p.collision_object(&sheet_at(0.2, -0.3, 0.3)).unwrap();
    assert_eq!(p.bodies.built, 1);
    let mv = CollisionObject { pose: at(0.1, -0.2, 0.4), ..object("world", "scan", CollisionObject::MOVE) };
    p.collision_object(&mv).unwrap();
    p.collision_object(&sheet_at(0.0, -0.25, 0.35)).unwrap();
    assert_eq!(p.bodies.built, 1, "neither the move nor the re-ADD built cells");
    let mut fresh = Pipeline::new(Params::default()).unwrap();
    fresh.collision_object(&sheet_at(0.0, -0.25, 0.35)).unwrap();
    let (a, b) = (reports(&p), reports(&fresh));
    assert_eq!(a, b);
    assert!(a.iter().filter(|(_, c)| c.iter().any(|(_, o)| o == "scan")).count() > 5, "the states must reach the sheet");
    // A different thickness is another body.
    p.set_params(Params { default_thickness: 0.05, ..Params::default() }).unwrap();
    assert_eq!(p.bodies.built, 2, "new parameters rebuild the object's cells");
    assert_eq!(p.scene_object_count(), (1, 0), "and keep the object");
}

/// Frames: an environment link, an object and its subframe, a fixed frame, a robot link at the
/// merged state (refused while that state is unknown); anything else refused, counted.
#[test]
fn frames_resolve_as_moveit_resolves_them() {
    let mut p = Pipeline::new(Params::default()).unwrap();
    let ball = |frame: &str, id: &str| CollisionObject {
        pose: at(0.0, 0.0, 0.1),
        primitives: vec![SolidPrimitive { kind: SolidPrimitive::SPHERE, dimensions: vec![0.05], ..Default::default() }],
        ..object(frame, id, CollisionObject::ADD)
    };
    let skip = p.collision_object(&ball("tool0", "held")).unwrap_err();
    assert_eq!(skip.cause, SkipCause::SceneFrame);
    assert!(skip.message.contains("is a robot link, but joint"), "{}", skip.message);
    let q = [0.3, -1.0, 1.2, 0.1, 0.5, 0.2, 0.01];
    let _ = p.joint_state(&JointState { name: ARM.iter().map(|s| s.to_string()).collect(), position: q.to_vec(), ..Default::default() }).unwrap();
    p.collision_object(&ball("tool0", "held")).unwrap();
    let robot = p.checker().robot();
    let mut all = vec![0.0; robot.joints.len()];
    for (name, v) in ARM.iter().zip(q) {
        all[robot.joint(name).unwrap()] = v;
    }
    let links = robot.forward_kinematics(&all, p.checker().base_pose()).unwrap();
    let tool = pose_from_isometry(&links[robot.link("tool0").unwrap()]);
    let want = tool * Pose::from_translation(Vector::new(0.0, 0.0, 0.1));
    let got = p.scene.world.get("held").unwrap().pose;
    assert!((got.translation - want.translation).length() < 1e-12, "{got:?} vs {want:?}");
    // An object with a subframe, and one placed at that subframe.
    let mut with_sub = ball("world", "plate");
    with_sub.pose = at(0.5, 0.0, 0.0);
    with_sub.subframe_names = vec!["corner".into()];
    with_sub.subframe_poses = vec![at(0.0, 0.1, 0.0)];
    p.collision_object(&with_sub).unwrap();
    p.collision_object(&ball("plate/corner", "on_corner")).unwrap();
    assert!((p.scene.world.get("on_corner").unwrap().pose.translation - Vector::new(0.5, 0.1, 0.1)).length() < 1e-12);
    p.collision_object(&ball("shelf", "on_shelf")).unwrap();
    // A fixed frame from a scene difference.
    let mut diff = PlanningScene { is_diff: true, ..Default::default() };
    diff.fixed_frame_transforms.push(crate::msgs::TransformStamped {
        header: Header { stamp: Time::default(), frame_id: "world".into() },
        child_frame_id: "camera".into(),
        transform: crate::msgs::Transform {
            translation: crate::msgs::Vector3 { x: 1.0, y: 2.0, z: 3.0 },
            rotation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
        },
    });
    diff.world.collision_objects.push(ball("camera", "seen"));
    p.planning_scene(&diff).unwrap();
    assert!((p.scene.world.get("seen").unwrap().pose.translation - Vector::new(1.0, 2.0, 3.1)).length() < 1e-12);
    let before = p.scene_object_count();
    let skip = p.collision_object(&ball("nowhere", "x")).unwrap_err();
    assert_eq!((skip.cause, p.scene_object_count()), (SkipCause::SceneFrame, before));
    assert_eq!(p.skipped().get(&SkipCause::SceneFrame), Some(&2));
}

/// A message is applied whole or not at all; `is_diff = false` replaces the scene; a new robot
/// description keeps it; `get_planning_scene`'s answer, applied to a fresh pipeline, gives the
/// same world.
#[test]
fn scenes_apply_whole_and_travel_back() {
    let mut p = Pipeline::new(Params::default()).unwrap();
    p.collision_object(&sheet_at(0.2, -0.3, 0.3)).unwrap();
    let crate_box = CollisionObject {
        primitives: vec![SolidPrimitive { kind: SolidPrimitive::BOX, dimensions: vec![0.3, 0.2, 0.1], ..Default::default() }],
        primitive_poses: vec![at(0.3, 0.1, 0.2)],
        ..object("world", "crate", CollisionObject::ADD)
    };
    // The second object is bad: neither is applied.
    let mut bad = crate_box.clone();
    bad.id = "base_link".into();
    let half = PlanningScene {
        is_diff: true,
        world: crate::msgs::planning_scene::PlanningSceneWorld { collision_objects: vec![crate_box.clone(), bad], ..Default::default() },
        ..Default::default()
    };
    assert_eq!(p.planning_scene(&half).unwrap_err().cause, SkipCause::SceneId);
    assert_eq!(p.scene_object_count(), (1, 0));
    p.collision_object(&crate_box).unwrap();
    let all = PlanningSceneComponents::WORLD_OBJECT_GEOMETRY | PlanningSceneComponents::TRANSFORMS | PlanningSceneComponents::LINK_PADDING_AND_SCALING;
    let msg = p.planning_scene_message(all, Time::default());
    assert_eq!(msg.world.collision_objects.len(), 2);
    assert_eq!(msg.link_padding.len(), p.checker().robot().links.len(), "padding and scale of every link, as in force");
    let mut fresh = Pipeline::new(Params::default()).unwrap();
    fresh.collision_object(&sheet_at(9.0, 9.0, 9.0)).unwrap();
    fresh.planning_scene(&msg).unwrap();
    assert_eq!(fresh.scene_object_count(), (2, 0), "is_diff false replaced the fresh pipeline's scene");
    assert_eq!(reports(&fresh), reports(&p));
    // A new robot (the same URDF, as a description) keeps the world objects.
    let urdf = std::fs::read_to_string(Params::default().robot_path()).unwrap().replace(
        "filename=\"gripper.obj\"",
        &format!("filename=\"file://{}\"", crate::model::bundled_config_dir().join("example_workcell/gripper.obj").display()),
    );
    let before = reports(&p);
    p.set_robot_description(&urdf, "test").unwrap();
    assert_eq!(p.scene_object_count(), (2, 0));
    assert_eq!(reports(&p), before);
    // The names-only answer has ids and poses, no shapes.
    let names = p.planning_scene_message(PlanningSceneComponents::WORLD_OBJECT_NAMES, Time::default());
    assert!(names.world.collision_objects.iter().all(|o| o.primitives.is_empty() && o.meshes.is_empty()));
}

/// An object attached to `tool0` with touch links is checked exactly as a fixed child link of
/// `tool0` with the same geometry, in a robot whose SRDF disables each touch link's pair with it:
/// the same contacts (the object named by its id, its type `attached_object`) for random states;
/// detached, it stays in the world where it was.
#[test]
fn an_attached_object_is_checked_as_a_fixed_child_link() {
    use crate::checker::{Checker, ObjectType};
    use crate::model::{PackageResolver, RobotModel};
    use crate::msgs::planning_scene::AttachedCollisionObject;
    let dir = std::env::temp_dir().join(format!("tc_attached_twin_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let srdf = explicit_srdf(&Checker::from_params(Params::default()).unwrap());
    let touch = ["gripper_link", "finger_left_link", "finger_right_link"];
    let twin_srdf = touch.iter().fold(srdf.clone(), |s, l| s + &format!("<disable_collisions link1=\"tray\" link2=\"{l}\" reason=\"Touch\"/>")) + "</robot>";
    let srdf = srdf + "</robot>";
    std::fs::write(dir.join("arm.srdf"), &srdf).unwrap();
    let params = Params { robot_semantic_file: dir.join("arm.srdf").display().to_string(), ..Params::default() };
    let mut p = Pipeline::new(params.clone()).unwrap();
    let q0 = [0.0, -0.5, 0.8, 0.0, 0.3, 0.0, 0.01];
    let _ = p.joint_state(&JointState { name: ARM.iter().map(|s| s.to_string()).collect(), position: q0.to_vec(), ..Default::default() }).unwrap();
    let tray = CollisionObject {
        pose: at(0.0, 0.0, 0.12),
        primitives: vec![
            SolidPrimitive { kind: SolidPrimitive::BOX, dimensions: vec![0.3, 0.2, 0.04], ..Default::default() },
            SolidPrimitive { kind: SolidPrimitive::SPHERE, dimensions: vec![0.06], ..Default::default() },
        ],
        primitive_poses: vec![at(0.0, 0.0, 0.0), at(0.1, 0.0, 0.05)],
        ..object("tool0", "tray", CollisionObject::ADD)
    };
    let attach =
        AttachedCollisionObject { link_name: "tool0".into(), object: tray, touch_links: touch.iter().map(|s| s.to_string()).collect(), ..Default::default() };
    p.attached_collision_object(&attach).unwrap();
    assert_eq!(p.scene_object_count(), (0, 1));
    // The twin: the robot URDF with a fixed child link "tray" of tool0.
    let robot_path = params.robot_path();
    let link = "<link name=\"tray\"><collision><origin xyz=\"0 0 0.12\"/><geometry><box size=\"0.3 0.2 0.04\"/></geometry></collision><collision><origin xyz=\"0.1 0 0.17\"/><geometry><sphere radius=\"0.06\"/></geometry></collision></link><joint name=\"tray_joint\" type=\"fixed\"><parent link=\"tool0\"/><child link=\"tray\"/></joint></robot>";
    let text = std::fs::read_to_string(&robot_path).unwrap().replacen("</robot>", link, 1);
    let resolver = PackageResolver::default();
    let robot = RobotModel::from_str(&text, "twin.urdf", robot_path.parent().unwrap(), &resolver, false).unwrap();
    let env = RobotModel::from_file(&params.environment_path(), &resolver, false).unwrap();
    let twin = Checker::from_models(params, robot, env, "twin".into(), "env".into(), Some(&twin_srdf)).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let names: Vec<String> = ARM.iter().map(|s| s.to_string()).collect();
    let mut rng = oorandom::Rand64::new(11);
    let (mut with_tray, mut tray_self) = (0, 0);
    for _ in 0..400 {
        let q: Vec<f64> = ARM.iter().map(|_| -2.5 + 5.0 * rng.rand_float()).collect();
        let (a, b) = (p.checker().check_joints(&names, &q).unwrap(), twin.check_joints(&names, &q).unwrap());
        // The same bodies, depths to 1e-9 (the object's pose went through its link's inverse
        // and back); triangle, point and normal the same unless another cell is as deep (a face
        // of the box flat against the sheet: rounding picks one of the tied cells).
        let names = |r: &crate::checker::StateReport| r.contacts.iter().map(|c| (c.link_name.clone(), c.object_name.clone())).collect::<Vec<_>>();
        assert_eq!(names(&a), names(&b), "at {q:?}");
        for (x, y) in a.contacts.iter().zip(&b.contacts) {
            let close = |u: &[f64], v: &[f64]| u.iter().zip(v).all(|(p, q)| (p - q).abs() < 1e-9);
            let (px, py) = (x.position.unwrap_or_default(), y.position.unwrap_or_default());
            assert!(close(&[x.depth], &[y.depth]), "at {q:?}: {x:?} vs {y:?}");
            assert!(x.triangle != y.triangle || (close(&px, &py) && close(&x.normal, &y.normal)), "at {q:?}: {x:?} vs {y:?}");
        }
        for c in &a.contacts {
            let tray_type = |name: &str, kind: ObjectType| name != "tray" || kind == ObjectType::AttachedObject;
            assert!(tray_type(&c.link_name, c.link_type) && tray_type(&c.object_name, c.object_type), "{c:?}");
        }
        with_tray += a.contacts.iter().any(|c| c.link_name == "tray") as usize;
        tray_self += a.contacts.iter().any(|c| c.object_name == "tray") as usize;
    }
    assert!(with_tray > 10 && tray_self > 3, "{with_tray} states with the tray against the world, {tray_self} against the arm: the cases must mix");
    // Detached: in the world where it is, no longer moving with the arm.
    let detach = AttachedCollisionObject { link_name: "tool0".into(), object: object("", "tray", CollisionObject::REMOVE), ..Default::default() };
    p.attached_collision_object(&detach).unwrap();
    assert_eq!(p.scene_object_count(), (1, 0));
    let robot = p.checker().robot();
    let mut all = vec![0.0; robot.joints.len()];
    for (name, v) in ARM.iter().zip(q0) {
        all[robot.joint(name).unwrap()] = v;
    }
    let tool = pose_from_isometry(&robot.forward_kinematics(&all, p.checker().base_pose()).unwrap()[robot.link("tool0").unwrap()]);
    let world_tray = p.scene.world.get("tray").unwrap();
    let box_pose = world_tray.pose * world_tray.shapes[0].1;
    assert!((box_pose.translation - (tool * Pose::from_translation(Vector::new(0.0, 0.0, 0.12))).translation).length() < 1e-12);
}

/// A plane is checked as the two-triangle square of the same plane and thickness (here 10 m a
/// side, its diagonal along the plane's own), its contacts with triangle `u32::MAX`.
#[test]
fn a_plane_is_a_thin_surface_without_an_edge() {
    use crate::checker::StateReport;
    use crate::msgs::planning_scene::Plane;
    let coef = [-1.0, 0.0, 0.0, 0.45];
    let mut p = Pipeline::new(Params::default()).unwrap();
    p.collision_object(&CollisionObject { planes: vec![Plane { coef }], ..object("world", "wall", CollisionObject::ADD) }).unwrap();
    let big = crate::checker::plane_mesh(&coef).unwrap();
    let small = |v: crate::math::Vector| Vector::new(0.45, 0.0, 0.0) + (v - Vector::new(0.45, 0.0, 0.0)) * (5.0 / crate::checker::PLANE_HALF_SIDE);
    let sheet = ShapeMesh {
        vertices: big.vertices.iter().map(|v| small(*v)).map(|v| Point { x: v.x, y: v.y, z: v.z }).collect(),
        triangles: big.triangles.iter().map(|t| MeshTriangle { vertex_indices: *t }).collect(),
    };
    let mut twin = Pipeline::new(Params::default()).unwrap();
    twin.collision_object(&CollisionObject { meshes: vec![sheet], ..object("world", "wall", CollisionObject::ADD) }).unwrap();
    let names: Vec<String> = ARM.iter().map(|s| s.to_string()).collect();
    let mut rng = oorandom::Rand64::new(9);
    let mut on_wall = 0;
    for _ in 0..300 {
        let q: Vec<f64> = ARM.iter().map(|_| -2.5 + 5.0 * rng.rand_float()).collect();
        let (a, b) = (p.checker().check_joints(&names, &q).unwrap(), twin.checker().check_joints(&names, &q).unwrap());
        // Bodies, depths and normals; not the points: where a link passes through the whole slab,
        // any point of the overlap is a contact point, and the cells decide which one is given.
        let without_triangles = |r: &StateReport| {
            r.contacts
                .iter()
                .map(|c| (c.link_name.clone(), c.object_name.clone(), c.normal.map(|v| (v * 1e9).round()), (c.depth * 1e9).round()))
                .collect::<Vec<_>>()
        };
        assert_eq!(without_triangles(&a), without_triangles(&b), "at {q:?}");
        for c in a.contacts.iter().filter(|c| c.object_name == "wall") {
            assert_eq!(c.triangle, u32::MAX);
            on_wall += 1;
        }
    }
    assert!(on_wall > 10, "{on_wall} contacts with the plane");
    let msg = p.planning_scene_message(PlanningSceneComponents::WORLD_OBJECT_GEOMETRY, Time::default());
    assert_eq!(msg.world.collision_objects[0].planes, [Plane { coef }], "get_planning_scene gives the plane back");
}

/// The allowed collision matrix: `get_planning_scene` gives the one in force (the default
/// reasoning's pairs without an SRDF); written back it changes nothing; an entry that allows a
/// link and an object silences that pair only; a full scene without a matrix brings the robot's
/// own pairs back; a new SRDF replaces it.
#[test]
fn the_allowed_collision_matrix_travels_and_applies() {
    let mut p = Pipeline::new(Params::default()).unwrap();
    p.collision_object(&sheet_at(0.2, -0.3, 0.3)).unwrap();
    let before = reports(&p);
    let acm = p.planning_scene_message(PlanningSceneComponents::ALLOWED_COLLISION_MATRIX, Time::default()).allowed_collision_matrix;
    let pairs = p.checker().self_pairs().pairs.clone();
    let diff = |acm| PlanningScene { is_diff: true, allowed_collision_matrix: acm, ..Default::default() };
    p.planning_scene(&diff(acm.clone())).unwrap();
    assert_eq!(p.checker().self_pairs().pairs, pairs, "the matrix written back checks the same pairs");
    assert_eq!(reports(&p), before);
    // Allow the sheet against the forearm.
    let mut edited = acm.clone();
    let (f, s) = (edited.entry_names.iter().position(|n| n == "forearm_link").unwrap(), edited.entry_names.iter().position(|n| n == "scan").unwrap());
    edited.entry_values[f].enabled[s] = true;
    edited.entry_values[s].enabled[f] = true;
    p.planning_scene(&diff(edited.clone())).unwrap();
    let after = reports(&p);
    assert!(after.iter().all(|(_, c)| !c.iter().any(|(l, o)| l == "forearm_link" && o == "scan")));
    let changed = before.iter().zip(&after).filter(|(a, b)| a != b).count();
    assert!(
        changed > 0 && before.iter().zip(&after).all(|(a, b)| a == b || a.1.iter().any(|(l, o)| l == "forearm_link" && o == "scan")),
        "only the allowed pair changes"
    );
    // A matrix alone (no object in the scene) stays in force across new parameters.
    let mut alone = PlanningScene { is_diff: false, ..diff(acm.clone()) };
    alone.allowed_collision_matrix = {
        let mut m = acm.clone();
        let (a, b) = pairs[0];
        let (na, nb) = (&p.checker().targets()[a].name, &p.checker().targets()[b].name);
        let (ia, ib) = (m.entry_names.iter().position(|n| n == na).unwrap(), m.entry_names.iter().position(|n| n == nb).unwrap());
        m.entry_values[ia].enabled[ib] = true;
        m.entry_values[ib].enabled[ia] = true;
        m
    };
    p.planning_scene(&alone).unwrap();
    assert!(!p.checker().self_pairs().pairs.contains(&pairs[0]));
    p.set_params(Params::default()).unwrap();
    assert!(!p.checker().self_pairs().pairs.contains(&pairs[0]), "the scene's matrix survives a parameter change");
    p.planning_scene(&PlanningScene::default()).unwrap();
    p.collision_object(&sheet_at(0.2, -0.3, 0.3)).unwrap();
    p.planning_scene(&diff(edited)).unwrap();
    assert_eq!(reports(&p), after);
    // A bad matrix is refused whole.
    let mut bad = acm.clone();
    let _ = bad.entry_values.pop();
    assert_eq!(p.planning_scene(&diff(bad)).unwrap_err().cause, SkipCause::SceneGeometry);
    assert_eq!(reports(&p), after);
    // A matrix that allows two links: their pair goes; a full scene without a matrix brings the
    // default reasoning's pairs back.
    let mut links = acm.clone();
    let (a, b) = pairs[0];
    let (na, nb) = (p.checker().targets()[a].name.clone(), p.checker().targets()[b].name.clone());
    let (ia, ib) = (links.entry_names.iter().position(|n| *n == na).unwrap(), links.entry_names.iter().position(|n| *n == nb).unwrap());
    links.entry_values[ia].enabled[ib] = true;
    links.entry_values[ib].enabled[ia] = true;
    p.planning_scene(&diff(links.clone())).unwrap();
    assert!(!p.checker().self_pairs().pairs.contains(&(a, b)));
    p.planning_scene(&PlanningScene::default()).unwrap();
    assert_eq!(p.checker().self_pairs().pairs, pairs, "a full scene without a matrix: the SRDF's (default) pairs again");
    // A new SRDF replaces a scene's matrix.
    p.planning_scene(&diff(links)).unwrap();
    let srdf = "<robot name=\"tc_arm\"></robot>";
    p.set_robot_semantic(srdf, "test").unwrap();
    assert!(p.checker().self_pairs().pairs.contains(&(a, b)), "an SRDF that disables nothing checks the pair again");
}

/// `triangle` counts over an object's meshes in message order: a contact with the second mesh
/// gives its triangle after the first mesh's.
#[test]
fn triangles_count_over_the_objects_meshes() {
    let mut p = Pipeline::new(Params::default()).unwrap();
    let first = sheet();
    let skip = first.triangles.len() as u32;
    let msg = CollisionObject {
        meshes: vec![first, sheet()],
        mesh_poses: vec![at(0.0, 0.0, 9.0), at(0.2, -0.3, 0.3)],
        ..object("world", "scan", CollisionObject::ADD)
    };
    p.collision_object(&msg).unwrap();
    let names: Vec<String> = ARM.iter().map(|s| s.to_string()).collect();
    let mut rng = oorandom::Rand64::new(5);
    let mut seen = 0;
    for _ in 0..150 {
        let q: Vec<f64> = ARM.iter().map(|_| -2.0 + 4.0 * rng.rand_float()).collect();
        for c in p.checker().check_joints(&names, &q).unwrap().contacts.iter().filter(|c| c.object_name == "scan") {
            assert!(c.triangle >= skip && c.triangle < 2 * skip, "{c:?}");
            seen += 1;
        }
    }
    assert!(seen > 5, "{seen} contacts with the second mesh");
}
