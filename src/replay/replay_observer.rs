//! Where a replay's progress, warnings and notes go: the library reports them, a front door shows
//! them (the CLI draws a bar on a terminal and prints to standard error).

use std::collections::HashSet;

/// Told what a replay is doing. Every method has a default that ignores it.
pub trait ReplayObserver {
    /// `messages` read from the bag so far (called every 1,024 messages).
    fn progress(&mut self, _messages: u64) {}
    /// Something the user should know: a refused description, a skipped message (the first of
    /// each kind only; the summary counts them all).
    fn warning(&mut self, _text: &str) {}
    /// What was applied: a robot or SRDF taken from the bag.
    fn note(&mut self, _text: &str) {}
    /// The replay ended (a bar is cleared here).
    fn finished(&mut self) {}
}

/// Ignores everything.
#[derive(Clone, Copy, Debug, Default)]
pub struct Quiet;

impl ReplayObserver for Quiet {}

/// Passes on the first warning of each kind only: a bag of a million bad messages must not give a
/// million lines.
pub(super) struct FirstWarnings<'a> {
    seen: HashSet<String>,
    pub observer: &'a mut dyn ReplayObserver,
}

impl<'a> FirstWarnings<'a> {
    pub(crate) fn new(observer: &'a mut dyn ReplayObserver) -> Self {
        FirstWarnings { seen: HashSet::new(), observer }
    }

    pub(crate) fn warn(&mut self, kind: &str, message: impl FnOnce() -> String) {
        if self.seen.insert(kind.to_owned()) {
            self.observer.warning(&format!("{} (further ones are counted, not printed)", message()));
        }
    }
}
