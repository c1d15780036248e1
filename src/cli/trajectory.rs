//! `check --trajectory FILE`: one `JointTrajectory` checked as the controller executes it, through
//! the pipeline the node's `check_trajectory` service uses.

use crate::ModelArgs;
use anyhow::{anyhow, bail, Result};
use std::io::Write;
use std::path::Path;
use thickness_collision::msgs::{CheckTrajectoryRequest, JointState};
use thickness_collision::pipeline::{outcome_json, read_trajectory_file, Interpolation, APPROACH_SEGMENT};

/// Checks the trajectory in `file` from `--joints` (else its first point), at rest. Prints one
/// JSON object (`--json`) or a few lines; an error when the trajectory is refused or a segment
/// could not be checked (after printing the answer).
pub fn check_trajectory(args: &ModelArgs, file: &Path, joints: Option<&str>, interpolation: &str, path_tolerance: Vec<f64>, json: bool) -> Result<()> {
    let interpolation = match Interpolation::parse(interpolation).map_err(|e| anyhow!("--interpolation: {e}"))? {
        Interpolation::Executed => String::new(),
        Interpolation::Linear => "linear".to_owned(),
    };
    let trajectory = read_trajectory_file(file).map_err(|e| anyhow!(e))?;
    let mut pipeline = super::load::pipeline(args)?;
    super::check::print_loaded(&pipeline);
    let start = match joints {
        Some(spec) => {
            let (name, position) = super::check::parse_joints(spec)?;
            JointState { name, position, ..Default::default() }
        }
        None => JointState {
            name: trajectory.joint_names.clone(),
            position: trajectory.points.first().map(|p| p.positions.clone()).unwrap_or_default(),
            ..Default::default()
        },
    };
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
        bail!("{}: {}", file.display(), response.error);
    }
    Ok(())
}
