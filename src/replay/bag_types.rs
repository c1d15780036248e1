//! What the bag reader gives: messages, the bounds it keeps, and why a bag cannot be read.

use std::path::{Path, PathBuf};

/// The longest record (MCAP) or message (sqlite3) this reader accepts: 256 MiB. A longer one is a
/// corrupt length, or a message this replay has no use for; either way an error naming the file
/// and the length, not an allocation of that size.
pub(crate) const MAX_RECORD_BYTES: usize = 256 << 20;
/// Bytes asked of the file at a time (the MCAP reader's buffer grows by at most this much more
/// than the data it holds).
pub(super) const READ_PIECE: usize = 256 << 10;
/// The `BufReader` over an MCAP file.
pub(super) const FILE_BUFFER: usize = 64 << 10;
/// Messages queued between the sqlite3 reader thread and the iterator.
pub(crate) const SQLITE_QUEUE: usize = 256;
/// Payload bytes queued between the sqlite3 reader thread and the iterator (one larger message
/// still passes, alone).
pub(crate) const SQLITE_QUEUE_BYTES: usize = 16 << 20;

/// One recorded message.
#[derive(Clone, Debug)]
pub struct BagMessage {
    /// Topic.
    pub topic: String,
    /// ROS type, e.g. `sensor_msgs/msg/JointState`.
    pub type_name: String,
    /// Receive time (nanoseconds since the epoch).
    pub log_time: i64,
    /// Serialized payload (CDR with its encapsulation header).
    pub data: Vec<u8>,
}

/// A bag that cannot be read (the whole bag, or from some point on).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BagError {
    /// The file cannot be read.
    #[error("cannot read bag {0}: {1}")]
    Io(PathBuf, std::io::Error),
    /// Not a directory with metadata.yaml, an .mcap or a .db3 file (or one compressed as .zstd).
    #[error("{0}: unknown storage format (expected a rosbag2 directory with metadata.yaml, an .mcap file or a .db3 file, or such a file compressed as .zstd)")]
    UnknownFormat(PathBuf),
    /// metadata.yaml is malformed or names a storage this reader does not know.
    #[error("{0}/metadata.yaml: {1}")]
    Metadata(PathBuf, String),
    /// The MCAP file is corrupt or truncated (after the given number of messages of that file).
    #[error("{path}: corrupt or truncated MCAP after {after} messages: {message}")]
    Mcap {
        /// File.
        path: PathBuf,
        /// Messages of this file read before the fault.
        after: usize,
        /// What the reader said.
        message: String,
    },
    /// The sqlite3 file is corrupt or not a rosbag2 database.
    #[error("{path}: sqlite3 bag error after {after} messages: {message}")]
    Sqlite {
        /// File.
        path: PathBuf,
        /// Messages of this file read before the fault.
        after: usize,
        /// What SQLite said.
        message: String,
    },
    /// A compressed file or message payload that cannot be decompressed within the bounds.
    #[error("{0}: {1}")]
    Decompress(PathBuf, String),
}

impl BagError {
    /// The same error naming `shown` (the `.zstd` file) instead of its decompressed copy.
    pub(super) fn shown_as(self, shown: &Path) -> Self {
        match self {
            BagError::Io(_, e) => BagError::Io(shown.to_owned(), e),
            BagError::Mcap { after, message, .. } => BagError::Mcap { path: shown.to_owned(), after, message },
            BagError::Sqlite { after, message, .. } => BagError::Sqlite { path: shown.to_owned(), after, message },
            other => other,
        }
    }
}
