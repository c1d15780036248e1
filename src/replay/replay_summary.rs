//! What a replay did: the counts it prints at the end, and why a replay that decoded nothing of
//! its input topic is not a success.

use crate::pipeline::{CheckedState, SkipCause};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// What a replay did.
#[derive(Clone, Debug, Default)]
pub struct ReplaySummary {
    /// States checked.
    pub states: usize,
    /// States in collision (or failed closed).
    pub in_collision: usize,
    /// Deepest contact: (state index from 1, link, object, depth).
    pub deepest: Option<(usize, String, String, f64)>,
    /// Messages skipped, by cause.
    pub skipped: BTreeMap<SkipCause, u64>,
    /// `robot_description` messages applied, and refused.
    pub descriptions: (usize, usize),
    /// `/robot_description_semantic` messages (SRDF) applied and refused.
    pub semantics: (usize, usize),
    /// Wall time of the replay loop (seconds), reading and writing included.
    pub seconds: f64,
    /// The fault that ended the bag early, if any (reports before it are kept).
    pub bag_error: Option<String>,
    /// Why no message of the input topic was decoded, when none was. A front door treats it as a
    /// failure. Messages that decode and are then refused by the pipeline (fail closed) do not
    /// set it.
    pub no_input: Option<NoInput>,
    /// Trajectories checked (`--trajectory-topic`), and those in collision or not checkable.
    pub trajectories: (usize, usize),
}

impl ReplaySummary {
    /// Counts one trajectory's answer.
    pub(super) fn record_trajectory(&mut self, t: &crate::pipeline::StreamedTrajectory) {
        self.trajectories.0 += 1;
        if !t.outcome.0.valid {
            self.trajectories.1 += 1;
        }
    }

    /// Counts one report.
    pub(super) fn record(&mut self, checked: &CheckedState) {
        self.states += 1;
        if checked.report.in_collision {
            self.in_collision += 1;
        }
        for c in &checked.report.contacts {
            if self.deepest.as_ref().is_none_or(|d| c.depth > d.3) {
                self.deepest = Some((self.states, c.link_name.clone(), c.object_name.clone(), c.depth));
            }
        }
    }
}

impl std::fmt::Display for ReplaySummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "states: {}, in collision: {}", self.states, self.in_collision)?;
        match &self.deepest {
            Some((i, l, o, d)) => writeln!(f, "deepest contact: {l} x {o}, {d:.4} m (state {i})")?,
            None => writeln!(f, "deepest contact: none")?,
        }
        let per = if self.states > 0 { self.seconds / self.states as f64 * 1e6 } else { 0.0 };
        writeln!(f, "time: {:.3} s, {per:.2} us per state ({:.0} states/s)", self.seconds, self.states as f64 / self.seconds.max(1e-12))?;
        if self.trajectories != (0, 0) {
            writeln!(f, "trajectories: {}, in collision or not checked: {}", self.trajectories.0, self.trajectories.1)?;
        }
        if self.descriptions != (0, 0) {
            writeln!(f, "robot descriptions: {} applied, {} refused", self.descriptions.0, self.descriptions.1)?;
        }
        if self.semantics != (0, 0) {
            writeln!(f, "robot semantic descriptions (SRDF): {} applied, {} refused", self.semantics.0, self.semantics.1)?;
        }
        let total: u64 = self.skipped.values().sum();
        write!(f, "skipped messages: {total}")?;
        for (cause, n) in &self.skipped {
            write!(f, "\n  {n} x {}", cause.key())?;
        }
        if let Some(e) = &self.bag_error {
            write!(f, "\nbag error: {e}")?;
        }
        Ok(())
    }
}

/// Why a replay decoded no message of its input topic.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum NoInput {
    /// The topic has no messages; `have`: the topics that have some, with their counts.
    NoMessages {
        /// The input topic.
        topic: String,
        /// The bag.
        bag: PathBuf,
        /// (topic, messages) of the bag.
        have: Vec<(String, u64)>,
    },
    /// Every message of the topic lies outside the replay's window.
    OutsideWindow {
        /// The input topic.
        topic: String,
        /// The bag.
        bag: PathBuf,
        /// Its messages.
        messages: u64,
        /// First and last (s after the bag's first message).
        span: (f64, f64),
        /// The window asked for.
        start: Option<f64>,
        /// The window asked for.
        end: Option<f64>,
    },
    /// None of the messages in the window decodes as the topic's type.
    Undecodable {
        /// The input topic.
        topic: String,
        /// The bag.
        bag: PathBuf,
        /// The type they should be.
        expected: String,
        /// Messages in the window.
        messages: u64,
        /// Of those, payloads that start like a zstd frame.
        zstd_frames: u64,
        /// The decoder's complaint about the first.
        first_error: String,
    },
}

/// What the input topic gave, for [`NoInput`].
#[derive(Default)]
pub(super) struct InputCount {
    /// Messages read, per topic.
    pub per_topic: BTreeMap<String, u64>,
    /// Messages of the input topic in the window.
    pub in_window: u64,
    /// Of those, decoded.
    pub decoded: u64,
    /// Of the undecodable ones, payloads that start like a zstd frame.
    pub zstd_frames: u64,
    pub first_error: Option<String>,
    /// First and last time (s after the bag's first message) of the input topic's messages
    /// outside the window.
    pub span: Option<(f64, f64)>,
}

impl InputCount {
    pub(super) fn refusal(&self, topic: &str, expected: &str, bag: &std::path::Path, start: Option<f64>, end: Option<f64>) -> Option<NoInput> {
        let (topic, bag) = (topic.to_owned(), bag.to_owned());
        let on_topic = self.per_topic.get(&topic).copied().unwrap_or(0);
        if self.decoded > 0 {
            None
        } else if on_topic == 0 {
            Some(NoInput::NoMessages { topic, bag, have: self.per_topic.iter().map(|(t, n)| (t.clone(), *n)).collect() })
        } else if self.in_window == 0 {
            Some(NoInput::OutsideWindow { topic, bag, messages: on_topic, span: self.span.unwrap_or_default(), start, end })
        } else {
            Some(NoInput::Undecodable {
                topic,
                bag,
                expected: expected.to_owned(),
                messages: self.in_window,
                zstd_frames: self.zstd_frames,
                first_error: self.first_error.clone().unwrap_or_else(|| "?".to_owned()),
            })
        }
    }
}
