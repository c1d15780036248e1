//! Parameters and overrides to a checker.

use crate::ModelArgs;
use anyhow::{bail, Result};
use std::path::PathBuf;
use thickness_collision::model::{InputFiles, Params, DEFAULT_NODE_FQN};
use thickness_collision::pipeline::Pipeline;

/// The parameters file (or the defaults) with the command line's overrides applied, read for
/// the node `check` and `replay` stand for: `thickness_collision` in the root namespace.
pub fn params(args: &ModelArgs) -> Result<Params> {
    params_for_node(args, &[], DEFAULT_NODE_FQN)
}

/// The CLI's `--params-file`, then `more` files, merged for the node `node_fqn` as rcl merges
/// them (or the defaults without any), with the command line's overrides applied.
pub fn params_for_node(args: &ModelArgs, more: &[PathBuf], node_fqn: &str) -> Result<Params> {
    let files: Vec<PathBuf> = args.params_file.iter().cloned().chain(more.iter().cloned()).collect();
    let mut params = if files.is_empty() {
        Params::default()
    } else {
        let loaded = Params::from_files_for_node(&files, node_fqn)?;
        for w in &loaded.warnings {
            eprintln!("thickness_collision: warning: {w}");
        }
        loaded.params
    };
    if let Some(t) = args.thickness {
        if !thickness_collision::limits::is_length(t) {
            let [lo, hi] = thickness_collision::limits::LENGTH_RANGE;
            bail!("--thickness {}: must be from {lo:e} to {hi:e} m", thickness_collision::limits::show_number(t));
        }
        params.default_thickness = t;
        params.thin_surfaces.thickness.iter_mut().for_each(|x| *x = t);
    }
    if let Some(srdf) = &args.srdf {
        params.robot_semantic_file = srdf.display().to_string();
    }
    params.input_files = InputFiles { robot: args.robot.clone(), environment: args.environment.clone() };
    if let Some(side) = args.side {
        params.default_side = side;
        let n = params.thin_surfaces.patterns.len();
        params.thin_surfaces.side = vec![side; n];
    }
    params.validate()?;
    Ok(params)
}

/// Loads the robot and the environment into the pipeline every front door feeds.
pub fn pipeline(args: &ModelArgs) -> Result<Pipeline> {
    Ok(Pipeline::new(params(args)?)?)
}
