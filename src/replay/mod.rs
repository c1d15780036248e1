//! Replay of recorded rosbag2 bags (MCAP or sqlite3) through the same pipeline as the node:
//! joint states (or `/tf`) in, one collision report per state out, as JSON lines, as a new rosbag2
//! bag with the `collisions` topic, markers and the robot for viewers, and/or as a timeline SVG.

mod bag_compression;
mod bag_mcap;
mod bag_output;
// Crate-visible for `fuzz_access`, which hands the fuzz harness the bag reader on its own.
pub(crate) mod bag_reader;
mod bag_sqlite;
mod bag_types;
mod bag_writer;
mod cdr;
mod cdr_writer;
mod output_error;
mod replay_error;
mod replay_observer;
mod replay_run;
mod replay_summary;
mod replay_trajectories;
mod timeline;
mod timeline_svg;

pub use self::bag_reader::BagError;
pub use self::cdr::{decode_cdr, encode_cdr_le, CdrError};
pub use self::output_error::OutputError;
pub use self::replay_error::ReplayError;
pub use self::replay_observer::{Quiet, ReplayObserver};
pub use self::replay_run::{replay, ReplayOptions};
pub use self::replay_summary::{NoInput, ReplaySummary};
