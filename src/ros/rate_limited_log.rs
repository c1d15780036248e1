//! The node's warnings: on the console at once, at most once a second per cause, so a flood of
//! bad messages cannot flood the log; and queued for `/rosout`, which the loop's tick sends.

use std::collections::HashMap;
use std::time::{Duration, Instant};

/// Lines queued for `/rosout` at most between two ticks; past that they reach the console only.
const MAX_QUEUED: usize = 64;

/// Warnings at most once a second per cause.
#[derive(Default)]
pub(super) struct RateLimitedLog {
    last: HashMap<String, Instant>,
    suppressed: HashMap<String, u64>,
    /// Lines written but not yet sent to `/rosout` (the node is borrowed elsewhere then).
    pending: Vec<String>,
}

impl RateLimitedLog {
    /// A warning for `cause`, unless one for it went out within the last second (then counted,
    /// and the count told with the next one).
    pub(super) fn warn(&mut self, cause: &str, message: impl FnOnce() -> String) {
        let now = Instant::now();
        match self.last.get(cause) {
            Some(t) if now.duration_since(*t) < Duration::from_secs(1) => {
                *self.suppressed.entry(cause.to_owned()).or_insert(0) += 1;
            }
            _ => {
                let n = self.suppressed.remove(cause).unwrap_or(0);
                let more = if n > 0 { format!(" ({n} more like it in the last second)") } else { String::new() };
                let text = format!("{}{more}", message());
                eprintln!("[WARN] thickness_collision: {text}");
                self.queue(text);
                // Causes are a handful of fixed strings: the maps stay small.
                let _ = self.last.insert(cause.to_owned(), now);
            }
        }
    }

    /// An error, every one (they are rare: a refused robot or SRDF).
    pub(super) fn error(&mut self, line: String) {
        eprintln!("[ERROR] thickness_collision: {line}");
        self.queue(line);
    }

    /// The lines queued for `/rosout` since the last call.
    pub(super) fn take_queued(&mut self) -> std::vec::Drain<'_, String> {
        self.pending.drain(..)
    }

    fn queue(&mut self, line: String) {
        if self.pending.len() < MAX_QUEUED {
            self.pending.push(line);
        }
    }
}
