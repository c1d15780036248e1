//! The replay loop: the node's offline twin. Bag messages go, in storage order, through the same
//! [`Pipeline`] the node feeds live; each checked state becomes a JSON line, messages in a new
//! rosbag2 bag (the report, its markers and the robot's poses) and/or a bar of the timeline. The
//! bag is streamed: memory is bounded by the model, not the recording.

use super::bag_compression::looks_like_zstd;
use super::bag_output::{OutputBag, DESCRIPTION_TOPIC};
use super::bag_reader::{open_bag, BagMessage, BagReader};
use super::cdr::decode_cdr;
use super::output_error::OutputError;
use super::replay_error::ReplayError;
use super::replay_observer::{FirstWarnings, ReplayObserver};
use super::replay_summary::{InputCount, ReplaySummary};
use super::replay_trajectories::{Trajectories, TRAJECTORY_TYPE};
use super::timeline::Timeline;
use super::timeline_svg::timeline_svg;
use crate::model::{Params, PoseSource};
use crate::msgs::{JointState, JointTrajectory, StringMsg, TfMessage};
use crate::pipeline::{CheckedState, Pipeline, RobotState, Skip, SkipCause, StreamedTrajectory};
use std::collections::HashSet;
use std::io::Write;
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
    /// Check the motion between consecutive states, overriding the parameters' `check_motion`.
    pub motion: Option<bool>,
    /// Draw the collision timeline into this SVG file.
    pub plot: Option<PathBuf>,
    /// The output bag gets `/collisions` only: no markers, `/tf` or `/robot_description`.
    pub no_markers: bool,
    /// A `trajectory_msgs/JointTrajectory` topic: each trajectory checked as executed, one JSON
    /// line per trajectory in `jsonl`.
    pub trajectory_topic: Option<String>,
}

/// Where the checked states go.
struct Outputs {
    jsonl: Option<(std::io::BufWriter<std::fs::File>, PathBuf)>,
    bag: Option<OutputBag>,
    plot: Option<(Timeline, PathBuf)>,
}

impl Outputs {
    /// Every output asked for, created now, so a path that cannot be written fails before the
    /// bag is read.
    fn create(opts: &ReplayOptions, bag: &BagReader, pipeline: &Pipeline, pose_source: PoseSource) -> Result<Outputs, OutputError> {
        let create = |p: &PathBuf| std::fs::File::create(p).map_err(|source| OutputError::Create { path: p.clone(), source });
        let jsonl = match &opts.jsonl {
            Some(p) => Some((std::io::BufWriter::new(create(p)?), p.clone())),
            None => None,
        };
        let params = pipeline.params();
        let bag = match &opts.out_dir {
            Some(d) => Some(OutputBag::create(d, bag.topics(), pose_source, &params.world_frame, &params.frame_prefix, !opts.no_markers)?),
            None => None,
        };
        let plot = match &opts.plot {
            Some(p) => {
                let _ = create(p)?;
                Some((Timeline::default(), p.clone()))
            }
            None => None,
        };
        Ok(Outputs { jsonl, bag, plot })
    }

    fn write(&mut self, pipeline: &Pipeline, state: &RobotState, checked: CheckedState, log_time: i64, seconds: f64) -> Result<(), OutputError> {
        if let Some((w, path)) = self.jsonl.as_mut() {
            w.write_all(checked.json().as_bytes()).and_then(|()| w.write_all(b"\n")).map_err(|source| OutputError::Write { path: path.clone(), source })?;
        }
        if let Some((timeline, _)) = self.plot.as_mut() {
            // A motion in collision may have met something only between the two states: the
            // state's own check tells which links collide at the state (plotted differently).
            let own = timeline
                .needs_state_check(&checked.report)
                .then(|| pipeline.check(state).report.contacts.into_iter().map(|c| c.link_name).collect::<HashSet<_>>());
            timeline.record(seconds, &checked.report, own.as_ref());
        }
        if let Some(b) = self.bag.as_mut() {
            b.report(pipeline, state, checked, log_time)?;
        }
        Ok(())
    }

    fn write_trajectory(&mut self, t: &StreamedTrajectory) -> Result<(), OutputError> {
        if let Some((w, path)) = self.jsonl.as_mut() {
            let line = t.json().to_string();
            w.write_all(line.as_bytes()).and_then(|()| w.write_all(b"\n")).map_err(|source| OutputError::Write { path: path.clone(), source })?;
        }
        Ok(())
    }

    fn finish(&mut self, bag: &Path) -> Result<(), OutputError> {
        if let Some((mut w, path)) = self.jsonl.take() {
            w.flush().map_err(|source| OutputError::Write { path, source })?;
        }
        if let Some(b) = self.bag.take() {
            b.finish()?;
        }
        if let Some((timeline, path)) = &self.plot {
            let svg = timeline_svg(timeline, &bag.display().to_string())?;
            std::fs::write(path, svg).map_err(|source| OutputError::Write { path: path.clone(), source })?;
        }
        Ok(())
    }
}

/// Replays a bag, telling `observer` what it does. Reports before a corrupt tail are kept; the
/// fault is in the summary (`bag_error`), as is a topic of which nothing decoded (`no_input`).
pub fn replay(params: Params, opts: &ReplayOptions, observer: &mut dyn ReplayObserver) -> Result<ReplaySummary, ReplayError> {
    let (mut replayer, bag) = Replayer::open(params, opts, observer)?;
    for item in bag {
        match item {
            Ok(m) => replayer.message(m)?,
            Err(e) => {
                replayer.summary.bag_error = Some(e.to_string());
                break;
            }
        }
    }
    replayer.finish()
}

/// One replay in progress: the pipeline, the outputs, and what was counted.
struct Replayer<'a> {
    opts: &'a ReplayOptions,
    pipeline: Pipeline,
    out: Outputs,
    summary: ReplaySummary,
    warnings: FirstWarnings<'a>,
    input: InputCount,
    topic: String,
    expected: &'static str,
    pose_source: PoseSource,
    /// The topics robot descriptions and SRDFs are applied from (`robot_description_topic` and
    /// `robot_description_semantic_topic`, absolute); `None`: closed, as in the node.
    doors: [Option<String>; 2],
    trajectories: Option<Trajectories>,
    t0: Option<i64>,
    read: u64,
    started: Instant,
}

impl<'a> Replayer<'a> {
    /// Opens the bag and checks its input topic, loads the robot, creates the outputs.
    fn open(mut params: Params, opts: &'a ReplayOptions, observer: &'a mut dyn ReplayObserver) -> Result<(Replayer<'a>, BagReader), ReplayError> {
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
        let bag = open_bag(&opts.bag)?;
        let topic = opts.topic.clone().unwrap_or_else(|| match pose_source {
            PoseSource::JointStates => "/joint_states".into(),
            PoseSource::Tf => "/tf".into(),
        });
        let expected = input_type(&bag, &topic, pose_source, &opts.bag)?;
        let door = |name: &str| (!name.is_empty()).then(|| format!("/{}", name.trim_start_matches('/')));
        let doors = [door(&params.robot_description_topic), door(&params.robot_description_semantic_topic)];
        // Both doors start with the robot the parameters name; a description in the bag replaces
        // it at its log time, as it would replace it in the running node.
        let pipeline = if bag.topics().iter().any(|(t, _)| Some(t) == doors[0].as_ref()) {
            // An SRDF given for the recorded robot is checked against it when it comes.
            Pipeline::new_expecting_description(params)?
        } else {
            Pipeline::new(params)?
        };
        let trajectories = match opts.trajectory_topic.as_deref() {
            Some(t) => {
                topic_in_bag(&bag, t, TRAJECTORY_TYPE, "--trajectory-topic", &opts.bag)?;
                Some(Trajectories::new(t))
            }
            None => None,
        };
        let out = Outputs::create(opts, &bag, &pipeline, pose_source)?;
        let replayer = Replayer {
            opts,
            pipeline,
            out,
            summary: ReplaySummary::default(),
            warnings: FirstWarnings::new(observer),
            input: InputCount::default(),
            topic,
            expected,
            pose_source,
            doors,
            trajectories,
            t0: None,
            read: 0,
            started: Instant::now(),
        };
        Ok((replayer, bag))
    }

    /// One bag message, in storage order.
    fn message(&mut self, m: BagMessage) -> Result<(), ReplayError> {
        self.read += 1;
        if self.read.is_multiple_of(1024) {
            self.warnings.observer.progress(self.read);
        }
        let t0 = *self.t0.get_or_insert(m.log_time);
        let seconds = (m.log_time - t0) as f64 * 1e-9;
        *self.input.per_topic.entry(m.topic.clone()).or_default() += 1;
        if let Some(b) = self.out.bag.as_mut() {
            b.input(&self.pipeline, &m)?;
        }
        if self.trajectories.as_ref().is_some_and(|t| t.topic == m.topic) {
            return self.trajectory(&m);
        }
        let Some(state) = self.state_of(&m, seconds) else { return Ok(()) };
        for w in self.pipeline.take_warnings() {
            self.warnings.observer.warning(&w);
        }
        match state {
            Ok(Some(state)) => {
                // One state per report, as the node gives when it keeps up.
                let Some(checked) = self.pipeline.check_path(std::slice::from_ref(&state)) else { return Ok(()) };
                self.summary.record(&checked);
                self.out.write(&self.pipeline, &state, checked, m.log_time, seconds)?;
            }
            Ok(None) => {}
            Err(Skip { cause, message }) => {
                self.warnings.warn(cause.key(), || format!("message at log time {} ns skipped ({}): {message}", m.log_time, cause.key()))
            }
        }
        Ok(())
    }

    /// What message `m` (at `seconds` into the bag) means for the pipeline: `None` when it is
    /// not a state (applied, out of the window, another topic, undecodable), else the state or
    /// why it is none.
    fn state_of(&mut self, m: &BagMessage, seconds: f64) -> Option<Result<Option<RobotState>, Skip>> {
        let (opts, pipeline, warnings) = (self.opts, &mut self.pipeline, &mut self.warnings);
        if Some(&m.topic) == self.doors[0].as_ref() {
            apply_description(pipeline, m, &opts.bag, &mut self.summary, warnings);
            return None;
        }
        if Some(&m.topic) == self.doors[1].as_ref() {
            apply_semantic(pipeline, m, &opts.bag, &mut self.summary, warnings);
            return None;
        }
        if let Some(result) = apply_scene_message(pipeline, m, warnings) {
            if let Err(Skip { cause, message }) = result {
                warnings.warn(cause.key(), || format!("{} at log time {} ns refused ({}): {message}", m.topic, m.log_time, cause.key()));
            }
            return None;
        }
        if self.pose_source == PoseSource::Tf && m.topic == "/tf_static" {
            return decode::<TfMessage>(pipeline, m, warnings).map(|msg| pipeline.tf_static(&msg).map(|()| None));
        }
        if m.topic != self.topic {
            return None;
        }
        let in_window = opts.start.is_none_or(|a| seconds >= a) && opts.end.is_none_or(|b| seconds <= b);
        if !in_window {
            self.input.span = Some(self.input.span.map_or((seconds, seconds), |(a, b)| (a.min(seconds), b.max(seconds))));
            return None;
        }
        self.input.in_window += 1;
        let decoded = match self.pose_source {
            PoseSource::JointStates => decode::<JointState>(pipeline, m, warnings).map(|msg| pipeline.joint_state(&msg).map(Some)),
            PoseSource::Tf => decode::<TfMessage>(pipeline, m, warnings).map(|msg| pipeline.tf(&msg).map(Some)),
        };
        if decoded.is_some() {
            self.input.decoded += 1;
        } else {
            self.input.zstd_frames += u64::from(looks_like_zstd(&m.data));
            if self.input.first_error.is_none() {
                self.input.first_error = Some(decode_error(self.pose_source, &m.data));
            }
        }
        decoded
    }

    /// A trajectory: checked once the next one arrives (or the bag ends).
    fn trajectory(&mut self, m: &BagMessage) -> Result<(), ReplayError> {
        let Some(msg) = decode::<JointTrajectory>(&mut self.pipeline, m, &mut self.warnings) else { return Ok(()) };
        let done = self.trajectories.as_mut().and_then(|t| t.receive(&self.pipeline, msg, m.log_time));
        self.trajectory_done(done)
    }

    fn trajectory_done(&mut self, done: Option<StreamedTrajectory>) -> Result<(), ReplayError> {
        if let Some(t) = done {
            self.summary.record_trajectory(&t);
            self.out.write_trajectory(&t)?;
        }
        Ok(())
    }

    /// Finishes the outputs and the summary.
    fn finish(mut self) -> Result<ReplaySummary, ReplayError> {
        let last = self.trajectories.as_mut().and_then(Trajectories::finish);
        self.trajectory_done(last)?;
        self.warnings.observer.finished();
        self.out.finish(&self.opts.bag)?;
        if self.pipeline.semantic_deferred() {
            return Err(ReplayError::SemanticUnused {
                file: self.pipeline.params().robot_semantic_file.clone(),
                bag: self.opts.bag.clone(),
                applied: self.summary.descriptions.0,
                refused: self.summary.descriptions.1,
            });
        }
        self.summary.seconds = self.started.elapsed().as_secs_f64();
        self.summary.skipped = self.pipeline.skipped().clone();
        if self.summary.bag_error.is_none() {
            self.summary.no_input = self.input.refusal(&self.topic, self.expected, &self.opts.bag, self.opts.start, self.opts.end);
        }
        Ok(self.summary)
    }
}

/// The type `pose_source` reads on `topic`, after checking the bag has the topic with that type
/// and in CDR.
fn input_type(bag: &BagReader, topic: &str, pose_source: PoseSource, path: &Path) -> Result<&'static str, ReplayError> {
    let (expected, source_name) = match pose_source {
        PoseSource::JointStates => ("sensor_msgs/msg/JointState", "joint_states"),
        PoseSource::Tf => ("tf2_msgs/msg/TFMessage", "tf"),
    };
    topic_in_bag(bag, topic, expected, source_name, path)?;
    Ok(expected)
}

/// Checks that the bag has `topic` with type `expected` (what `source_name` reads) in CDR.
fn topic_in_bag(bag: &BagReader, topic: &str, expected: &'static str, source_name: &'static str, path: &Path) -> Result<(), ReplayError> {
    if !bag.topics().iter().any(|(t, _)| *t == topic) {
        let have: Vec<&str> = bag.topics().iter().map(|(t, _)| t.as_str()).collect();
        return Err(ReplayError::MissingTopic { topic: topic.to_owned(), bag: path.to_owned(), have: crate::limits::name_list(&have) });
    }
    if let Some((_, ty)) = bag.topics().iter().find(|(t, ty)| *t == topic && !ty.is_empty() && ty != expected) {
        return Err(ReplayError::WrongType { topic: topic.to_owned(), bag: path.to_owned(), found: ty.clone(), source_name, expected });
    }
    // Every message would be undecodable: say why once, up front.
    if let Some((_, encoding)) = bag.encodings().iter().find(|(t, e)| *t == topic && e != "cdr") {
        return Err(ReplayError::Encoding { topic: topic.to_owned(), bag: path.to_owned(), encoding: encoding.clone() });
    }
    Ok(())
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

/// A planning-scene message (MoveIt's topics in the root namespace, as the node subscribes them
/// there), applied at its log time as the node applies it on arrival (with the parameter
/// `planning_scene`, as the node subscribes them): `None` for another topic,
/// else whether it was applied (an undecodable one is counted and warned about, and `Ok`).
fn apply_scene_message(pipeline: &mut Pipeline, m: &BagMessage, warnings: &mut FirstWarnings) -> Option<Result<(), Skip>> {
    use crate::msgs::planning_scene::{AttachedCollisionObject, CollisionObject, PlanningScene, PlanningSceneWorld};
    if !pipeline.params().planning_scene {
        return None;
    }
    let result = match m.topic.as_str() {
        "/collision_object" => decode::<CollisionObject>(pipeline, m, warnings).map(|o| pipeline.collision_object(&o)),
        "/attached_collision_object" => decode::<AttachedCollisionObject>(pipeline, m, warnings).map(|o| pipeline.attached_collision_object(&o)),
        "/planning_scene" => decode::<PlanningScene>(pipeline, m, warnings).map(|s| pipeline.planning_scene(&s)),
        "/planning_scene_world" => decode::<PlanningSceneWorld>(pipeline, m, warnings).map(|w| pipeline.planning_scene_world(&w)),
        _ => return None,
    };
    for w in pipeline.take_warnings() {
        warnings.observer.warning(&w);
    }
    Some(result.unwrap_or(Ok(())))
}

fn apply_description(pipeline: &mut Pipeline, m: &BagMessage, bag: &Path, summary: &mut ReplaySummary, warnings: &mut FirstWarnings) {
    let source = format!("{DESCRIPTION_TOPIC} in {} at log time {} ns", bag.display(), m.log_time);
    let result =
        decode_cdr::<StringMsg>(&m.data).map_err(|e| e.to_string()).and_then(|d| pipeline.set_robot_description(&d.data, &source).map_err(|e| e.to_string()));
    match result {
        Ok(()) => {
            summary.descriptions.0 += 1;
            let s = pipeline.checker().summary();
            warnings.observer.note(&format!("robot from {source}: {} links, {} checked", s.robot_links, s.checked_links));
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
            warnings.observer.note(&pipeline.checker().self_pairs().summary(pipeline.checker()));
        }
        Err(e) => {
            summary.semantics.1 += 1;
            warnings.warn("semantic", || format!("{source} refused, keeping the current collision matrix: {e}"));
        }
    }
}
