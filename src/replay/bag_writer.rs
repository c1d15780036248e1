//! Writing a rosbag2 bag: a directory with `metadata.yaml` and one `.mcap` file.

use super::cdr::encode_cdr_le;
use crate::msgs::{full_definition, CollisionReport, COLLISION_REPORT_TYPE};
use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Writes `collisions` reports into a new rosbag2 MCAP bag.
pub struct BagWriter {
    dir: PathBuf,
    file_name: String,
    writer: mcap::Writer<BufWriter<std::fs::File>>,
    channel: u16,
    topic: String,
    count: u64,
    first: Option<i64>,
    last: i64,
}

impl BagWriter {
    /// Creates `dir` (which must not exist yet, as `ros2 bag record -o` requires) with one topic.
    pub fn create(dir: &Path, topic: &str) -> Result<BagWriter> {
        if dir.exists() {
            anyhow::bail!("output bag {} already exists", dir.display());
        }
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let name = dir.file_name().and_then(|n| n.to_str()).unwrap_or("collisions");
        let file_name = format!("{name}_0.mcap");
        let file = std::fs::File::create(dir.join(&file_name)).with_context(|| format!("cannot create {}", dir.join(&file_name).display()))?;
        // Uncompressed, as `ros2 bag record` writes MCAP by default; zstd cost ~15 % of a replay.
        let mut writer = mcap::WriteOptions::new().profile("ros2").library("thickness_collision").compression(None).create(BufWriter::new(file))?;
        let definition = full_definition(COLLISION_REPORT_TYPE).unwrap_or_default();
        let schema = writer.add_schema(COLLISION_REPORT_TYPE, "ros2msg", definition.as_bytes())?;
        let mut metadata = BTreeMap::new();
        let _ = metadata.insert("offered_qos_profiles".to_owned(), String::new());
        let channel = writer.add_channel(schema, topic, "cdr", &metadata)?;
        Ok(BagWriter { dir: dir.to_owned(), file_name, writer, channel, topic: topic.to_owned(), count: 0, first: None, last: 0 })
    }

    /// Appends one report received at `log_time` (nanoseconds).
    pub fn write(&mut self, report: &CollisionReport, log_time: i64) -> Result<()> {
        let data = encode_cdr_le(report);
        let header =
            mcap::records::MessageHeader { channel_id: self.channel, sequence: self.count as u32, log_time: log_time as u64, publish_time: log_time as u64 };
        self.writer.write_to_known_channel(&header, &data)?;
        self.count += 1;
        let _ = self.first.get_or_insert(log_time);
        self.last = self.last.max(log_time);
        Ok(())
    }

    /// Finishes the MCAP file and writes `metadata.yaml`.
    pub fn finish(mut self) -> Result<PathBuf> {
        let _ = self.writer.finish()?;
        let start = self.first.unwrap_or(0);
        let duration = self.last - start;
        let meta = format!(
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  duration:\n    nanoseconds: {duration}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  message_count: {n}\n  topics_with_message_count:\n    - topic_metadata:\n        name: {topic}\n        type: {ty}\n        serialization_format: cdr\n        offered_qos_profiles: ''\n      message_count: {n}\n  compression_format: ''\n  compression_mode: ''\n  relative_file_paths:\n    - {file}\n  files:\n    - path: {file}\n      starting_time:\n        nanoseconds_since_epoch: {start}\n      duration:\n        nanoseconds: {duration}\n      message_count: {n}\n",
            n = self.count,
            topic = self.topic,
            ty = COLLISION_REPORT_TYPE,
            file = self.file_name,
        );
        std::fs::write(self.dir.join("metadata.yaml"), meta)?;
        Ok(self.dir)
    }
}
