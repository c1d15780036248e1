//! Reading rosbag2 bags: a directory with `metadata.yaml`, an `.mcap` file or a `.db3` file.
//!
//! Streaming: [`open_bag`] reads only what lists the topics (the MCAP summary section, the sqlite3
//! `topics` table); the messages then come one at a time from the [`BagReader`] iterator, so the
//! memory is bounded by the largest record, never by the size of the bag:
//!
//! - MCAP is read through a `BufReader<File>` by the `mcap` crate's sans-io [`LinearReader`]
//!   (no memory map, no whole-file read), chunks (uncompressed, zstd or lz4) decompressed record by
//!   record. A record longer than [`MAX_RECORD_BYTES`] is an error, and the reader's buffer grows
//!   only with bytes actually read, so a corrupt length cannot allocate more than that.
//! - sqlite3 rows come from a reader thread that owns the connection, over a channel bounded both
//!   in messages ([`SQLITE_QUEUE`]) and in bytes ([`SQLITE_QUEUE_BYTES`]).
//! - Compressed bags (`compression_mode` `message` or `file`, zstd; a bare `.zstd` file) are
//!   decompressed as [`super::bag_compression`] describes, within the same bounds.

use super::bag_compression::{compression_from_metadata, decompress_message, message_context, Compression, MessageContext, Scratch, MAX_FILE_BYTES};
use super::bag_mcap::{mcap_topics, McapStream};
use super::bag_sqlite::{sqlite_topics, SqliteStream};
use super::bag_types::MAX_RECORD_BYTES;
pub use super::bag_types::{BagError, BagMessage};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// A storage file: where it is read, and how errors name it (they differ for a decompressed copy).
#[derive(Clone, Debug)]
struct BagFile {
    read: PathBuf,
    shown: PathBuf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Storage {
    Mcap,
    Sqlite,
}

/// An open bag: its topics, and its messages in storage order as an iterator (MCAP: file order;
/// sqlite3: by timestamp, then row id; the files of a directory one after the other).
///
/// The iterator yields `Err` once, at the fault that ends a corrupt or truncated file (after the
/// good messages before it), and `None` from then on.
pub struct BagReader {
    storage: Storage,
    compression: Compression,
    files: Vec<BagFile>,
    next_file: usize,
    current: Option<Source>,
    /// Messages of the current file yielded so far.
    read_in_file: usize,
    /// Message compression's zstd context, made at the first message.
    message_context: Option<MessageContext>,
    topics: Vec<(String, String)>,
    encodings: Vec<(String, String)>,
    topics_fault: Option<BagError>,
    done: bool,
    /// The decompressed copies of a file-compressed bag (dropped last: after the sources).
    _scratch: Option<Scratch>,
}

enum Source {
    Mcap(Box<McapStream>),
    Sqlite(SqliteStream),
}

impl BagReader {
    /// Topics and their types as declared by the bag (all files, first declaration first), known
    /// right after [`open_bag`]. MCAP: from each file's summary section; a file without one (a
    /// recording that was cut off, or a writer that writes none) is scanned once at open for its
    /// channel records. sqlite3: each file's `topics` table.
    pub fn topics(&self) -> &[(String, String)] {
        &self.topics
    }

    /// The fault that stopped the scan for topics in an MCAP file without a summary: `topics()`
    /// then holds the topics declared before it (the iterator reports the same fault again when it
    /// gets there). `None` when the topics are complete.
    pub fn topics_fault(&self) -> Option<&BagError> {
        self.topics_fault.as_ref()
    }

    /// Topics and their message encodings as declared (MCAP: each channel's `message_encoding`;
    /// sqlite3: the `topics` table's `serialization_format`), one pair per distinct encoding of a
    /// topic. ROS 2 records `cdr`; an MCAP file converted from ROS 1 says `ros1`.
    pub fn encodings(&self) -> &[(String, String)] {
        &self.encodings
    }
}

impl std::fmt::Debug for BagReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BagReader")
            .field("storage", &self.storage)
            .field("compression", &self.compression)
            .field("files", &self.files)
            .field("topics", &self.topics)
            .field("topics_fault", &self.topics_fault)
            .finish_non_exhaustive()
    }
}

impl Iterator for BagReader {
    type Item = Result<BagMessage, BagError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        loop {
            if self.current.is_none() {
                let Some(file) = self.files.get(self.next_file) else {
                    self.done = true;
                    return None;
                };
                self.next_file += 1;
                self.read_in_file = 0;
                let source = match self.storage {
                    Storage::Mcap => McapStream::open(&file.read).map(|s| Source::Mcap(Box::new(s))),
                    Storage::Sqlite => SqliteStream::start(&file.read).map(Source::Sqlite),
                };
                match source {
                    Ok(s) => self.current = Some(s),
                    Err(e) => {
                        self.done = true;
                        return Some(Err(e.shown_as(&file.shown)));
                    }
                }
            }
            let item = match self.current.as_mut() {
                Some(Source::Mcap(s)) => s.next(),
                Some(Source::Sqlite(s)) => s.next(),
                None => None,
            };
            let shown = || self.files.get(self.next_file.saturating_sub(1)).map(|f| f.shown.clone()).unwrap_or_default();
            let item = match item {
                Some(Ok(m)) if self.compression == Compression::Message => {
                    Some(match message_context_of(&mut self.message_context).and_then(|c| decompress_message(&m.data, MAX_RECORD_BYTES, c)) {
                        Ok(data) => Ok(BagMessage { data, ..m }),
                        Err(e) => Err(BagError::Decompress(
                            shown(),
                            format!("message {} of the file (at {} ns on {}) {e} (compression_mode message, zstd)", self.read_in_file + 1, m.log_time, m.topic),
                        )),
                    })
                }
                other => other,
            };
            match item {
                Some(Ok(m)) => {
                    self.read_in_file += 1;
                    return Some(Ok(m));
                }
                Some(Err(e)) => {
                    let e = e.shown_as(&shown());
                    self.done = true;
                    self.current = None;
                    return Some(Err(e));
                }
                None => self.current = None,
            }
        }
    }
}

impl std::iter::FusedIterator for BagReader {}

fn message_context_of(slot: &mut Option<MessageContext>) -> Result<&mut MessageContext, String> {
    match slot {
        Some(c) => Ok(c),
        None => Ok(slot.insert(message_context()?)),
    }
}

/// Opens a bag: checks the files, reads the topics, reads no messages (iterate for those). A
/// file-compressed bag is decompressed here, every file, into the temporary folder.
pub fn open_bag(path: &Path) -> Result<BagReader, BagError> {
    let (storage, compression, files) = if path.is_dir() { directory_files(path)? } else { single_file(path)? };
    let (files, scratch) = decompressed(files, compression)?;
    let mut topics = Vec::new();
    let mut encodings = Vec::new();
    let mut seen = HashSet::new();
    let mut topics_fault = None;
    for file in &files {
        let (declared, fault) = match storage {
            Storage::Mcap => mcap_topics(&file.read).map_err(|e| e.shown_as(&file.shown))?,
            Storage::Sqlite => (sqlite_topics(&file.read).map_err(|e| e.shown_as(&file.shown))?, None),
        };
        for (topic, ty, encoding) in declared {
            if !encodings.iter().any(|(t, e)| *t == topic && *e == encoding) {
                encodings.push((topic.clone(), encoding));
            }
            let t = (topic, ty);
            if seen.insert(t.clone()) {
                topics.push(t);
            }
        }
        if fault.is_some() {
            // The iterator stops at this fault too: the files after it are never read.
            topics_fault = fault.map(|e| e.shown_as(&file.shown));
            break;
        }
    }
    Ok(BagReader {
        storage,
        compression,
        files,
        next_file: 0,
        current: None,
        read_in_file: 0,
        message_context: None,
        topics,
        encodings,
        topics_fault,
        done: false,
        _scratch: scratch,
    })
}

/// A rosbag2 directory: its storage, compression and files from `metadata.yaml`, each file inside
/// the directory and listed once.
fn directory_files(path: &Path) -> Result<(Storage, Compression, Vec<PathBuf>), BagError> {
    let meta_path = path.join("metadata.yaml");
    if !meta_path.exists() {
        return Err(BagError::UnknownFormat(path.to_owned()));
    }
    let text = crate::limits::read_regular_text(&meta_path, "bag metadata", crate::limits::MAX_DESCRIPTION_BYTES)
        .map_err(|e| BagError::Metadata(path.to_owned(), e.to_string()))?;
    let meta: serde_yaml_ng::Value = serde_yaml_ng::from_str(&text).map_err(|e| BagError::Metadata(path.to_owned(), e.to_string()))?;
    let info = &meta["rosbag2_bagfile_information"];
    let files: Vec<PathBuf> =
        info["relative_file_paths"].as_sequence().map(|s| s.iter().filter_map(|f| f.as_str()).map(|f| path.join(f)).collect()).unwrap_or_default();
    if files.is_empty() {
        return Err(BagError::Metadata(path.to_owned(), "relative_file_paths is empty or missing".into()));
    }
    for (i, f) in files.iter().enumerate() {
        let rel = f.strip_prefix(path).unwrap_or(f);
        if rel.components().any(|c| !matches!(c, std::path::Component::Normal(_) | std::path::Component::CurDir)) {
            return Err(BagError::Metadata(path.to_owned(), format!("relative_file_paths: '{}' leaves the bag directory", rel.display())));
        }
        if files[..i].contains(f) {
            return Err(BagError::Metadata(path.to_owned(), format!("relative_file_paths lists '{}' twice", rel.display())));
        }
    }
    let storage = match info["storage_identifier"].as_str().unwrap_or("") {
        "mcap" => Storage::Mcap,
        "sqlite3" => Storage::Sqlite,
        other => return Err(BagError::Metadata(path.to_owned(), format!("unknown storage_identifier '{other}' (expected mcap or sqlite3)"))),
    };
    let compression = compression_from_metadata(info).map_err(|e| BagError::Metadata(path.to_owned(), e))?;
    Ok((storage, compression, files))
}

/// One storage file given directly, by its extension (`.mcap`, `.db3`, either with `.zstd`).
fn single_file(path: &Path) -> Result<(Storage, Compression, Vec<PathBuf>), BagError> {
    let (inner, compression) = match path.extension().and_then(|e| e.to_str()) {
        Some("zstd") => (path.file_stem().map(Path::new).and_then(|s| s.extension()).and_then(|e| e.to_str()), Compression::File),
        e => (e, Compression::None),
    };
    match inner {
        Some("mcap") => Ok((Storage::Mcap, compression, vec![path.to_owned()])),
        Some("db3") => Ok((Storage::Sqlite, compression, vec![path.to_owned()])),
        _ if !path.exists() => Err(BagError::Io(path.to_owned(), std::io::Error::from(std::io::ErrorKind::NotFound))),
        _ => Err(BagError::UnknownFormat(path.to_owned())),
    }
}

/// The files to read: a compressed one decompressed into a scratch folder (rosbag2 names each
/// `<file>.zstd`; such a name is decompressed even when metadata.yaml does not say so, a file
/// compressed by hand).
fn decompressed(files: Vec<PathBuf>, compression: Compression) -> Result<(Vec<BagFile>, Option<Scratch>), BagError> {
    let mut scratch = None;
    let files = files
        .into_iter()
        .map(|f| {
            if compression != Compression::File && f.extension().is_none_or(|e| e != "zstd") {
                return Ok(BagFile { read: f.clone(), shown: f });
            }
            if !f.exists() {
                return Err(BagError::Io(f, std::io::Error::from(std::io::ErrorKind::NotFound)));
            }
            let s = match &mut scratch {
                Some(s) => s,
                None => {
                    let tmp = std::env::temp_dir();
                    let s = Scratch::create(&tmp)
                        .map_err(|e| BagError::Decompress(f.clone(), format!("cannot make a folder in {} to decompress it into: {e}", tmp.display())))?;
                    scratch.insert(s)
                }
            };
            let read = s.decompress(&f, MAX_FILE_BYTES).map_err(|e| BagError::Decompress(f.clone(), e))?;
            Ok(BagFile { read, shown: PathBuf::from(format!("{} (decompressed)", f.display())) })
        })
        .collect::<Result<Vec<_>, BagError>>()?;
    Ok((files, scratch))
}

#[cfg(test)]
mod tests {
    use super::super::bag_mcap::check_strings;
    use super::*;

    use mcap::records::{op, Record};
    use std::collections::BTreeMap;
    use std::io::Cursor;

    /// A temporary directory, removed when the test ends.
    struct Scratch(PathBuf);

    impl std::ops::Deref for Scratch {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn scratch(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("tc_bag_reader_{}_{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }

    /// An MCAP file with two topics (the second declared after messages of the first).
    fn write_mcap(opts: mcap::WriteOptions, n: usize) -> Vec<u8> {
        let mut buf = Cursor::new(Vec::new());
        {
            let mut w = opts.create(&mut buf).unwrap();
            let s = w.add_schema("sensor_msgs/msg/JointState", "ros2msg", b"float64[] position").unwrap();
            let js = w.add_channel(s, "/joint_states", "cdr", &BTreeMap::new()).unwrap();
            for k in 0..n {
                w.write_to_known_channel(
                    &mcap::records::MessageHeader { channel_id: js, sequence: k as u32, log_time: 1000 + k as u64, publish_time: 0 },
                    &payload(k),
                )
                .unwrap();
                if k == n / 2 {
                    let s2 = w.add_schema("std_msgs/msg/String", "ros2msg", b"string data").unwrap();
                    let c2 = w.add_channel(s2, "/robot_description", "cdr", &BTreeMap::new()).unwrap();
                    w.write_to_known_channel(
                        &mcap::records::MessageHeader { channel_id: c2, sequence: 0, log_time: 1000 + k as u64, publish_time: 0 },
                        b"urdf",
                    )
                    .unwrap();
                }
            }
            let _ = w.finish().unwrap();
        }
        buf.into_inner()
    }

    fn payload(k: usize) -> Vec<u8> {
        (0..(k % 97) + 8).map(|i| (i * 31 + k) as u8).collect()
    }

    fn all(r: BagReader) -> (Vec<BagMessage>, Option<BagError>) {
        let mut msgs = Vec::new();
        let mut r = r;
        for m in r.by_ref() {
            match m {
                Ok(m) => msgs.push(m),
                Err(e) => {
                    assert!(r.next().is_none(), "nothing after an error");
                    return (msgs, Some(e));
                }
            }
        }
        (msgs, None)
    }

    /// What mcap's whole-buffer MessageStream reads.
    fn reference(bytes: &[u8]) -> Vec<(String, String, i64, Vec<u8>)> {
        mcap::MessageStream::new(bytes)
            .unwrap()
            .map(|m| m.unwrap())
            .map(|m| (m.channel.topic.clone(), m.channel.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default(), m.log_time as i64, m.data.into_owned()))
            .collect()
    }

    fn same(got: &[BagMessage], want: &[(String, String, i64, Vec<u8>)]) {
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(want) {
            assert_eq!((&g.topic, &g.type_name, g.log_time, &g.data), (&w.0, &w.1, w.2, &w.3));
        }
    }

    const TOPICS: [(&str, &str); 2] = [("/joint_states", "sensor_msgs/msg/JointState"), ("/robot_description", "std_msgs/msg/String")];

    fn topics_are(r: &BagReader, want: &[(&str, &str)]) {
        let got: Vec<(&str, &str)> = r.topics().iter().map(|(a, b)| (a.as_str(), b.as_str())).collect();
        assert_eq!(got, want);
    }

    #[test]
    fn mcap_layouts_stream_like_the_whole_file_reader() {
        let d = scratch("layouts");
        let layouts: Vec<(&str, mcap::WriteOptions)> = vec![
            ("zstd", mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).chunk_size(Some(4096)).calculate_chunk_crcs(true)),
            ("lz4", mcap::WriteOptions::new().compression(Some(mcap::Compression::Lz4)).chunk_size(Some(4096))),
            ("plain_chunks", mcap::WriteOptions::new().compression(None).chunk_size(Some(4096))),
            ("no_chunks", mcap::WriteOptions::new().use_chunks(false)),
            ("no_summary", mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).chunk_size(Some(4096)).emit_summary_records(false)),
        ];
        for (name, opts) in layouts {
            let bytes = write_mcap(opts, 3000);
            let f = d.join(format!("{name}.mcap"));
            std::fs::write(&f, &bytes).unwrap();
            let r = open_bag(&f).unwrap();
            topics_are(&r, &TOPICS);
            assert!(r.topics_fault().is_none());
            let (msgs, err) = all(r);
            assert!(err.is_none(), "{name}: {err:?}");
            same(&msgs, &reference(&bytes));
            assert_eq!(msgs.len(), 3001, "{name}");
        }
    }

    #[test]
    fn truncated_mcap_keeps_the_messages_before_the_cut() {
        let d = scratch("cut");
        let bytes = write_mcap(mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).chunk_size(Some(4096)), 3000);
        let f = d.join("cut.mcap");
        std::fs::write(&f, &bytes[..bytes.len() * 6 / 10]).unwrap();
        let r = open_bag(&f).unwrap();
        // No summary: the topics declared before the cut, and the fault.
        topics_are(&r, &TOPICS);
        assert!(r.topics_fault().is_some_and(|e| e.to_string().contains("truncated")));
        let (msgs, err) = all(r);
        let err = err.expect("an error at the cut").to_string();
        assert!(err.contains("cut.mcap") && err.contains("truncated") && err.contains("ended in the middle"), "{err}");
        let want = reference(&bytes);
        assert!(msgs.len() > 1000 && msgs.len() < 3000, "{}", msgs.len());
        same(&msgs, &want[..msgs.len()]);
        assert!(err.contains(&format!("after {} messages", msgs.len())), "{err}");

        // Cut after the header record, before the first channel: no topics, the fault says why.
        let header_end = 8 + 9 + u64::from_le_bytes(bytes[9..17].try_into().unwrap()) as usize;
        std::fs::write(&f, &bytes[..header_end + 5]).unwrap();
        let r = open_bag(&f).unwrap();
        assert!(r.topics().is_empty() && r.topics_fault().is_some());
        let (msgs, err) = all(r);
        assert!(msgs.is_empty() && err.is_some());
    }

    /// The offset of the first message record of an unchunked file.
    fn first_message(bytes: &[u8]) -> usize {
        let mut pos = 8;
        loop {
            let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap()) as usize;
            if bytes[pos] == op::MESSAGE {
                return pos;
            }
            pos += 9 + len;
        }
    }

    #[test]
    fn corrupt_lengths_are_errors_not_allocations() {
        let d = scratch("lengths");
        let bytes = write_mcap(mcap::WriteOptions::new().use_chunks(false), 200);
        let at = first_message(&bytes);
        let f = d.join("huge.mcap");
        for (len, says) in [(1u64 << 40, "limit of 256 MiB"), (u64::MAX, "limit of 256 MiB"), (100 << 20, "ended in the middle")] {
            let mut b = bytes.clone();
            b[at + 1..at + 9].copy_from_slice(&len.to_le_bytes());
            std::fs::write(&f, &b).unwrap();
            // The summary is intact: topics come from it.
            let r = open_bag(&f).unwrap();
            topics_are(&r, &TOPICS);
            let (msgs, err) = all(r);
            let err = err.expect("an error").to_string();
            assert!(msgs.is_empty() && err.contains("huge.mcap") && err.contains(says), "{err}");
            if len != 100 << 20 {
                assert!(err.contains(&len.to_string()), "{err}");
            }
        }
        // A channel record whose topic claims 4 GiB.
        let mut b = bytes.clone();
        let mut pos = 8;
        while b[pos] != op::CHANNEL {
            pos += 9 + u64::from_le_bytes(b[pos + 1..pos + 9].try_into().unwrap()) as usize;
        }
        b[pos + 9 + 4..pos + 9 + 8].copy_from_slice(&u32::MAX.to_le_bytes());
        let cut = b.len() / 2;
        std::fs::write(&f, &b[..cut]).unwrap(); // no summary: the scan meets the channel record too
        let r = open_bag(&f).unwrap();
        assert!(r.topics_fault().is_some_and(|e| e.to_string().contains("overrun")), "{:?}", r.topics_fault());
        let (_, err) = all(r);
        assert!(err.is_some_and(|e| e.to_string().contains("overrun")));
    }

    #[test]
    fn not_an_mcap_file_fails_at_open() {
        let d = scratch("notmcap");
        let f = d.join("x.mcap");
        std::fs::write(&f, b"definitely not an mcap file, only named like one").unwrap();
        let e = open_bag(&f).unwrap_err().to_string();
        assert!(e.contains("x.mcap") && e.contains("magic"), "{e}");
        // Cut inside the header record: nothing readable either.
        let bytes = write_mcap(mcap::WriteOptions::new(), 10);
        std::fs::write(&f, &bytes[..12]).unwrap();
        assert!(open_bag(&f).unwrap_err().to_string().contains("x.mcap"));
        std::fs::write(&f, b"").unwrap();
        assert!(open_bag(&f).is_err());
        let e = open_bag(&d.join("missing.mcap")).unwrap_err().to_string();
        assert!(e.contains("missing.mcap"), "{e}");
        let t = d.join("notes.txt");
        std::fs::write(&t, "x").unwrap();
        assert!(open_bag(&t).unwrap_err().to_string().contains("unknown storage format"));
    }

    fn metadata(dir: &Path, storage: &str, files: &[&str]) {
        let list: String = files.iter().map(|f| format!("\n    - {f}")).collect();
        std::fs::write(
            dir.join("metadata.yaml"),
            format!("rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: {storage}\n  relative_file_paths:{list}\n"),
        )
        .unwrap();
    }

    #[test]
    fn a_directory_reads_its_files_in_order() {
        let d = scratch("dir");
        let a = write_mcap(mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)), 500);
        let mut b = Cursor::new(Vec::new());
        {
            let mut w = mcap::WriteOptions::new().create(&mut b).unwrap();
            let s = w.add_schema("tf2_msgs/msg/TFMessage", "ros2msg", b"").unwrap();
            let c = w.add_channel(s, "/tf", "cdr", &BTreeMap::new()).unwrap();
            for k in 0..10u32 {
                w.write_to_known_channel(
                    &mcap::records::MessageHeader { channel_id: c, sequence: k, log_time: 5000 + u64::from(k), publish_time: 0 },
                    &[k as u8; 3],
                )
                .unwrap();
            }
            let _ = w.finish().unwrap();
        }
        let b = b.into_inner();
        std::fs::write(d.join("bag_0.mcap"), &a).unwrap();
        std::fs::write(d.join("bag_1.mcap"), &b).unwrap();
        metadata(&d, "mcap", &["bag_0.mcap", "bag_1.mcap"]);
        let r = open_bag(&d).unwrap();
        topics_are(&r, &[TOPICS[0], TOPICS[1], ("/tf", "tf2_msgs/msg/TFMessage")]);
        let (msgs, err) = all(r);
        assert!(err.is_none());
        let mut want = reference(&a);
        want.extend(reference(&b));
        same(&msgs, &want);

        metadata(&d, "mcap", &["bag_0.mcap", "gone.mcap"]);
        assert!(open_bag(&d).unwrap_err().to_string().contains("gone.mcap"));
        metadata(&d, "rosbag_v1", &["bag_0.mcap"]);
        assert!(open_bag(&d).unwrap_err().to_string().contains("unknown storage_identifier"));
        metadata(&d, "mcap", &[]);
        assert!(open_bag(&d).unwrap_err().to_string().contains("relative_file_paths"));
    }

    fn write_db3(path: &Path, rows: &[(i64, i64, Vec<u8>)]) {
        let db = rusqlite::Connection::open(path).unwrap();
        db.execute_batch(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
             CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);
             CREATE INDEX timestamp_idx ON messages (timestamp ASC);
             INSERT INTO topics VALUES (1, '/joint_states', 'sensor_msgs/msg/JointState', 'cdr', ''), (2, '/tf', 'tf2_msgs/msg/TFMessage', 'cdr', '');",
        )
        .unwrap();
        let tx = db.unchecked_transaction().unwrap();
        for (topic, t, data) in rows {
            let _ = tx.execute("INSERT INTO messages (topic_id, timestamp, data) VALUES (?1, ?2, ?3)", rusqlite::params![topic, t, data]).unwrap();
        }
        tx.commit().unwrap();
    }

    #[test]
    fn sqlite_streams_in_timestamp_order_and_stops_cleanly() {
        let d = scratch("db3");
        // Out of order on purpose, one topic id without a topic, some large rows (byte budget).
        let mut rows: Vec<(i64, i64, Vec<u8>)> = (0..5000).map(|k| (1 + (k % 2), (k * 7919) % 5000, payload(k as usize))).collect();
        rows.push((9, 100_000, vec![1, 2, 3]));
        for k in 0..6 {
            rows.push((2, 200_000 + k, vec![k as u8; 5 << 20]));
        }
        let f = d.join("bag.db3");
        write_db3(&f, &rows);
        let r = open_bag(&f).unwrap();
        topics_are(&r, &[("/joint_states", "sensor_msgs/msg/JointState"), ("/tf", "tf2_msgs/msg/TFMessage")]);
        let (msgs, err) = all(r);
        assert!(err.is_none(), "{err:?}");
        let mut want: Vec<&(i64, i64, Vec<u8>)> = rows.iter().collect();
        want.sort_by_key(|r| r.1); // stable: equal timestamps keep their row order
        assert_eq!(msgs.len(), want.len());
        for (m, (topic, t, data)) in msgs.iter().zip(&want) {
            assert_eq!((m.log_time, &m.data), (*t, data));
            let name = match topic {
                1 => "/joint_states",
                2 => "/tf",
                _ => "<unknown topic id 9>",
            };
            assert_eq!(m.topic, name);
        }
        // Dropping the reader half-way ends its thread (this would hang otherwise).
        let mut r = open_bag(&f).unwrap();
        assert!(r.nth(10).is_some_and(|m| m.is_ok()));
        drop(r);
        let mut r = open_bag(&f).unwrap();
        assert!(r.nth(4999 + 3).is_some_and(|m| m.is_ok_and(|m| m.data.len() == 5 << 20)));
        drop(r);

        // A directory of two files.
        write_db3(&d.join("b.db3"), &[(2, 1, vec![9])]);
        metadata(&d, "sqlite3", &["bag.db3", "b.db3"]);
        let (msgs, err) = all(open_bag(&d).unwrap());
        assert!(err.is_none() && msgs.len() == rows.len() + 1 && msgs.last().is_some_and(|m| m.data == [9]));

        // Not a database: an error at open naming the file.
        let bad = d.join("bad.db3");
        std::fs::write(&bad, b"this is not a database, it only has the name of one").unwrap();
        let e = open_bag(&bad).unwrap_err().to_string();
        assert!(e.contains("bad.db3"), "{e}");
    }

    /// An MCAP file with the messages of `bytes`, each payload passed through `payload`.
    fn remap_mcap(bytes: &[u8], payload: impl Fn(&[u8]) -> Vec<u8>) -> Vec<u8> {
        let mut buf = Cursor::new(Vec::new());
        {
            let mut w = mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).create(&mut buf).unwrap();
            for m in mcap::MessageStream::new(bytes).unwrap() {
                let m = m.unwrap();
                w.write(&mcap::Message { data: std::borrow::Cow::Owned(payload(&m.data)), ..m }).unwrap();
            }
            let _ = w.finish().unwrap();
        }
        buf.into_inner()
    }

    fn compressed_metadata(dir: &Path, storage: &str, files: &[&str], mode: &str, format: &str) {
        metadata(dir, storage, files);
        let mut text = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
        text += &format!("  compression_format: {format}\n  compression_mode: {mode}\n");
        std::fs::write(dir.join("metadata.yaml"), text).unwrap();
    }

    /// The scratch folders of this process in the temporary folder.
    fn scratch_folders() -> usize {
        let prefix = format!("thickness_collision_bag_{}_", std::process::id());
        std::fs::read_dir(std::env::temp_dir()).unwrap().filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with(&prefix)).count()
    }

    #[test]
    fn compressed_directories_read_like_plain_ones() {
        let d = scratch("compressed");
        let plain = write_mcap(mcap::WriteOptions::new(), 300);
        let want = reference(&plain);
        let zstd1 = |b: &[u8]| zstd::bulk::compress(b, 1).unwrap();

        // Message mode, MCAP.
        std::fs::write(d.join("bag_0.mcap"), remap_mcap(&plain, zstd1)).unwrap();
        compressed_metadata(&d, "mcap", &["bag_0.mcap"], "MESSAGE", "zstd");
        let (msgs, err) = all(open_bag(&d).unwrap());
        assert!(err.is_none(), "{err:?}");
        same(&msgs, &want);
        // Without the metadata the payloads are what is stored: zstd frames.
        let (raw, _) = all(open_bag(&d.join("bag_0.mcap")).unwrap());
        assert!(raw.iter().all(|m| super::super::bag_compression::looks_like_zstd(&m.data)));

        // A payload that declares 2^40 bytes: an error naming the file, the message and the size.
        let mut lying = vec![0x28, 0xb5, 0x2f, 0xfd, 0xe0];
        lying.extend_from_slice(&(1u64 << 40).to_le_bytes());
        let n = std::cell::Cell::new(0);
        std::fs::write(
            d.join("bag_0.mcap"),
            remap_mcap(&plain, |b| {
                n.set(n.get() + 1);
                if n.get() == 7 {
                    lying.clone()
                } else {
                    zstd1(b)
                }
            }),
        )
        .unwrap();
        let (msgs, err) = all(open_bag(&d).unwrap());
        let err = err.expect("refused").to_string();
        assert_eq!(msgs.len(), 6);
        assert!(err.contains("bag_0.mcap: message 7 of the file") && err.contains("1099511627776 bytes") && err.contains("limit of 268435456"), "{err}");

        // Message mode, sqlite3.
        let rows: Vec<(i64, i64, Vec<u8>)> = (0..200).map(|k| (1 + (k % 2), k, payload(k as usize))).collect();
        let packed: Vec<(i64, i64, Vec<u8>)> = rows.iter().map(|(t, k, p)| (*t, *k, zstd1(p))).collect();
        write_db3(&d.join("bag_0.db3"), &packed);
        compressed_metadata(&d, "sqlite3", &["bag_0.db3"], "message", "zstd");
        let (msgs, err) = all(open_bag(&d).unwrap());
        assert!(err.is_none(), "{err:?}");
        assert_eq!(msgs.iter().map(|m| m.data.clone()).collect::<Vec<_>>(), rows.iter().map(|r| r.2.clone()).collect::<Vec<_>>());
        let r = open_bag(&d).unwrap();
        assert_eq!(r.encodings(), [("/joint_states".to_owned(), "cdr".to_owned()), ("/tf".to_owned(), "cdr".to_owned())]);

        // File mode: two files, each compressed whole; a scratch folder while open, none after.
        let second = write_mcap(mcap::WriteOptions::new().compression(Some(mcap::Compression::Lz4)), 50);
        std::fs::write(d.join("bag_0.mcap.zstd"), zstd1(&plain)).unwrap();
        std::fs::write(d.join("bag_1.mcap.zstd"), zstd1(&second)).unwrap();
        compressed_metadata(&d, "mcap", &["bag_0.mcap.zstd", "bag_1.mcap.zstd"], "FILE", "zstd");
        let r = open_bag(&d).unwrap();
        assert_eq!(scratch_folders(), 1);
        let (msgs, err) = all(r);
        assert!(err.is_none(), "{err:?}");
        let mut both = want.clone();
        both.extend(reference(&second));
        same(&msgs, &both);
        assert_eq!(scratch_folders(), 0, "removed with the reader");
        // A corrupt file inside: named as the compressed file, decompressed.
        let mut cut = plain.clone();
        cut.truncate(plain.len() * 6 / 10);
        std::fs::write(d.join("bag_1.mcap.zstd"), zstd1(&cut)).unwrap();
        let (_, err) = all(open_bag(&d).unwrap());
        let err = err.expect("truncated").to_string();
        assert!(err.contains("bag_1.mcap.zstd (decompressed): corrupt or truncated MCAP"), "{err}");
        // Not zstd at all: refused at open, nothing left behind.
        std::fs::write(d.join("bag_1.mcap.zstd"), &second).unwrap();
        let err = open_bag(&d).unwrap_err().to_string();
        assert!(err.contains("bag_1.mcap.zstd: is not a zstd file"), "{err}");
        assert_eq!(scratch_folders(), 0, "removed on error");
        // Missing.
        compressed_metadata(&d, "mcap", &["bag_0.mcap.zstd", "gone.mcap.zstd"], "FILE", "zstd");
        assert!(open_bag(&d).unwrap_err().to_string().contains("gone.mcap.zstd"));
        // A bare .zstd file, and one whose inner name is not a storage.
        let (msgs, err) = all(open_bag(&d.join("bag_0.mcap.zstd")).unwrap());
        assert!(err.is_none());
        same(&msgs, &want);
        std::fs::write(d.join("notes.txt.zstd"), zstd1(b"x")).unwrap();
        assert!(open_bag(&d.join("notes.txt.zstd")).unwrap_err().to_string().contains("unknown storage format"));

        // Unknown formats and modes: refused at open, naming metadata.yaml and the value.
        for (mode, format, says) in [("MESSAGE", "lz4", "compression_format 'lz4'"), ("CHUNK", "zstd", "compression_mode 'CHUNK'")] {
            compressed_metadata(&d, "mcap", &["bag_0.mcap"], mode, format);
            let err = open_bag(&d).unwrap_err().to_string();
            assert!(err.contains("metadata.yaml") && err.contains(says), "{err}");
        }
    }

    /// A reader can move to another thread.
    const _: fn() = || {
        fn send<T: Send>() {}
        send::<BagReader>();
    };

    #[test]
    fn schema_and_channel_string_checks() {
        let mut body = Vec::new();
        body.extend_from_slice(&1u16.to_le_bytes());
        body.extend_from_slice(&1u16.to_le_bytes());
        for s in ["/t", "cdr"] {
            body.extend_from_slice(&(s.len() as u32).to_le_bytes());
            body.extend_from_slice(s.as_bytes());
        }
        let mut map = Vec::new();
        for s in ["k", "v"] {
            map.extend_from_slice(&(s.len() as u32).to_le_bytes());
            map.extend_from_slice(s.as_bytes());
        }
        body.extend_from_slice(&(map.len() as u32).to_le_bytes());
        body.extend_from_slice(&map);
        assert!(check_strings(op::CHANNEL, &body).is_ok());
        assert!(matches!(mcap::parse_record(op::CHANNEL, &body), Ok(Record::Channel(_))));
        for at in [4, 10, 17, 21, 26] {
            let mut b = body.clone();
            b[at..at + 4].copy_from_slice(&0x7fff_ffffu32.to_le_bytes());
            assert!(check_strings(op::CHANNEL, &b).is_err(), "{at}");
        }
        assert!(check_strings(op::CHANNEL, &body[..body.len() - 1]).is_err());
    }
}
