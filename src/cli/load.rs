//! Parameters and overrides to a checker.

use crate::ModelArgs;
use anyhow::{bail, Result};
use thickness_collision::model::Params;
use thickness_collision::pipeline::Pipeline;

/// The parameters file (or the defaults) with the command line's overrides applied.
pub fn params(args: &ModelArgs) -> Result<Params> {
    let mut params = match &args.params_file {
        Some(path) => Params::from_file(path)?,
        None => Params::default(),
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
    Ok(Pipeline::new(params(args)?, args.robot.as_deref(), args.environment.as_deref())?)
}
