//! Why a replay cannot start or finish.

use super::bag_output::DESCRIPTION_TOPIC;
use super::bag_reader::BagError;
use super::output_error::OutputError;
use crate::checker::CheckerError;
use std::path::PathBuf;

/// Why a replay cannot start or finish. Reports written before the error are kept.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// The bag cannot be opened.
    #[error(transparent)]
    Bag(#[from] BagError),
    /// The robot or environment cannot be loaded.
    #[error(transparent)]
    Checker(#[from] CheckerError),
    /// An output cannot be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The input topic is not in the bag.
    #[error("topic {topic} is not in bag {} (it has: {have})", bag.display())]
    MissingTopic {
        /// The topic.
        topic: String,
        /// The bag.
        bag: PathBuf,
        /// The bag's topics, listed.
        have: String,
    },
    /// The input topic has another type than the pose source reads.
    #[error("topic {topic} in bag {} has type {found}; pose_source {source_name} reads {expected}", bag.display())]
    WrongType {
        /// The topic.
        topic: String,
        /// The bag.
        bag: PathBuf,
        /// Its type.
        found: String,
        /// `joint_states` or `tf`.
        source_name: &'static str,
        /// The type that pose source reads.
        expected: &'static str,
    },
    /// The input topic is not CDR: every message would be undecodable.
    #[error("topic {topic} in bag {} has message encoding '{encoding}'; replay decodes cdr (ROS 2's serialization) only", bag.display())]
    Encoding {
        /// The topic.
        topic: String,
        /// The bag.
        bag: PathBuf,
        /// Its encoding.
        encoding: String,
    },
    /// The parameters' SRDF fitted no robot of the replay.
    #[error("robot_semantic_file {file} fits neither the bundled arm nor a {DESCRIPTION_TOPIC} of bag {} ({applied} applied, {refused} refused)", bag.display())]
    SemanticUnused {
        /// The SRDF file.
        file: String,
        /// The bag.
        bag: PathBuf,
        /// Descriptions applied.
        applied: usize,
        /// Descriptions refused.
        refused: usize,
    },
}
