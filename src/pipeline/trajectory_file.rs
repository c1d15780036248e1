//! A `trajectory_msgs/JointTrajectory` from a file, for `check --trajectory`: YAML or JSON with
//! the message's field names, as `ros2 topic echo --once` prints one (its trailing `---` line is
//! accepted), `header`, `velocities`, `accelerations` and `effort` optional.

use crate::limits::read_regular;
use crate::msgs::JointTrajectory;
use std::path::Path;

/// Largest trajectory file read (a 65,536-point, 7-joint trajectory with velocities and
/// accelerations in YAML is about 40 MiB).
pub const MAX_TRAJECTORY_FILE_BYTES: u64 = 64 << 20;

/// Reads one trajectory; the error names the file and what is wrong, on one line.
pub fn read_trajectory_file(path: &Path) -> Result<JointTrajectory, String> {
    let name = path.display();
    let bytes = read_regular(path, "trajectory file", MAX_TRAJECTORY_FILE_BYTES).map_err(|e| e.to_string())?;
    let text = std::str::from_utf8(&bytes).map_err(|e| format!("{name}: not UTF-8 text ({e})"))?;
    // `ros2 topic echo` ends each message with a line `---`.
    let trimmed = text.trim_end();
    let text = trimmed.strip_suffix("---").filter(|t| t.is_empty() || t.ends_with('\n')).unwrap_or(trimmed);
    serde_yaml_ng::from_str::<JointTrajectory>(text).map_err(|e| format!("{name}: not a JointTrajectory ({})", e.to_string().replace('\n', " ")))
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
        let (a, b) = (read_trajectory_file(&write("t.yaml", yaml)).unwrap(), read_trajectory_file(&write("t.json", json)).unwrap());
        assert_eq!(a.points, b.points);
        assert_eq!((a.joint_names.len(), a.points[0].positions[1], a.points[0].time_from_start.nanosec), (2, 1.0, 500_000_000));
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
