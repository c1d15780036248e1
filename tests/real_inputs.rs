//! Inputs nobody on this project wrote, tried as a new user would: MoveIt's xacro configurations
//! (moveit_resources, and the same expanded by PyPI's `xacro`), example-robot-data's Panda, robots
//! with nothing to check, joint states of another robot, partial streams, an SRDF for a robot
//! that comes in a bag, and the binary away from its source tree. Each either refuses with a
//! one-line error (exit 2) or answers honestly; none reports a state free that was never checked.

mod common;

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_thickness_collision"));
    // `run` must never reach past loopback, even when a test expects it to stop at start.
    c.env("ROS_LOCALHOST_ONLY", "1").env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST");
    c
}

fn dir(name: &str) -> PathBuf {
    common::emptied(common::scratch_subdir("real_inputs", name))
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/moveit_resources").join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Exit 2 with a last stderr line naming every needle; the line is returned.
fn refused(out: Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "expected exit 2; stdout: {} stderr: {stderr}", String::from_utf8_lossy(&out.stdout));
    let last = stderr.trim_end().lines().last().unwrap_or("").to_owned();
    for n in needles {
        assert!(last.contains(n), "the error should name {n:?}: {last}");
    }
    last
}

fn ok(out: Output) -> (String, String) {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "failed ({:?}): {stderr}", out.status.code());
    (String::from_utf8(out.stdout).unwrap(), stderr)
}

fn params_file(d: &Path, name: &str, body: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(&p, format!("thickness_collision:\n  ros__parameters:\n{body}")).unwrap();
    p
}

/// Every actuated joint of the bundled arm, at `q` (six arm joints, two fingers).
const ARM: [&str; 8] =
    ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint", "finger_right_joint"];

fn write_bag(path: &Path, messages: &[Value], description: Option<String>) {
    let _ = common::run_peer("bag_tool.py", &json!({"op": "write", "path": path, "storage": "mcap", "messages": messages, "robot_description": description}));
}

const T0: i64 = 1_700_000_000_000_000_000;

fn joint_messages(names: &[&str], states: &[Vec<f64>]) -> Vec<Value> {
    states
        .iter()
        .enumerate()
        .map(|(k, p)| json!({"t": T0 + k as i64 * 10_000_000, "stamp": T0 + k as i64 * 10_000_000, "name": names, "position": p}))
        .collect()
}

#[test]
fn moveit_xacro_files_are_refused_with_the_command_that_expands_them() {
    for file in ["panda.urdf.xacro", "fanuc.urdf.xacro"] {
        let out = bin().args(["check", "--robot", s(&fixture(file)), "--joints", "panda_joint1=0"]).output().unwrap();
        refused(out, &[file, "unexpanded xacro", "xacro ", "> robot.urdf", "robot_description"]);
    }
    // Recognised by what it holds, under a plain name too: the element and its line.
    let d = dir("xacro");
    let renamed = d.join("panda_config.urdf");
    std::fs::copy(fixture("panda.urdf.xacro"), &renamed).unwrap();
    refused(bin().args(["check", "--robot", s(&renamed), "--joints", "panda_joint1=0"]).output().unwrap(), &["panda_config.urdf", "line 3", "<xacro:arg>"]);

    // MoveIt's SRDF as its config ships it, for the Panda of example-robot-data.
    let (panda, map) = common::erd_robot("panda_description/urdf/panda.urdf");
    let params = params_file(&d, "panda.yaml", &format!("    package_map: [\"{}\"]\n", map[0]));
    let panda_check = |srdf: &Path| {
        bin().args(["check", "--params-file", s(&params), "--robot", s(&panda), "--srdf", s(srdf), "--joints", "panda_joint1=0"]).output().unwrap()
    };
    refused(panda_check(&fixture("panda_arm.srdf.xacro")), &["panda_arm.srdf.xacro", "unexpanded xacro", "> robot.srdf"]);

    // Expanded by the real xacro (PyPI), the same macro is an SRDF that fits the Panda: its
    // disable_collisions are used. (The shipped file includes its macro through `$(find ...)`,
    // which needs a ROS install; the wrapper includes it by path.)
    std::fs::copy(fixture("panda_arm.xacro"), d.join("panda_arm.xacro")).unwrap();
    let wrapper = d.join("panda_arm_local.srdf.xacro");
    std::fs::write(
        &wrapper,
        "<?xml version=\"1.0\"?>\n<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\" name=\"panda\">\n  <xacro:include filename=\"panda_arm.xacro\"/>\n  <xacro:panda_arm/>\n</robot>\n",
    )
    .unwrap();
    let expanded = d.join("panda_arm.srdf");
    let x = Command::new(common::python())
        .args(["-c", "import sys, xacro; sys.argv[0] = 'xacro'; xacro.main()", s(&wrapper), "-o", s(&expanded)])
        .output()
        .unwrap();
    assert!(x.status.success(), "xacro: {}", String::from_utf8_lossy(&x.stderr));
    let (out, stderr) = ok(panda_check(&expanded));
    assert!(stderr.contains("(SRDF ") && stderr.contains("panda_arm.srdf"), "{stderr}");
    assert!(out.contains("free") || out.contains("IN COLLISION"), "{out}");
    // example-robot-data's plain Panda declares xmlns:xacro and is no xacro.
    let text = std::fs::read_to_string(&panda).unwrap();
    assert!(text.contains("xmlns:xacro"), "the case this guards: a namespace declaration alone");
}

#[test]
fn a_robot_with_nothing_to_check_is_refused_at_start() {
    let d = dir("nothing");
    let visual_only = d.join("visual_only.urdf");
    std::fs::write(
        &visual_only,
        r#"<robot name="shown_only">
  <link name="base"><visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link>
  <link name="arm"><visual><geometry><cylinder radius="0.05" length="0.5"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#,
    )
    .unwrap();
    let bag = d.join("bag");
    write_bag(&bag, &joint_messages(&["j1"], &[vec![0.0], vec![0.5]]), None);
    let nothing = params_file(&d, "nothing.yaml", "    checked_links: [\"no_such_link*\"]\n");
    let cases: [(&[&str], &[&str]); 2] = [
        (&["--robot", s(&visual_only)], &["visual_only.urdf", "'shown_only' has no link to check", "use_visual_when_no_collision: true"]),
        (&["--params-file", s(&nothing)], &["robot.urdf", "checked_links", "no_such_link*", "matches none"]),
    ];
    for (model, needles) in cases {
        refused(bin().arg("check").args(model).args(["--joints", "j1=0"]).output().unwrap(), needles);
        refused(bin().args(["replay", s(&bag)]).args(model).output().unwrap(), needles);
        refused(bin().arg("run").args(model).output().unwrap(), needles);
    }
    // With its visuals checked, the same robot is checked.
    let visual = params_file(&d, "visual.yaml", "    use_visual_when_no_collision: true\n");
    let (out, _) = ok(bin().args(["check", "--params-file", s(&visual), "--robot", s(&visual_only), "--joints", "j1=0", "--json"]).output().unwrap());
    let v: Value = serde_json::from_str(out.trim()).unwrap();
    assert!(v["error"].as_str().unwrap_or("").is_empty(), "{v}");

    // A robot_description with nothing to check, in a bag: refused, the arm stays and its own
    // states are checked.
    let description = std::fs::read_to_string(&visual_only).unwrap();
    let arm_bag = d.join("arm_bag");
    write_bag(&arm_bag, &joint_messages(&ARM, &[vec![0.0; 8], vec![0.1; 8]]), Some(description));
    let (out, stderr) = ok(bin().args(["replay", s(&arm_bag), "--jsonl", s(&d.join("arm.jsonl"))]).output().unwrap());
    assert!(stderr.contains("refused") && stderr.contains("no link to check"), "{stderr}");
    assert!(out.contains("robot descriptions: 0 applied, 1 refused"), "{out}");
    assert!(out.contains("states: 2,"), "{out}");
}

#[test]
fn states_of_another_robot_are_never_reported_free() {
    let d = dir("foreign");
    // A check --states line naming none of the arm's joints, and an empty one: each fails closed
    // in its place, with the cause.
    let states = d.join("foreign.jsonl");
    std::fs::write(
        &states,
        format!(
            "{}\n{}\n{}\n",
            json!({"name": ["panda_joint1", "panda_joint2"], "position": [0.0, 0.3]}),
            json!({"name": [], "position": []}),
            json!({"name": ARM, "position": vec![0.0; 8]})
        ),
    )
    .unwrap();
    let out = bin().args(["check", "--states", s(&states), "--json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<Value> = String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["in_collision"], true);
    assert!(lines[0]["error"].as_str().unwrap().contains("names none of the 7 moving joints"), "{}", lines[0]);
    assert_eq!(lines[1]["in_collision"], true);
    assert!(lines[1]["error"].as_str().unwrap().contains("names no joint"), "{}", lines[1]);
    assert_eq!(lines[2]["error"], "", "the arm's own state is checked");

    // A bag of another robot: every message skipped as not ours, none reported.
    let bag = d.join("panda_bag");
    write_bag(&bag, &joint_messages(&["panda_joint1", "panda_joint2"], &[vec![0.0, 0.1], vec![0.2, 0.3], vec![0.4, 0.5]]), None);
    let jsonl = d.join("panda.jsonl");
    let out = bin().args(["replay", s(&bag), "--jsonl", s(&jsonl)]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(stdout.contains("3 x not_our_robot"), "{stdout} {}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read_to_string(&jsonl).unwrap_or_default(), "", "no report for a state never checked");
}

#[test]
fn last_waits_for_every_joint_that_moves_a_checked_link() {
    let d = dir("last");
    // The colliding state of the README, given in two messages.
    let full = json!({"name": ARM, "position": [0.0, 1.2, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0]});
    let lines = [json!({"name": &ARM[..3], "position": [0.0, 1.2, 0.3]}), json!({"name": &ARM[3..], "position": vec![0.0; 5]})];
    let states = d.join("split.jsonl");
    std::fs::write(&states, format!("{}\n{}\n", lines[0], lines[1])).unwrap();
    let run = |extra: &[&str]| {
        let out = bin().args(["check", "--states", s(&states), "--json"]).args(extra).output().unwrap();
        let code = out.status.code();
        (code, String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str::<Value>(l).unwrap()).collect::<Vec<_>>())
    };
    let (code, got) = run(&[]);
    assert_eq!(code, Some(2), "a line that could not be checked");
    assert_eq!(got[0]["in_collision"], true);
    let why = got[0]["error"].as_str().unwrap();
    assert!(why.contains("'wrist_1_joint' (and 3 more) never received") && why.contains("missing_joint: last"), "{why}");
    let whole = d.join("whole.jsonl");
    std::fs::write(&whole, format!("{full}\n")).unwrap();
    let (want, _) = ok(bin().args(["check", "--states", s(&whole), "--json"]).output().unwrap());
    let want: Value = serde_json::from_str(want.trim()).unwrap();
    assert_eq!(want["in_collision"], true);
    assert_eq!(got[1], want, "once complete, the merged state is the whole one");

    // Only the joints that move a checked link are waited for.
    let upper = params_file(&d, "upper.yaml", "    checked_links: [upper_arm_link]\n");
    let (code, got) = run(&["--params-file", s(&upper)]);
    assert_eq!(code, Some(0), "{got:?}");
    assert_eq!(got[0]["error"], "", "shoulder_pan and shoulder_lift move upper_arm_link; both were given");

    // `zero` keeps its meaning: what a message lacks is at 0.
    let zero = params_file(&d, "zero.yaml", "    missing_joint: zero\n");
    let (code, got) = run(&["--params-file", s(&zero)]);
    assert_eq!(code, Some(0));
    assert_eq!(got[0], want, "the first three joints, the others at 0: the same pose");
}

#[test]
fn an_srdf_for_the_recorded_robot_is_checked_against_it() {
    let d = dir("srdf");
    let config = thickness_collision::model::bundled_config_dir();
    // The bundled arm under other names, as another robot's description would come.
    let urdf = std::fs::read_to_string(config.join("example_workcell/robot.urdf"))
        .unwrap()
        .replace("filename=\"gripper.obj\"", &format!("filename=\"file://{}\"", config.join("example_workcell/gripper.obj").display()));
    let renamed = urdf
        .replace("<link name=\"", "<link name=\"r2_")
        .replace("<joint name=\"", "<joint name=\"r2_")
        .replace(" link=\"", " link=\"r2_")
        .replace(" joint=\"", " joint=\"r2_");
    let names: Vec<String> = ARM.iter().map(|j| format!("r2_{j}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let bag = d.join("bag");
    write_bag(&bag, &joint_messages(&names, &[vec![0.0; 8], vec![0.05; 8]]), Some(renamed));
    let srdf = d.join("r2.srdf");
    std::fs::write(&srdf, "<robot name=\"r2_arm\"><disable_collisions link1=\"r2_base_link\" link2=\"r2_shoulder_link\" reason=\"Adjacent\"/></robot>")
        .unwrap();
    let (out, stderr) = ok(bin().args(["replay", s(&bag), "--srdf", s(&srdf)]).output().unwrap());
    assert!(out.contains("robot descriptions: 1 applied, 0 refused") && out.contains("states: 2,"), "{out} {stderr}");

    // One that fits neither robot is refused, with both named.
    let wrong = d.join("wrong.srdf");
    std::fs::write(&wrong, "<robot name=\"x\"><disable_collisions link1=\"panda_link0\" link2=\"panda_link1\"/></robot>").unwrap();
    let last = refused(bin().args(["replay", s(&bag), "--srdf", s(&wrong)]).output().unwrap(), &["wrong.srdf", "/robot_description"]);
    assert!(last.contains("fits neither"), "{last}");
    // Where no description can come, it is checked against the robot at once.
    refused(bin().args(["check", "--srdf", s(&srdf), "--joints", "elbow_joint=0"]).output().unwrap(), &["r2.srdf", "r2_base_link"]);
}

#[test]
fn an_installed_binary_finds_the_workcell_under_its_prefix() {
    let d = dir("prefix");
    std::fs::create_dir_all(d.join("bin")).unwrap();
    let exe = d.join("bin/thickness_collision");
    std::fs::copy(env!("CARGO_BIN_EXE_thickness_collision"), &exe).unwrap();
    let share = d.join("share/thickness_collision/config/example_workcell");
    std::fs::create_dir_all(&share).unwrap();
    let config = thickness_collision::model::bundled_config_dir();
    for e in std::fs::read_dir(config.join("example_workcell")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), share.join(e.file_name())).unwrap();
    }
    std::fs::copy(config.join("params.yaml"), share.parent().unwrap().join("params.yaml")).unwrap();
    let out = Command::new(&exe)
        .args(["check", "--joints", "shoulder_pan_joint=0,shoulder_lift_joint=1.2,elbow_joint=0.3", "--json"])
        .env_remove("THICKNESS_COLLISION_CONFIG")
        .current_dir(&d)
        .output()
        .unwrap();
    let (stdout, stderr) = ok(out);
    assert!(stderr.contains(&format!("{}", share.join("robot.urdf").display())), "{stderr}");
    assert_eq!(serde_json::from_str::<Value>(stdout.trim()).unwrap()["in_collision"], true);
}
