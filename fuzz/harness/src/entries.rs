//! The entries of the targets that read files and messages: robot descriptions, meshes, CDR
//! messages, state lines, parameters and bags.

use crate::cdr_records::{split_records, CdrKind};
use crate::fixtures::{check_on_workcell, fresh_pipeline, fresh_workcell, note_contained_panic, robot_from_text, scratch_dir, workcell};
use std::path::Path;
use std::sync::{Mutex, OnceLock};
use thickness_collision::fuzz_access::{open_bag, parse_mesh, PipelineAccess};
use thickness_collision::math::Vector;
use thickness_collision::mesh::{MeshTopology, TopologySettings};
use thickness_collision::model::{Params, Srdf};
use thickness_collision::msgs::{CheckStatesRequest, ClockMsg, JointState, StringMsg, TfMessage};
use thickness_collision::pipeline::{parse_state_line, Pipeline, RobotState};
use thickness_collision::replay::decode_cdr;
use thickness_collision::thickness::{ThicknessArea, ThicknessSettings};

/// SRDF text (a `robot_semantic_file` or a `robot_description_semantic` message) parsed against
/// the bundled arm, then everything the checker and `check_state_validity` ask of it: the pairs,
/// the allowed collision matrix over every link pair, and every group's joints and links.
pub fn srdf(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let checker = workcell().checker();
    let robot = checker.robot();
    let Ok(model) = Srdf::parse(text, "fuzz.srdf", robot) else { return };
    for a in 0..robot.links.len() {
        for b in 0..robot.links.len() {
            let _ = model.is_disabled(a, b);
        }
    }
    for name in model.group_names() {
        let _ = model.group_joints(name, robot);
        let _ = model.group_links(name, robot);
    }
    thickness_collision::fuzz_access::build_self_pairs(checker, model.clone());
}

/// URDF text through `RobotModel::from_str`, then a checker and three states.
pub fn urdf(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        robot_from_text(text);
    }
}

fn mesh(data: &[u8], name: &str) {
    for scale in [Vector::splat(1.0), Vector::new(0.001, -0.001, 0.001)] {
        match parse_mesh(data, Path::new(name), scale) {
            Ok(m) => {
                // What the checker does next with a mesh: weld and build the topology and cells.
                if let Ok(topology) = MeshTopology::build(&m.vertices, &m.triangles, &TopologySettings::default()) {
                    let _ = ThicknessArea::build(&topology, &ThicknessSettings { thickness: 0.01, ..Default::default() });
                }
            }
            Err(e) => note_contained_panic(&e.to_string()),
        }
    }
}

/// STL bytes (ASCII or binary) through `parse_mesh`, then the topology and the cells.
pub fn mesh_stl(data: &[u8]) {
    mesh(data, "fuzz.stl");
}

/// OBJ bytes through `parse_mesh`, then the topology and the cells.
pub fn mesh_obj(data: &[u8]) {
    mesh(data, "fuzz.obj");
}

/// COLLADA bytes through `parse_mesh`, then the topology and the cells.
pub fn mesh_dae(data: &[u8]) {
    mesh(data, "fuzz.dae");
}

/// A sequence of CDR messages (see [`cdr_records`](crate::cdr_records)) decoded as the node
/// decodes them and handed to a fresh pipeline in order; every state it yields is checked against
/// the workcell.
pub fn cdr(data: &[u8]) {
    // The pipeline (a few milliseconds to build) only once a message decodes.
    let mut pipeline: Option<Pipeline> = None;
    // The node checks the motion from each state to the next: so does this, on the workcell.
    let mut previous: Option<RobotState> = None;
    let mut motion_to = |state: RobotState| {
        check_on_workcell(&state);
        if let Some(from) = previous.as_ref() {
            let _ = workcell().check_motion(from, &state);
        }
        previous = Some(state);
    };
    for (kind, payload) in split_records(data) {
        match kind {
            CdrKind::JointStates => {
                if let Ok(msg) = decode_cdr::<JointState>(payload) {
                    if let Ok(state) = pipeline.get_or_insert_with(fresh_pipeline).joint_state(&msg) {
                        motion_to(state);
                    }
                }
            }
            CdrKind::Tf => {
                if let Ok(msg) = decode_cdr::<TfMessage>(payload) {
                    if let Ok(state) = pipeline.get_or_insert_with(fresh_pipeline).tf(&msg) {
                        motion_to(state);
                    }
                }
            }
            CdrKind::TfStatic => {
                if let Ok(msg) = decode_cdr::<TfMessage>(payload) {
                    let _ = pipeline.get_or_insert_with(fresh_pipeline).tf_static(&msg);
                }
            }
            CdrKind::Description => {
                // The node's `set_robot_description` reloads the environment from its files for
                // every description (tens of milliseconds); the robot's own path is the same.
                if let Ok(msg) = decode_cdr::<StringMsg>(payload) {
                    robot_from_text(&msg.data);
                }
            }
            CdrKind::CheckStates => {
                if let Ok(req) = decode_cdr::<CheckStatesRequest>(payload) {
                    let _ = workcell().check_request(&req.states);
                }
            }
            CdrKind::Clock => {
                let _ = decode_cdr::<ClockMsg>(payload);
            }
        }
        if let Some(p) = pipeline.as_mut() {
            let _ = p.take_warnings();
        }
    }
}

/// The workcell pipeline that `check --states` lines go through (it keeps the TF tree and merged
/// joints between lines, as `check` does); rebuilt every [`LINES_PER_PIPELINE`] inputs so made-up
/// frames never fill its TF tree for good.
fn line_pipeline() -> &'static Mutex<(Pipeline, usize, Option<RobotState>)> {
    static LINES: OnceLock<Mutex<(Pipeline, usize, Option<RobotState>)>> = OnceLock::new();
    LINES.get_or_init(|| Mutex::new((fresh_workcell(), 0, None)))
}

const LINES_PER_PIPELINE: usize = 2_000;

/// One `check --states` line: parsed, then checked by a fresh pipeline and by the workcell
/// pipeline that keeps its state between lines (as `check` does), and as the next waypoint of a
/// motion file (`check --states --motion`: the motion from the previous input's state to it).
pub fn state_line(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(state) = parse_state_line(text) else { return };
    let _ = fresh_pipeline().check_line(state.clone());
    if let Ok(mut guard) = line_pipeline().lock() {
        let (pipeline, uses, previous) = &mut *guard;
        *uses += 1;
        if *uses > LINES_PER_PIPELINE {
            *pipeline = fresh_workcell();
            *uses = 1;
            *previous = None;
        }
        let _ = pipeline.check_line(state.clone());
        if let (_, Ok(next)) = pipeline.line_state(state) {
            if let Some(from) = previous.as_ref() {
                let _ = pipeline.check_motion(from, &next);
            }
            *previous = Some(next);
        }
        let _ = pipeline.take_warnings();
    }
}

/// A parameters YAML file through `Params::from_yaml` and `validate`, then `-p` style overrides
/// of every parameter with its own value (the node's parameter services take that path).
pub fn params_yaml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(params) = Params::from_yaml(text, Path::new("fuzz.yaml")) else { return };
    if params.validate().is_err() {
        return;
    }
    let _ = params.to_yaml();
    for (name, value) in params.flat() {
        let _ = params.with_value(&name, value);
    }
}

/// Bag bytes written to a file of the given name in the scratch directory and read to the end,
/// every message decoded by its type and handed to a fresh pipeline as `replay` does.
fn bag(data: &[u8], name: &str) {
    let dir = scratch_dir();
    let path = dir.join(name);
    // SQLite may leave a journal beside the database; a stale one must not change the next run.
    for side in ["-journal", "-wal", "-shm"] {
        let _ = std::fs::remove_file(dir.join(format!("{name}{side}")));
    }
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let Ok(reader) = open_bag(&path) else { return };
    let mut pipeline: Option<Pipeline> = None;
    for item in reader {
        let Ok(m) = item else { break };
        let pipeline = pipeline.get_or_insert_with(fresh_pipeline);
        match (m.topic.as_str(), m.type_name.as_str()) {
            ("/robot_description", _) => {
                if let Ok(msg) = decode_cdr::<StringMsg>(&m.data) {
                    robot_from_text(&msg.data);
                }
            }
            ("/tf_static", _) => {
                if let Ok(msg) = decode_cdr::<TfMessage>(&m.data) {
                    let _ = pipeline.tf_static(&msg);
                }
            }
            (_, "tf2_msgs/msg/TFMessage") => {
                if let Ok(msg) = decode_cdr::<TfMessage>(&m.data) {
                    if let Ok(state) = pipeline.tf(&msg) {
                        check_on_workcell(&state);
                    }
                }
            }
            _ => {
                if let Ok(msg) = decode_cdr::<JointState>(&m.data) {
                    if let Ok(state) = pipeline.joint_state(&msg) {
                        check_on_workcell(&state);
                    }
                }
            }
        }
        let _ = pipeline.take_warnings();
    }
}

/// MCAP bytes as an `.mcap` file through `open_bag` and the whole iterator.
pub fn bag_mcap(data: &[u8]) {
    bag(data, "fuzz.mcap");
}

/// SQLite bytes as a `.db3` file through `open_bag` and the whole iterator.
pub fn bag_sqlite(data: &[u8]) {
    bag(data, "fuzz.db3");
}

/// A planning-scene message (first byte: which type), through its bounded decoder and back: see
/// `fuzz_access::planning_scene_round_trip`.
pub fn planning_scene(data: &[u8]) {
    let _ = thickness_collision::fuzz_access::planning_scene_round_trip(data);
}

/// A planning-scene message (first byte: which type) applied to the bundled workcell's pipeline,
/// its arm at a known state: see `fuzz_access::planning_scene_apply`. The scene is emptied
/// after each input (a full, empty scene), so inputs do not build on each other.
pub fn planning_scene_apply(data: &[u8]) {
    use thickness_collision::msgs::JointState;
    thread_local! {
        static PIPELINE: std::cell::RefCell<Option<thickness_collision::pipeline::Pipeline>> = const { std::cell::RefCell::new(None) };
    }
    PIPELINE.with(|cell| {
        let mut cell = cell.borrow_mut();
        let pipeline = cell.get_or_insert_with(|| {
            let mut p = crate::fixtures::fresh_pipeline();
            let name: Vec<String> = p.checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
            let position = vec![0.2; name.len()];
            let _ = p.joint_state(&JointState { name, position, ..Default::default() });
            p
        });
        let _ = thickness_collision::fuzz_access::planning_scene_apply(pipeline, data);
        thickness_collision::fuzz_access::planning_scene_clear(pipeline);
    });
}
