//! The replay loop: bag messages to states, states to reports, reports to JSON lines and a bag.

use super::bag_reader::{open_bag, BagMessage};
use super::bag_writer::BagWriter;
use crate::checker::{Checker, JointMemory, StateReport, TfTree};
use crate::model::Params;
use crate::msgs::{decode_cdr, CollisionReport, Header, JointState, StringMsg, TfMessage, Time};
use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where robot states come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PoseSource {
    /// `sensor_msgs/JointState` through forward kinematics.
    #[value(name = "joint_states")]
    JointStates,
    /// `tf2_msgs/TFMessage`: link poses composed up to `world_frame`.
    #[value(name = "tf")]
    Tf,
}

/// What to replay and where the results go.
#[derive(Clone, Debug)]
pub struct ReplayOptions {
    /// rosbag2 directory, `.mcap` or `.db3`.
    pub bag: PathBuf,
    /// Input topic (default `/joint_states`, or `/tf`).
    pub topic: Option<String>,
    /// Where states come from.
    pub pose_source: PoseSource,
    /// Output rosbag2 directory with the `collisions` topic.
    pub out_dir: Option<PathBuf>,
    /// Output JSON lines, one report per state.
    pub jsonl: Option<PathBuf>,
    /// Skip messages before this many seconds after the bag's first message.
    pub start: Option<f64>,
    /// Skip messages after this many seconds after the bag's first message.
    pub end: Option<f64>,
    /// Show a progress bar (only drawn on a terminal).
    pub progress: bool,
}

/// What a replay did.
#[derive(Clone, Debug, Default)]
pub struct ReplaySummary {
    /// States checked.
    pub states: usize,
    /// States in collision.
    pub in_collision: usize,
    /// Deepest contact: (state index from 1, link, object, depth).
    pub deepest: Option<(usize, String, String, f64)>,
    /// Messages skipped, by cause.
    pub skipped: BTreeMap<String, usize>,
    /// Wall time of the replay loop (seconds), reading and writing included.
    pub seconds: f64,
    /// The fault that ended the bag early, if any (reports before it are kept).
    pub bag_error: Option<String>,
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
        let total: usize = self.skipped.values().sum();
        write!(f, "skipped messages: {total}")?;
        for (cause, n) in &self.skipped {
            write!(f, "\n  {n} x {cause}")?;
        }
        if let Some(e) = &self.bag_error {
            write!(f, "\nbag error: {e}")?;
        }
        Ok(())
    }
}

fn bump(skipped: &mut BTreeMap<String, usize>, cause: String) -> bool {
    let n = skipped.entry(cause).or_insert(0);
    *n += 1;
    *n == 1
}

/// Replays a bag. Reports before a corrupt tail are kept; the fault is in the summary and makes
/// the result an error after the outputs are written.
pub fn replay(params: Params, robot: Option<&Path>, environment: Option<&Path>, opts: &ReplayOptions) -> Result<ReplaySummary> {
    let bag = open_bag(&opts.bag)?;
    let topic = opts.topic.clone().unwrap_or_else(|| match opts.pose_source {
        PoseSource::JointStates => "/joint_states".into(),
        PoseSource::Tf => "/tf".into(),
    });
    if !bag.topics.iter().any(|(t, _)| *t == topic) {
        let have: Vec<&str> = bag.topics.iter().map(|(t, _)| t.as_str()).collect();
        if let Some(e) = bag.error {
            return Err(anyhow::Error::new(e).context(format!("topic {topic} not found before the bag's fault")));
        }
        bail!("topic {topic} is not in bag {} (it has: {})", opts.bag.display(), have.join(", "));
    }

    // The robot from the bag's /robot_description when no file is given.
    let description = if robot.is_none() && params.robot_description_file.is_empty() {
        bag.messages.iter().find(|m| m.topic == "/robot_description").map(|m| decode_cdr::<StringMsg>(&m.data))
    } else {
        None
    };
    let checker = match description {
        Some(Ok(d)) => Checker::from_description(params, &d.data, &format!("/robot_description in {}", opts.bag.display()), environment)?,
        Some(Err(e)) => return Err(anyhow::Error::new(e).context(format!("/robot_description in {}", opts.bag.display()))),
        None => Checker::from_params(params, robot, environment)?,
    };
    let world = checker.params.world_frame.clone();

    let t0 = bag.messages.first().map_or(0, |m| m.log_time);
    let window = |m: &BagMessage| {
        let s = (m.log_time - t0) as f64 * 1e-9;
        opts.start.map_or(true, |a| s >= a) && opts.end.map_or(true, |b| s <= b)
    };
    let inputs: Vec<&BagMessage> = bag.messages.iter().filter(|m| (m.topic == topic || (opts.pose_source == PoseSource::Tf && m.topic == "/tf_static")) && window(m)).collect();

    let mut jsonl = match &opts.jsonl {
        Some(p) => Some(std::io::BufWriter::new(std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))?)),
        None => None,
    };
    let mut out_bag = match &opts.out_dir {
        Some(d) => Some(BagWriter::create(d, "/collisions")?),
        None => None,
    };
    let bar = if opts.progress && std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(inputs.len() as u64);
        b.set_style(indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} states {per_sec} {eta}").unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()));
        Some(b)
    } else {
        None
    };

    let started = Instant::now();
    let mut summary = ReplaySummary::default();
    let mut memory = JointMemory::new(&checker.robot);
    let mut tf = TfTree::default();
    let robot_links: Vec<String> = checker.targets.iter().map(|t| t.name.clone()).collect();
    for (k, m) in inputs.iter().enumerate() {
        if let Some(b) = &bar {
            if k % 1024 == 0 {
                b.set_position(k as u64);
            }
        }
        let (report, stamp): (StateReport, Time) = match opts.pose_source {
            PoseSource::JointStates => {
                let js = match decode_cdr::<JointState>(&m.data) {
                    Ok(js) => js,
                    Err(e) => {
                        if bump(&mut summary.skipped, format!("undecodable message on {topic}")) {
                            eprintln!("thickness_collision: warning: message at {} ns on {topic} does not decode: {e}", m.log_time);
                        }
                        continue;
                    }
                };
                match checker.check_joints(&js.name, &js.position, &mut memory, false) {
                    Ok((r, unknown)) => {
                        for u in unknown {
                            if memory.first_unknown(&u) {
                                eprintln!("thickness_collision: warning: '{u}' is not a joint of the robot model; ignored (warned once)");
                            }
                        }
                        (r, js.header.stamp)
                    }
                    Err(e) => {
                        if bump(&mut summary.skipped, format!("rejected state: {e}")) {
                            eprintln!("thickness_collision: warning: state at {} ns rejected: {e}", m.log_time);
                        }
                        continue;
                    }
                }
            }
            PoseSource::Tf => {
                let msg = match decode_cdr::<TfMessage>(&m.data) {
                    Ok(msg) => msg,
                    Err(e) => {
                        if bump(&mut summary.skipped, format!("undecodable message on {}", m.topic)) {
                            eprintln!("thickness_collision: warning: message at {} ns on {} does not decode: {e}", m.log_time, m.topic);
                        }
                        continue;
                    }
                };
                for bad in tf.update(&msg) {
                    let _ = bump(&mut summary.skipped, format!("non-finite transform for {bad}"));
                }
                if m.topic == "/tf_static" {
                    continue;
                }
                let poses: Vec<(String, crate::math::Pose)> = robot_links.iter().filter_map(|l| tf.world_pose(l, &world).map(|p| (l.clone(), p))).collect();
                let stamp = msg.transforms.iter().map(|t| t.header.stamp).max().unwrap_or_default();
                match checker.check_transforms(&poses) {
                    Ok(r) => (r, stamp),
                    Err(e) => {
                        let _ = bump(&mut summary.skipped, format!("rejected state: {e}"));
                        continue;
                    }
                }
            }
        };
        summary.states += 1;
        if report.in_collision {
            summary.in_collision += 1;
        }
        for c in &report.contacts {
            if summary.deepest.as_ref().map_or(true, |d| c.depth > d.3) {
                summary.deepest = Some((summary.states, c.link_name.clone(), c.object_name.clone(), c.depth));
            }
        }
        if let Some(w) = jsonl.as_mut() {
            serde_json::to_writer(&mut *w, &report)?;
            w.write_all(b"\n")?;
        }
        if let Some(b) = out_bag.as_mut() {
            b.write(&CollisionReport::from_state(&report, Header { stamp, frame_id: world.clone() }), m.log_time)?;
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let Some(mut w) = jsonl {
        w.flush()?;
    }
    if let Some(b) = out_bag {
        let _ = b.finish()?;
    }
    summary.seconds = started.elapsed().as_secs_f64();
    summary.bag_error = bag.error.map(|e| e.to_string());
    Ok(summary)
}
