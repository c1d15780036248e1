//! The fuzz targets' entry points, one function per target, shared by the `cargo fuzz` crate in
//! `fuzz/` and by `tests/fuzz_regressions.rs`, which replays every saved input on stable: a crash
//! the fuzzer found stays found by `cargo test`. Feature `testing`; not part of the library's API.
//!
//! Every entry takes raw bytes and must never panic, abort or hang, whatever the bytes. Each goes
//! as deep as the front door it stands for: URDF text is loaded and the robot checked in a few
//! states against a small scene; a decoded message goes through a [`Pipeline`] the way the node
//! hands it over, and the states it yields are checked against the bundled workcell.
//!
//! Reproducibility: the pipeline's input policy (merged joint states, the TF tree) keeps state
//! between messages, so each input gets a fresh pipeline on the bundled robot with an empty
//! environment (cheap to build); its states are then checked against one workcell pipeline built
//! once, whose `check` keeps no state. The same input gives the same run in any order.
//!
//! Panics that the library contains on purpose (`limits::contain_panic` around mesh-loader) are
//! not failures; they are noted on standard error once per place, with the prefix
//! [`CONTAINED_PANIC_PREFIX`], so a campaign can count new ones.

use crate::checker::Checker;
use crate::collision::{Scene, TargetShape};
use crate::math::{Pose, Vector};
use crate::mesh::{generate, MeshTopology, TopologySettings};
use crate::model::mesh_file::parse_mesh;
use crate::model::{PackageResolver, Params, RobotModel};
use crate::msgs::{CheckTrajectoryRequest, JointState, StringMsg, TfMessage, Time};
use crate::pipeline::{parse_state_line, Pipeline, RobotState};
use crate::replay::{decode_cdr, open_bag};
use crate::thickness::{ThicknessArea, ThicknessSettings};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// A target's entry: raw bytes in, nothing out, never a panic.
pub type Entry = fn(&[u8]);

/// Every target: its name (the `fuzz/fuzz_targets/<name>.rs` file and the
/// `fuzz/regressions/<name>/` folder) and its entry.
pub const TARGETS: &[(&str, Entry)] = &[
    ("urdf", urdf),
    ("mesh_stl", mesh_stl),
    ("mesh_obj", mesh_obj),
    ("mesh_dae", mesh_dae),
    ("cdr", cdr),
    ("state_line", state_line),
    ("params_yaml", params_yaml),
    ("bag_mcap", bag_mcap),
    ("bag_sqlite", bag_sqlite),
    ("check_trajectory", check_trajectory),
    ("check_state_validity", check_state_validity),
    ("srdf", srdf),
];

/// Printed before a panic the library contained (mesh-loader), once per message.
pub const CONTAINED_PANIC_PREFIX: &str = "fuzz_entry: contained panic:";

/// `thickness_collision_msgs/srv/CheckStates` request, as the node decodes it (the node's own
/// type lives behind the `ros` feature; the wire format is this struct's).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckStatesRequest {
    /// The states to check.
    pub states: Vec<JointState>,
}

/// `rosgraph_msgs/msg/Clock` (`use_sim_time`), as the node decodes it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ClockMsg {
    /// Simulated time.
    pub clock: Time,
}

/// The message kinds of the [`cdr`] target, by the record's kind byte (modulo their count).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CdrKind {
    /// `joint_states` (`sensor_msgs/msg/JointState`).
    JointStates = 0,
    /// `/tf` (`tf2_msgs/msg/TFMessage`).
    Tf = 1,
    /// `/tf_static`.
    TfStatic = 2,
    /// `robot_description` (`std_msgs/msg/String`).
    Description = 3,
    /// A `check_states` request.
    CheckStates = 4,
    /// `/clock`.
    Clock = 5,
}

const CDR_KINDS: [CdrKind; 6] = [CdrKind::JointStates, CdrKind::Tf, CdrKind::TfStatic, CdrKind::Description, CdrKind::CheckStates, CdrKind::Clock];

/// One input of the [`cdr`] target: records of `[kind: u8][length: u16 LE][payload]`, the last
/// one taking what is left when its length runs past the end. Used to write seeds.
pub fn cdr_records(records: &[(CdrKind, Vec<u8>)]) -> Vec<u8> {
    let mut out = Vec::new();
    for (kind, payload) in records {
        out.push(*kind as u8);
        out.extend_from_slice(&(payload.len().min(u16::MAX as usize) as u16).to_le_bytes());
        out.extend_from_slice(&payload[..payload.len().min(u16::MAX as usize)]);
    }
    out
}

/// The records of a [`cdr`] input, as the target reads them.
pub fn split_records(mut data: &[u8]) -> Vec<(CdrKind, &[u8])> {
    let mut out = Vec::new();
    while let [kind, rest @ ..] = data {
        let kind = CDR_KINDS[*kind as usize % CDR_KINDS.len()];
        let (len, rest) = match rest {
            [a, b, rest @ ..] => (u16::from_le_bytes([*a, *b]) as usize, rest),
            _ => (rest.len(), &rest[rest.len()..]),
        };
        let n = len.min(rest.len());
        out.push((kind, &rest[..n]));
        data = &rest[n..];
    }
    out
}

/// Writes to standard error once per place a contained panic comes from, and to
/// the file `FUZZ_CONTAINED_PANICS_LOG` names, if set.
fn note_contained_panic(error: &str) {
    static SEEN: OnceLock<Mutex<HashSet<String>>> = OnceLock::new();
    let Some(at) = error.find("panicked") else { return };
    // "panicked at file:line: message": one note per place (messages carry varying indices).
    let text = &error[at..];
    let place = text.split(": ").next().unwrap_or(text).to_owned();
    let seen = SEEN.get_or_init(Default::default);
    if let Ok(mut seen) = seen.lock() {
        if seen.insert(place) {
            let key = text.trim_end_matches(')');
            eprintln!("{CONTAINED_PANIC_PREFIX} {key}");
            // libFuzzer's fork mode drops its workers' output: the campaign asks for a file.
            if let Some(log) = std::env::var_os("FUZZ_CONTAINED_PANICS_LOG") {
                use std::io::Write;
                if let Ok(mut f) = std::fs::OpenOptions::new().create(true).append(true).open(log) {
                    let _ = writeln!(f, "{key}");
                }
            }
        }
    }
}

/// A directory of this process's own for the files the bag targets write (two fuzzers run at a
/// time, each in its own process).
fn scratch_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("thickness_collision_fuzz_{}", std::process::id()));
        if let Err(e) = std::fs::create_dir_all(&dir) {
            panic!("fuzz_entry: cannot create the scratch directory {}: {e}", dir.display());
        }
        dir
    })
}

/// The bundled workcell (robot and environment), built once, with the arm's whole state at 0
/// received (as a node has it once its joint states arrived: requests that leave joints out take
/// them from it); its `check` keeps no state.
fn workcell() -> &'static Pipeline {
    static WORKCELL: OnceLock<Pipeline> = OnceLock::new();
    WORKCELL.get_or_init(|| match Pipeline::new(Params::default()) {
        Ok(mut p) => {
            let name: Vec<String> = p.checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
            let position = vec![0.0; name.len()];
            if let Err(e) = p.joint_state(&JointState { name, position, ..Default::default() }) {
                panic!("fuzz_entry: the arm's zero state is refused: {}", e.message);
            }
            p
        }
        Err(e) => panic!("fuzz_entry: the bundled workcell does not load: {e}"),
    })
}

/// The workcell pipeline that `check --states` lines go through (it keeps the TF tree and merged
/// joints between lines, as `check` does); rebuilt every [`LINES_PER_PIPELINE`] inputs so made-up
/// frames never fill its TF tree for good.
fn line_pipeline() -> &'static Mutex<(Pipeline, usize, Option<RobotState>)> {
    static LINES: OnceLock<Mutex<(Pipeline, usize, Option<RobotState>)>> = OnceLock::new();
    LINES.get_or_init(|| Mutex::new((fresh_workcell(), 0, None)))
}

const LINES_PER_PIPELINE: usize = 2_000;

fn fresh_workcell() -> Pipeline {
    match Pipeline::new(Params::default()) {
        Ok(p) => p,
        Err(e) => panic!("fuzz_entry: the bundled workcell does not load: {e}"),
    }
}

/// A new pipeline on the bundled robot and an empty environment: the input policy of a fresh
/// node, quick to build.
fn fresh_pipeline() -> Pipeline {
    static EMPTY_ENV: OnceLock<PathBuf> = OnceLock::new();
    let env = EMPTY_ENV.get_or_init(|| {
        let path = scratch_dir().join("empty_environment.urdf");
        if let Err(e) = std::fs::write(&path, "<robot name=\"empty\"><link name=\"world\"/></robot>\n") {
            panic!("fuzz_entry: cannot write {}: {e}", path.display());
        }
        path
    });
    match Pipeline::new(Params { input_files: crate::model::InputFiles { robot: None, environment: Some(env.clone()) }, ..Params::default() }) {
        Ok(p) => p,
        Err(e) => panic!("fuzz_entry: the bundled robot does not load: {e}"),
    }
}

/// A small scene for robots from URDF text: a thin 1 m sheet at the origin (4 x 4 squares) and a
/// solid box. Built per input (a `Scene` is not `Clone`); a few hundred microseconds.
fn small_scene() -> Scene {
    let mut scene = Scene::new();
    let (v, t) = generate::flat_grid(4, 4, 1.0, 1.0);
    if let Ok(mesh) = MeshTopology::build(&v, &t, &TopologySettings::default()) {
        if let Ok(area) = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }) {
            let _ = scene.add_surface("sheet", Pose::IDENTITY, area);
        }
    }
    if let Some(shape) = TargetShape::cuboid(Vector::new(0.2, 0.2, 0.2)) {
        let _ = scene.add_solid("box", Pose::from_translation(Vector::new(0.5, 0.0, 0.5)), shape);
    }
    scene
}

/// A robot from URDF text, checked against [`small_scene`] at zero, at its lower and at its
/// upper limits (where finite): the path of a `robot_description` up to the numeric core.
fn robot_from_text(text: &str) {
    let Ok(robot) = RobotModel::from_str(text, "fuzz.urdf", Path::new("/nonexistent"), &PackageResolver::default(), false) else {
        return;
    };
    let n = robot.joints.len();
    let at = |side: usize| -> Vec<f64> { robot.joints.iter().map(|j| if j.limits[side].is_finite() { j.limits[side] } else { 0.0 }).collect() };
    let states = [vec![0.0; n], at(0), at(1)];
    let Ok(checker) = Checker::from_robot_and_scene(Params::default(), robot, small_scene(), "fuzz.urdf".into()) else {
        return;
    };
    for q in &states {
        let _ = checker.check_positions(q);
    }
}

/// Checks a state from a fresh pipeline against the workcell.
fn check_on_workcell(state: &RobotState) {
    let _ = workcell().check(state);
}

/// SRDF text (a `robot_semantic_file` or a `robot_description_semantic` message) parsed against
/// the bundled arm, then everything the checker and `check_state_validity` ask of it: the pairs,
/// the allowed collision matrix over every link pair, and every group's joints and links.
pub fn srdf(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let checker = workcell().checker();
    let robot = checker.robot();
    let Ok(model) = crate::model::Srdf::parse(text, "fuzz.srdf", robot) else { return };
    for a in 0..robot.links.len() {
        for b in 0..robot.links.len() {
            let _ = model.is_disabled(a, b);
        }
    }
    for name in model.group_names() {
        let _ = model.group_joints(name, robot);
        let _ = model.group_links(name, robot);
    }
    let _ = crate::checker::SelfPairs::build(checker, Some(model.clone()));
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

/// A sequence of CDR messages (see [`cdr_records`]) decoded as the node decodes them and handed
/// to a fresh pipeline in order; every state it yields is checked against the workcell.
pub fn cdr(data: &[u8]) {
    // The pipeline (a few milliseconds to build) only once a message decodes.
    let mut pipeline: Option<Pipeline> = None;
    // The node checks the motion from each state to the next: so does this, on the workcell.
    let mut previous: Option<RobotState> = None;
    let mut motion_to = |state: RobotState| {
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
                        check_on_workcell(&state);
                        motion_to(state);
                    }
                }
            }
            CdrKind::Tf => {
                if let Ok(msg) = decode_cdr::<TfMessage>(payload) {
                    if let Ok(state) = pipeline.get_or_insert_with(fresh_pipeline).tf(&msg) {
                        check_on_workcell(&state);
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

/// Points of a fuzzed trajectory checked against the workcell (all of them are validated, and
/// checked against an empty environment).
const TRAJECTORY_POINTS_ON_WORKCELL: usize = 4;

/// Joint travel (radians or metres, summed over the joints) of the longest segment up to which a
/// trajectory is walked: a segment of made-up positions (7e44 rad, as the fuzzer makes them) needs
/// the motion check's full 2^20 sub-intervals, 5 s even against an empty environment, which would
/// leave the fuzzer a handful of runs. Longer ones are only validated.
const TRAJECTORY_TRAVEL_WALKED: f64 = 20.0;

/// A `check_trajectory` request: a CDR payload (with its 4-byte encapsulation header) decoded as
/// the node decodes it, resolved against a fresh pipeline that has merged one partial joint state
/// (so joints left out come from the current state, others from `missing_joint`); when no segment
/// travels more than [`TRAJECTORY_TRAVEL_WALKED`], walked in full against an empty environment and
/// its first [`TRAJECTORY_POINTS_ON_WORKCELL`] points against the workcell.
pub fn check_trajectory(data: &[u8]) {
    let Ok(request) = decode_cdr::<CheckTrajectoryRequest>(data) else { return };
    let mut pipeline = fresh_pipeline();
    let first = pipeline.checker().robot().joints.iter().find(|j| j.is_actuated()).map(|j| j.name.clone());
    if let Some(name) = first {
        let _ = pipeline.joint_state(&JointState { name: vec![name], position: vec![0.25], ..Default::default() });
    }
    let job = pipeline.trajectory_job(&request.trajectory);
    let travel = request.trajectory.points.windows(2).map(|w| w[0].positions.iter().zip(&w[1].positions).map(|(a, b)| (b - a).abs()).sum::<f64>());
    let short = travel.fold(0.0, f64::max) <= TRAJECTORY_TRAVEL_WALKED;
    if !short && job.refused().is_none() {
        return;
    }
    // A refused request is answered without a check, whatever its travel.
    let answer = job.run();
    // A refused request is never valid, and says why.
    assert!(answer.valid || !answer.error.is_empty() || answer.segment >= 0, "an invalid answer without a cause: {answer:?}");
    assert!(!answer.valid || (answer.segment == -1 && answer.error.is_empty()), "a valid answer with a segment or an error: {answer:?}");
    if short {
        let mut head = request.trajectory;
        head.points.truncate(TRAJECTORY_POINTS_ON_WORKCELL);
        let _ = workcell().check_trajectory(&head);
    }
}

/// What every `check_state_validity` answer must be: refused (a reason) means not valid and no
/// contacts; otherwise valid exactly when there are no contacts; never cost sources or
/// constraint results.
fn assert_validity_answer(answer: &crate::msgs::moveit::GetStateValidityResponse, reason: Option<&str>) {
    assert!(answer.cost_sources.is_empty() && answer.constraint_result.is_empty(), "cost sources or constraint results: {answer:?}");
    match reason {
        Some(r) => assert!(!answer.valid && answer.contacts.is_empty() && !r.is_empty() && !r.contains('\n'), "refused ({r}) but {answer:?}"),
        None => assert_eq!(answer.valid, answer.contacts.is_empty(), "valid with contacts, or not valid without: {answer:?}"),
    }
}

/// A `check_state_validity` request (`moveit_msgs/srv/GetStateValidity`): a CDR payload (with its
/// 4-byte encapsulation header) decoded as the node decodes it, resolved against a fresh pipeline
/// that has merged one partial joint state (joints left out from the merged state or
/// `missing_joint`) and checked against an empty environment, then against the workcell; the
/// answers' invariants asserted.
pub fn check_state_validity(data: &[u8]) {
    let Ok(request) = decode_cdr::<crate::msgs::moveit::GetStateValidityRequest>(data) else { return };
    let mut pipeline = fresh_pipeline();
    let first = pipeline.checker().robot().joints.iter().find(|j| j.is_actuated()).map(|j| j.name.clone());
    if let Some(name) = first {
        let _ = pipeline.joint_state(&JointState { name: vec![name], position: vec![0.25], ..Default::default() });
    }
    let (answer, reason) = pipeline.check_validity(&request);
    assert_validity_answer(&answer, reason.as_deref());
    let (answer, reason) = workcell().check_validity(&request);
    assert_validity_answer(&answer, reason.as_deref());
}

/// Seed inputs for every target, generated from the bundled workcell and the library's own
/// encoders: (target, file name, bytes). `tests/fuzz_regressions.rs` writes them to
/// `fuzz/corpus/<target>/` (`scripts/fuzz_campaign.sh` asks it to); the bag seeds, written by
/// rosbags, are kept in `fuzz/regressions/bag_*/` instead.
pub fn seeds() -> Vec<(&'static str, String, Vec<u8>)> {
    use crate::msgs::{Header, Quaternion, Transform, TransformStamped, Vector3};
    use crate::replay::encode_cdr_le;
    let config = crate::model::bundled_config_dir().join("example_workcell");
    let read = |name: &str| std::fs::read(config.join(name)).unwrap_or_default();
    let mut out: Vec<(&'static str, String, Vec<u8>)> = Vec::new();

    // URDF: the workcell's two files, and a robot of every primitive shape with a mimic joint.
    out.push(("urdf", "robot.urdf".into(), read("robot.urdf")));
    out.push(("urdf", "environment.urdf".into(), read("environment.urdf")));
    let shapes = r#"<robot name="shapes">
  <link name="world"/>
  <link name="a"><collision><origin xyz="0 0 0.5" rpy="0 1.57 0"/><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>
  <link name="b"><collision><geometry><sphere radius="0.1"/></geometry></collision><collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision></link>
  <link name="c"><collision><geometry><capsule radius="0.05" length="0.2"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.5 0 0.5"/><axis xyz="1 0 0"/><limit lower="0" upper="0.4" effort="1" velocity="1"/></joint>
  <joint name="j3" type="continuous"><parent link="b"/><child link="c"/><axis xyz="0 1 0"/><mimic joint="j1" multiplier="2" offset="0.1"/></joint>
</robot>
"#;
    out.push(("urdf", "shapes.urdf".into(), shapes.as_bytes().to_vec()));

    // SRDF for the bundled arm: every element the parser reads, and some it reads past.
    let srdf = r#"<?xml version="1.0"?>
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
    out.push(("srdf", "workcell_arm.srdf".into(), srdf.as_bytes().to_vec()));

    // Meshes: the workcell's OBJs (the small ones), the gripper as binary and ASCII STL, and a
    // COLLADA file with one triangle list.
    out.push(("mesh_obj", "gripper.obj".into(), read("gripper.obj")));
    out.push(("mesh_obj", "bent_panel.obj".into(), read("bent_panel.obj")));
    let tris: Vec<[[f32; 3]; 3]> = match parse_mesh(&read("gripper.obj"), Path::new("gripper.obj"), Vector::splat(1.0)) {
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
    let dae = r##"<?xml version="1.0" encoding="utf-8"?>
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
    out.push(("mesh_dae", "quad.dae".into(), dae.as_bytes().to_vec()));

    // CDR: every kind the node decodes, alone and in sequences, for the workcell robot.
    let robot = workcell().checker().robot();
    let names: Vec<String> = robot.joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
    let header = |frame: &str| Header { stamp: Time { sec: 1, nanosec: 2 }, frame_id: frame.into() };
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
    let description = StringMsg { data: shapes.into() };
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

    // State lines: a joint state, a partial one, and link transforms.
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

    // Trajectories: every joint through the workcell (into a guard), a partial one, one point,
    // and refused ones (lengths, time going back, NaN, an unknown joint).
    {
        use crate::msgs::{DurationMsg, JointTrajectory, JointTrajectoryPoint};
        let point = |positions: Vec<f64>, sec: i32| JointTrajectoryPoint { positions, time_from_start: DurationMsg { sec, nanosec: 0 }, ..Default::default() };
        let request = |joint_names: Vec<String>, points: Vec<JointTrajectoryPoint>| {
            encode_cdr_le(&CheckTrajectoryRequest { trajectory: JointTrajectory { header: header("world"), joint_names, points } })
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

    // State validity requests: every joint (free), into a guard, a partial state, an unknown group,
    // and refused ones (an attached object, constraints, a multi-DOF joint, NaN, an unknown joint).
    {
        use crate::msgs::moveit::{AttachedCollisionObject, GetStateValidityRequest, JointConstraint, RobotStateMsg};
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

    // Parameters: the bundled file and the defaults written out.
    let params = std::fs::read(crate::model::bundled_config_dir().join("params.yaml")).unwrap_or_default();
    out.push(("params_yaml", "params.yaml".into(), params));
    out.push(("params_yaml", "defaults.yaml".into(), Params::default().to_yaml().into_bytes()));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_srdf_seed_parses_against_the_bundled_arm() {
        let seeds = seeds();
        let (_, _, bytes) = seeds.iter().find(|(t, _, _)| *t == "srdf").expect("an srdf seed");
        let text = std::str::from_utf8(bytes).unwrap();
        let model = crate::model::Srdf::parse(text, "seed", workcell().checker().robot()).unwrap();
        assert_eq!(model.group_names(), vec!["all", "arm", "hand"]);
        srdf(bytes);
    }

    #[test]
    fn trajectory_seeds_decode_and_reach_the_check() {
        let mut seen = 0;
        for (_, name, bytes) in seeds().into_iter().filter(|s| s.0 == "check_trajectory") {
            let request = decode_cdr::<CheckTrajectoryRequest>(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
            let a = workcell().check_trajectory(&request.trajectory);
            match name.as_str() {
                "every_joint.cdr" => assert!(a.valid || a.segment >= 0, "{name}: {a:?}"),
                "into_guard.cdr" => assert!(!a.valid && a.segment >= 0 && a.error.is_empty() && !a.contacts.is_empty(), "{name}: {a:?}"),
                "one_point.cdr" => assert!(!a.valid && a.segment == 0 && a.fraction == 0.0, "{name}: {a:?}"),
                _ => assert!(!a.valid && a.segment == -1 && !a.error.is_empty(), "{name}: {a:?}"),
            }
            seen += 1;
        }
        assert_eq!(seen, 7);
    }

    #[test]
    fn validity_seeds_decode_and_reach_the_check() {
        let mut seen = 0;
        for (_, name, bytes) in seeds().into_iter().filter(|s| s.0 == "check_state_validity") {
            let request = decode_cdr::<crate::msgs::moveit::GetStateValidityRequest>(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
            let (a, reason) = workcell().check_validity(&request);
            assert_validity_answer(&a, reason.as_deref());
            match name.as_str() {
                "every_joint.cdr" | "partial.cdr" => assert!(reason.is_none(), "{name}: {reason:?}"),
                "into_guard.cdr" | "group.cdr" => assert!(!a.valid && reason.is_none() && !a.contacts.is_empty(), "{name}: {a:?}"),
                _ => assert!(reason.is_some(), "{name}: {a:?}"),
            }
            seen += 1;
        }
        assert_eq!(seen, 9);
    }

    #[test]
    fn records_split_back() {
        let input = cdr_records(&[(CdrKind::Tf, vec![1, 2, 3]), (CdrKind::Clock, vec![])]);
        assert_eq!(split_records(&input), vec![(CdrKind::Tf, &[1u8, 2, 3][..]), (CdrKind::Clock, &[][..])]);
        // A length past the end takes the rest; a lone kind byte is an empty record.
        assert_eq!(split_records(&[4, 9, 0, 7]), vec![(CdrKind::CheckStates, &[7u8][..])]);
        assert_eq!(split_records(&[6]), vec![(CdrKind::JointStates, &[][..])]);
    }
}
