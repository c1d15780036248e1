//! The replay loop: the node's offline twin. Bag messages go, in storage order, through the same
//! [`Pipeline`] the node feeds live; each checked state becomes a JSON line, messages in a new
//! rosbag2 bag (the report, its markers and the robot's poses) and/or a bar of the timeline. The
//! bag is streamed: memory is bounded by the model, not the recording.

use super::bag_compression::looks_like_zstd;
use super::bag_output::{OutputBag, DESCRIPTION_TOPIC};
use super::bag_reader::{open_bag, BagMessage};
use super::cdr::decode_cdr;
use super::timeline::Timeline;
use super::timeline_svg::timeline_svg;
use crate::model::{Params, PoseSource};
use crate::msgs::{JointState, StringMsg, TfMessage};
use crate::pipeline::{CheckedState, Pipeline, RobotState, Skip, SkipCause};
use anyhow::{bail, Context, Result};
use std::collections::{BTreeMap, HashSet};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

const SEMANTIC_TOPIC: &str = "/robot_description_semantic";

/// What to replay and where the results go.
#[derive(Clone, Debug, Default)]
pub struct ReplayOptions {
    /// rosbag2 directory, `.mcap` or `.db3`.
    pub bag: PathBuf,
    /// Input topic (default `/joint_states`, or `/tf`).
    pub topic: Option<String>,
    /// Where states come from, overriding the parameters' `pose_source`.
    pub pose_source: Option<PoseSource>,
    /// The robot's `/tf` frame prefix, overriding the parameters' `frame_prefix`.
    pub frame_prefix: Option<String>,
    /// Output rosbag2 directory with the `collisions` topic.
    pub out_dir: Option<PathBuf>,
    /// Output JSON lines, one report per state.
    pub jsonl: Option<PathBuf>,
    /// Skip states before this many seconds after the bag's first message.
    pub start: Option<f64>,
    /// Skip states after this many seconds after the bag's first message.
    pub end: Option<f64>,
    /// Show a progress bar (only drawn on a terminal).
    pub progress: bool,
    /// Check the motion between consecutive states, overriding the parameters' `check_motion`.
    pub motion: Option<bool>,
    /// Draw the collision timeline into this SVG file.
    pub plot: Option<PathBuf>,
    /// The output bag gets `/collisions` only: no markers, `/tf` or `/robot_description`.
    pub no_markers: bool,
}

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
    /// Why no message of the input topic was decoded, when none was: the topic has no messages,
    /// none in the `--start`/`--end` window, or none decodes. The CLI exits 2 on it. Messages
    /// that decode and are then refused by the pipeline (fail closed) do not set it.
    pub no_input: Option<String>,
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

/// Warns about the first message of each kind of trouble only: a bag of a million bad messages
/// must not print a million lines (the summary counts them all).
#[derive(Default)]
struct FirstWarnings {
    seen: HashSet<String>,
}

impl FirstWarnings {
    fn warn(&mut self, kind: &str, message: impl FnOnce() -> String) {
        if self.seen.insert(kind.to_owned()) {
            eprintln!("thickness_collision: warning: {} (further ones are counted, not printed)", message());
        }
    }
}

/// Where the checked states go.
struct Outputs {
    jsonl: Option<std::io::BufWriter<std::fs::File>>,
    jsonl_path: Option<PathBuf>,
    bag: Option<OutputBag>,
    plot: Option<(Timeline, PathBuf)>,
}

/// Replays a bag. Reports before a corrupt tail are kept; the fault is in the summary and makes
/// the result an error after the outputs are written.
pub fn replay(params: Params, opts: &ReplayOptions) -> Result<ReplaySummary> {
    let mut params = params;
    if let Some(p) = opts.pose_source {
        params.pose_source = p;
    }
    if let Some(m) = opts.motion {
        params.check_motion = m;
    }
    if let Some(p) = &opts.frame_prefix {
        params.frame_prefix = p.clone();
    }
    let pose_source = params.pose_source;
    for (flag, v) in [("--start", opts.start), ("--end", opts.end)] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
            bail!("{flag} {v}: must be a finite number of seconds >= 0 after the bag's first message");
        }
    }
    if let (Some(a), Some(b)) = (opts.start, opts.end) {
        if a > b {
            bail!("--start {a} is after --end {b}: no message could be replayed");
        }
    }
    let bag = open_bag(&opts.bag)?;
    let topic = opts.topic.clone().unwrap_or_else(|| match pose_source {
        PoseSource::JointStates => "/joint_states".into(),
        PoseSource::Tf => "/tf".into(),
    });
    if !bag.topics().iter().any(|(t, _)| *t == topic) {
        let have: Vec<&str> = bag.topics().iter().map(|(t, _)| t.as_str()).collect();
        bail!("topic {topic} is not in bag {} (it has: {})", opts.bag.display(), crate::limits::name_list(&have));
    }
    let expected = match pose_source {
        PoseSource::JointStates => "sensor_msgs/msg/JointState",
        PoseSource::Tf => "tf2_msgs/msg/TFMessage",
    };
    if let Some((_, ty)) = bag.topics().iter().find(|(t, ty)| *t == topic && !ty.is_empty() && ty != expected) {
        bail!(
            "topic {topic} in bag {} has type {ty}; pose_source {} reads {expected}",
            opts.bag.display(),
            if pose_source == PoseSource::Tf { "tf" } else { "joint_states" }
        );
    }
    // Every message would be undecodable: say why once, up front.
    if let Some((_, encoding)) = bag.encodings().iter().find(|(t, e)| *t == topic && e != "cdr") {
        bail!("topic {topic} in bag {} has message encoding '{encoding}'; replay decodes cdr (ROS 2's serialization) only", opts.bag.display());
    }
    // Both doors start with the robot the parameters name; a description in the bag replaces it
    // at its log time, as it would replace it in the running node.
    let mut pipeline = if bag.topics().iter().any(|(t, _)| t == DESCRIPTION_TOPIC) {
        // An SRDF given for the recorded robot is checked against it when it comes.
        Pipeline::new_expecting_description(params)?
    } else {
        Pipeline::new(params)?
    };

    let mut out = Outputs {
        jsonl: match &opts.jsonl {
            Some(p) => Some(std::io::BufWriter::new(std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))?)),
            None => None,
        },
        jsonl_path: opts.jsonl.clone(),
        bag: match &opts.out_dir {
            Some(d) => {
                Some(OutputBag::create(d, bag.topics(), pose_source, &pipeline.params().world_frame, &pipeline.params().frame_prefix, !opts.no_markers)?)
            }
            None => None,
        },
        plot: match &opts.plot {
            // Created now, so a path that cannot be written fails before the bag is read.
            Some(p) => {
                let _ = std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))?;
                Some((Timeline::default(), p.clone()))
            }
            None => None,
        },
    };
    let bar = if opts.progress && std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new_spinner();
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {pos} messages {per_sec}").unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
        );
        Some(b)
    } else {
        None
    };

    let started = Instant::now();
    let mut summary = ReplaySummary::default();
    let mut warnings = FirstWarnings::default();
    let mut t0 = None;
    let mut read = 0u64;
    let mut input = InputCount::default();
    for item in bag {
        let m = match item {
            Ok(m) => m,
            Err(e) => {
                summary.bag_error = Some(e.to_string());
                break;
            }
        };
        read += 1;
        if let Some(b) = &bar {
            if read % 1024 == 0 {
                b.set_position(read);
            }
        }
        let t0 = *t0.get_or_insert(m.log_time);
        let seconds = (m.log_time - t0) as f64 * 1e-9;
        *input.per_topic.entry(m.topic.clone()).or_default() += 1;
        if let Some(b) = out.bag.as_mut() {
            b.input(&pipeline, &m)?;
        }
        let in_window = opts.start.is_none_or(|a| seconds >= a) && opts.end.is_none_or(|b| seconds <= b);
        let state = if m.topic == DESCRIPTION_TOPIC {
            apply_description(&mut pipeline, &m, &opts.bag, &mut summary, &mut warnings);
            continue;
        } else if m.topic == SEMANTIC_TOPIC {
            apply_semantic(&mut pipeline, &m, &opts.bag, &mut summary, &mut warnings);
            continue;
        } else if pose_source == PoseSource::Tf && m.topic == "/tf_static" {
            match decode::<TfMessage>(&mut pipeline, &m, &mut warnings) {
                Some(msg) => pipeline.tf_static(&msg).map(|()| None),
                None => continue,
            }
        } else if m.topic != topic || !in_window {
            if m.topic == topic {
                input.span = Some(input.span.map_or((seconds, seconds), |(a, b)| (a.min(seconds), b.max(seconds))));
            }
            continue;
        } else {
            input.in_window += 1;
            let decoded = match pose_source {
                PoseSource::JointStates => decode::<JointState>(&mut pipeline, &m, &mut warnings).map(|msg| pipeline.joint_state(&msg).map(Some)),
                PoseSource::Tf => decode::<TfMessage>(&mut pipeline, &m, &mut warnings).map(|msg| pipeline.tf(&msg).map(Some)),
            };
            match decoded {
                Some(state) => {
                    input.decoded += 1;
                    state
                }
                None => {
                    input.zstd_frames += u64::from(looks_like_zstd(&m.data));
                    if input.first_error.is_none() {
                        input.first_error = Some(decode_error(pose_source, &m.data));
                    }
                    continue;
                }
            }
        };
        for w in pipeline.take_warnings() {
            eprintln!("thickness_collision: warning: {w}");
        }
        match state {
            Ok(Some(state)) => {
                // One state per report, as the node gives when it keeps up.
                let Some(checked) = pipeline.check_path(std::slice::from_ref(&state)) else { continue };
                record(&mut summary, &checked);
                write_outputs(&mut out, &pipeline, &state, checked, m.log_time, seconds)?;
            }
            Ok(None) => {}
            Err(Skip { cause, message }) => {
                warnings.warn(cause.key(), || format!("message at log time {} ns skipped ({}): {message}", m.log_time, cause.key()))
            }
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let (Some(mut w), Some(path)) = (out.jsonl, &opts.jsonl) {
        w.flush().with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(b) = out.bag {
        b.finish()?;
    }
    if let Some((timeline, path)) = &out.plot {
        let svg = timeline_svg(timeline, &opts.bag.display().to_string()).map_err(anyhow::Error::msg)?;
        std::fs::write(path, svg).with_context(|| format!("cannot write {}", path.display()))?;
    }
    if pipeline.semantic_deferred() {
        bail!(
            "robot_semantic_file {} fits neither the bundled arm nor a {DESCRIPTION_TOPIC} of bag {} ({} applied, {} refused)",
            pipeline.params().robot_semantic_file,
            opts.bag.display(),
            summary.descriptions.0,
            summary.descriptions.1
        );
    }
    summary.seconds = started.elapsed().as_secs_f64();
    summary.skipped = pipeline.skipped().clone();
    if summary.bag_error.is_none() {
        summary.no_input = input.refusal(&topic, expected, &opts.bag, opts.start, opts.end);
    }
    Ok(summary)
}

/// What the input topic gave, for the refusal of a replay that decoded none of it.
#[derive(Default)]
struct InputCount {
    /// Messages read, per topic.
    per_topic: BTreeMap<String, u64>,
    /// Messages of the input topic in the `--start`/`--end` window.
    in_window: u64,
    /// Of those, decoded.
    decoded: u64,
    /// Of the undecodable ones, payloads that start like a zstd frame.
    zstd_frames: u64,
    first_error: Option<String>,
    /// First and last time (s after the bag's first message) of the input topic's messages
    /// outside the window.
    span: Option<(f64, f64)>,
}

impl InputCount {
    fn refusal(&self, topic: &str, expected: &str, bag: &Path, start: Option<f64>, end: Option<f64>) -> Option<String> {
        let on_topic = self.per_topic.get(topic).copied().unwrap_or(0);
        if self.decoded > 0 {
            return None;
        }
        if on_topic == 0 {
            let have: Vec<String> = self.per_topic.iter().map(|(t, n)| format!("{t} ({n})")).collect();
            let have = if have.is_empty() { "no messages at all".to_owned() } else { format!("messages on {}", have.join(", ")) };
            return Some(format!("bag {} has no messages on topic {topic}, so no state to check (it has {have})", bag.display()));
        }
        // "none of the 1 messages decodes" reads badly; one message gets its own wording.
        let subject = |n: u64| if n == 1 { "the one message".to_owned() } else { format!("none of the {n} messages") };
        let verb = |n: u64, one: &'static str, many: &'static str| if n == 1 { one } else { many };
        if self.in_window == 0 {
            let (a, b) = self.span.unwrap_or_default();
            let flag = |f: &str, v: Option<f64>| v.map_or(String::new(), |v| format!(" {f} {v}"));
            return Some(format!(
                "{} on {topic} in bag {} {}{}{} (logged {a:.3} to {b:.3} s after the bag's first message)",
                subject(on_topic),
                bag.display(),
                verb(on_topic, "is not inside", "is inside"),
                flag("--start", start),
                flag("--end", end)
            ));
        }
        let hint = if self.zstd_frames == self.in_window {
            verb(
                self.in_window,
                "; it is a zstd frame: a message-compressed bag read without its metadata.yaml (replay the bag's directory)",
                "; they are zstd frames: a message-compressed bag read without its metadata.yaml (replay the bag's directory)",
            )
        } else {
            ""
        };
        Some(format!(
            "{} on {topic} in bag {} {} as CDR {expected} (the first error: {}){hint}",
            subject(self.in_window),
            bag.display(),
            verb(self.in_window, "does not decode", "decodes"),
            self.first_error.as_deref().unwrap_or("?")
        ))
    }
}

/// The decoder's complaint about a payload, for the refusal.
fn decode_error(pose_source: PoseSource, data: &[u8]) -> String {
    let e = match pose_source {
        PoseSource::JointStates => decode_cdr::<JointState>(data).err(),
        PoseSource::Tf => decode_cdr::<TfMessage>(data).err(),
    };
    e.map_or_else(|| "?".to_owned(), |e| e.to_string())
}

/// Decodes a message, or counts it as undecodable.
fn decode<T: serde::de::DeserializeOwned>(pipeline: &mut Pipeline, m: &BagMessage, warnings: &mut FirstWarnings) -> Option<T> {
    match decode_cdr::<T>(&m.data) {
        Ok(msg) => Some(msg),
        Err(e) => {
            pipeline.count_skip(SkipCause::Undecodable, 1);
            warnings.warn(SkipCause::Undecodable.key(), || format!("message at log time {} ns on {} does not decode: {e}", m.log_time, m.topic));
            None
        }
    }
}

fn apply_description(pipeline: &mut Pipeline, m: &BagMessage, bag: &Path, summary: &mut ReplaySummary, warnings: &mut FirstWarnings) {
    let source = format!("{DESCRIPTION_TOPIC} in {} at log time {} ns", bag.display(), m.log_time);
    let result =
        decode_cdr::<StringMsg>(&m.data).map_err(|e| e.to_string()).and_then(|d| pipeline.set_robot_description(&d.data, &source).map_err(|e| e.to_string()));
    match result {
        Ok(()) => {
            summary.descriptions.0 += 1;
            let s = pipeline.checker().summary();
            eprintln!("thickness_collision: robot from {source}: {} links, {} checked", s.robot_links, s.checked_links);
        }
        Err(e) => {
            summary.descriptions.1 += 1;
            warnings.warn("description", || format!("{source} refused, keeping the current robot: {e}"));
        }
    }
}

/// An SRDF in the bag, applied at its log time as the node applies `robot_description_semantic`.
fn apply_semantic(pipeline: &mut Pipeline, m: &BagMessage, bag: &Path, summary: &mut ReplaySummary, warnings: &mut FirstWarnings) {
    let source = format!("{SEMANTIC_TOPIC} in {} at log time {} ns", bag.display(), m.log_time);
    let result =
        decode_cdr::<StringMsg>(&m.data).map_err(|e| e.to_string()).and_then(|d| pipeline.set_robot_semantic(&d.data, &source).map_err(|e| e.to_string()));
    match result {
        Ok(()) => {
            summary.semantics.0 += 1;
            eprintln!("thickness_collision: {}", pipeline.checker().self_pairs().summary(pipeline.checker()));
        }
        Err(e) => {
            summary.semantics.1 += 1;
            warnings.warn("semantic", || format!("{source} refused, keeping the current collision matrix: {e}"));
        }
    }
}

fn record(summary: &mut ReplaySummary, checked: &CheckedState) {
    summary.states += 1;
    if checked.report.in_collision {
        summary.in_collision += 1;
    }
    for c in &checked.report.contacts {
        if summary.deepest.as_ref().is_none_or(|d| c.depth > d.3) {
            summary.deepest = Some((summary.states, c.link_name.clone(), c.object_name.clone(), c.depth));
        }
    }
}

fn write_outputs(out: &mut Outputs, pipeline: &Pipeline, state: &RobotState, checked: CheckedState, log_time: i64, seconds: f64) -> Result<()> {
    if let (Some(w), Some(path)) = (out.jsonl.as_mut(), &out.jsonl_path) {
        w.write_all(checked.json().as_bytes()).and_then(|()| w.write_all(b"\n")).with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some((timeline, _)) = out.plot.as_mut() {
        // A motion in collision may have met something only between the two states: the state's
        // own check tells which links collide at the state (plotted differently).
        let own = timeline
            .needs_state_check(&checked.report)
            .then(|| pipeline.check(state).report.contacts.into_iter().map(|c| c.link_name).collect::<std::collections::HashSet<_>>());
        timeline.record(seconds, &checked.report, own.as_ref());
    }
    if let Some(b) = out.bag.as_mut() {
        b.report(pipeline, state, checked, log_time)?;
    }
    Ok(())
}
