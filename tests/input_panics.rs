//! Issue 11, item 5: inputs that used to reach a panic now get a clear error naming them.

mod common;

use std::process::Command;
use thickness_collision::checker::{Checker, CheckerError};
use thickness_collision::model::{bundled_config_dir, PackageResolver, Params, PositionsError, RobotModel};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn arm() -> RobotModel {
    RobotModel::from_file(&bundled_config_dir().join("example_workcell/robot.urdf"), &PackageResolver::default(), false).unwrap()
}

fn workcell() -> RobotModel {
    RobotModel::from_file(&bundled_config_dir().join("example_workcell/environment.urdf"), &PackageResolver::default(), false).unwrap()
}

#[test]
fn issue_11_from_models_validates_the_parameters() {
    // Parallel arrays of different lengths used to index out of bounds at the first state.
    let mut params = Params::default();
    params.thin_surfaces.patterns = vec!["guard_*".into(), "shelf".into()];
    params.thin_surfaces.thickness = vec![0.03];
    let e = Checker::from_models(params, arm(), workcell(), "arm".into(), "cell".into(), None).err().expect("refused");
    assert!(matches!(e, CheckerError::Params(_)), "{e}");
    assert!(e.to_string().contains("thin_surfaces.thickness"), "{e}");
    let params = Params { padding: thickness_collision::model::Padding { links: vec!["*".into()], values: vec![] }, ..Params::default() };
    let e = Checker::from_models(params, arm(), workcell(), "arm".into(), "cell".into(), None).err().expect("refused");
    assert!(e.to_string().contains("padding.values"), "{e}");
}

#[test]
fn issue_11_forward_kinematics_checks_its_positions() {
    let robot = arm();
    let base = nalgebra::Isometry3::identity();
    assert_eq!(robot.forward_kinematics(&[0.1, 0.2], &base).unwrap_err(), PositionsError::Length { expected: robot.joints.len(), got: 2 });
    let mut q = vec![0.0; robot.joints.len()];
    q[2] = f64::INFINITY;
    let e = robot.forward_kinematics(&q, &base).unwrap_err();
    assert!(e.to_string().contains(&robot.joints[2].name) && e.to_string().contains("inf"), "{e}");
    // Through the checker as well.
    let checker = Checker::from_params(Params::default()).unwrap();
    assert!(checker.check_positions(&[0.0; 3]).unwrap_err().to_string().contains("3 joint positions"));
    assert!(checker.check_world_poses(&[None; 2]).is_err());
}

#[test]
fn issue_11_a_tiny_marker_rate_is_refused_not_a_panic() {
    let dir = common::scratch_dir("input_panics");
    let params = dir.join("rate.yaml");
    std::fs::write(&params, "thickness_collision:\n  ros__parameters:\n    marker_rate: 1.0e-300\n").unwrap();
    let out = bin().args(["check", "--params-file", params.to_str().unwrap(), "--joints", "elbow_joint=0"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("marker_rate") && err.contains("1e-300"), "{err}");
    // The node refuses it before it starts any DDS participant (no network involved).
    let out = bin().args(["run", "--ros-args", "-p", "marker_rate:=1e-300"]).env("ROS_LOCALHOST_ONLY", "1").output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("marker_rate"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}
