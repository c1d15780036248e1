//! Writing a rosbag2 bag: a directory with `metadata.yaml` and one `.mcap` file.

use super::cdr::encode_cdr_le_into;
use super::cdr_writer::CdrWriter;
use super::output_error::OutputError;
use crate::msgs::full_definition;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The QoS `ros2 bag record` stores for a transient-local ("latched") publisher. `ros2 bag play`
/// offers a topic with the QoS recorded for it, so RViz (which subscribes to
/// `/robot_description` transient local) gets the description and the cells whenever it joins.
const LATCHED_QOS: &str = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 1\n  deadline:\n    sec: 9223372036\n    nsec: 854775807\n  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n  avoid_ros_namespace_conventions: false";

/// A topic of a [`BagWriter`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct TopicId(usize);

struct TopicEntry {
    name: String,
    type_name: &'static str,
    channel: u16,
    qos: &'static str,
    count: u64,
}

/// Writes messages on a few topics into a new rosbag2 MCAP bag.
pub(crate) struct BagWriter {
    dir: PathBuf,
    file_name: String,
    writer: mcap::Writer<BufWriter<std::fs::File>>,
    schemas: BTreeMap<&'static str, u16>,
    topics: Vec<TopicEntry>,
    first: Option<i64>,
    last: i64,
    /// The message being encoded, reused.
    buf: Vec<u8>,
}

impl BagWriter {
    /// Creates `dir`, which must not exist yet (as `ros2 bag record -o` requires).
    pub(crate) fn create(dir: &Path) -> Result<BagWriter, OutputError> {
        if dir.exists() {
            return Err(OutputError::Exists(dir.to_owned()));
        }
        std::fs::create_dir_all(dir).map_err(|source| OutputError::Create { path: dir.to_owned(), source })?;
        let name = dir.file_name().and_then(|n| n.to_str()).unwrap_or("collisions");
        let file_name = format!("{name}_0.mcap");
        let file = std::fs::File::create(dir.join(&file_name)).map_err(|source| OutputError::Create { path: dir.join(&file_name), source })?;
        // Uncompressed, as `ros2 bag record` writes MCAP by default; zstd cost ~15 % of a replay.
        let writer = mcap::WriteOptions::new().profile("ros2").library("thickness_collision").compression(None).create(BufWriter::new(file))?;
        Ok(BagWriter { dir: dir.to_owned(), file_name, writer, schemas: BTreeMap::new(), topics: Vec::new(), first: None, last: 0, buf: Vec::new() })
    }

    /// Adds a topic of a type this crate has the full definition of (`crate::msgs::full_definition`);
    /// `latched` records it as offered transient local.
    pub(crate) fn add_topic(&mut self, topic: &str, type_name: &'static str, latched: bool) -> Result<TopicId, OutputError> {
        let schema = match self.schemas.get(type_name) {
            Some(id) => *id,
            None => {
                let definition = full_definition(type_name).ok_or_else(|| OutputError::NoDefinition(type_name.to_owned()))?;
                let id = self.writer.add_schema(type_name, "ros2msg", definition.as_bytes())?;
                let _ = self.schemas.insert(type_name, id);
                id
            }
        };
        let qos = if latched { LATCHED_QOS } else { "" };
        let mut metadata = BTreeMap::new();
        let _ = metadata.insert("offered_qos_profiles".to_owned(), qos.to_owned());
        let channel = self.writer.add_channel(schema, topic, "cdr", &metadata)?;
        self.topics.push(TopicEntry { name: topic.to_owned(), type_name, channel, qos, count: 0 });
        Ok(TopicId(self.topics.len() - 1))
    }

    /// Appends one message received at `log_time` (nanoseconds).
    pub(crate) fn write<T: Serialize>(&mut self, topic: TopicId, msg: &T, log_time: i64) -> Result<(), OutputError> {
        let mut buf = std::mem::take(&mut self.buf);
        encode_cdr_le_into(&mut buf, msg);
        let written = self.write_raw(topic, &buf, log_time);
        self.buf = buf;
        written
    }

    /// Appends one message encoded by `encode` (a [`super::cdr_writer::CdrWriter`] method) into the
    /// writer's reused buffer.
    pub(super) fn write_with(&mut self, topic: TopicId, encode: impl FnOnce(CdrWriter), log_time: i64) -> Result<(), OutputError> {
        let mut buf = std::mem::take(&mut self.buf);
        encode(CdrWriter::new(&mut buf));
        let written = self.write_raw(topic, &buf, log_time);
        self.buf = buf;
        written
    }

    /// Appends one message already in CDR (with its encapsulation header), as copied from a bag.
    pub(crate) fn write_raw(&mut self, topic: TopicId, data: &[u8], log_time: i64) -> Result<(), OutputError> {
        let entry = &mut self.topics[topic.0];
        // MCAP sequence numbers are 32 bits and may wrap; readers order by log time.
        let header =
            mcap::records::MessageHeader { channel_id: entry.channel, sequence: entry.count as u32, log_time: log_time as u64, publish_time: log_time as u64 };
        self.writer.write_to_known_channel(&header, data)?;
        entry.count += 1;
        let _ = self.first.get_or_insert(log_time);
        self.last = self.last.max(log_time);
        Ok(())
    }

    /// Finishes the MCAP file and writes `metadata.yaml`.
    pub(crate) fn finish(mut self) -> Result<PathBuf, OutputError> {
        let _ = self.writer.finish()?;
        let start = self.first.unwrap_or(0);
        let duration = self.last - start;
        let total: u64 = self.topics.iter().map(|t| t.count).sum();
        let mut topics = String::new();
        for t in &self.topics {
            // A YAML double-quoted scalar: the QoS text's newlines as \n.
            let qos = t.qos.replace('\n', "\\n");
            topics += &format!(
                "    - topic_metadata:\n        name: {}\n        type: {}\n        serialization_format: cdr\n        offered_qos_profiles: \"{qos}\"\n      message_count: {}\n",
                t.name, t.type_name, t.count
            );
        }
        let meta = format!(
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  duration:\n    nanoseconds: {duration}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  message_count: {total}\n  topics_with_message_count:\n{topics}  compression_format: ''\n  compression_mode: ''\n  relative_file_paths:\n    - {file}\n  files:\n    - path: {file}\n      starting_time:\n        nanoseconds_since_epoch: {start}\n      duration:\n        nanoseconds: {duration}\n      message_count: {total}\n",
            file = self.file_name,
        );
        std::fs::write(self.dir.join("metadata.yaml"), meta).map_err(|source| OutputError::Write { path: self.dir.join("metadata.yaml"), source })?;
        Ok(self.dir)
    }
}
