//! A planning scene's `link_padding` and `link_scale` on the pipeline: checked exactly as a robot
//! whose URDF and `padding` parameter give the links those sizes.

use super::scene_tests::{at, explicit_srdf, object, reports, ARM};
use super::{Pipeline, SkipCause};
use crate::checker::{Checker, StateReport};
use crate::model::{PackageResolver, Padding, Params, RobotModel};
use crate::msgs::planning_scene::{AttachedCollisionObject, CollisionObject, LinkPadding, LinkScale, PlanningScene, PlanningSceneComponents, SolidPrimitive};
use crate::msgs::{JointState, Time};

fn padding(link: &str, padding: f64) -> LinkPadding {
    LinkPadding { link_name: link.into(), padding }
}

fn scale(link: &str, scale: f64) -> LinkScale {
    LinkScale { link_name: link.into(), scale }
}

/// The contacts of `a` and `b` name the same bodies, with depths within 1e-9.
fn same_contacts(a: &StateReport, b: &StateReport) -> bool {
    let names = |r: &StateReport| r.contacts.iter().map(|c| (c.link_name.clone(), c.object_name.clone())).collect::<Vec<_>>();
    names(a) == names(b) && a.contacts.iter().zip(&b.contacts).all(|(x, y)| (x.depth - y.depth).abs() < 1e-9)
}

/// Reports of `n` random arm states from each checker, compared; how many of them had a contact of
/// `link` (so that the sizes are seen to matter).
fn compare(a: &Checker, b: &Checker, n: usize, link: &str) -> usize {
    let names: Vec<String> = ARM.iter().map(|s| s.to_string()).collect();
    let mut rng = oorandom::Rand64::new(17);
    let mut touching = 0;
    for _ in 0..n {
        let q: Vec<f64> = ARM.iter().map(|_| -2.5 + 5.0 * rng.rand_float()).collect();
        let (x, y) = (a.check_joints(&names, &q).unwrap(), b.check_joints(&names, &q).unwrap());
        assert!(same_contacts(&x, &y), "at {q:?}:\n{:?}\nvs\n{:?}", x.contacts, y.contacts);
        touching += x.contacts.iter().any(|c| c.link_name == link || c.object_name == link) as usize;
    }
    touching
}

/// Padding replaces the parameter's for the links named, scale applies first (a primitive about
/// its origin, the gripper mesh about its vertices' mean, which is its origin), an attached object
/// takes its link's sizes; the twin is the robot URDF with those sizes written in, the `padding`
/// parameter holding the paddings, and a fixed child link for the tray.
#[test]
fn link_sizes_are_checked_as_the_urdf_that_has_them() {
    let dir = std::env::temp_dir().join(format!("tc_link_sizes_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let touch = ["gripper_link", "finger_left_link", "finger_right_link"];
    let srdf = explicit_srdf(&Checker::from_params(Params::default()).unwrap());
    let twin_srdf = touch.iter().fold(srdf.clone(), |s, l| s + &format!("<disable_collisions link1=\"tray\" link2=\"{l}\" reason=\"Touch\"/>")) + "</robot>";
    std::fs::write(dir.join("arm.srdf"), srdf + "</robot>").unwrap();
    let params = Params { robot_semantic_file: dir.join("arm.srdf").display().to_string(), ..Params::default() };
    let mut p = Pipeline::new(params.clone()).unwrap();
    let plain = reports(&p);
    let q0 = [0.0, -0.5, 0.8, 0.0, 0.3, 0.0, 0.01];
    let _ = p.joint_state(&JointState { name: ARM.iter().map(|s| s.to_string()).collect(), position: q0.to_vec(), ..Default::default() }).unwrap();
    let tray = CollisionObject {
        pose: at(0.0, 0.0, 0.12),
        primitives: vec![SolidPrimitive { kind: SolidPrimitive::BOX, dimensions: vec![0.15, 0.1, 0.02], ..Default::default() }],
        primitive_poses: vec![at(0.0, 0.0, 0.0)],
        ..object("tool0", "tray", CollisionObject::ADD)
    };
    p.attached_collision_object(&AttachedCollisionObject {
        link_name: "tool0".into(),
        object: tray,
        touch_links: touch.map(String::from).to_vec(),
        ..Default::default()
    })
    .unwrap();
    let sizes = PlanningScene {
        is_diff: true,
        link_padding: vec![
            padding("upper_arm_link", 0.03),
            padding("wrist_1_link", 0.02),
            padding("gripper_link", 0.01),
            padding("tool0", 0.01),
            padding("no_such_link", 5.0),
        ],
        link_scale: vec![scale("forearm_link", 1.5), scale("wrist_1_link", 0.5), scale("gripper_link", 1.3), scale("tool0", 2.0)],
        ..Default::default()
    };
    p.planning_scene(&sizes).unwrap();

    let robot_path = params.robot_path();
    let text = std::fs::read_to_string(&robot_path)
        .unwrap()
        .replace("<capsule radius=\"0.04\" length=\"0.3\"/>", "<capsule radius=\"0.06\" length=\"0.45\"/>")
        .replace("<sphere radius=\"0.05\"/>", "<sphere radius=\"0.025\"/>")
        .replace("filename=\"gripper.obj\"", "filename=\"gripper.obj\" scale=\"1.3 1.3 1.3\"")
        .replacen(
            "</robot>",
            "<link name=\"tray\"><collision><origin xyz=\"0 0 0.12\"/><geometry><box size=\"0.3 0.2 0.04\"/></geometry></collision></link><joint name=\"tray_joint\" type=\"fixed\"><parent link=\"tool0\"/><child link=\"tray\"/></joint></robot>",
            1,
        );
    let resolver = PackageResolver::default();
    let robot = RobotModel::from_str(&text, "twin.urdf", robot_path.parent().unwrap(), &resolver, false).unwrap();
    let env = RobotModel::from_file(&params.environment_path(), &resolver, false).unwrap();
    let links = ["upper_arm_link", "wrist_1_link", "gripper_link", "tray"].map(String::from).to_vec();
    let twin_params = Params { padding: Padding { links, values: vec![0.03, 0.02, 0.01, 0.01] }, ..params.clone() };
    let twin = Checker::from_models(twin_params, robot, env, "twin".into(), "env".into(), Some(&twin_srdf)).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    for link in ["upper_arm_link", "forearm_link", "tray"] {
        assert!(compare(p.checker(), &twin, 300, link) > 5, "{link} must touch something in some states");
    }

    // get_planning_scene gives the sizes in force; a difference naming one link keeps the others.
    let in_force = |p: &Pipeline| {
        let msg = p.planning_scene_message(PlanningSceneComponents::LINK_PADDING_AND_SCALING, Time::default());
        let pad = |l: &str| msg.link_padding.iter().find(|e| e.link_name == l).map(|e| e.padding);
        let sc = |l: &str| msg.link_scale.iter().find(|e| e.link_name == l).map(|e| e.scale);
        (pad("upper_arm_link"), pad("shoulder_link"), sc("forearm_link"), sc("base_link"))
    };
    assert_eq!(in_force(&p), (Some(0.03), Some(0.0), Some(1.5), Some(1.0)));
    p.planning_scene(&PlanningScene { is_diff: true, link_padding: vec![padding("shoulder_link", 0.04)], ..Default::default() }).unwrap();
    assert_eq!(in_force(&p), (Some(0.03), Some(0.04), Some(1.5), Some(1.0)));
    let answer = p.planning_scene_message(PlanningSceneComponents::LINK_PADDING_AND_SCALING, Time::default());

    // Out of range: refused whole, the sizes in force kept.
    for bad in [
        PlanningScene { is_diff: true, link_padding: vec![padding("base_link", 0.1), padding("shoulder_link", -0.01)], ..Default::default() },
        PlanningScene { is_diff: true, link_padding: vec![padding("base_link", f64::NAN)], ..Default::default() },
        PlanningScene { is_diff: true, link_scale: vec![scale("base_link", 0.0)], ..Default::default() },
        PlanningScene { is_diff: true, link_scale: vec![scale("base_link", 1e4)], ..Default::default() },
    ] {
        let skip = p.planning_scene(&bad).unwrap_err();
        assert_eq!(skip.cause, SkipCause::SceneGeometry, "{}", skip.message);
        assert!(skip.message.contains("base_link") || skip.message.contains("shoulder_link"), "{}", skip.message);
        assert_eq!(in_force(&p), (Some(0.03), Some(0.04), Some(1.5), Some(1.0)));
    }

    // A whole scene without sizes brings the parameter's back: the plain arm's reports again
    // (with the tray detached by it too).
    p.planning_scene(&PlanningScene { is_diff: false, ..Default::default() }).unwrap();
    assert_eq!(in_force(&p), (Some(0.0), Some(0.0), Some(1.0), Some(1.0)));
    assert_eq!(reports(&p), plain);
    // The answer taken back whole gives those sizes again.
    p.planning_scene(&PlanningScene { is_diff: false, ..answer }).unwrap();
    assert_eq!(in_force(&p), (Some(0.03), Some(0.04), Some(1.5), Some(1.0)));
    assert_ne!(reports(&p), plain);
}
