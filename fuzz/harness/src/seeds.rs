//! Seed inputs for every target, generated from the bundled workcell and the library's own
//! encoders.

use crate::cdr_records::{cdr_records, CdrKind, CDR_KINDS};
use crate::fixtures::workcell;
use std::path::Path;
use thickness_collision::fuzz_access::{parse_mesh, AttachedCollisionObject, GetStateValidityRequest, JointConstraint, RobotStateMsg};
use thickness_collision::math::Vector;
use thickness_collision::model::{bundled_config_dir, Params};
use thickness_collision::msgs::{
    CheckStatesRequest, CheckTrajectoryRequest, ClockMsg, DurationMsg, Header, JointState, JointTrajectory, JointTrajectoryPoint, Quaternion, StringMsg,
    TfMessage, Time, Transform, TransformStamped, Vector3,
};
use thickness_collision::replay::encode_cdr_le;

/// One seed: (target, file name, bytes).
type Seed = (&'static str, String, Vec<u8>);

/// A robot of every primitive shape with a mimic joint: a `urdf` seed, and the `robot_description`
/// of a `cdr` seed.
const SHAPES_URDF: &str = r#"<robot name="shapes">
  <link name="world"/>
  <link name="a"><collision><origin xyz="0 0 0.5" rpy="0 1.57 0"/><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>
  <link name="b"><collision><geometry><sphere radius="0.1"/></geometry></collision><collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision></link>
  <link name="c"><collision><geometry><capsule radius="0.05" length="0.2"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.5 0 0.5"/><axis xyz="1 0 0"/><limit lower="0" upper="0.4" effort="1" velocity="1"/></joint>
  <joint name="j3" type="continuous"><parent link="b"/><child link="c"/><axis xyz="0 1 0"/><mimic joint="j1" multiplier="2" offset="0.1"/></joint>
</robot>
"#;

/// SRDF for the bundled arm: every element the parser reads, and some it reads past.
const WORKCELL_SRDF: &str = r#"<?xml version="1.0"?>
<robot name="workcell_arm">
  <virtual_joint name="world_joint" type="fixed" parent_frame="world" child_link="base_link"/>
  <group name="arm"><chain base_link="base_link" tip_link="gripper_link"/></group>
  <group name="hand"><joint name="finger_left_joint"/><link name="finger_right_link"/></group>
  <group name="all"><group name="arm"/><group name="hand"/><joint name="world_joint"/></group>
  <group_state name="home" group="arm"><joint name="elbow_joint" value="0.3"/></group_state>
  <end_effector name="gripper" parent_link="gripper_link" group="hand"/>
  <disable_collisions link1="finger_left_link" link2="finger_right_link" reason="Adjacent"/>
  <disable_default_collisions link="base_link"/>
  <enable_collisions link1="base_link" link2="gripper_link"/>
  <passive_joint name="tool0_joint"/>
</robot>
"#;

/// A COLLADA file with one triangle list (a unit quad).
const QUAD_DAE: &str = r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="1" name="meter"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="quad" name="quad"><mesh>
      <source id="quad-pos"><float_array id="quad-pos-array" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
        <technique_common><accessor source="#quad-pos-array" count="4" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
      <vertices id="quad-vtx"><input semantic="POSITION" source="#quad-pos"/></vertices>
      <triangles count="2"><input semantic="VERTEX" source="#quad-vtx" offset="0"/><p>0 1 2 0 2 3</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene"><node id="n"><instance_geometry url="#quad"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"##;

/// Seed inputs for every target, generated from the bundled workcell and the library's own
/// encoders: (target, file name, bytes). `tests/fuzz_regressions.rs` writes them to
/// `fuzz/corpus/<target>/` (`scripts/fuzz_campaign.sh` asks it to); the bag seeds, written by
/// rosbags, are kept in `fuzz/regressions/bag_*/` instead.
pub fn seeds() -> Vec<Seed> {
    let mut out: Vec<Seed> = vec![
        // URDF: the workcell's two files, and a robot of every primitive shape with a mimic joint.
        ("urdf", "robot.urdf".into(), read_workcell("robot.urdf")),
        ("urdf", "environment.urdf".into(), read_workcell("environment.urdf")),
        ("urdf", "shapes.urdf".into(), SHAPES_URDF.as_bytes().to_vec()),
        ("srdf", "workcell_arm.srdf".into(), WORKCELL_SRDF.as_bytes().to_vec()),
    ];
    mesh_seeds(&mut out);
    cdr_seeds(&mut out);
    state_line_seeds(&mut out);
    trajectory_seeds(&mut out);
    validity_seeds(&mut out);
    // Planning-scene messages: the bytes Cyclone DDS wrote for the interface test, behind their
    // type byte.
    let scene_bytes: [(u8, &str, &[u8]); 2] = [
        (0, "collision_object.cdr", include_bytes!("../../../tests/fixtures/planning_scene/collision_object.cdr")),
        (2, "planning_scene.cdr", include_bytes!("../../../tests/fixtures/planning_scene/planning_scene.cdr")),
    ];
    for (kind, file, bytes) in scene_bytes {
        out.push(("planning_scene", file.into(), [&[kind][..], bytes].concat()));
        out.push(("planning_scene_apply", file.into(), [&[kind][..], bytes].concat()));
    }
    // Parameters: the bundled file and the defaults written out.
    let params = std::fs::read(bundled_config_dir().join("params.yaml")).unwrap_or_default();
    out.push(("params_yaml", "params.yaml".into(), params));
    out.push(("params_yaml", "defaults.yaml".into(), Params::default().to_yaml().into_bytes()));
    out
}

/// A file of the bundled example workcell, empty when it cannot be read.
fn read_workcell(name: &str) -> Vec<u8> {
    std::fs::read(bundled_config_dir().join("example_workcell").join(name)).unwrap_or_default()
}

/// The workcell's actuated joints, in order.
fn workcell_joint_names() -> Vec<String> {
    workcell().checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect()
}

fn header(frame: &str) -> Header {
    Header { stamp: Time { sec: 1, nanosec: 2 }, frame_id: frame.into() }
}

/// Meshes: the workcell's OBJs (the small ones), the gripper as binary and ASCII STL, and a
/// COLLADA file with one triangle list.
fn mesh_seeds(out: &mut Vec<Seed>) {
    out.push(("mesh_obj", "gripper.obj".into(), read_workcell("gripper.obj")));
    out.push(("mesh_obj", "bent_panel.obj".into(), read_workcell("bent_panel.obj")));
    let tris: Vec<[[f32; 3]; 3]> = match parse_mesh(&read_workcell("gripper.obj"), Path::new("gripper.obj"), Vector::splat(1.0)) {
        Ok(m) => m.triangles.iter().map(|t| t.map(|i| m.vertices[i as usize]).map(|v| [v.x as f32, v.y as f32, v.z as f32])).collect(),
        Err(_) => Vec::new(),
    };
    let mut binary = vec![0u8; 80];
    binary.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    let mut ascii = String::from("solid gripper\n");
    for t in &tris {
        binary.extend(std::iter::repeat_n(0u8, 12));
        for v in t {
            for c in v {
                binary.extend_from_slice(&c.to_le_bytes());
            }
        }
        binary.extend_from_slice(&[0, 0]);
        ascii.push_str("facet normal 0 0 0\n outer loop\n");
        for v in t {
            ascii.push_str(&format!("  vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        ascii.push_str(" endloop\nendfacet\n");
    }
    ascii.push_str("endsolid gripper\n");
    out.push(("mesh_stl", "gripper_binary.stl".into(), binary));
    out.push(("mesh_stl", "gripper_ascii.stl".into(), ascii.into_bytes()));
    out.push(("mesh_dae", "quad.dae".into(), QUAD_DAE.as_bytes().to_vec()));
}

/// CDR: every kind the node decodes, alone and in sequences, for the workcell robot.
fn cdr_seeds(out: &mut Vec<Seed>) {
    let robot = workcell().checker().robot();
    let names = workcell_joint_names();
    let joint_state = |positions: Vec<f64>, names: Vec<String>| JointState { header: header(""), name: names, position: positions, ..Default::default() };
    let full = joint_state(names.iter().enumerate().map(|(i, _)| 0.3 * i as f64).collect(), names.clone());
    let partial = joint_state(vec![1.2], names.iter().skip(1).take(1).cloned().collect());
    let transforms: Vec<TransformStamped> = robot
        .links
        .iter()
        .enumerate()
        .map(|(i, l)| TransformStamped {
            header: header("world"),
            child_frame_id: l.name.clone(),
            transform: Transform { translation: Vector3 { x: 0.1 * i as f64, y: 0.0, z: 0.5 }, rotation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } },
        })
        .collect();
    let tf = TfMessage { transforms };
    let tf_static = TfMessage {
        transforms: vec![TransformStamped {
            header: header("world"),
            child_frame_id: "odom".into(),
            transform: Transform { translation: Vector3 { x: 1.0, y: 0.0, z: 0.0 }, rotation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } },
        }],
    };
    let description = StringMsg { data: SHAPES_URDF.into() };
    let request = CheckStatesRequest { states: vec![full.clone(), partial.clone()] };
    let clock = ClockMsg { clock: Time { sec: 5, nanosec: 6 } };
    type Records = Vec<(CdrKind, Vec<u8>)>;
    let cdr_seeds: [(&str, Records); 7] = [
        ("joint_state", vec![(CdrKind::JointStates, encode_cdr_le(&full))]),
        ("joint_states_merged", vec![(CdrKind::JointStates, encode_cdr_le(&full)), (CdrKind::JointStates, encode_cdr_le(&partial))]),
        ("tf", vec![(CdrKind::TfStatic, encode_cdr_le(&tf_static)), (CdrKind::Tf, encode_cdr_le(&tf))]),
        ("description", vec![(CdrKind::Description, encode_cdr_le(&description))]),
        ("check_states", vec![(CdrKind::CheckStates, encode_cdr_le(&request))]),
        ("clock", vec![(CdrKind::Clock, encode_cdr_le(&clock))]),
        ("all", CDR_KINDS.iter().map(|k| (*k, Vec::new())).collect()),
    ];
    for (name, records) in cdr_seeds {
        out.push(("cdr", format!("{name}.cdr"), cdr_records(&records)));
    }
}

/// State lines: a joint state, a partial one, and link transforms.
fn state_line_seeds(out: &mut Vec<Seed>) {
    let robot = workcell().checker().robot();
    let names = workcell_joint_names();
    let positions: Vec<f64> = names.iter().map(|_| 0.5).collect();
    let lines = [
        ("joints", serde_json::json!({"name": names, "position": positions, "stamp": 12})),
        ("partial", serde_json::json!({"name": [names.first()], "position": [1.0]})),
        (
            "transforms",
            serde_json::json!({"transforms": robot.links.iter().map(|l| serde_json::json!({"link": l.name, "translation": [0.0, 0.0, 0.5], "rotation": [0.0, 0.0, 0.0, 1.0]})).collect::<Vec<_>>()}),
        ),
    ];
    for (name, line) in lines {
        out.push(("state_line", format!("{name}.json"), line.to_string().into_bytes()));
    }
}

/// Trajectories: every joint through the workcell (into a guard), a partial one, one point, and
/// refused ones (lengths, time going back, NaN, an unknown joint).
fn trajectory_seeds(out: &mut Vec<Seed>) {
    let names = workcell_joint_names();
    let point = |positions: Vec<f64>, sec: i32| JointTrajectoryPoint { positions, time_from_start: DurationMsg { sec, nanosec: 0 }, ..Default::default() };
    let request = |joint_names: Vec<String>, points: Vec<JointTrajectoryPoint>| {
        encode_cdr_le(&CheckTrajectoryRequest { trajectory: JointTrajectory { header: header("world"), joint_names, points }, ..Default::default() })
    };
    let lift_elbow = vec!["shoulder_lift_joint".to_string(), "elbow_joint".to_string()];
    let wave: Vec<JointTrajectoryPoint> =
        (0..5).map(|k| point(names.iter().enumerate().map(|(i, _)| 0.2 * (k * (i + 1)) as f64).collect(), k as i32)).collect();
    let trajectories = [
        ("every_joint", request(names.clone(), wave)),
        ("into_guard", request(lift_elbow.clone(), vec![point(vec![0.0, 0.0], 0), point(vec![0.2, 0.1], 1), point(vec![1.2, 0.3], 3)])),
        ("one_point", request(lift_elbow.clone(), vec![point(vec![1.2, 0.3], 2)])),
        ("lengths", request(lift_elbow.clone(), vec![point(vec![0.0], 0)])),
        ("time_back", request(lift_elbow.clone(), vec![point(vec![0.0, 0.0], 2), point(vec![0.1, 0.0], 1)])),
        ("nan", request(lift_elbow.clone(), vec![point(vec![0.0, f64::NAN], 0)])),
        ("unknown_joint", request(vec!["no_such_joint".into()], vec![point(vec![0.0], 0)])),
    ];
    for (name, bytes) in trajectories {
        out.push(("check_trajectory", format!("{name}.cdr"), bytes));
    }
}

/// State validity requests: every joint (free), into a guard, a partial state, an unknown group,
/// and refused ones (an attached object, constraints, a multi-DOF joint, NaN, an unknown joint).
fn validity_seeds(out: &mut Vec<Seed>) {
    let names = workcell_joint_names();
    let request = |name: Vec<String>, position: Vec<f64>| GetStateValidityRequest {
        robot_state: RobotStateMsg { joint_state: JointState { header: header("world"), name, position, ..Default::default() }, ..Default::default() },
        ..Default::default()
    };
    let lift_elbow = vec!["shoulder_lift_joint".to_string(), "elbow_joint".to_string()];
    let mut group = request(lift_elbow.clone(), vec![1.2, 0.3]);
    group.group_name = "arm".into();
    let mut attached = request(lift_elbow.clone(), vec![0.0, 0.0]);
    attached.robot_state.attached_collision_objects.push(AttachedCollisionObject { link_name: "tool0".into(), ..Default::default() });
    let mut constrained = request(lift_elbow.clone(), vec![0.0, 0.0]);
    constrained.constraints.joint_constraints.push(JointConstraint { joint_name: "elbow_joint".into(), ..Default::default() });
    let mut multi = request(vec![], vec![]);
    multi.robot_state.multi_dof_joint_state.joint_names.push("virtual_joint".into());
    multi.robot_state.multi_dof_joint_state.transforms.push(Transform::default());
    let requests = [
        ("every_joint", request(names.clone(), vec![0.0; names.len()])),
        ("into_guard", request(lift_elbow.clone(), vec![1.2, 0.3])),
        ("partial", request(vec!["elbow_joint".into()], vec![0.4])),
        ("group", group),
        ("attached", attached),
        ("constraints", constrained),
        ("multi_dof", multi),
        ("nan", request(lift_elbow.clone(), vec![0.0, f64::NAN])),
        ("unknown_joint", request(vec!["no_such_joint".into()], vec![0.0])),
    ];
    for (name, r) in requests {
        out.push(("check_state_validity", format!("{name}.cdr"), encode_cdr_le(&r)));
    }
}
