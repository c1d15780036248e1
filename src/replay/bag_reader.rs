//! Reading rosbag2 bags: a directory with `metadata.yaml`, an `.mcap` file or a `.db3` file.

use std::path::{Path, PathBuf};

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
    #[error("cannot read bag {0}")]
    Io(PathBuf, #[source] std::io::Error),
    /// Not a directory with metadata.yaml, an .mcap or a .db3 file.
    #[error("{0}: unknown storage format (expected a rosbag2 directory with metadata.yaml, an .mcap file or a .db3 file)")]
    UnknownFormat(PathBuf),
    /// metadata.yaml is malformed or names a storage this reader does not know.
    #[error("{0}/metadata.yaml: {1}")]
    Metadata(PathBuf, String),
    /// The MCAP file is corrupt or truncated (at the given message count).
    #[error("{path}: corrupt or truncated MCAP after {after} messages: {message}")]
    Mcap {
        /// File.
        path: PathBuf,
        /// Messages read before the fault.
        after: usize,
        /// What the reader said.
        message: String,
    },
    /// The sqlite3 file is corrupt or not a rosbag2 database.
    #[error("{path}: sqlite3 bag error after {after} messages: {message}")]
    Sqlite {
        /// File.
        path: PathBuf,
        /// Messages read before the fault.
        after: usize,
        /// What SQLite said.
        message: String,
    },
}

/// The messages of a bag in storage order, then the error that ended it early, if any.
pub struct BagReader {
    /// Messages read.
    pub messages: Vec<BagMessage>,
    /// The fault that stopped reading (a truncated or corrupt tail).
    pub error: Option<BagError>,
    /// The topics and their types, as declared by the bag.
    pub topics: Vec<(String, String)>,
}

/// Opens a bag and reads all its messages (the fault of a corrupt tail is kept in `error`).
pub fn open_bag(path: &Path) -> Result<BagReader, BagError> {
    if path.is_dir() {
        let meta_path = path.join("metadata.yaml");
        let text = std::fs::read_to_string(&meta_path).map_err(|_| BagError::UnknownFormat(path.to_owned()))?;
        let meta: serde_yaml::Value = serde_yaml::from_str(&text).map_err(|e| BagError::Metadata(path.to_owned(), e.to_string()))?;
        let info = &meta["rosbag2_bagfile_information"];
        let storage = info["storage_identifier"].as_str().unwrap_or("");
        let files: Vec<PathBuf> = info["relative_file_paths"].as_sequence().map(|s| s.iter().filter_map(|f| f.as_str()).map(|f| path.join(f)).collect()).unwrap_or_default();
        if files.is_empty() {
            return Err(BagError::Metadata(path.to_owned(), "relative_file_paths is empty or missing".into()));
        }
        let mut all = BagReader { messages: Vec::new(), error: None, topics: Vec::new() };
        for file in files {
            let part = match storage {
                "mcap" => read_mcap(&file)?,
                "sqlite3" => read_sqlite(&file)?,
                other => return Err(BagError::Metadata(path.to_owned(), format!("unknown storage_identifier '{other}' (expected mcap or sqlite3)"))),
            };
            all.messages.extend(part.messages);
            for t in part.topics {
                if !all.topics.contains(&t) {
                    all.topics.push(t);
                }
            }
            if part.error.is_some() {
                all.error = part.error;
                break;
            }
        }
        return Ok(all);
    }
    match path.extension().and_then(|e| e.to_str()) {
        Some("mcap") => read_mcap(path),
        Some("db3") => read_sqlite(path),
        _ if !path.exists() => Err(BagError::Io(path.to_owned(), std::io::Error::from(std::io::ErrorKind::NotFound))),
        _ => Err(BagError::UnknownFormat(path.to_owned())),
    }
}

fn read_mcap(path: &Path) -> Result<BagReader, BagError> {
    let buf = std::fs::read(path).map_err(|e| BagError::Io(path.to_owned(), e))?;
    let mut out = BagReader { messages: Vec::new(), error: None, topics: Vec::new() };
    let stream = match mcap::MessageStream::new(&buf) {
        Ok(s) => s,
        Err(e) => {
            out.error = Some(BagError::Mcap { path: path.to_owned(), after: 0, message: e.to_string() });
            return Ok(out);
        }
    };
    for item in stream {
        match item {
            Ok(m) => {
                let type_name = m.channel.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default();
                let topic = (m.channel.topic.clone(), type_name.clone());
                if !out.topics.contains(&topic) {
                    out.topics.push(topic);
                }
                out.messages.push(BagMessage { topic: m.channel.topic.clone(), type_name, log_time: m.log_time as i64, data: m.data.into_owned() });
            }
            Err(e) => {
                out.error = Some(BagError::Mcap { path: path.to_owned(), after: out.messages.len(), message: e.to_string() });
                break;
            }
        }
    }
    Ok(out)
}

fn read_sqlite(path: &Path) -> Result<BagReader, BagError> {
    if !path.is_file() {
        return Err(BagError::Io(path.to_owned(), std::io::Error::from(std::io::ErrorKind::NotFound)));
    }
    let mut out = BagReader { messages: Vec::new(), error: None, topics: Vec::new() };
    let fail = |after: usize, e: rusqlite::Error| BagError::Sqlite { path: path.to_owned(), after, message: e.to_string() };
    let db = rusqlite::Connection::open_with_flags(path, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY | rusqlite::OpenFlags::SQLITE_OPEN_NO_MUTEX).map_err(|e| fail(0, e))?;
    let mut topics = std::collections::HashMap::new();
    {
        let mut stmt = db.prepare("SELECT id, name, type FROM topics").map_err(|e| fail(0, e))?;
        let rows = stmt.query_map([], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, String>(1)?, r.get::<_, String>(2)?))).map_err(|e| fail(0, e))?;
        for row in rows {
            let (id, name, ty) = row.map_err(|e| fail(0, e))?;
            out.topics.push((name.clone(), ty.clone()));
            let _ = topics.insert(id, (name, ty));
        }
    }
    let mut stmt = db.prepare("SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id").map_err(|e| fail(0, e))?;
    let rows = stmt.query_map([], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, i64>(1)?, r.get::<_, Vec<u8>>(2)?)));
    let rows = match rows {
        Ok(r) => r,
        Err(e) => {
            out.error = Some(fail(0, e));
            return Ok(out);
        }
    };
    for row in rows {
        match row {
            Ok((tid, ts, data)) => {
                let (topic, type_name) = topics.get(&tid).cloned().unwrap_or_else(|| (format!("<unknown topic id {tid}>"), String::new()));
                out.messages.push(BagMessage { topic, type_name, log_time: ts, data });
            }
            Err(e) => {
                out.error = Some(fail(out.messages.len(), e));
                break;
            }
        }
    }
    Ok(out)
}
