//! The pipeline without DDS: merging, `missing_joint`, TF with a prefix, run-time parameters.

use super::{Pipeline, SkipCause};
use crate::checker::{Checker, StateReport};
use crate::math::pose_from_isometry;
use crate::model::{MissingJoint, Params};
use crate::msgs::{Header, JointState, Quaternion, TfMessage, Time, Transform, TransformStamped, Vector3};
use nalgebra::Isometry3;

const ARM: [&str; 7] = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];

fn js(names: &[&str], positions: &[f64], ns: i64) -> JointState {
    JointState {
        header: Header { stamp: Time::from_nanos(ns), frame_id: String::new() },
        name: names.iter().map(|s| s.to_string()).collect(),
        position: positions.to_vec(),
        ..Default::default()
    }
}

fn pipeline(params: Params) -> Pipeline {
    Pipeline::new(params).unwrap()
}

/// A colliding pose of the bundled arm (the forearm reaches into the guard) and a clear one.
fn poses() -> ([f64; 7], [f64; 7]) {
    let checker = Checker::from_params(Params::default()).unwrap();
    let names: Vec<String> = ARM.iter().map(|s| s.to_string()).collect();
    let mut colliding = None;
    let mut clear = None;
    for k in 0..200 {
        let x = k as f64;
        let q = [(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02];
        let r = checker.check_joints(&names, &q).unwrap();
        if r.in_collision && colliding.is_none() {
            colliding = Some(q);
        }
        if !r.in_collision && clear.is_none() {
            clear = Some(q);
        }
    }
    (colliding.unwrap(), clear.unwrap())
}

#[test]
fn partial_states_from_two_publishers_merge_under_last() {
    let (hit, _) = poses();
    let mut p = pipeline(Params::default());
    assert_eq!(p.params().missing_joint, MissingJoint::Last, "the default merges, as robot_state_publisher does");
    // The arm publisher, then the gripper publisher. Until the gripper's joint arrived the state
    // is not known (MoveIt's current state monitor waits likewise): no state, counted.
    let a = p.joint_state(&js(&ARM[..6], &hit[..6], 1)).unwrap_err();
    assert_eq!(a.cause, SkipCause::Incomplete);
    assert!(a.message.contains("'finger_left_joint' never received"), "{}", a.message);
    let b = p.joint_state(&js(&ARM[6..], &hit[6..], 2)).unwrap();
    let whole = pipeline(Params::default()).joint_state(&js(&ARM, &hit, 2)).unwrap();
    assert_eq!(b, whole, "merged partial states equal the whole state");
    assert!(p.check(&b).report.in_collision);
    assert_eq!(p.check(&b).stamp, Time::from_nanos(2));
    // From then on every partial message gives a state: the rest comes from the merge.
    let (_, clear) = poses();
    let c = p.joint_state(&js(&ARM[..6], &clear[..6], 3)).unwrap();
    let mut both = clear;
    both[6..].copy_from_slice(&hit[6..]);
    assert_eq!(c, pipeline(Params::default()).joint_state(&js(&ARM, &both, 3)).unwrap());
    assert_eq!(p.skipped().get(&SkipCause::Incomplete), Some(&1));
}

#[test]
fn last_waits_only_for_the_joints_that_move_a_checked_link() {
    let (hit, _) = poses();
    // The forearm is moved by the first three joints alone.
    let mut p = pipeline(Params { checked_links: vec!["forearm_link".into()], ..Params::default() });
    let a = p.joint_state(&js(&ARM[..2], &hit[..2], 1)).unwrap_err();
    assert!(a.message.contains("'elbow_joint' never received"), "{}", a.message);
    assert!(p.joint_state(&js(&ARM[2..3], &hit[2..3], 2)).is_ok());
}

#[test]
fn another_robots_joint_states_are_skipped_on_every_mode() {
    for missing in [MissingJoint::Last, MissingJoint::Zero, MissingJoint::Reject] {
        let mut p = pipeline(Params { missing_joint: missing, ..Params::default() });
        for names in [&["panda_joint1", "panda_joint2"][..], &[]] {
            let skip = p.joint_state(&js(names, &vec![0.0; names.len()], 1)).unwrap_err();
            assert_eq!(skip.cause, SkipCause::NotOurRobot, "{missing:?} {names:?}");
        }
        // A fixed or mimic joint alone moves nothing either.
        let skip = p.joint_state(&js(&["finger_right_joint", "tool0_joint"], &[0.0, 0.0], 1)).unwrap_err();
        assert_eq!(skip.cause, SkipCause::NotOurRobot);
        assert_eq!(p.skipped().get(&SkipCause::NotOurRobot), Some(&3));
        // check_states slots: empty and foreign states fail closed with the cause.
        let foreign = js(&["panda_joint1"], &[0.0], 1);
        let reports = p.check_request(&[js(&[], &[], 1), foreign]);
        assert!(reports[0].in_collision && reports[0].error.contains("names no joint"), "{:?}", reports[0]);
        assert!(reports[1].in_collision && reports[1].error.contains("'panda_joint1' is not a joint"), "{:?}", reports[1]);
    }
}

#[test]
fn zero_checks_each_message_alone_and_reject_waits_for_every_joint() {
    let (hit, _) = poses();
    let zero = Params { missing_joint: MissingJoint::Zero, ..Params::default() };
    let mut p = pipeline(zero);
    let _ = p.joint_state(&js(&ARM, &hit, 1)).unwrap();
    let alone = p.joint_state(&js(&ARM[6..], &hit[6..], 2)).unwrap();
    let fresh = pipeline(Params { missing_joint: MissingJoint::Zero, ..Params::default() }).joint_state(&js(&ARM[6..], &hit[6..], 2)).unwrap();
    assert_eq!(alone, fresh, "under zero a message does not inherit earlier ones");

    let mut p = pipeline(Params { missing_joint: MissingJoint::Reject, ..Params::default() });
    let skip = p.joint_state(&js(&ARM[..6], &hit[..6], 1)).unwrap_err();
    assert_eq!(skip.cause, SkipCause::MissingJoint);
    assert!(skip.message.contains("finger_left_joint"), "{}", skip.message);
    assert!(p.joint_state(&js(&ARM[6..], &hit[6..], 2)).is_ok(), "complete once the gripper arrived");
    assert_eq!(p.skipped().get(&SkipCause::MissingJoint), Some(&1));
}

#[test]
fn bad_messages_are_skipped_counted_and_not_merged() {
    let (hit, clear) = poses();
    let mut p = pipeline(Params::default());
    let good = p.joint_state(&js(&ARM, &clear, 1)).unwrap();
    let nan = p.joint_state(&js(&ARM[..1], &[f64::NAN], 2)).unwrap_err();
    assert_eq!(nan.cause, SkipCause::NonFinite);
    let lengths = p.joint_state(&js(&ARM[..2], &hit[..1], 3)).unwrap_err();
    assert_eq!(lengths.cause, SkipCause::Lengths);
    // A message with a bad position changes nothing: the next partial state merges onto `good`.
    let after = p.joint_state(&js(&ARM[..1], &clear[..1], 4)).unwrap();
    let report = |s| StateReport { check_seconds: 0.0, ..p.check(s).report };
    assert_eq!(report(&after), report(&good));
    // Unknown names: ignored, warned once each; a NaN on another robot's joint is not ours.
    let other = p.joint_state(&js(&["other_robot_joint", ARM[0]], &[f64::NAN, clear[0]], 5));
    assert!(other.is_ok());
    // A message of unknown names alone is another robot's: skipped, and it breaks no trail.
    assert_eq!(p.joint_state(&js(&["other_robot_joint"], &[1.0], 6)).unwrap_err().cause, SkipCause::NotOurRobot);
    let warnings = p.take_warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("other_robot_joint"));
    assert_eq!(p.skipped().values().sum::<u64>(), 3);
}

fn tf_message(prefix: &str, world: &str, checker: &Checker, q: &[f64], ns: i64) -> TfMessage {
    let mut full = vec![0.0; checker.robot().joints.len()];
    for (n, v) in ARM.iter().zip(q) {
        full[checker.robot().joint(n).unwrap()] = *v;
    }
    let poses = checker.robot().forward_kinematics(&full, &Isometry3::identity()).unwrap();
    let transforms = checker
        .targets()
        .iter()
        .map(|t| {
            let p = pose_from_isometry(&poses[t.link]);
            TransformStamped {
                header: Header { stamp: Time::from_nanos(ns), frame_id: world.into() },
                child_frame_id: format!("{prefix}{}", t.name),
                transform: Transform {
                    translation: Vector3 { x: p.translation.x, y: p.translation.y, z: p.translation.z },
                    rotation: Quaternion { x: p.rotation.x, y: p.rotation.y, z: p.rotation.z, w: p.rotation.w },
                },
            }
        })
        .collect();
    TfMessage { transforms }
}

#[test]
fn tf_with_a_prefix_gives_the_joint_state_answer_and_foreign_frames_are_skipped() {
    let (hit, _) = poses();
    let params = Params { frame_prefix: "robot1/".into(), ..Params::default() };
    let mut p = pipeline(params);
    let checker = Checker::from_params(Params::default()).unwrap();
    let by_joints = pipeline(Params::default()).check(&pipeline(Params::default()).joint_state(&js(&ARM, &hit, 7)).unwrap());
    let state = p.tf(&tf_message("robot1/", "world", &checker, &hit, 7)).unwrap();
    let by_tf = p.check(&state);
    assert_eq!(by_tf.stamp, Time::from_nanos(7));
    assert!(by_tf.report.in_collision);
    assert_eq!(by_tf.report.contacts.len(), by_joints.report.contacts.len());
    for (a, b) in by_tf.report.contacts.iter().zip(&by_joints.report.contacts) {
        assert_eq!(a.link_name, b.link_name);
        assert!((a.depth - b.depth).abs() < 1e-9);
    }
    // Another robot's frames (no prefix): not a state of this robot.
    let skip = p.tf(&tf_message("robot2/", "world", &checker, &hit, 8)).unwrap_err();
    assert_eq!(skip.cause, SkipCause::NotOurRobot);
    // A robot whose frames hang off a frame that does not reach the world yet.
    let mut q = pipeline(Params { frame_prefix: "robot1/".into(), ..Params::default() });
    let skip = q.tf(&tf_message("robot1/", "robot1/odom", &checker, &hit, 9)).unwrap_err();
    assert_eq!(skip.cause, SkipCause::Unreachable);
    // /tf_static closes the chain; the next /tf is a state.
    let odom = TfMessage {
        transforms: vec![TransformStamped {
            header: Header { stamp: Time::default(), frame_id: "world".into() },
            child_frame_id: "robot1/odom".into(),
            transform: Transform::default(),
        }],
    };
    q.tf_static(&odom).unwrap();
    assert!(q.tf(&tf_message("robot1/", "robot1/odom", &checker, &hit, 10)).is_ok());
    // A non-finite transform: the whole message is refused.
    let mut bad = tf_message("robot1/", "world", &checker, &hit, 11);
    bad.transforms[0].transform.translation.x = f64::NAN;
    assert_eq!(q.tf(&bad).unwrap_err().cause, SkipCause::BadTransform);
}

#[test]
fn world_frame_set_at_run_time_is_used_by_tf_lookups_and_headers() {
    let (hit, _) = poses();
    let checker = Checker::from_params(Params::default()).unwrap();
    let mut p = pipeline(Params::default());
    let in_map = tf_message("", "map", &checker, &hit, 1);
    assert_eq!(p.tf(&in_map).unwrap_err().cause, SkipCause::Unreachable, "'map' is not the world yet");
    let params = p.params().with_overrides(&[("world_frame".into(), "map".into())]).unwrap();
    p.set_params(params).unwrap();
    let state = p.tf(&in_map).unwrap();
    let checked = p.check(&state);
    assert_eq!(checked.message(&p.params().world_frame).header.frame_id, "map");
    assert!(checked.report.in_collision);
}

#[test]
fn a_parameter_rebuild_keeps_a_robot_received_as_description() {
    let urdf = std::fs::read_to_string(crate::model::bundled_config_dir().join("example_workcell/robot.urdf")).unwrap();
    let gripper = crate::model::bundled_config_dir().join("example_workcell/gripper.obj");
    let urdf =
        urdf.replace("filename=\"gripper.obj\"", &format!("filename=\"file://{}\"", gripper.display())).replace("name=\"tc_arm\"", "name=\"from_topic\"");
    let mut p = pipeline(Params::default());
    p.set_robot_description(&urdf, "test").unwrap();
    let thicker = p.params().with_overrides(&[("default_thickness".into(), "0.05".into())]).unwrap();
    p.set_params(thicker).unwrap();
    assert_eq!(p.checker().summary().robot_source, "test", "the robot keeps its source");
    assert_eq!(p.params().default_thickness, 0.05);
    assert!(p.set_robot_description("<robot name='broken'><link name='a'></robot>", "bad").is_err());
    assert_eq!(p.checker().summary().robot_source, "test", "a bad description leaves the robot");
}

#[test]
fn service_states_fail_closed_in_their_slots() {
    let (hit, clear) = poses();
    let p = pipeline(Params::default());
    let mut unknown = js(&ARM, &clear, 3);
    unknown.name[0] = "no_such_joint".into();
    let reports = p.check_request(&[js(&ARM, &hit, 1), js(&ARM[..1], &[f64::NAN], 2), unknown, js(&ARM, &clear, 4)]);
    assert_eq!(reports.len(), 4);
    assert!(reports[0].in_collision && reports[0].error.is_empty());
    assert!(reports[1].in_collision && reports[1].error.contains("non-finite"), "{}", reports[1].error);
    assert!(reports[2].in_collision && reports[2].error.contains("no_such_joint"), "{}", reports[2].error);
    assert!(!reports[3].in_collision && reports[3].error.is_empty());
    assert_eq!(reports.iter().map(|r| r.header.stamp.as_nanos()).collect::<Vec<_>>(), vec![1, 2, 3, 4]);
}

/// The bundled arm (every joint but the finger's mimic) at A and C, close together and free, and
/// B, free, on the far side of the guard sheet and the shelf from them (as in
/// tests/one_pipeline.rs).
const TRIPLE_NAMES: [&str; 8] =
    ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint", "tool0_joint"];
const TRIPLE: [[f64; 8]; 3] = [
    [
        2.3262656677907794,
        0.6818684280582978,
        2.39428789294752,
        2.276771623960049,
        1.4581508272089656,
        1.2689149002932716,
        0.01847976994306216,
        -1.915057823936282,
    ],
    [
        -2.636566638810667,
        -0.5700379417947858,
        1.5543806482359694,
        1.5653099275652815,
        -0.5548617135963831,
        -2.789680498270184,
        0.03316370801149869,
        -1.8962443176668413,
    ],
    [
        2.3489918091071202,
        0.7010671794714393,
        2.385904178256132,
        2.285909494944286,
        1.4359962858749236,
        1.257838600196322,
        0.01883300333765152,
        -1.9291643109626693,
    ],
];

fn triple(p: &mut Pipeline, i: usize, ms: i64) -> super::RobotState {
    p.joint_state(&js(&TRIPLE_NAMES, &TRIPLE[i], ms * 1_000_000)).unwrap()
}

#[test]
fn a_report_covers_every_state_since_the_last_one() {
    let mut p = pipeline(Params::default());
    assert!(p.params().check_motion, "motions are checked by default");
    let a = triple(&mut p, 0, 0);
    let first = p.check_path(std::slice::from_ref(&a)).unwrap();
    assert_eq!((first.report.in_collision, first.report.motion), (false, false), "the first state is checked on its own");
    // B and C arrive together: one report, stamped with C, covering A -> B -> C.
    let b = triple(&mut p, 1, 10);
    let c = triple(&mut p, 2, 20);
    let r = p.check_path(&[b, c.clone()]).unwrap();
    assert_eq!(r.stamp, c.stamp);
    assert!(r.report.in_collision && r.report.motion && r.report.error.is_empty(), "{r:?}");
    let f = r.report.fraction.unwrap();
    assert!((0.0..0.5).contains(&f), "A -> B is the first of two steps and collides: {f}");
    // C alone after A is free: what a node that dropped B would have reported.
    let mut q = pipeline(Params::default());
    let a = triple(&mut q, 0, 0);
    let _ = q.check_path(&[a]);
    let c = triple(&mut q, 2, 20);
    let r = q.check_path(&[c]).unwrap();
    assert_eq!((r.report.in_collision, r.report.motion, r.report.fraction), (false, true, None), "{r:?}");
}

#[test]
fn the_trail_breaks_where_no_motion_is_known() {
    let motion_into = |p: &mut Pipeline, i: usize, ms: i64| {
        let s = triple(p, i, ms);
        p.check_path(&[s]).unwrap().report.motion
    };
    let mut p = pipeline(Params::default());
    assert!(!motion_into(&mut p, 0, 0), "first state");
    assert!(motion_into(&mut p, 2, 100), "100 ms later");
    assert!(!motion_into(&mut p, 0, 50), "a stamp going back");
    assert!(!motion_into(&mut p, 2, 600), "550 ms later, past motion_max_gap");
    assert!(motion_into(&mut p, 0, 1100), "500 ms later, at motion_max_gap");
    assert!(p.joint_state(&js(&TRIPLE_NAMES[..1], &[f64::NAN], 1_150_000_000)).is_err());
    assert!(!motion_into(&mut p, 2, 1200), "after a rejected message");
    p.set_params(Params { motion_max_gap: 1.0, ..Params::default() }).unwrap();
    assert!(!motion_into(&mut p, 0, 1300), "after new parameters");
    assert!(motion_into(&mut p, 2, 2200), "900 ms later, within the new gap");
}

#[test]
fn without_check_motion_the_newest_state_is_checked_and_older_ones_are_stale() {
    let mut p = pipeline(Params { check_motion: false, ..Params::default() });
    let states: Vec<_> = (0..3).map(|i| triple(&mut p, i, 10 * i as i64)).collect();
    let r = p.check_path(&states).unwrap();
    assert_eq!((r.report.in_collision, r.report.motion, r.stamp), (false, false, states[2].stamp), "only C is checked: {r:?}");
    assert_eq!(p.skipped().get(&SkipCause::Stale), Some(&2));
}

#[test]
fn an_srdf_received_after_the_robot_changes_its_self_pairs_and_shares_its_scene() {
    let mut p = pipeline(Params::default());
    let before = p.checker().clone();
    let n = before.targets().len();
    p.set_robot_semantic(r#"<robot name="workcell"></robot>"#, "the test").unwrap();
    let after = p.checker().clone();
    assert_eq!(after.self_pairs().pairs.len(), n * (n - 1) / 2, "an SRDF that disables nothing checks every pair");
    assert!(before.self_pairs().pairs.len() < after.self_pairs().pairs.len(), "without an SRDF adjacent pairs are allowed");
    assert!(std::ptr::eq(before.scene(), after.scene()), "the scene is shared, not built again");
    // A file naming a link the robot lacks is refused whole, and the pairs stay as they were.
    let bad = r#"<robot name="workcell"><disable_collisions link1="no_such_link" link2="base_link" reason="Never"/></robot>"#;
    assert!(p.set_robot_semantic(bad, "the test").is_err());
    assert_eq!(p.checker().self_pairs().pairs, after.self_pairs().pairs);
}
