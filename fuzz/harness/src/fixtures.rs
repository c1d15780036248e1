//! What the entries share: the bundled workcell, fresh pipelines, the small scene URDF robots are
//! checked against, a scratch directory, and the note of a contained panic.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};
use thickness_collision::checker::Checker;
use thickness_collision::collision::{Scene, TargetShape};
use thickness_collision::math::{Pose, Vector};
use thickness_collision::mesh::{generate, MeshTopology, TopologySettings};
use thickness_collision::model::{InputFiles, PackageResolver, Params, RobotModel};
use thickness_collision::msgs::JointState;
use thickness_collision::pipeline::{Pipeline, RobotState};
use thickness_collision::thickness::{ThicknessArea, ThicknessSettings};

/// Printed before a panic the library contained (mesh-loader), once per message.
pub const CONTAINED_PANIC_PREFIX: &str = "fuzz_entry: contained panic:";

/// Writes to standard error once per place a contained panic comes from, and to
/// the file `FUZZ_CONTAINED_PANICS_LOG` names, if set.
pub(crate) fn note_contained_panic(error: &str) {
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
pub(crate) fn scratch_dir() -> &'static Path {
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
pub fn workcell() -> &'static Pipeline {
    static WORKCELL: OnceLock<Pipeline> = OnceLock::new();
    WORKCELL.get_or_init(|| {
        let mut p = fresh_workcell();
        let name: Vec<String> = p.checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
        let position = vec![0.0; name.len()];
        if let Err(e) = p.joint_state(&JointState { name, position, ..Default::default() }) {
            panic!("fuzz_entry: the arm's zero state is refused: {}", e.message);
        }
        p
    })
}

/// The bundled workcell as a new pipeline: nothing received yet.
pub(crate) fn fresh_workcell() -> Pipeline {
    match Pipeline::new(Params::default()) {
        Ok(p) => p,
        Err(e) => panic!("fuzz_entry: the bundled workcell does not load: {e}"),
    }
}

/// A new pipeline on the bundled robot and an empty environment: the input policy of a fresh
/// node, quick to build.
pub(crate) fn fresh_pipeline() -> Pipeline {
    static EMPTY_ENV: OnceLock<PathBuf> = OnceLock::new();
    let env = EMPTY_ENV.get_or_init(|| {
        let path = scratch_dir().join("empty_environment.urdf");
        if let Err(e) = std::fs::write(&path, "<robot name=\"empty\"><link name=\"world\"/></robot>\n") {
            panic!("fuzz_entry: cannot write {}: {e}", path.display());
        }
        path
    });
    let params = Params { input_files: InputFiles { robot: None, environment: Some(env.clone()) }, ..Params::default() };
    match Pipeline::new(params) {
        Ok(p) => p,
        Err(e) => panic!("fuzz_entry: the bundled robot does not load: {e}"),
    }
}

/// A fresh pipeline that has merged one partial joint state: the first actuated joint at 0.25,
/// so a request's joints left out come from the merged state, the others from `missing_joint`.
pub(crate) fn fresh_pipeline_with_one_joint() -> Pipeline {
    let mut pipeline = fresh_pipeline();
    let first = pipeline.checker().robot().joints.iter().find(|j| j.is_actuated()).map(|j| j.name.clone());
    if let Some(name) = first {
        let _ = pipeline.joint_state(&JointState { name: vec![name], position: vec![0.25], ..Default::default() });
    }
    pipeline
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
pub(crate) fn robot_from_text(text: &str) {
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
pub(crate) fn check_on_workcell(state: &RobotState) {
    let _ = workcell().check(state);
}
