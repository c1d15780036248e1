//! `replay`: a recorded bag through the checker, with a summary at the end.

use crate::ModelArgs;
use anyhow::{anyhow, Result};
use thickness_collision::replay::{replay as run_replay, ReplayOptions};

pub fn replay(args: &ModelArgs, opts: &ReplayOptions) -> Result<()> {
    let params = super::load::params(args)?;
    let summary = run_replay(params, opts)?;
    println!("{summary}");
    if let Some(e) = &summary.bag_error {
        // The reports before the fault are written; the bag itself is bad.
        return Err(anyhow!("{e}"));
    }
    if let Some(e) = &summary.no_input {
        // Nothing of the input was checked: not a success, whatever the reason.
        return Err(anyhow!("{e}"));
    }
    Ok(())
}
