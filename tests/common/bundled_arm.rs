//! The bundled arm as the planning-scene and validity tests use it: random states within its
//! limits, SRDFs that stand for its default self-collision reasoning, and the arm holding a tray.

use std::fmt::Write as _;
use thickness_collision::checker::Checker;
use thickness_collision::model::{JointKind, Params};

/// `n` random states of the bundled arm within its limits (continuous joints within +-3.1), seeded:
/// the actuated joints' names and one position list per state.
pub fn random_arm_states(n: usize, seed: u128) -> (Vec<String>, Vec<Vec<f64>>) {
    let checker = Checker::from_params(Params::default()).unwrap();
    let joints: Vec<_> = checker.robot().joints.iter().filter(|j| j.is_actuated()).collect();
    let names = joints.iter().map(|j| j.name.clone()).collect();
    let mut rng = oorandom::Rand64::new(seed);
    let states = (0..n)
        .map(|_| {
            joints
                .iter()
                .map(|j| {
                    let (lo, hi) = if j.kind == JointKind::Continuous { (-3.1, 3.1) } else { (j.limits[0], j.limits[1]) };
                    lo + (hi - lo) * rng.rand_float()
                })
                .collect()
        })
        .collect();
    (names, states)
}

/// An SRDF for the bundled arm that disables exactly what the default reasoning allows (so the
/// node with it checks what `check` without one does), and the same with the pairs of a fixed
/// child link `tray` and each touch link disabled: (plain, with the tray).
pub fn arm_srdfs(touch: &[&str]) -> (String, String) {
    let plain = Checker::from_params(Params::default()).unwrap();
    let targets = plain.targets();
    let mut srdf = String::from("<robot name=\"tc_arm\">");
    for a in 0..targets.len() {
        for b in a + 1..targets.len() {
            if !plain.self_pairs().pairs.contains(&(a, b)) {
                let _ = write!(srdf, "<disable_collisions link1=\"{}\" link2=\"{}\" reason=\"Default\"/>", targets[a].name, targets[b].name);
            }
        }
    }
    let with_tray = touch.iter().fold(srdf.clone(), |s, l| s + &format!("<disable_collisions link1=\"tray\" link2=\"{l}\" reason=\"Touch\"/>"));
    (srdf + "</robot>", with_tray + "</robot>")
}

/// The bundled arm holding a tray: a fixed child link `tray` of `tool0` (a 0.3 x 0.2 x 0.04 m box
/// 0.12 m out along its z), as URDF text with absolute mesh paths.
pub fn arm_with_tray() -> String {
    let config = thickness_collision::model::bundled_config_dir();
    let tray = "<link name=\"tray\"><collision><origin xyz=\"0 0 0.12\"/><geometry><box size=\"0.3 0.2 0.04\"/></geometry></collision></link><joint name=\"tray_joint\" type=\"fixed\"><parent link=\"tool0\"/><child link=\"tray\"/></joint></robot>";
    std::fs::read_to_string(config.join("example_workcell/robot.urdf"))
        .unwrap()
        .replace("filename=\"gripper.obj\"", &format!("filename=\"file://{}\"", config.join("example_workcell/gripper.obj").display()))
        .replacen("</robot>", tray, 1)
}
