//! The joint-state bags the replay benchmarks read: one MCAP file of `sensor_msgs/msg/JointState`
//! on `/joint_states`, stamped and logged `period_ns` apart, and the `metadata.yaml` rosbag2 needs.

use mcap::records::MessageHeader;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;
use thickness_collision::msgs::{Header, JointState, Time};
use thickness_collision::replay::encode_cdr_le;

/// The first state's stamp and log time (ns).
pub const T0: i64 = 1_700_000_000_000_000_000;

/// Writes `dir/<stem>_0.mcap` and `dir/metadata.yaml` with the states `(names, positions)` in
/// order; returns how many were written.
pub fn write_joint_state_bag(dir: &Path, stem: &str, period_ns: i64, states: impl IntoIterator<Item = (Vec<String>, Vec<f64>)>) -> usize {
    std::fs::create_dir_all(dir).unwrap();
    let file_name = format!("{stem}_0.mcap");
    let file = std::fs::File::create(dir.join(&file_name)).unwrap();
    let mut w = mcap::WriteOptions::new().profile("ros2").create(BufWriter::new(file)).unwrap();
    let def = "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n";
    let schema = w.add_schema("sensor_msgs/msg/JointState", "ros2msg", def.as_bytes()).unwrap();
    let ch = w.add_channel(schema, "/joint_states", "cdr", &BTreeMap::new()).unwrap();
    let mut count = 0;
    for (k, (name, position)) in states.into_iter().enumerate() {
        let t = T0 + k as i64 * period_ns;
        let msg = JointState { header: Header { stamp: Time::from_nanos(t), frame_id: String::new() }, name, position, velocity: vec![], effort: vec![] };
        w.write_to_known_channel(&MessageHeader { channel_id: ch, sequence: k as u32, log_time: t as u64, publish_time: t as u64 }, &encode_cdr_le(&msg))
            .unwrap();
        count += 1;
    }
    let _ = w.finish().unwrap();
    std::fs::write(
        dir.join("metadata.yaml"),
        format!(
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths:\n    - {file_name}\n  message_count: {count}\n"
        ),
    )
    .unwrap();
    count
}
