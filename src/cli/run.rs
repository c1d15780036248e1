//! `run`: the ROS 2 node.

use crate::ModelArgs;
use anyhow::Result;
use thickness_collision::model::Params;
use thickness_collision::ros::{parse_ros_args, run as run_node, RunOptions};

pub fn run(args: &ModelArgs, ros_args: &[String]) -> Result<()> {
    let ros_args = parse_ros_args(ros_args)?;
    // --params-file after --ros-args counts like the CLI's own (the last file wins).
    let mut model = args.clone();
    if let Some(f) = ros_args.params_files.last() {
        model.params_file = Some(f.into());
    }
    let params: Params = super::load::params(&model)?;
    run_node(params, &RunOptions { ros_args, robot: model.robot.clone(), environment: model.environment.clone() })
}
