//! The planning scene's messages: CDR round trips of populated messages, the bounds refused
//! while decoding, and the `ros2msg` definitions against the serde structs' field order.

use super::definitions::{full_definition, ATTACHED_COLLISION_OBJECT_TYPE, COLLISION_OBJECT_TYPE, PLANNING_SCENE_TYPE, PLANNING_SCENE_WORLD_TYPE};
use super::planning_scene::*;
use super::{
    ColorRgba, DurationMsg, Header, JointState, JointTrajectory, JointTrajectoryPoint, PoseMsg, Quaternion, Time, Transform, TransformStamped, Vector3,
};
use crate::replay::{decode_cdr, encode_cdr_le};
use serde::de::DeserializeOwned;
use serde::Serialize;

fn pose(x: f64, y: f64, z: f64) -> PoseMsg {
    PoseMsg { position: Vector3 { x, y, z }, orientation: Quaternion { x: 0.0, y: 0.0, z: 0.38268343236508984, w: 0.9238795325112867 } }
}

fn header(frame: &str, sec: i32) -> Header {
    Header { stamp: Time { sec, nanosec: 250_000_000 }, frame_id: frame.into() }
}

/// An object with every field given: two primitives (a box and a prism), a two-triangle mesh, a
/// plane, two subframes.
fn collision_object(id: &str, operation: u8) -> CollisionObject {
    let square = [(-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1)];
    CollisionObject {
        header: header("world", 7),
        pose: pose(0.5, -0.25, 0.125),
        id: id.into(),
        kind: ObjectType { key: "fixture".into(), db: "{'type':'none'}".into() },
        primitives: vec![
            SolidPrimitive { kind: SolidPrimitive::BOX, dimensions: vec![0.2, 0.3, 0.4], polygon: Polygon::default() },
            SolidPrimitive {
                kind: SolidPrimitive::PRISM,
                dimensions: vec![0.05],
                polygon: Polygon { points: square.iter().map(|&(x, y)| Point32 { x, y, z: 0.0 }).collect() },
            },
        ],
        primitive_poses: vec![pose(0.0, 0.0, 0.2), pose(0.1, 0.0, 0.0)],
        meshes: vec![ShapeMesh {
            triangles: vec![MeshTriangle { vertex_indices: [0, 1, 2] }, MeshTriangle { vertex_indices: [0, 2, 3] }],
            vertices: vec![
                Vector3 { x: 0.0, y: 0.0, z: 0.0 },
                Vector3 { x: 1.0, y: 0.0, z: 0.0 },
                Vector3 { x: 1.0, y: 1.0, z: 0.0 },
                Vector3 { x: 0.0, y: 1.0, z: 0.0 },
            ],
        }],
        mesh_poses: vec![pose(0.0, 0.0, 1.0)],
        planes: vec![Plane { coef: [0.0, 0.0, 1.0, -0.5] }],
        plane_poses: vec![PoseMsg::default()],
        subframe_names: vec!["tip".into(), "base".into()],
        subframe_poses: vec![pose(0.0, 0.0, 0.3), PoseMsg::default()],
        operation,
    }
}

fn planning_scene() -> PlanningScene {
    let tray = AttachedCollisionObject {
        link_name: "tool0".into(),
        object: collision_object("tray", CollisionObject::ADD),
        touch_links: vec!["tool0".into(), "wrist_3_link".into()],
        detach_posture: JointTrajectory {
            header: header("", 1),
            joint_names: vec!["finger".into()],
            points: vec![JointTrajectoryPoint {
                positions: vec![0.04],
                velocities: vec![0.0],
                accelerations: vec![],
                effort: vec![1.5],
                time_from_start: DurationMsg { sec: 1, nanosec: 5 },
            }],
        },
        weight: 0.75,
    };
    let identity = Transform { translation: Vector3 { x: 1.0, y: 2.0, z: 3.0 }, rotation: Quaternion::default() };
    PlanningScene {
        name: "cell".into(),
        robot_state: RobotStateMsg {
            joint_state: JointState {
                header: header("", 3),
                name: vec!["shoulder".into(), "elbow".into()],
                position: vec![0.5, -1.25],
                velocity: vec![],
                effort: vec![],
            },
            multi_dof_joint_state: MultiDofJointState {
                header: header("world", 3),
                joint_names: vec!["base".into()],
                transforms: vec![identity],
                twist: vec![Twist { linear: Vector3 { x: 0.1, y: 0.0, z: 0.0 }, angular: Vector3::default() }],
                wrench: vec![Wrench { force: Vector3 { x: 0.0, y: 0.0, z: -9.81 }, torque: Vector3::default() }],
            },
            attached_collision_objects: vec![tray],
            is_diff: true,
        },
        robot_model_name: "ur5e".into(),
        fixed_frame_transforms: vec![TransformStamped { header: header("world", 0), child_frame_id: "table".into(), transform: identity }],
        allowed_collision_matrix: AllowedCollisionMatrix {
            entry_names: vec!["tool0".into(), "sheet".into()],
            entry_values: vec![AllowedCollisionEntry { enabled: vec![false, true] }, AllowedCollisionEntry { enabled: vec![true, false] }],
            default_entry_names: vec!["wall".into()],
            default_entry_values: vec![true],
        },
        link_padding: vec![LinkPadding { link_name: "tool0".into(), padding: 0.01 }],
        link_scale: vec![LinkScale { link_name: "wrist_3_link".into(), scale: 1.1 }],
        object_colors: vec![ObjectColor { id: "sheet".into(), color: ColorRgba { r: 0.5, g: 0.25, b: 1.0, a: 0.8 } }],
        world: PlanningSceneWorld {
            collision_objects: vec![collision_object("sheet", CollisionObject::ADD), collision_object("wall", CollisionObject::MOVE)],
            octomap: OctomapWithPose {
                header: header("world", 9),
                origin: pose(0.0, 0.0, 0.5),
                octomap: Octomap {
                    header: header("world", 9),
                    binary: true,
                    id: "OcTree".into(),
                    resolution: 0.05,
                    // Bytes past 127: `int8[]` on the wire, the same bytes back.
                    data: vec![0, 1, 127, 128, 200, 255],
                },
            },
        },
        is_diff: false,
    }
}

/// Encodes, decodes and compares; the decoded message encodes to the same bytes.
fn round_trip<T: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug>(msg: &T) -> Vec<u8> {
    let bytes = encode_cdr_le(msg);
    let back: T = decode_cdr(&bytes).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(&back, msg);
    assert_eq!(encode_cdr_le(&back), bytes);
    bytes
}

#[test]
fn a_populated_collision_object_round_trips_through_cdr() {
    let object = collision_object("sheet", CollisionObject::APPEND);
    let bytes = round_trip(&object);
    // The wire layout, read by hand: encapsulation, header (stamp, frame id "world"), then the
    // pose's seven doubles at the next 8-byte boundary of the payload (payload byte 24).
    assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
    assert_eq!(&bytes[4..12], &[7, 0, 0, 0, 0x80, 0xb2, 0xe6, 0x0e]);
    assert_eq!(&bytes[12..22], b"\x06\0\0\0world\0");
    assert_eq!(&bytes[28..36], &0.5f64.to_le_bytes());
    // `operation` is the last byte.
    assert_eq!(bytes.last(), Some(&CollisionObject::APPEND));
    let _ = round_trip(&AttachedCollisionObject { link_name: "tool0".into(), object, touch_links: vec!["tool0".into()], ..Default::default() });
}

#[test]
fn a_populated_planning_scene_round_trips_through_cdr() {
    let scene = planning_scene();
    let bytes = round_trip(&scene);
    // The octomap's bytes are the last sequence, before `is_diff`.
    assert_eq!(&bytes[bytes.len() - 11..], &[6, 0, 0, 0, 0, 1, 127, 128, 200, 255, 0]);
    let _ = round_trip(&scene.world);
    let _ = round_trip(&ApplyPlanningSceneRequest { scene: scene.clone() });
    let _ = round_trip(&ApplyPlanningSceneResponse { success: true });
    let all = PlanningSceneComponents::SCENE_SETTINGS
        | PlanningSceneComponents::ROBOT_STATE
        | PlanningSceneComponents::ROBOT_STATE_ATTACHED_OBJECTS
        | PlanningSceneComponents::WORLD_OBJECT_NAMES
        | PlanningSceneComponents::WORLD_OBJECT_GEOMETRY
        | PlanningSceneComponents::OCTOMAP
        | PlanningSceneComponents::TRANSFORMS
        | PlanningSceneComponents::ALLOWED_COLLISION_MATRIX
        | PlanningSceneComponents::LINK_PADDING_AND_SCALING
        | PlanningSceneComponents::OBJECT_COLORS;
    assert_eq!(all, 1023);
    let request = round_trip(&GetPlanningSceneRequest { components: PlanningSceneComponents { components: all } });
    assert_eq!(request, [0, 1, 0, 0, 0xff, 0x03, 0, 0]);
    let _ = round_trip(&GetPlanningSceneResponse { scene });
}

/// The same two messages as a Cyclone DDS peer serialises them (`tests/peers/scene_cdr.py`, from
/// IDL types built from `moveit_msgs`' definitions; `tests/msgs_interface.rs` checks that the
/// peer still produces these bytes).
const CYCLONE_COLLISION_OBJECT: &[u8] = include_bytes!("../../tests/fixtures/planning_scene/collision_object.cdr");
const CYCLONE_PLANNING_SCENE: &[u8] = include_bytes!("../../tests/fixtures/planning_scene/planning_scene.cdr");

#[test]
fn the_bytes_a_cyclone_peer_sends_decode_to_the_same_messages() {
    let object = collision_object("sheet", CollisionObject::APPEND);
    assert_eq!(decode_cdr::<CollisionObject>(CYCLONE_COLLISION_OBJECT).unwrap(), object);
    assert_eq!(encode_cdr_le(&object), CYCLONE_COLLISION_OBJECT);
    let scene = planning_scene();
    assert_eq!(decode_cdr::<PlanningScene>(CYCLONE_PLANNING_SCENE).unwrap(), scene);
    assert_eq!(encode_cdr_le(&scene), CYCLONE_PLANNING_SCENE);
}

fn refusal<T: DeserializeOwned + std::fmt::Debug>(bytes: &[u8]) -> String {
    decode_cdr::<T>(bytes).expect_err("refused").to_string()
}

#[test]
fn a_sequence_past_its_bound_is_refused_while_decoding() {
    // At the bound a world decodes; one more object and it is refused, naming the field.
    let world = |n: usize| PlanningSceneWorld { collision_objects: vec![CollisionObject::default(); n], ..Default::default() };
    let ok: PlanningSceneWorld = decode_cdr(&encode_cdr_le(&world(MAX_SCENE_OBJECTS))).unwrap();
    assert_eq!(ok.collision_objects.len(), MAX_SCENE_OBJECTS);
    let e = refusal::<PlanningSceneWorld>(&encode_cdr_le(&world(MAX_SCENE_OBJECTS + 1)));
    assert!(e.contains("PlanningSceneWorld.collision_objects") && e.contains("at most 10000 allowed"), "{e}");
    // The same inside a scene, and for the attached objects.
    let mut scene = PlanningScene { world: world(MAX_SCENE_OBJECTS + 1), ..Default::default() };
    let e = refusal::<PlanningScene>(&encode_cdr_le(&scene));
    assert!(e.contains("PlanningSceneWorld.collision_objects"), "{e}");
    scene.world = PlanningSceneWorld::default();
    scene.robot_state.attached_collision_objects = vec![AttachedCollisionObject::default(); MAX_SCENE_OBJECTS + 1];
    let e = refusal::<ApplyPlanningSceneRequest>(&encode_cdr_le(&ApplyPlanningSceneRequest { scene }));
    assert!(e.contains("RobotState.attached_collision_objects"), "{e}");
    // `float64[<=3]`.
    let mut object = collision_object("box", CollisionObject::ADD);
    object.primitives[0].dimensions.push(0.5);
    let e = refusal::<CollisionObject>(&encode_cdr_le(&object));
    assert!(e.contains("SolidPrimitive.dimensions") && e.contains("at most 3 allowed"), "{e}");
}

#[test]
fn the_link_and_matrix_bounds_refuse_one_entry_more() {
    let attached = |n: usize| AttachedCollisionObject { touch_links: vec![String::new(); n], ..Default::default() };
    let ok: AttachedCollisionObject = decode_cdr(&encode_cdr_le(&attached(MAX_LINK_ENTRIES))).unwrap();
    assert_eq!(ok.touch_links.len(), MAX_LINK_ENTRIES);
    let e = refusal::<AttachedCollisionObject>(&encode_cdr_le(&attached(MAX_LINK_ENTRIES + 1)));
    assert!(e.contains("AttachedCollisionObject.touch_links") && e.contains("at most 65536 allowed"), "{e}");
    let row = |n: usize| AllowedCollisionMatrix { entry_values: vec![AllowedCollisionEntry { enabled: vec![true; n] }], ..Default::default() };
    let ok: AllowedCollisionMatrix = decode_cdr(&encode_cdr_le(&row(MAX_ACM_NAMES))).unwrap();
    assert_eq!(ok.entry_values[0].enabled.len(), MAX_ACM_NAMES);
    let e = refusal::<AllowedCollisionMatrix>(&encode_cdr_le(&row(MAX_ACM_NAMES + 1)));
    assert!(e.contains("AllowedCollisionEntry.enabled") && e.contains("at most 75536 allowed"), "{e}");
}

#[test]
fn a_claimed_length_is_not_believed() {
    // A mesh that claims 4294967295 triangles and holds one: refused where the bytes end,
    // having reserved room for 1024 triangles at most (the bounded decoder never reserves from
    // a claim), where believing the claim would have reserved 48 GiB.
    let object = CollisionObject {
        meshes: vec![ShapeMesh { triangles: vec![MeshTriangle { vertex_indices: [0xdead_beef; 3] }], vertices: vec![] }],
        ..Default::default()
    };
    let mut bytes = encode_cdr_le(&object);
    let first = bytes.windows(4).position(|w| w == 0xdead_beef_u32.to_le_bytes()).expect("the triangle");
    bytes[first - 4..first].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = refusal::<CollisionObject>(&bytes);
    assert!(!e.is_empty());
    // Likewise an octomap claiming more bytes than the message holds.
    let mut world = PlanningSceneWorld::default();
    world.octomap.octomap.data = vec![7; 16];
    let mut bytes = encode_cdr_le(&world);
    let at = bytes.len() - 20;
    assert_eq!(&bytes[at..at + 4], &16u32.to_le_bytes());
    bytes[at..at + 4].copy_from_slice(&(MAX_OCTOMAP_BYTES as u32 + 1).to_le_bytes());
    let _ = refusal::<PlanningSceneWorld>(&bytes);
}

/// The names of a struct's fields in serialisation order (= wire order), from its JSON text.
fn field_order<T: Serialize + Default>() -> Vec<String> {
    struct Keys;
    impl<'de> serde::de::Visitor<'de> for Keys {
        type Value = Vec<String>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Vec<String>, A::Error> {
            let mut keys = Vec::new();
            while let Some(k) = map.next_key::<String>()? {
                let _: serde::de::IgnoredAny = map.next_value()?;
                keys.push(k);
            }
            Ok(keys)
        }
    }
    let text = serde_json::to_string(&T::default()).unwrap();
    serde::Deserializer::deserialize_map(&mut serde_json::Deserializer::from_str(&text), Keys).unwrap()
}

/// A `ros2msg` definition split into its sections: (type name, field names, field types
/// resolved to `pkg/Type`, constants as (name, value)).
type Section = (String, Vec<String>, Vec<String>, Vec<(String, String)>);

fn sections(main: &str, text: &str) -> Vec<Section> {
    const PRIMITIVES: [&str; 14] =
        ["bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "float32", "float64", "string"];
    let mut out = Vec::new();
    let separator = "=".repeat(80);
    for (i, part) in text.split(&format!("{separator}\n")).enumerate() {
        let (name, body) = match i {
            0 => (main.replace("/msg/", "/"), part),
            _ => {
                let (first, rest) = part.split_once('\n').unwrap();
                (first.strip_prefix("MSG: ").unwrap().to_owned(), rest)
            }
        };
        let package = name.split('/').next().unwrap().to_owned();
        let (mut fields, mut types, mut constants) = (Vec::new(), Vec::new(), Vec::new());
        for line in body.lines().map(|l| l.split('#').next().unwrap().trim()).filter(|l| !l.is_empty()) {
            let (ty, rest) = line.split_once(' ').unwrap();
            if let Some((constant, value)) = rest.split_once('=') {
                constants.push((constant.trim().to_owned(), value.trim().to_owned()));
                continue;
            }
            let base = ty.split('[').next().unwrap();
            if !PRIMITIVES.contains(&base) {
                types.push(if base.contains('/') { base.to_owned() } else { format!("{package}/{base}") });
            }
            fields.push(rest.trim().to_owned());
        }
        out.push((name, fields, types, constants));
    }
    out
}

#[test]
fn the_scene_topics_definitions_hold_their_closure_in_the_structs_field_order() {
    let order: Vec<(&str, Vec<String>)> = vec![
        ("moveit_msgs/PlanningScene", field_order::<PlanningScene>()),
        ("moveit_msgs/PlanningSceneWorld", field_order::<PlanningSceneWorld>()),
        ("moveit_msgs/CollisionObject", field_order::<CollisionObject>()),
        ("moveit_msgs/AttachedCollisionObject", field_order::<AttachedCollisionObject>()),
        ("moveit_msgs/RobotState", field_order::<RobotStateMsg>()),
        ("moveit_msgs/AllowedCollisionMatrix", field_order::<AllowedCollisionMatrix>()),
        ("moveit_msgs/AllowedCollisionEntry", field_order::<AllowedCollisionEntry>()),
        ("moveit_msgs/LinkPadding", field_order::<LinkPadding>()),
        ("moveit_msgs/LinkScale", field_order::<LinkScale>()),
        ("moveit_msgs/ObjectColor", field_order::<ObjectColor>()),
        ("object_recognition_msgs/ObjectType", field_order::<ObjectType>()),
        ("shape_msgs/SolidPrimitive", field_order::<SolidPrimitive>()),
        ("shape_msgs/Mesh", field_order::<ShapeMesh>()),
        ("shape_msgs/MeshTriangle", field_order::<MeshTriangle>()),
        ("shape_msgs/Plane", field_order::<Plane>()),
        ("octomap_msgs/OctomapWithPose", field_order::<OctomapWithPose>()),
        ("octomap_msgs/Octomap", field_order::<Octomap>()),
        ("geometry_msgs/Polygon", field_order::<Polygon>()),
        ("geometry_msgs/Point32", field_order::<Point32>()),
        ("geometry_msgs/Twist", field_order::<Twist>()),
        ("geometry_msgs/Wrench", field_order::<Wrench>()),
        ("geometry_msgs/TransformStamped", field_order::<TransformStamped>()),
        ("geometry_msgs/Transform", field_order::<Transform>()),
        ("geometry_msgs/Pose", field_order::<PoseMsg>()),
        ("geometry_msgs/Point", field_order::<Vector3>()),
        ("geometry_msgs/Vector3", field_order::<Vector3>()),
        ("geometry_msgs/Quaternion", field_order::<Quaternion>()),
        ("sensor_msgs/JointState", field_order::<JointState>()),
        ("sensor_msgs/MultiDOFJointState", field_order::<MultiDofJointState>()),
        ("trajectory_msgs/JointTrajectory", field_order::<JointTrajectory>()),
        ("trajectory_msgs/JointTrajectoryPoint", field_order::<JointTrajectoryPoint>()),
        ("std_msgs/Header", field_order::<Header>()),
        ("std_msgs/ColorRGBA", field_order::<ColorRgba>()),
        ("builtin_interfaces/Time", field_order::<Time>()),
        ("builtin_interfaces/Duration", field_order::<DurationMsg>()),
    ];
    for ty in [PLANNING_SCENE_TYPE, PLANNING_SCENE_WORLD_TYPE, COLLISION_OBJECT_TYPE, ATTACHED_COLLISION_OBJECT_TYPE] {
        let text = full_definition(ty).unwrap_or_else(|| panic!("{ty}: no definition"));
        let parts = sections(ty, &text);
        let names: Vec<&str> = parts.iter().map(|p| p.0.as_str()).collect();
        // Each type once, each one used, every type used defined.
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{ty}: a section twice: {names:?}");
        let used: Vec<&str> = parts.iter().flat_map(|p| p.2.iter().map(String::as_str)).collect();
        for name in &names[1..] {
            assert!(used.contains(name), "{ty}: {name} is defined but not used");
        }
        for u in &used {
            assert!(names.contains(u), "{ty}: {u} is used but not defined");
        }
        for (name, fields, _, constants) in &parts {
            let rust = &order.iter().find(|o| o.0 == name).unwrap_or_else(|| panic!("{ty}: no Rust type listed for {name}")).1;
            let rust: Vec<&str> = rust.iter().map(String::as_str).collect();
            assert_eq!(fields, &rust, "{ty}: {name}");
            let value = |c: &str| constants.iter().find(|k| k.0 == c).map(|k| k.1.parse::<u8>().unwrap());
            match name.as_str() {
                "moveit_msgs/CollisionObject" => assert_eq!(
                    [value("ADD"), value("REMOVE"), value("APPEND"), value("MOVE")],
                    [CollisionObject::ADD, CollisionObject::REMOVE, CollisionObject::APPEND, CollisionObject::MOVE].map(Some)
                ),
                "shape_msgs/SolidPrimitive" => assert_eq!(
                    [value("BOX"), value("SPHERE"), value("CYLINDER"), value("CONE"), value("PRISM")],
                    [SolidPrimitive::BOX, SolidPrimitive::SPHERE, SolidPrimitive::CYLINDER, SolidPrimitive::CONE, SolidPrimitive::PRISM].map(Some)
                ),
                _ => {}
            }
        }
    }
}
