//! The `check` command on the bundled workcell: JSON lines, the same answer from every input
//! form, and every kind of bad input as a one-line error naming it, with exit code 2.

mod common;

use std::path::PathBuf;
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn tmp(name: &str) -> PathBuf {
    common::scratch_dir("cli_check").join(name)
}

fn ok(out: Output) -> String {
    assert!(out.status.success(), "failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

fn err(out: Output, needles: &[&str]) {
    assert_eq!(out.status.code(), Some(2), "expected exit 2; stderr: {}", String::from_utf8_lossy(&out.stderr));
    let e = String::from_utf8(out.stderr).unwrap();
    let last = e.trim_end().lines().last().unwrap_or("").to_owned();
    for n in needles {
        assert!(last.contains(n), "error should name {n:?}: {last}");
    }
}

const COLLIDING: &str = "shoulder_pan_joint=0,shoulder_lift_joint=1.2,elbow_joint=0.3";

#[test]
fn json_lines_agree_across_input_forms_and_runs() {
    let joints = ok(bin().args(["check", "--joints", COLLIDING, "--json"]).output().unwrap());
    let v: serde_json::Value = serde_json::from_str(joints.trim()).unwrap();
    assert_eq!(v["in_collision"], true);
    let c = &v["contacts"][0];
    for field in ["link_name", "object_name", "triangle", "depth", "position", "normal"] {
        assert!(!c[field].is_null(), "contact lacks {field}");
    }
    assert_eq!(c["object_name"], "guard_sheet");

    // The same state in a states file, after a clear whole one with an unknown joint (a warning
    // only): the second line merges onto the first.
    let states = tmp("states.jsonl");
    std::fs::write(
        &states,
        concat!(
            r#"{"name": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint", "other_robot_joint"], "position": [0, 0, 0, 0, 0, 0, 0, 1.0]}"#,
            "\n",
            r#"{"name": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"], "position": [0, 1.2, 0.3]}"#,
            "\n",
        ),
    )
    .unwrap();
    let run = || bin().args(["check", "--states", states.to_str().unwrap(), "--json"]).output().unwrap();
    let first = run();
    let stderr = String::from_utf8_lossy(&first.stderr).to_string();
    assert!(stderr.contains("'other_robot_joint' is not a joint"), "{stderr}");
    let lines = ok(first);
    let lines: Vec<&str> = lines.lines().collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(serde_json::from_str::<serde_json::Value>(lines[0]).unwrap()["in_collision"], false);
    assert_eq!(lines[1], joints.trim(), "the same state gives the same bytes");
    assert_eq!(ok(run()), ok(run()), "deterministic");

    // Human-readable output names the link and the object.
    let text = ok(bin().args(["check", "--joints", COLLIDING]).output().unwrap());
    assert!(text.contains("IN COLLISION") && text.contains("forearm_link x guard_sheet"), "{text}");
}

#[test]
fn out_of_limits_is_flagged() {
    let out = ok(bin().args(["check", "--joints", "elbow_joint=3.0", "--json"]).output().unwrap());
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(v["out_of_limits"], serde_json::json!(["elbow_joint"]));
}

#[test]
fn thickness_and_side_override_the_parameters() {
    // The wrist ball (r = 5 cm) placed with its nearest point 1 to 3 cm behind the corrugated
    // guard sheet (surface between x = 0.54 and 0.56, front towards -x).
    let states = tmp("behind.jsonl");
    std::fs::write(&states, r#"{"transforms": [{"link": "wrist_1_link", "translation": [0.62, 0.0, 0.4], "rotation": [0, 0, 0, 1]}]}"#).unwrap();
    // Only the wrist is checked: a transforms line must place every checked link.
    let params = tmp("wrist_only.yaml");
    std::fs::write(&params, "thickness_collision:\n  ros__parameters:\n    checked_links: [wrist_1_link]\n").unwrap();
    let hit = |extra: &[&str]| -> bool {
        let out =
            ok(bin().args(["check", "--params-file", params.to_str().unwrap(), "--states", states.to_str().unwrap(), "--json"]).args(extra).output().unwrap());
        serde_json::from_str::<serde_json::Value>(out.trim()).unwrap()["in_collision"].as_bool().unwrap()
    };
    assert!(hit(&[]), "default 2 cm reaches it");
    assert!(hit(&["--thickness", "0.2"]));
    assert!(!hit(&["--thickness", "0.005"]), "5 mm does not");
    assert!(!hit(&["--side", "front"]), "front cells lie on the other side");
    assert!(hit(&["--side", "both"]));
    // With every link checked, the other links' poses are unknown: not checked, reported in
    // collision with the cause, exit 2.
    let out = bin().args(["check", "--states", states.to_str().unwrap(), "--json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_str(String::from_utf8_lossy(&out.stdout).trim()).unwrap();
    assert_eq!(v["in_collision"], true);
    assert!(v["error"].as_str().unwrap().contains("does not reach world_frame"), "{v}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 1"));
}

#[test]
fn bad_input_is_a_clear_error() {
    // Malformed XML.
    let bad_xml = tmp("bad.urdf");
    std::fs::write(&bad_xml, "<robot name='x'><link name='a'></robot>").unwrap();
    err(bin().args(["check", "--robot", bad_xml.to_str().unwrap(), "--joints", "a=0"]).output().unwrap(), &["bad.urdf", "malformed"]);
    // Unknown package.
    let pkg = tmp("pkg.urdf");
    std::fs::write(
        &pkg,
        r#"<robot name="x"><link name="a"><collision><geometry><mesh filename="package://no_such_pkg/m.stl"/></geometry></collision></link></robot>"#,
    )
    .unwrap();
    err(
        bin()
            .args(["check", "--robot", pkg.to_str().unwrap(), "--joints", "a=0"])
            .env("AMENT_PREFIX_PATH", "/nonexistent_prefix")
            .env_remove("ROS_PACKAGE_PATH")
            .output()
            .unwrap(),
        &["package://no_such_pkg/m.stl", "'no_such_pkg'", "/nonexistent_prefix/share/no_such_pkg"],
    );
    // Missing mesh file.
    let missing = tmp("missing.urdf");
    std::fs::write(&missing, r#"<robot name="x"><link name="a"><collision><geometry><mesh filename="nowhere.stl"/></geometry></collision></link></robot>"#)
        .unwrap();
    err(bin().args(["check", "--robot", missing.to_str().unwrap(), "--joints", "a=0"]).output().unwrap(), &["link 'a'", "nowhere.stl"]);
    // A mesh with NaN.
    std::fs::write(tmp("nan.obj"), "v 0 0 0\nv 1 nan 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n").unwrap();
    let nan = tmp("nan.urdf");
    std::fs::write(&nan, r#"<robot name="x"><link name="a"><collision><geometry><mesh filename="nan.obj"/></geometry></collision></link></robot>"#).unwrap();
    err(bin().args(["check", "--robot", nan.to_str().unwrap(), "--joints", "a=0"]).output().unwrap(), &["link 'a'", "nan.obj", "non-finite"]);
    // Unknown parameter key.
    let params = tmp("params.yaml");
    std::fs::write(&params, "thickness_collision:\n  ros__parameters:\n    default_thicknes: 0.01\n").unwrap();
    err(bin().args(["check", "--params-file", params.to_str().unwrap(), "--joints", "elbow_joint=0"]).output().unwrap(), &["params.yaml", "default_thicknes"]);
    // A joint name in --joints not in the model, and a NaN position.
    err(bin().args(["check", "--joints", "elbow_jiont=0.1"]).output().unwrap(), &["--joints", "'elbow_jiont'"]);
    err(bin().args(["check", "--joints", "elbow_joint=nan"]).output().unwrap(), &["elbow_joint", "non-finite"]);
    // A JSON line that is not a state, and unequal lengths.
    let states = tmp("bad.jsonl");
    std::fs::write(&states, "{\"name\": [\"elbow_joint\"], \"position\": [0.1]}\n{\"hello\": 1}\n").unwrap();
    err(bin().args(["check", "--states", states.to_str().unwrap()]).output().unwrap(), &["bad.jsonl", "line 2", "keys [hello]", "expected {\"name\""]);
    std::fs::write(&states, "{\"name\": [\"elbow_joint\"], \"position\": [0.1, 0.2]}\n").unwrap();
    err(bin().args(["check", "--states", states.to_str().unwrap()]).output().unwrap(), &["line 1", "1 names but 2 positions"]);
    // missing_joint: reject.
    std::fs::write(&params, "thickness_collision:\n  ros__parameters:\n    missing_joint: reject\n").unwrap();
    err(bin().args(["check", "--params-file", params.to_str().unwrap(), "--joints", "elbow_joint=0"]).output().unwrap(), &["lacks joint"]);
}

/// A `package://` path that leaves its package: the reason is said once, and so is every part of
/// the chain that leads to it (a `Display` that embeds its `#[source]` repeats under `{:#}`).
#[test]
fn package_escape_is_reported_once() {
    let pkg = tmp("pkg");
    std::fs::create_dir_all(&pkg).unwrap();
    let params = tmp("escape_params.yaml");
    std::fs::write(&params, format!("thickness_collision:\n  ros__parameters:\n    package_map: [\"pkg={}\"]\n", pkg.display())).unwrap();
    let uri = "package://pkg/../../etc/passwd.stl";
    let robot = tmp("escape.urdf");
    std::fs::write(
        &robot,
        format!(
            r#"<robot name="escape"><link name="base"/><link name="arm"><collision><geometry><mesh filename="{uri}"/></geometry></collision></link>
<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#
        ),
    )
    .unwrap();
    let out = bin().args(["check", "--params-file", params.to_str().unwrap(), "--robot", robot.to_str().unwrap(), "--joints", "j=0"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    err(out, &["escape.urdf", "link 'arm'", uri, "leaves its package"]);
    let last = stderr.trim_end().lines().last().unwrap_or("");
    for phrase in ["leaves its package", "cannot resolve", uri, "escape.urdf"] {
        assert_eq!(last.matches(phrase).count(), 1, "{phrase:?} once in: {last}");
    }
}

/// A file that cannot be opened: the OS's reason once.
#[test]
fn missing_states_file_is_reported_once() {
    let missing = tmp("no_such_states.jsonl");
    let out = bin().args(["check", "--states", missing.to_str().unwrap()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    err(out, &["no_such_states.jsonl"]);
    let last = stderr.trim_end().lines().last().unwrap_or("");
    assert_eq!(last.matches("No such file").count(), 1, "{last}");
}

/// A robot whose joints are all fixed has one pose, which any joint state stands for: `--joints`
/// naming its fixed joint and every line of a states file (even an empty state) are checked as
/// that pose, with the same answer.
#[test]
fn a_robot_without_actuated_joints_checks_its_one_pose() {
    let robot = tmp("fixed_only.urdf");
    std::fs::write(
        &robot,
        r#"<robot name="fixed_only"><link name="base"/><link name="arm"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link><joint name="f" type="fixed"><parent link="base"/><child link="arm"/></joint></robot>"#,
    )
    .unwrap();
    let env = tmp("fixed_only_env.urdf");
    std::fs::write(
        &env,
        r#"<robot name="cell"><link name="world"/><link name="block"><collision><origin xyz="0.25 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link><joint name="j" type="fixed"><parent link="world"/><child link="block"/></joint></robot>"#,
    )
    .unwrap();
    let (r, e) = (robot.to_str().unwrap(), env.to_str().unwrap());
    let joints = ok(bin().args(["check", "--robot", r, "--environment", e, "--joints", "f=0", "--json"]).output().unwrap());
    let v: serde_json::Value = serde_json::from_str(joints.trim()).unwrap();
    assert_eq!((&v["in_collision"], &v["contacts"][0]["object_name"]), (&serde_json::json!(true), &serde_json::json!("block")), "{v}");
    let states = tmp("fixed_only.jsonl");
    std::fs::write(&states, "{\"name\": [\"f\"], \"position\": [0]}\n{\"name\": [], \"position\": []}\n").unwrap();
    let lines = ok(bin().args(["check", "--robot", r, "--environment", e, "--states", states.to_str().unwrap(), "--json"]).output().unwrap());
    let lines: Vec<&str> = lines.lines().collect();
    assert_eq!(lines, [joints.trim(), joints.trim()], "every state is the one pose");
}

/// `check --trajectory` on a trajectory written the way `ros2 topic pub` examples write one for a
/// UR arm's `joint_trajectory_controller` (flow style, quoted names, `time_from_start: {sec: 3}`
/// with `nanosec` left out, a header with only `stamp: {sec: 0}`): read as ROS 2 reads it (a field
/// left out is 0), the same answer as the trajectory written out in full. Such a trajectory names
/// only the arm's joints: without the gripper's it is refused, the error saying which joint and
/// that `--joints` gives it; with them in `--joints` (the arm starting at the first point) it is
/// checked, the same as from a `--joints` that names every joint.
#[test]
fn a_trajectory_as_ros2_topic_pub_examples_write_it_is_read_as_ros_reads_it() {
    let arm = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"];
    let (first, last) = ([0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.2, 0.3, 0.0, 0.0, 0.0]);
    let list = |xs: &[f64]| xs.iter().map(|x| format!("{x:.1}")).collect::<Vec<_>>().join(", ");
    let names = arm.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(",\n    ");
    let short = tmp("pub_example.yaml");
    std::fs::write(
        &short,
        format!(
            "{{\n  header: {{stamp: {{sec: 0}}}},\n  joint_names: [\n    {names}\n  ],\n  points: [\n    {{positions: [{}], time_from_start: {{sec: 1}}}},\n    {{positions: [{}], time_from_start: {{sec: 3}}}}\n  ]\n}}\n",
            list(&first),
            list(&last)
        ),
    )
    .unwrap();
    let full = tmp("pub_example_full.json");
    let point = |p: &[f64], sec: i32| serde_json::json!({"positions": p, "velocities": [], "accelerations": [], "effort": [], "time_from_start": {"sec": sec, "nanosec": 0}});
    let message =
        serde_json::json!({"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "joint_names": arm, "points": [point(&first, 1), point(&last, 3)]});
    std::fs::write(&full, message.to_string()).unwrap();

    err(bin().args(["check", "--trajectory", short.to_str().unwrap(), "--json"]).output().unwrap(), &["pub_example.yaml", "finger_left_joint", "--joints"]);
    let gripper = "finger_left_joint=0,finger_right_joint=0";
    let everything = format!("{gripper},{}", arm.iter().zip(first).map(|(n, x)| format!("{n}={x}")).collect::<Vec<_>>().join(","));
    let answer = ok(bin().args(["check", "--trajectory", short.to_str().unwrap(), "--json", "--joints", gripper]).output().unwrap());
    let written_out = ok(bin().args(["check", "--trajectory", full.to_str().unwrap(), "--json", "--joints", &everything]).output().unwrap());
    assert_eq!(answer, written_out);
    let v: serde_json::Value = serde_json::from_str(answer.trim()).unwrap();
    // The arm swings into the colliding pose of `COLLIDING`: met on the way, after the first
    // point (1 s) and no later than the last (3 s).
    assert_eq!((v["in_collision"].as_bool(), v["error"].as_str()), (Some(true), Some("")), "{v}");
    let time = v["time"].as_f64().unwrap();
    assert!(time > 1.0 && time <= 3.0, "{v}");
}

/// `check --trajectory` on a `FollowJointTrajectory` goal (as `ros2 action send_goal` takes one):
/// its trajectory checked in the tube its `path_tolerance` gives, the same answer as the bare
/// trajectory with that tube in `--path-tolerance`; a tolerance of 0 (the controller's default,
/// unknown here) warned about and no tube for that joint; -1 (no bound: no tube to prove) refused
/// with exit 2, unless `--path-tolerance` gives the tube instead.
#[test]
fn a_follow_joint_trajectory_goal_is_checked_in_its_tube() {
    let names = "[shoulder_pan_joint, shoulder_lift_joint, elbow_joint, wrist_1_joint, wrist_2_joint, wrist_3_joint, finger_left_joint, finger_right_joint]";
    let points = "  points:\n  - positions: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n    time_from_start: {sec: 1}\n  - positions: [0.0, 0.3, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0]\n    time_from_start: {sec: 3}\n";
    let bare = tmp("goal_bare.yaml");
    std::fs::write(&bare, format!("joint_names: {names}\n{}", points.replace("\n  ", "\n").trim_start())).unwrap();
    let goal = |name: &str, lift: &str| {
        let path = tmp(name);
        let text = format!(
            "trajectory:\n  joint_names: {names}\n{points}path_tolerance:\n- {{name: elbow_joint, position: 0.0, velocity: 0.0, acceleration: 0.0}}\n- {{name: shoulder_lift_joint, position: {lift}, velocity: 0.0, acceleration: 0.0}}\ngoal_tolerance: []\ngoal_time_tolerance: {{sec: 0, nanosec: 0}}\n"
        );
        std::fs::write(&path, text).unwrap();
        path
    };
    let run = |file: &PathBuf, tube: Option<&str>| {
        let mut cmd = bin();
        cmd.args(["check", "--trajectory", file.to_str().unwrap(), "--json"]);
        if let Some(tube) = tube {
            cmd.args(["--path-tolerance", tube]);
        }
        cmd.output().unwrap()
    };
    let mut answers = Vec::new();
    for lift in ["0.05", "0.9"] {
        let from_goal = run(&goal(&format!("goal_{lift}.yaml"), lift), None);
        let stderr = String::from_utf8_lossy(&from_goal.stderr).into_owned();
        assert!(stderr.contains("warning:") && stderr.contains("'elbow_joint' is 0") && stderr.contains("--path-tolerance"), "{stderr}");
        let from_goal = ok(from_goal);
        assert_eq!(from_goal, ok(run(&bare, Some(&format!("0,{lift},0,0,0,0,0,0")))), "tolerance {lift}");
        answers.push(from_goal);
    }
    // The tube reaches something the narrow one does not: the goal's tolerance is used.
    assert_ne!(answers[0], answers[1]);
    let unbounded = goal("goal_unbounded.yaml", "-1.0");
    err(run(&unbounded, None), &["goal_unbounded.yaml", "'shoulder_lift_joint' is -1", "--path-tolerance"]);
    assert_eq!(ok(run(&unbounded, Some("0,0.9,0,0,0,0,0,0"))), answers[1]);
}
