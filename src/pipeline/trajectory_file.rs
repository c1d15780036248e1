//! A `trajectory_msgs/JointTrajectory` from a file, for `check --trajectory`: YAML or JSON with
//! the message's field names, as `ros2 topic echo --once` prints one (its trailing `---` line is
//! accepted), `header`, `velocities`, `accelerations` and `effort` optional; or a
//! `control_msgs/action/FollowJointTrajectory` goal holding one (`trajectory:`), whose
//! `path_tolerance` gives the tube the check proves free.

use crate::limits::read_regular;
use crate::msgs::JointTrajectory;
use serde::de::IgnoredAny;
use serde::Deserialize;
use std::path::Path;

/// Largest trajectory file read (a 65,536-point, 7-joint trajectory with velocities and
/// accelerations in YAML is about 40 MiB).
pub const MAX_TRAJECTORY_FILE_BYTES: u64 = 64 << 20;

/// What a trajectory file gives the check.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrajectoryFile {
    /// The trajectory, bare or the goal's.
    pub trajectory: JointTrajectory,
    /// A goal's `path_tolerance`: each joint's name and position tolerance, as given (see
    /// [`TrajectoryFile::path_tolerance`]); empty for a bare trajectory.
    pub goal_path_tolerance: Vec<(String, f64)>,
}

/// Whether the document is a goal: a mapping with `trajectory` (read without keeping anything).
#[derive(Deserialize)]
struct Probe {
    #[serde(default)]
    trajectory: Option<IgnoredAny>,
}

/// `control_msgs/action/FollowJointTrajectory`'s goal, the fields the check uses; the goal
/// tolerances and `goal_time_tolerance` are about the end state and time, not the path.
#[derive(Deserialize)]
struct Goal {
    trajectory: JointTrajectory,
    #[serde(default)]
    multi_dof_trajectory: MultiDof,
    #[serde(default, deserialize_with = "crate::msgs::bounded_trajectory_seq")]
    path_tolerance: Vec<JointTolerance>,
}

#[derive(Default, Deserialize)]
struct MultiDof {
    #[serde(default)]
    points: Vec<IgnoredAny>,
}

/// `control_msgs/msg/JointTolerance`: only the position bounds the path (velocity and
/// acceleration tolerances abort a controller, they move nothing).
#[derive(Deserialize)]
struct JointTolerance {
    name: String,
    #[serde(default)]
    position: f64,
}

/// Reads one trajectory or goal; the error names the file and what is wrong, on one line.
pub fn read_trajectory_file(path: &Path) -> Result<TrajectoryFile, String> {
    let name = path.display();
    let bytes = read_regular(path, "trajectory file", MAX_TRAJECTORY_FILE_BYTES).map_err(|e| e.to_string())?;
    let text = std::str::from_utf8(&bytes).map_err(|e| format!("{name}: not UTF-8 text ({e})"))?;
    // `ros2 topic echo` ends each message with a line `---`.
    let trimmed = text.trim_end();
    let text = trimmed.strip_suffix("---").filter(|t| t.is_empty() || t.ends_with('\n')).unwrap_or(trimmed);
    let one_line = |e: serde_yaml_ng::Error| e.to_string().replace('\n', " ");
    if !serde_yaml_ng::from_str::<Probe>(text).is_ok_and(|p| p.trajectory.is_some()) {
        let trajectory = serde_yaml_ng::from_str::<JointTrajectory>(text).map_err(|e| format!("{name}: not a JointTrajectory ({})", one_line(e)))?;
        return Ok(TrajectoryFile { trajectory, ..TrajectoryFile::default() });
    }
    let goal = serde_yaml_ng::from_str::<Goal>(text).map_err(|e| format!("{name}: not a FollowJointTrajectory goal ({})", one_line(e)))?;
    if !goal.multi_dof_trajectory.points.is_empty() {
        let n = goal.multi_dof_trajectory.points.len();
        return Err(format!("{name}: multi_dof_trajectory has {n} points (allowed: none; only the joint trajectory is checked)"));
    }
    let goal_path_tolerance = goal.path_tolerance.into_iter().map(|t| (t.name, t.position)).collect();
    Ok(TrajectoryFile { trajectory: goal.trajectory, goal_path_tolerance })
}

impl TrajectoryFile {
    /// The goal's path tolerances as the controller reads them, in `joint_names` order (a
    /// request's `path_tolerance`; empty when the goal gives none), and a note for each it
    /// cannot use as given. A positive position is the tube; 0 is the controller's own default,
    /// which only the controller knows (noted, and that joint checked without a tube, as a goal
    /// that gives no tolerance is); -1 is no bound at all, which no tube can prove free
    /// (refused). Unnamed joints get none.
    pub fn path_tolerance(&self) -> Result<(Vec<f64>, Vec<String>), String> {
        let names = &self.trajectory.joint_names;
        if self.goal_path_tolerance.is_empty() {
            return Ok((Vec::new(), Vec::new()));
        }
        let mut out = vec![0.0; names.len()];
        let mut seen = vec![false; names.len()];
        let mut notes = Vec::new();
        for (name, position) in &self.goal_path_tolerance {
            let Some(j) = names.iter().position(|n| n == name) else {
                return Err(format!("path_tolerance names joint '{name}', which trajectory.joint_names does not (allowed: {})", names.join(", ")));
            };
            if std::mem::replace(&mut seen[j], true) {
                return Err(format!("path_tolerance names joint '{name}' twice"));
            }
            match *position {
                x if x.is_finite() && x > 0.0 => out[j] = x,
                0.0 => notes.push(format!("path_tolerance of joint '{name}' is 0, the controller's default, not known here: checked without a tube for it")),
                -1.0 => return Err(format!("path_tolerance of joint '{name}' is -1, no bound: no tube can be proved free")),
                x => return Err(format!("path_tolerance of joint '{name}' is {x} (allowed: above 0, 0 for the controller's default, -1 for none)")),
            }
        }
        Ok((out, notes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("tc_trajectory_file_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn yaml_as_echoed_and_json_read_the_same() {
        let yaml = "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: world\njoint_names:\n- a\n- b\npoints:\n- positions: [0.0, 1]\n  velocities: []\n  accelerations: []\n  effort: []\n  time_from_start:\n    sec: 1\n    nanosec: 500000000\n---\n";
        let json = r#"{"joint_names": ["a", "b"], "points": [{"positions": [0.0, 1.0], "time_from_start": {"sec": 1, "nanosec": 500000000}}]}"#;
        let (a, b) = (read_trajectory_file(&write("t.yaml", yaml)).unwrap().trajectory, read_trajectory_file(&write("t.json", json)).unwrap().trajectory);
        assert_eq!(a.points, b.points);
        assert_eq!((a.joint_names.len(), a.points[0].positions[1], a.points[0].time_from_start.nanosec), (2, 1.0, 500_000_000));
    }

    const POINT: &str = "  points:\n  - positions: [0.0, 1.0]\n    time_from_start: {sec: 1, nanosec: 0}\n";

    fn goal(tolerances: &str) -> String {
        format!("trajectory:\n  joint_names: [a, b]\n{POINT}path_tolerance:{tolerances}goal_time_tolerance: {{sec: 0, nanosec: 0}}\n")
    }

    /// A FollowJointTrajectory goal reads as its trajectory, with its position tolerances in
    /// `joint_names` order (a joint it leaves out gets none).
    #[test]
    fn a_goal_reads_as_its_trajectory_with_its_tube() {
        let bare = "joint_names: [a, b]\npoints:\n- positions: [0.0, 1.0]\n  time_from_start: {sec: 1, nanosec: 0}\n";
        let bare = read_trajectory_file(&write("bare.yaml", bare)).unwrap();
        let file = read_trajectory_file(&write("goal.yaml", &goal("\n- {name: b, position: 0.02, velocity: 0.0, acceleration: 0.0}\n"))).unwrap();
        assert_eq!(file.trajectory, bare.trajectory);
        assert_eq!(file.path_tolerance().unwrap(), (vec![0.0, 0.02], vec![]));
        assert_eq!(bare.path_tolerance().unwrap(), (vec![], vec![]));
        // 0 is the controller's default: noted, no tube for that joint.
        let file = read_trajectory_file(&write("zero.yaml", &goal("\n- {name: a, position: 0.0}\n- {name: b, position: 0.01}\n"))).unwrap();
        let (tube, notes) = file.path_tolerance().unwrap();
        assert_eq!(tube, vec![0.0, 0.01]);
        assert!(notes.len() == 1 && notes[0].contains("'a'") && notes[0].contains("default"), "{notes:?}");
    }

    /// Tolerances no tube can stand for, or naming what the trajectory does not, are refused
    /// with the joint and the value; a multi-DOF trajectory (not checked here) too.
    #[test]
    fn a_goal_the_check_cannot_prove_is_refused() {
        for (tolerances, says) in [
            ("\n- {name: a, position: -1.0}\n", "'a' is -1, no bound"),
            ("\n- {name: a, position: -0.5}\n", "'a' is -0.5 (allowed: above 0"),
            ("\n- {name: a, position: .nan}\n", "'a' is NaN"),
            ("\n- {name: c, position: 0.1}\n", "joint 'c', which trajectory.joint_names does not (allowed: a, b)"),
            ("\n- {name: a, position: 0.1}\n- {name: a, position: 0.2}\n", "'a' twice"),
        ] {
            let e = read_trajectory_file(&write("bad_goal.yaml", &goal(tolerances))).unwrap().path_tolerance().unwrap_err();
            assert!(e.contains(says), "{tolerances}: {e}");
        }
        let multi = format!("{}multi_dof_trajectory:\n  points:\n  - time_from_start: {{sec: 1, nanosec: 0}}\n", goal(" []\n"));
        let e = read_trajectory_file(&write("multi.yaml", &multi)).unwrap_err();
        assert!(e.contains("multi.yaml") && e.contains("multi_dof_trajectory has 1 points"), "{e}");
        let e = read_trajectory_file(&write("no_names.yaml", "trajectory:\n  points: []\n")).unwrap_err();
        assert!(e.contains("not a FollowJointTrajectory goal") && e.contains("joint_names"), "{e}");
    }

    #[test]
    fn a_bad_file_is_one_line_naming_it() {
        for (name, text, says) in [
            ("no_time.yaml", "joint_names: [a]\npoints:\n- positions: [0.0]\n", "time_from_start"),
            ("text.yaml", "hello", "not a JointTrajectory"),
            ("binary.yaml", "\u{0}\u{1}", "not a JointTrajectory"),
        ] {
            let e = read_trajectory_file(&write(name, text)).unwrap_err();
            assert!(e.contains(name) && e.contains(says) && !e.contains('\n'), "{e}");
        }
        let e = read_trajectory_file(Path::new("/nonexistent/t.yaml")).unwrap_err();
        assert!(e.contains("/nonexistent/t.yaml"), "{e}");
    }
}
