//! MCAP storage files: the topics from the summary section (or a pass over the file without
//! one), and the messages streamed record by record through the `mcap` crate's sans-io reader,
//! each record bounded by [`MAX_RECORD_BYTES`].

use super::bag_types::{BagError, BagMessage, FILE_BUFFER, MAX_RECORD_BYTES, READ_PIECE};
use mcap::read::ChannelAccumulator;
use mcap::records::{op, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::collections::{HashMap, HashSet};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// (topic, type, message encoding) triples.
pub(super) type Topics = Vec<(String, String, String)>;

/// Why a pass over an MCAP file stopped early.
pub(super) enum Fault {
    Io(std::io::Error),
    Mcap(McapError),
    Bad(String),
}

impl From<McapError> for Fault {
    fn from(e: McapError) -> Self {
        Fault::Mcap(e)
    }
}

impl Fault {
    fn into_bag_error(self, path: &Path, after: usize) -> BagError {
        let message = match self {
            Fault::Io(e) => return BagError::Io(path.to_owned(), e),
            Fault::Mcap(McapError::RecordTooLarge { opcode, len }) => {
                format!("a record (opcode {opcode:#04x}) claims {len} bytes, more than this reader's limit of {} MiB per record", MAX_RECORD_BYTES >> 20)
            }
            Fault::Mcap(McapError::ChunkTooLarge(len)) => {
                format!("a chunk claims {len} bytes, more than this reader's limit of {} MiB per record", MAX_RECORD_BYTES >> 20)
            }
            Fault::Mcap(e) => match std::error::Error::source(&e) {
                Some(s) => format!("{e}: {s}"),
                None => e.to_string(),
            },
            Fault::Bad(s) => s,
        };
        BagError::Mcap { path: path.to_owned(), after, message }
    }
}

/// Feeds an MCAP file to the sans-io linear reader, a bounded piece at a time.
pub(super) struct Pump {
    src: BufReader<File>,
    reader: LinearReader,
}

impl Pump {
    fn new(file: File, options: LinearReaderOptions) -> Self {
        Pump { src: BufReader::with_capacity(FILE_BUFFER, file), reader: LinearReader::new_with_options(options) }
    }

    /// Hands the records to `on` until it returns `Some`; `Ok(None)` at the clean end of the file.
    fn next_record<T>(&mut self, mut on: impl FnMut(u8, &[u8]) -> Result<Option<T>, Fault>) -> Result<Option<T>, Fault> {
        loop {
            // mcap 0.26's LinearReader subtracts a record's length from its chunk's remaining
            // size unchecked (`linear_reader.rs:745`): a record inside an uncompressed chunk that
            // claims more bytes than the chunk has panics with overflow checks on (debug builds;
            // found by `cargo fuzz`, fuzz/regressions/bag_mcap/). Contained, the file ends there
            // with an error like any other corrupt MCAP.
            let reader = &mut self.reader;
            // (The reader moves into the closure, so the event may borrow it past the call.)
            let event = crate::limits::contain_panic(move || {
                let reader = reader;
                reader.next_event()
            })
            .map_err(|panic| Fault::Bad(format!("the mcap crate failed on this file ({panic})")))?;
            let want = match event {
                None => return Ok(None),
                Some(Err(e)) => return Err(Fault::Mcap(e)),
                Some(Ok(LinearReadEvent::ReadRequest(n))) => n,
                Some(Ok(LinearReadEvent::Record { opcode, data })) => {
                    if let Some(t) = on(opcode, data)? {
                        return Ok(Some(t));
                    }
                    continue;
                }
            };
            // Never more than READ_PIECE at once: the reader's buffer is sized by the request, and
            // a corrupt length must not size it beyond the bytes the file really has.
            let buf = self.reader.insert(want.clamp(1, READ_PIECE));
            let n = loop {
                match self.src.read(buf) {
                    Ok(n) => break n,
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                    Err(e) => return Err(Fault::Io(e)),
                }
            };
            self.reader.notify_read(n);
        }
    }
}

/// Checks that the length-prefixed strings of a schema or channel record fit in the record before
/// the `mcap` crate parses it (its parser reserves a string's claimed length up front: up to 4 GiB
/// from one corrupt u32).
pub(super) fn check_strings(opcode: u8, body: &[u8]) -> Result<(), Fault> {
    fn string(body: &[u8], pos: &mut usize, end: usize) -> Option<()> {
        let len = u32::from_le_bytes(body.get(*pos..*pos + 4)?.try_into().ok()?) as usize;
        *pos = pos.checked_add(4)?.checked_add(len)?;
        (*pos <= end).then_some(())
    }
    let ok = || -> Option<()> {
        let mut pos = match opcode {
            op::SCHEMA => 2,
            op::CHANNEL => 4,
            _ => return Some(()),
        };
        string(body, &mut pos, body.len())?;
        string(body, &mut pos, body.len())?;
        if opcode == op::CHANNEL {
            let map_len = u32::from_le_bytes(body.get(pos..pos + 4)?.try_into().ok()?) as usize;
            pos += 4;
            let end = pos.checked_add(map_len)?;
            if end > body.len() {
                return None;
            }
            while pos < end {
                string(body, &mut pos, end)?;
                string(body, &mut pos, end)?;
            }
        }
        Some(())
    };
    ok().ok_or_else(|| Fault::Bad(format!("a {} record's strings overrun its {} bytes", if opcode == op::SCHEMA { "schema" } else { "channel" }, body.len())))
}

/// Schemas and channels as declared, for the topic list (lenient: no cross-checks, which the
/// message pass does).
#[derive(Default)]
pub(super) struct Declared {
    schemas: HashMap<u16, String>,
    channel_ids: HashSet<u16>,
    channels: Vec<(String, u16, String)>,
}

impl Declared {
    fn add(&mut self, opcode: u8, body: &[u8]) -> Result<(), Fault> {
        if opcode != op::SCHEMA && opcode != op::CHANNEL {
            return Ok(());
        }
        check_strings(opcode, body)?;
        match mcap::parse_record(opcode, body)? {
            Record::Schema { header, .. } => {
                let _ = self.schemas.entry(header.id).or_insert(header.name);
            }
            Record::Channel(c) if self.channel_ids.insert(c.id) => self.channels.push((c.topic, c.schema_id, c.message_encoding)),
            _ => {}
        }
        Ok(())
    }

    fn topics(self) -> Topics {
        let schemas = self.schemas;
        self.channels.into_iter().map(|(topic, schema, encoding)| (topic, schemas.get(&schema).cloned().unwrap_or_default(), encoding)).collect()
    }
}

/// A bag file opened only when it is a regular file (a FIFO would block, a device never end).
pub(super) fn open_bag_file(path: &Path) -> Result<File, BagError> {
    crate::limits::open_regular(path, "bag file", u64::MAX).map(|(f, _)| f).map_err(|e| match e {
        crate::limits::InputFileError::Io { error, .. } => BagError::Io(path.to_owned(), error),
        other => BagError::Io(path.to_owned(), std::io::Error::other(other.to_string())),
    })
}

/// The topics of an MCAP file, and the fault that cut the scan short when there was no summary.
pub(super) fn mcap_topics(path: &Path) -> Result<(Topics, Option<BagError>), BagError> {
    let io = |e| BagError::Io(path.to_owned(), e);
    let file = open_bag_file(path)?;
    let size = file.metadata().map_err(io)?.len();
    if let Some(topics) = summary_topics(file, size) {
        return Ok((topics, None));
    }
    // No usable summary: one pass over the channel records (data bytes are skipped, but chunks
    // have to be decompressed to find the records in them).
    let mut pump = Pump::new(open_bag_file(path)?, LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES));
    let mut declared = Declared::default();
    let (mut records, mut messages) = (0usize, 0usize);
    let scan = pump.next_record(|opcode, body| {
        records += 1;
        match opcode {
            op::DATA_END => return Ok(Some(())),
            op::MESSAGE => messages += 1,
            _ => declared.add(opcode, body)?,
        }
        Ok(None)
    });
    match scan {
        Ok(_) => Ok((declared.topics(), None)),
        // Not even the header: not an MCAP file (or an empty one).
        Err(e) if records == 0 => Err(e.into_bag_error(path, 0)),
        Err(e) => Ok((declared.topics(), Some(e.into_bag_error(path, messages)))),
    }
}

/// The topics from the summary section, or `None` when there is no usable one.
pub(super) fn summary_topics(mut file: File, size: u64) -> Option<Topics> {
    // Footer record (opcode, length, summary start, summary offset start, CRC) and end magic.
    const TAIL: usize = 1 + 8 + 8 + 8 + 4 + 8;
    let magic = mcap::MAGIC.len() as u64;
    if size < magic + TAIL as u64 {
        return None;
    }
    let footer_at = size - TAIL as u64;
    let _ = file.seek(SeekFrom::Start(footer_at)).ok()?;
    let mut tail = [0u8; TAIL];
    file.read_exact(&mut tail).ok()?;
    let field = |at: usize| tail.get(at..at + 8).and_then(|b| b.try_into().ok()).map(u64::from_le_bytes);
    if tail[0] != op::FOOTER || field(1)? != 20 || &tail[TAIL - 8..] != mcap::MAGIC {
        return None;
    }
    let summary_start = field(9)?;
    if summary_start < magic || summary_start >= footer_at {
        return None;
    }
    let _ = file.seek(SeekFrom::Start(summary_start)).ok()?;
    let limit = usize::try_from(footer_at - summary_start).unwrap_or(usize::MAX).min(MAX_RECORD_BYTES);
    let mut pump = Pump::new(file, LinearReaderOptions::default().with_skip_start_magic(true).with_record_length_limit(limit));
    let mut declared = Declared::default();
    let end = pump.next_record(|opcode, body| {
        if opcode == op::FOOTER {
            return Ok(Some(()));
        }
        declared.add(opcode, body)?;
        Ok(None)
    });
    // A summary that does not run into the footer, or lists no channels, is not used.
    (matches!(end, Ok(Some(()))) && !declared.channels.is_empty()).then(|| declared.topics())
}

/// The messages of one MCAP file.
pub(super) struct McapStream {
    path: PathBuf,
    pump: Pump,
    channels: ChannelAccumulator<'static>,
    past_data_end: bool,
    read: usize,
}

impl McapStream {
    pub(super) fn open(path: &Path) -> Result<Self, BagError> {
        let file = open_bag_file(path)?;
        let options = LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES).with_validate_chunk_crcs(true);
        Ok(McapStream { path: path.to_owned(), pump: Pump::new(file, options), channels: ChannelAccumulator::default(), past_data_end: false, read: 0 })
    }

    pub(super) fn next(&mut self) -> Option<Result<BagMessage, BagError>> {
        let Self { pump, channels, past_data_end, .. } = self;
        // Read on to the end magic after the data end record (the summary is skipped, not parsed),
        // so that a truncated tail is reported.
        let next = pump.next_record(|opcode, body| {
            if *past_data_end {
                return if opcode == op::MESSAGE { Err(Fault::Bad("a message record after the data end record".into())) } else { Ok(None) };
            }
            match opcode {
                op::DATA_END => *past_data_end = true,
                op::SCHEMA | op::CHANNEL => {
                    check_strings(opcode, body)?;
                    match mcap::parse_record(opcode, body)? {
                        Record::Schema { header, data } => channels.add_schema_from_slice(header, &data)?,
                        Record::Channel(c) => channels.add_channel(c)?,
                        _ => {}
                    }
                }
                op::MESSAGE => {
                    if let Record::Message { header, data } = mcap::parse_record(opcode, body)? {
                        let channel = channels.get(header.channel_id).ok_or(McapError::UnknownChannel(header.sequence, header.channel_id))?;
                        return Ok(Some(BagMessage {
                            topic: channel.topic.clone(),
                            type_name: channel.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default(),
                            log_time: i64::try_from(header.log_time).unwrap_or(i64::MAX),
                            data: data.into_owned(),
                        }));
                    }
                }
                _ => {}
            }
            Ok(None)
        });
        match next {
            Ok(Some(m)) => {
                self.read += 1;
                Some(Ok(m))
            }
            Ok(None) => None,
            Err(e) => Some(Err(e.into_bag_error(&self.path, self.read))),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// sqlite3
