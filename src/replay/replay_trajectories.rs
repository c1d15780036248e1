//! `--trajectory-topic`: the `trajectory_msgs/JointTrajectory` messages of a topic (a
//! controller's `~/joint_trajectory`), each checked as executed from the joint state in force
//! when it was recorded, preempted by the next (`pipeline::TrajectoryStream`); one JSON line per
//! trajectory in `--jsonl`, counted in the summary.

use crate::pipeline::{Pipeline, StreamedTrajectory, TrajectoryStream};

/// The type a trajectory topic must have.
pub(super) const TRAJECTORY_TYPE: &str = "trajectory_msgs/msg/JointTrajectory";

/// The trajectory topic being replayed.
#[derive(Debug)]
pub(super) struct Trajectories {
    pub(super) topic: String,
    stream: TrajectoryStream,
}

impl Trajectories {
    /// The trajectories of `topic` (the bag was checked to have it: `replay_run::topic_in_bag`).
    pub(super) fn new(topic: &str) -> Trajectories {
        Trajectories { topic: topic.to_owned(), stream: TrajectoryStream::default() }
    }

    /// A trajectory recorded at `log_time`: the answer for the one it preempts.
    pub(super) fn receive(&mut self, pipeline: &Pipeline, trajectory: crate::msgs::JointTrajectory, log_time: i64) -> Option<StreamedTrajectory> {
        self.stream.receive(pipeline, trajectory, log_time)
    }

    /// The answer for the last trajectory.
    pub(super) fn finish(&mut self) -> Option<StreamedTrajectory> {
        self.stream.finish()
    }
}
