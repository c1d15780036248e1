//! `--trajectory-topic`: the `trajectory_msgs/JointTrajectory` messages of a topic (a
//! controller's `~/joint_trajectory`), each checked as executed from the joint state in force
//! when it was recorded, preempted by the next (`pipeline::TrajectoryStream`); one JSON line per
//! trajectory in `--jsonl`, counted in the summary.

use super::bag_reader::BagReader;
use super::replay_error::ReplayError;
use crate::pipeline::{Pipeline, StreamedTrajectory, TrajectoryStream};
use std::path::Path;

/// The type a trajectory topic must have.
const TRAJECTORY_TYPE: &str = "trajectory_msgs/msg/JointTrajectory";

/// The trajectory topic being replayed.
#[derive(Debug)]
pub(super) struct Trajectories {
    pub(super) topic: String,
    stream: TrajectoryStream,
}

impl Trajectories {
    /// Checks that the bag has `topic` as CDR `JointTrajectory` messages.
    pub(super) fn open(bag: &BagReader, topic: &str, path: &Path) -> Result<Trajectories, ReplayError> {
        if !bag.topics().iter().any(|(t, _)| *t == topic) {
            let have: Vec<&str> = bag.topics().iter().map(|(t, _)| t.as_str()).collect();
            return Err(ReplayError::MissingTopic { topic: topic.to_owned(), bag: path.to_owned(), have: crate::limits::name_list(&have) });
        }
        if let Some((_, ty)) = bag.topics().iter().find(|(t, ty)| *t == topic && !ty.is_empty() && ty != TRAJECTORY_TYPE) {
            return Err(ReplayError::WrongType {
                topic: topic.to_owned(),
                bag: path.to_owned(),
                found: ty.clone(),
                source_name: "--trajectory-topic",
                expected: TRAJECTORY_TYPE,
            });
        }
        if let Some((_, encoding)) = bag.encodings().iter().find(|(t, e)| *t == topic && e != "cdr") {
            return Err(ReplayError::Encoding { topic: topic.to_owned(), bag: path.to_owned(), encoding: encoding.clone() });
        }
        Ok(Trajectories { topic: topic.to_owned(), stream: TrajectoryStream::default() })
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
