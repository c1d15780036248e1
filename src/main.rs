//! The `thickness_collision` command line.

mod cli;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use thickness_collision::model::PoseSource;
use thickness_collision::thickness::Side;

// The core's enums parse themselves (FromStr); the CLI only names them.
fn parse_side(s: &str) -> Result<Side, String> {
    s.parse()
}

fn parse_pose_source(s: &str) -> Result<PoseSource, String> {
    s.parse()
}

#[derive(Parser)]
#[command(name = "thickness_collision", version, about = "Collision checking against thin surfaces with thickness areas")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build the thickness cells of one mesh file and print the build report.
    Areas {
        /// An STL, OBJ or COLLADA (.dae) file.
        mesh: PathBuf,
        /// Thickness of every cell (metres).
        #[arg(long, allow_negative_numbers = true)]
        thickness: f64,
        /// Where the volume goes relative to each face's front normal: back, front or both.
        #[arg(long, default_value = "back", value_parser = parse_side)]
        side: Side,
        /// Scale applied to the file's coordinates: one factor, or three as `sx,sy,sz`.
        #[arg(long, default_value = "1")]
        scale: String,
        /// Write the cells as JSON to this file.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Check robot states against the environment and print the collisions.
    Check {
        #[command(flatten)]
        model: ModelArgs,
        /// One state: `joint=value,joint=value,...` (radians / metres). With `--trajectory`, the
        /// state the robot is in when the trajectory starts (at rest); the trajectory's joints it
        /// leaves out start at the first point, the joints the trajectory does not name need it.
        #[arg(long, conflicts_with = "states", required_unless_present_any = ["states", "show_params", "trajectory"])]
        joints: Option<String>,
        /// A JSON-lines file of states, in order, through the node's pipeline: `{"name": [...],
        /// "position": [...]}` or `{"transforms": [{"link": ..., "translation": [x,y,z],
        /// "rotation": [x,y,z,w]}]}`, each with an optional `"stamp"` (integer nanoseconds).
        #[arg(long)]
        states: Option<PathBuf>,
        /// One JSON object per state on standard output.
        #[arg(long)]
        json: bool,
        /// The states file is one path: the first line is checked as a state, every further line
        /// as the motion from the previous line's state to its own (nothing crossed in between
        /// is missed; see `motion_tolerance`).
        #[arg(long, requires = "states")]
        motion: bool,
        /// Print the parameters in force as a ROS 2 parameters file and exit.
        #[arg(long)]
        show_params: bool,
        /// One `trajectory_msgs/JointTrajectory` (YAML or JSON with the message's field names, as
        /// `ros2 topic echo --once` prints it), or a `FollowJointTrajectory` goal holding one
        /// (its `path_tolerance` the tube), checked as `joint_trajectory_controller` executes
        /// it, from `--joints` (else from its first point, at rest). Exit 0 free or colliding, 2
        /// when it is refused or cannot be read.
        #[arg(long, conflicts_with = "states")]
        trajectory: Option<PathBuf>,
        /// With `--trajectory`: `spline` (the default: as the controller executes it) or
        /// `linear` (the straight chords between the waypoints).
        #[arg(long, requires = "trajectory", default_value = "spline")]
        interpolation: String,
        /// With `--trajectory`: how far each joint may stray from the path, one value per
        /// `joint_names` entry, comma-separated (radians / metres); in place of a goal's.
        #[arg(long, requires = "trajectory", value_delimiter = ',')]
        path_tolerance: Vec<f64>,
    },
    /// Run the ROS 2 node (on the bundled workcell by default).
    #[cfg(feature = "ros")]
    Run {
        #[command(flatten)]
        model: ModelArgs,
        /// ROS arguments: `--ros-args -r __ns:=/robot1 -r __node:=name -p key:=value --params-file F`.
        #[arg(long = "ros-args", num_args = 0.., allow_hyphen_values = true)]
        ros_args: Vec<String>,
    },
    /// Replay a recorded rosbag2 bag (MCAP or sqlite3) through the checker.
    Replay {
        /// A rosbag2 directory (with metadata.yaml), an .mcap file or a .db3 file.
        bag: PathBuf,
        #[command(flatten)]
        model: ModelArgs,
        /// Input topic (default /joint_states, or /tf with --pose-source tf).
        #[arg(long)]
        topic: Option<String>,
        /// Where robot states come from: joint_states or tf (default: the parameters' pose_source).
        #[arg(long, value_parser = parse_pose_source)]
        pose_source: Option<PoseSource>,
        /// The robot's frame prefix on /tf (default: the parameters' frame_prefix).
        #[arg(long)]
        frame_prefix: Option<String>,
        /// Write a rosbag2 bag (metadata.yaml + .mcap) here: `/collisions`, the contact and cell
        /// markers, `/tf` and `/robot_description` (to open beside the input in Foxglove or RViz).
        #[arg(long = "out")]
        out_dir: Option<PathBuf>,
        /// The output bag gets `/collisions` only (no markers, `/tf` or `/robot_description`):
        /// a tenth of the size for joint-state input.
        #[arg(long, requires = "out_dir")]
        no_markers: bool,
        /// Draw the collision timeline (one row per link, a bar per interval in collision) into
        /// this SVG file.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Write one JSON report per state here (the objects of `check --json`).
        #[arg(long)]
        jsonl: Option<PathBuf>,
        /// Seconds after the bag's first message to start at.
        #[arg(long)]
        start: Option<f64>,
        /// Seconds after the bag's first message to stop at.
        #[arg(long)]
        end: Option<f64>,
        /// Check the motion between consecutive states (default: the parameters' check_motion).
        #[arg(long, overrides_with = "no_motion")]
        motion: bool,
        /// Check every state on its own, not the motions between them.
        #[arg(long, overrides_with = "motion")]
        no_motion: bool,
        /// A `trajectory_msgs/JointTrajectory` topic (e.g.
        /// `/joint_trajectory_controller/joint_trajectory`): each trajectory checked as the
        /// controller executes it, from the joint state recorded before it, until the next one
        /// preempts it; one JSON line per trajectory in `--jsonl` (as `check --trajectory
        /// --json`, with `trajectory`, `log_time` and `preempted_after`).
        #[arg(long)]
        trajectory_topic: Option<String>,
    },
}

/// Where the robot, the environment and the thin-surface settings come from (shared by
/// `check`, `run` and `replay`).
#[derive(Args, Clone, Debug)]
pub struct ModelArgs {
    /// A ROS 2 parameters file (`thickness_collision: ros__parameters: ...`).
    #[arg(long)]
    params_file: Option<PathBuf>,
    /// Robot URDF (default: the parameters' `robot_description_file`, else the bundled arm).
    #[arg(long)]
    robot: Option<PathBuf>,
    /// Environment URDF (default: the parameters' `environment_file`, else the bundled workcell).
    #[arg(long)]
    environment: Option<PathBuf>,
    /// Thickness of every thin surface (metres), overriding the parameters.
    #[arg(long, allow_negative_numbers = true)]
    thickness: Option<f64>,
    /// Side of every thin surface (back, front or both), overriding the parameters.
    #[arg(long, value_parser = parse_side)]
    side: Option<Side>,
    /// The robot's SRDF (its disable_collisions form the allowed collision matrix), overriding
    /// the parameters' robot_semantic_file.
    #[arg(long)]
    srdf: Option<PathBuf>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("thickness_collision: error: {err:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Areas { mesh, thickness, side, scale, json } => cli::areas::areas(mesh, thickness, side, &scale, json),
        Command::Check { model, joints, states, json, motion, show_params, trajectory, interpolation, path_tolerance } => match trajectory {
            Some(file) => cli::trajectory::check_trajectory(&model, &file, joints.as_deref(), &interpolation, path_tolerance, json),
            None => cli::check::check(&model, &cli::check::CheckRequest { joints: joints.as_deref(), states: states.as_deref(), json, motion, show_params }),
        },
        #[cfg(feature = "ros")]
        Command::Run { model, ros_args } => cli::run::run(&model, &ros_args),
        Command::Replay { bag, model, topic, pose_source, frame_prefix, out_dir, no_markers, plot, jsonl, start, end, motion, no_motion, trajectory_topic } => {
            let motion = if motion {
                Some(true)
            } else if no_motion {
                Some(false)
            } else {
                None
            };
            let opts = thickness_collision::replay::ReplayOptions {
                bag,
                topic,
                pose_source,
                frame_prefix,
                out_dir,
                jsonl,
                start,
                end,
                motion,
                plot,
                no_markers,
                trajectory_topic,
            };
            cli::replay::replay(&model, &opts)
        }
    }
}
