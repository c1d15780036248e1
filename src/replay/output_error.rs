//! Why an output of a replay (the new bag, the JSON lines, the timeline) cannot be written.

use crate::limits::InputFileError;
use std::path::PathBuf;

/// An output that cannot be written. Each names the file; the cause is its `source`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// `ros2 bag record -o` refuses an existing directory; so does this writer.
    #[error("output bag {0} already exists")]
    Exists(PathBuf),
    /// A file or directory cannot be created.
    #[error("cannot create {path}")]
    Create {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A file cannot be written.
    #[error("cannot write {path}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP writer failed.
    #[error(transparent)]
    Mcap(#[from] mcap::McapError),
    /// A topic of a type this crate has no full message definition of.
    #[error("no message definition for {0}")]
    NoDefinition(String),
    /// The robot's URDF (for `/robot_description` in the output) cannot be read.
    #[error("the robot's URDF for /robot_description in the output bag")]
    Description(#[source] InputFileError),
    /// The writer thread cannot be started.
    #[error("cannot start the bag writer thread")]
    Thread(#[source] std::io::Error),
    /// The writer thread panicked (a defect).
    #[error("the bag writer panicked")]
    Panicked,
    /// The writer thread stopped without saying why.
    #[error("the bag writer stopped")]
    Stopped,
    /// The timeline could not be drawn.
    #[error("drawing the timeline failed: {0}")]
    Timeline(String),
}
