//! `run`: the ROS 2 node.

use crate::ModelArgs;
use anyhow::Result;
use std::path::PathBuf;
use thickness_collision::model::{node_fqn, Params};
use thickness_collision::ros::{parse_ros_args, run as run_node, RunOptions};

pub fn run(args: &ModelArgs, ros_args: &[String]) -> Result<()> {
    let ros_args = parse_ros_args(ros_args)?;
    // The CLI's --params-file, then each one after --ros-args, merged as rcl merges them, for
    // this node's name: the sections a launch file writes for it (`/**`, its full name) apply.
    let fqn = node_fqn(ros_args.namespace.as_deref(), ros_args.node_name.as_deref());
    let more: Vec<PathBuf> = ros_args.params_files.iter().map(PathBuf::from).collect();
    let params: Params = super::load::params_for_node(args, &more, &fqn)?;
    run_node(params, &RunOptions { ros_args })
}
