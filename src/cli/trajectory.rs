//! `check --trajectory FILE`: one `JointTrajectory` checked as the controller executes it, through
//! the pipeline the node's `check_trajectory` service uses.

use crate::ModelArgs;
use anyhow::{anyhow, bail, Result};
use std::io::Write;
use std::path::Path;
use thickness_collision::msgs::{CheckTrajectoryRequest, JointState, JointTrajectory};
use thickness_collision::pipeline::{outcome_json, read_trajectory_file, Interpolation, APPROACH_SEGMENT};

/// Checks the trajectory in `file` from `--joints` (else its first point), at rest. Prints one
/// JSON object (`--json`) or a few lines; an error when the trajectory is refused or a segment
/// could not be checked (after printing the answer).
pub fn check_trajectory(args: &ModelArgs, file: &Path, joints: Option<&str>, interpolation: &str, path_tolerance: Vec<f64>, json: bool) -> Result<()> {
    let interpolation = match Interpolation::parse(interpolation).map_err(|e| anyhow!("--interpolation: {e}"))? {
        Interpolation::Executed => String::new(),
        Interpolation::Linear => "linear".to_owned(),
    };
    let read = read_trajectory_file(file).map_err(|e| anyhow!(e))?;
    // `--path-tolerance` is the tube when given, in place of a goal's.
    let path_tolerance = if path_tolerance.is_empty() {
        let (tolerance, notes) = read.path_tolerance().map_err(|e| anyhow!("{}: {e} (give the tube with --path-tolerance)", file.display()))?;
        for note in notes {
            eprintln!("warning: {}: {note} (give it with --path-tolerance)", file.display());
        }
        tolerance
    } else {
        path_tolerance
    };
    let trajectory = read.trajectory;
    let mut pipeline = super::load::pipeline(args)?;
    super::check::print_loaded(&pipeline);
    let start = start_state(&trajectory, joints)?;
    // A start that is not a state (a bad --joints, an empty first point) leaves the current state
    // unknown: the trajectory is then refused by the missing_joint rule, or checked from 0.
    if let Err(skip) = pipeline.joint_state(&start) {
        if joints.is_some() {
            bail!("--joints: {}", skip.message);
        }
    }
    let request = CheckTrajectoryRequest { trajectory, interpolation, path_tolerance };
    let outcome = pipeline.check_trajectory_with_report(&request);
    let (response, report) = &outcome;
    let time = response.time_from_start.sec as f64 + response.time_from_start.nanosec as f64 * 1e-9;
    let contact_found = !response.valid && response.fraction >= 0.0;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    if json {
        writeln!(out, "{}", outcome_json(&outcome))?;
    } else if response.valid {
        writeln!(out, "trajectory: clear")?;
    } else if contact_found {
        let segment =
            if response.segment == APPROACH_SEGMENT { "the approach from the start state".to_owned() } else { format!("segment {}", response.segment) };
        writeln!(out, "trajectory: IN COLLISION at {time:.6} s ({segment}, {:.4} of the way)", response.fraction)?;
        if let Some(report) = report {
            super::check::print_contacts(&mut out, report)?;
        }
    }
    out.flush()?;
    if !response.error.is_empty() {
        // A controller's trajectory names only the joints it drives (an arm's, not its gripper's):
        // the others' positions come from `--joints`, as the node takes them from /joint_states.
        let hint = if response.error.contains("neither in joint_names") { "; give the joints the trajectory does not name with --joints" } else { "" };
        bail!("{}: {}{hint}", file.display(), response.error);
    }
    Ok(())
}

/// The state the trajectory starts from, at rest: `--joints`, and for every joint of the
/// trajectory `--joints` does not name, its first point (so `--joints` may give only the joints
/// the trajectory leaves out, a gripper's beside an arm's trajectory).
fn start_state(trajectory: &JointTrajectory, joints: Option<&str>) -> Result<JointState> {
    let (mut name, mut position) = match joints {
        Some(spec) => super::check::parse_joints(spec)?,
        None => (Vec::new(), Vec::new()),
    };
    if let Some(first) = trajectory.points.first().filter(|p| p.positions.len() == trajectory.joint_names.len()) {
        for (n, x) in trajectory.joint_names.iter().zip(&first.positions) {
            if !name.contains(n) {
                name.push(n.clone());
                position.push(*x);
            }
        }
    }
    Ok(JointState { name, position, ..Default::default() })
}
