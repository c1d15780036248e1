//! sqlite3 storage files: the `topics` table, and the `messages` rows (by timestamp, then row id)
//! from a reader thread that owns the connection, over a channel bounded in messages
//! ([`SQLITE_QUEUE`]) and in bytes ([`SQLITE_QUEUE_BYTES`]).

use super::bag_mcap::Topics;
use super::bag_types::{BagError, BagMessage, MAX_RECORD_BYTES, SQLITE_QUEUE, SQLITE_QUEUE_BYTES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;

pub(super) fn sqlite_open(path: &Path) -> Result<rusqlite::Connection, BagError> {
    if !path.is_file() {
        return Err(BagError::Io(path.to_owned(), std::io::Error::from(std::io::ErrorKind::NotFound)));
    }
    rusqlite::Connection::open_with_flags(path, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY | rusqlite::OpenFlags::SQLITE_OPEN_NO_MUTEX)
        .map_err(|e| BagError::Sqlite { path: path.to_owned(), after: 0, message: e.to_string() })
}

pub(super) fn sqlite_topic_rows(db: &rusqlite::Connection) -> rusqlite::Result<Vec<(i64, String, String, String)>> {
    let mut stmt = db.prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")?;
    let rows = stmt.query_map([], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, String>(1)?, r.get::<_, String>(2)?, r.get::<_, String>(3)?)))?;
    rows.collect()
}

pub(super) fn sqlite_topics(path: &Path) -> Result<Topics, BagError> {
    let db = sqlite_open(path)?;
    let rows = sqlite_topic_rows(&db).map_err(|e| BagError::Sqlite { path: path.to_owned(), after: 0, message: e.to_string() })?;
    Ok(rows.into_iter().map(|(_, name, ty, encoding)| (name, ty, encoding)).collect())
}

/// What the sqlite3 reader thread sends.
pub(super) enum Row {
    Message(BagMessage),
    Fault(String),
    End,
}

/// The byte budget of the queue: the thread waits while more than SQLITE_QUEUE_BYTES are queued.
#[derive(Default)]
pub(super) struct Flow {
    state: Mutex<FlowState>,
    cv: Condvar,
}

#[derive(Default)]
pub(super) struct FlowState {
    bytes: usize,
    closed: bool,
}

impl Flow {
    /// Waits for room for `n` bytes; false once the iterator is gone.
    fn acquire(&self, n: usize) -> bool {
        let Ok(mut s) = self.state.lock() else { return false };
        while !s.closed && s.bytes > 0 && s.bytes.saturating_add(n) > SQLITE_QUEUE_BYTES {
            s = match self.cv.wait(s) {
                Ok(s) => s,
                Err(_) => return false,
            };
        }
        if s.closed {
            return false;
        }
        s.bytes += n;
        true
    }

    fn release(&self, n: usize) {
        if let Ok(mut s) = self.state.lock() {
            s.bytes = s.bytes.saturating_sub(n);
        }
        self.cv.notify_one();
    }

    fn close(&self) {
        if let Ok(mut s) = self.state.lock() {
            s.closed = true;
        }
        self.cv.notify_all();
    }
}

/// The messages of one sqlite3 file, read row by row by a thread that owns the connection.
pub(super) struct SqliteStream {
    path: PathBuf,
    rx: Option<Receiver<Row>>,
    flow: Arc<Flow>,
    thread: Option<JoinHandle<()>>,
    read: usize,
}

impl SqliteStream {
    pub(super) fn start(path: &Path) -> Result<Self, BagError> {
        let db = sqlite_open(path)?;
        let (tx, rx) = sync_channel(SQLITE_QUEUE);
        let flow = Arc::new(Flow::default());
        let thread = {
            let flow = Arc::clone(&flow);
            std::thread::Builder::new()
                .name("bag-sqlite3".into())
                .spawn(move || {
                    let last = match send_rows(&db, &tx, &flow) {
                        Ok(true) => Row::End,
                        Ok(false) => return, // the iterator is gone
                        Err(e) => Row::Fault(e),
                    };
                    let _ = tx.send(last);
                })
                .map_err(|e| BagError::Io(path.to_owned(), e))?
        };
        Ok(SqliteStream { path: path.to_owned(), rx: Some(rx), flow, thread: Some(thread), read: 0 })
    }

    pub(super) fn next(&mut self) -> Option<Result<BagMessage, BagError>> {
        let row = self.rx.as_ref()?.recv();
        let fault = match row {
            Ok(Row::Message(m)) => {
                self.flow.release(m.data.len());
                self.read += 1;
                return Some(Ok(m));
            }
            Ok(Row::End) => None,
            Ok(Row::Fault(message)) => Some(message),
            Err(_) => Some("the sqlite3 reader thread stopped without finishing".to_owned()),
        };
        self.rx = None;
        fault.map(|message| Err(BagError::Sqlite { path: self.path.clone(), after: self.read, message }))
    }
}

impl Drop for SqliteStream {
    fn drop(&mut self) {
        // Unblock the thread wherever it waits (byte budget or a full queue), then wait for it so
        // that the connection is closed when the reader is.
        self.flow.close();
        self.rx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The reader thread: every row in timestamp order. Ok(false) when the iterator went away.
pub(super) fn send_rows(db: &rusqlite::Connection, tx: &SyncSender<Row>, flow: &Flow) -> Result<bool, String> {
    let topics: HashMap<i64, (String, String)> =
        sqlite_topic_rows(db).map_err(|e| e.to_string())?.into_iter().map(|(id, name, ty, _)| (id, (name, ty))).collect();
    let mut stmt = db.prepare("SELECT topic_id, timestamp, length(data), data FROM messages ORDER BY timestamp, id").map_err(|e| e.to_string())?;
    let mut rows = stmt.query([]).map_err(|e| e.to_string())?;
    while let Some(row) = rows.next().map_err(|e| e.to_string())? {
        let tid: i64 = row.get(0).map_err(|e| e.to_string())?;
        let log_time: i64 = row.get(1).map_err(|e| e.to_string())?;
        // length() reads the record header only: a long blob is refused before it is loaded.
        let len: Option<i64> = row.get(2).map_err(|e| e.to_string())?;
        if len.is_some_and(|n| usize::try_from(n).map_or(true, |n| n > MAX_RECORD_BYTES)) {
            return Err(format!(
                "the message at {log_time} ns has {} bytes, more than this reader's limit of {} MiB per message",
                len.unwrap_or_default(),
                MAX_RECORD_BYTES >> 20
            ));
        }
        let data: Vec<u8> = row.get(3).map_err(|e| e.to_string())?;
        let (topic, type_name) = topics.get(&tid).cloned().unwrap_or_else(|| (format!("<unknown topic id {tid}>"), String::new()));
        if !flow.acquire(data.len()) || tx.send(Row::Message(BagMessage { topic, type_name, log_time, data })).is_err() {
            return Ok(false);
        }
    }
    Ok(true)
}
