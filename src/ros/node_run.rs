//! The node's life: participant, node, topics and services, and the loop that hands every
//! input to the [`Pipeline`] and publishes what it returns. Nothing here decides an answer.
//! Joint states are mostly answered before they reach the loop, on the thread that received
//! them, whenever the loop is not holding the node's state (`states_on_receive.rs`).
//!
//! `check_trajectory` requests are resolved by the pipeline on the loop (validation and the
//! current joint state: no geometry) and checked on a worker thread of their own, so a long
//! trajectory never stalls the live stream; the loop sends the answer when the worker is done.

use super::description_msg::DescriptionMsg;
use super::diagnostics::{diagnostics, NodeStats};
use super::discovery_range::DiscoverySettings;
use super::memory_return::{self, MemoryReturn};
use super::param_services::{ros_mapping, ParamRequest, ParamServers};
use super::param_values::{declarations, to_json, READ_ONLY};
use super::ros_args::RosArgs;
use super::states_on_receive::{Checking, OnReceive};
use super::validity_worker::{ValidityWorker, MAX_VALIDITY_PENDING};
use crate::limits::MAX_DESCRIPTION_BYTES;
use crate::markers::{cell_markers, contact_markers};
use crate::model::{Params, PoseSource, ServiceMapping};
use crate::msgs::moveit::{GetStateValidityRequest, GetStateValidityResponse};
use crate::msgs::{CheckStatesRequest, CheckStatesResponse, ClockMsg};
use crate::msgs::{CheckTrajectoryRequest, CheckTrajectoryResponse, CollisionReport, DiagnosticArray, JointState, MarkerArray, TfMessage, Time};
use crate::pipeline::{Pipeline, RobotState, Skip, SkipCause, TrajectoryJob};
use anyhow::{anyhow, Context as _, Result};
use futures::stream::Stream;
use futures::StreamExt;
use ros2_client::dds::rustdds::{DomainParticipant, DomainParticipantBuilder};
use ros2_client::qos::{History, WhenFull};
use ros2_client::{
    Context, MessageInfo, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile, ReadError, ServiceMapping as RosServiceMapping, ServiceTypeName,
};
use std::collections::HashMap;
use std::path::PathBuf;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How the node was started.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// `--ros-args`.
    pub ros_args: RosArgs,
    /// Robot URDF override (`--robot`).
    pub robot: Option<PathBuf>,
    /// Environment URDF override (`--environment`).
    pub environment: Option<PathBuf>,
}

/// Warnings at most once a second per cause, so a flood of bad messages cannot flood the log.
#[derive(Default)]
struct RateLimitedLog {
    last: HashMap<String, Instant>,
    suppressed: HashMap<String, u64>,
    /// Messages written but not yet sent to `/rosout` (the node is borrowed elsewhere then).
    pending: Vec<String>,
}

impl RateLimitedLog {
    fn warn(&mut self, cause: &str, message: impl FnOnce() -> String) {
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
                if self.pending.len() < 64 {
                    self.pending.push(text);
                }
                // Causes are a handful of fixed strings: the maps stay small.
                let _ = self.last.insert(cause.to_owned(), now);
            }
        }
    }
}

/// The DDS participant: `ROS_DOMAIN_ID`, and the discovery range and static peers the
/// environment asks for ([`DiscoverySettings`]).
fn participant() -> Result<(DomainParticipant, u16, DiscoverySettings)> {
    let domain = domain_id(std::env::var("ROS_DOMAIN_ID").ok().as_deref())?;
    let discovery = DiscoverySettings::from_env()?;
    let builder = discovery.apply(DomainParticipantBuilder::new(domain));
    Ok((builder.build().context("cannot create the DDS participant")?, domain, discovery))
}

/// The line a refused description is logged and diagnosed with: the topic once, then why. The
/// error names its source (`/robot_description topic: ...`) when it comes from the text itself;
/// that prefix is dropped, as the line already starts with the topic.
fn refusal_line(topic: &str, source: &str, what_stays: &str, error: &str) -> String {
    let error = error.replace('\n', " ");
    let reason = error.strip_prefix(source).and_then(|r| r.strip_prefix(": ")).unwrap_or(&error);
    format!("{topic} rejected, {what_stays}: {reason}")
}

/// The largest domain id: RTPS ports are `7400 + 250 * domain + ...`, and above 232 they pass
/// 65535 and wrap (the limit the ROS 2 "Domain ID" article gives).
const MAX_DOMAIN_ID: u16 = 232;

/// `ROS_DOMAIN_ID` (`None` or blank: domain 0), refused outside 0-232.
fn domain_id(value: Option<&str>) -> Result<u16> {
    let Some(text) = value.map(str::trim).filter(|t| !t.is_empty()) else {
        return Ok(0);
    };
    match text.parse::<u64>() {
        Ok(d) if d <= u64::from(MAX_DOMAIN_ID) => Ok(d as u16),
        _ => Err(anyhow!("ROS_DOMAIN_ID='{text}' is not a domain id: an integer from 0 to {MAX_DOMAIN_ID} is allowed")),
    }
}

/// Reliable, transient local ("latched"), keep last `depth`: how `robot_description`,
/// `/tf_static` and the cell markers are offered.
fn latched(base: QosProfile, depth: usize) -> QosProfile {
    base.reliability_reliable(WhenFull::DEFAULT).durability(ros2_client::qos::Durability::TransientLocal).history(History::KeepLast { depth })
}

fn resolve(remaps: &[(String, String)], name: &str) -> String {
    remaps.iter().find(|(from, _)| from == name || from.trim_start_matches('/') == name).map_or(name.to_owned(), |(_, to)| to.clone())
}

/// A topic or service name resolved against the node's namespace, as an absolute name
/// (`joint_states` under `/robot1` is `/robot1/joint_states`; `/tf` stays `/tf`).
fn ros_name(name: &str, namespace: &str) -> Result<Name> {
    let full = if name.starts_with('/') { name.to_owned() } else { format!("{}/{}", namespace.trim_end_matches('/'), name) };
    let full = full.trim_end_matches('/');
    let (ns, base) = full.rsplit_once('/').ok_or_else(|| anyhow!("invalid ROS name '{full}'"))?;
    Name::new(if ns.is_empty() { "/" } else { ns }, base).map_err(|e| anyhow!("invalid ROS name '{full}': {e:?}"))
}

/// The node's topics, publishers, subscriptions and service, made once at start.
pub(super) struct Interfaces {
    pub(super) states: ros2_client::Subscription<JointState>,
    tf: Option<(ros2_client::Subscription<TfMessage>, ros2_client::Subscription<TfMessage>)>,
    descriptions: ros2_client::Subscription<DescriptionMsg>,
    semantics: ros2_client::Subscription<DescriptionMsg>,
    clock: Option<ros2_client::Subscription<ClockMsg>>,
    collisions: ros2_client::Publisher<CollisionReport>,
    cells: ros2_client::Publisher<MarkerArray>,
    contacts: ros2_client::Publisher<MarkerArray>,
    diagnostics: ros2_client::Publisher<DiagnosticArray>,
    check_states: ros2_client::Server<CheckStatesRequest, CheckStatesResponse>,
    check_trajectory: ros2_client::Server<CheckTrajectoryRequest, CheckTrajectoryResponse>,
    check_state_validity: ros2_client::Server<GetStateValidityRequest, GetStateValidityResponse>,
    names: Names,
}

/// Resolved names, for the banner and the warnings.
struct Names {
    joint_states: String,
    collisions: String,
    check_states: String,
    check_trajectory: String,
    check_state_validity: String,
    description: String,
    semantic: String,
    cells: String,
    contacts: String,
}

/// Reliable, keep last `depth`.
fn reliable(depth: usize) -> QosProfile {
    QosProfile::publisher_default().reliability_reliable(WhenFull::DEFAULT).history(History::KeepLast { depth })
}

impl Interfaces {
    /// Every topic and service the node uses. `joint_states` and `/tf` are best effort (sensor
    /// streams, keep last); reports and the service reliable; `robot_description`, `/tf_static`
    /// and the cell markers latched (reliable, transient local), as their publishers offer them.
    fn build(node: &mut Node, params: &Params, ros_args: &RosArgs) -> Result<Interfaces> {
        let namespace = ros_args.namespace.clone().unwrap_or_else(|| "/".into());
        let remaps = &ros_args.remaps;
        let names = Names {
            joint_states: resolve(remaps, "joint_states"),
            collisions: resolve(remaps, "collisions"),
            check_states: resolve(remaps, "check_states"),
            check_trajectory: resolve(remaps, "check_trajectory"),
            check_state_validity: resolve(remaps, "check_state_validity"),
            description: resolve(remaps, "robot_description"),
            semantic: resolve(remaps, "robot_description_semantic"),
            cells: resolve(remaps, "collision_markers/cells"),
            contacts: resolve(remaps, "collision_markers/contacts"),
        };
        let best_effort = |depth| QosProfile::subscription_default().reliability_best_effort().history(History::KeepLast { depth });
        let topic = |node: &mut Node, name: &str, ns: &str, pkg: &str, ty: &str, qos: &QosProfile| {
            node.create_topic(&ros_name(name, ns)?, MessageTypeName::new(pkg, ty), qos).map_err(|e| anyhow!("topic {name}: {e:?}"))
        };
        let sub_err = |name: &str| {
            let name = name.to_owned();
            move |e| anyhow!("subscription {name}: {e:?}")
        };
        let pub_err = |name: &str| {
            let name = name.to_owned();
            move |e| anyhow!("publisher {name}: {e:?}")
        };

        // 100 samples kept: states that arrive while one is checked are covered by the next
        // report's motion (check_motion), not lost.
        let js = topic(node, &names.joint_states, &namespace, "sensor_msgs", "JointState", &best_effort(STATES_KEPT))?;
        let states = node.create_subscription::<JointState>(&js, Some(best_effort(STATES_KEPT))).map_err(sub_err(&names.joint_states))?;
        let desc_qos = latched(QosProfile::subscription_default(), 1);
        let desc = topic(node, &names.description, &namespace, "std_msgs", "String", &desc_qos)?;
        let descriptions = node.create_subscription::<DescriptionMsg>(&desc, Some(desc_qos.clone())).map_err(sub_err(&names.description))?;
        // The SRDF, latched as move_group offers it; bounded like the description.
        let sem = topic(node, &names.semantic, &namespace, "std_msgs", "String", &desc_qos)?;
        let semantics = node.create_subscription::<DescriptionMsg>(&sem, Some(desc_qos.clone())).map_err(sub_err(&names.semantic))?;
        let clock = if params.use_sim_time {
            let t = topic(node, "/clock", "/", "rosgraph_msgs", "Clock", &best_effort(1))?;
            Some(node.create_subscription::<ClockMsg>(&t, None).map_err(sub_err("/clock"))?)
        } else {
            None
        };
        // /tf and /tf_static are absolute: the same for every robot, frames told apart by frame_prefix.
        let tf = if params.pose_source == PoseSource::Tf {
            let static_qos = latched(QosProfile::subscription_default(), 100);
            let tf_topic = topic(node, &resolve(remaps, "/tf"), "/", "tf2_msgs", "TFMessage", &best_effort(100))?;
            let st_topic = topic(node, &resolve(remaps, "/tf_static"), "/", "tf2_msgs", "TFMessage", &static_qos)?;
            Some((
                node.create_subscription::<TfMessage>(&tf_topic, Some(best_effort(100))).map_err(sub_err("/tf"))?,
                node.create_subscription::<TfMessage>(&st_topic, Some(static_qos)).map_err(sub_err("/tf_static"))?,
            ))
        } else {
            None
        };
        let out = topic(node, &names.collisions, &namespace, "thickness_collision_msgs", "CollisionReport", &reliable(100))?;
        let collisions = node.create_publisher::<CollisionReport>(&out, None).map_err(pub_err(&names.collisions))?;
        let latched_pub = latched(QosProfile::publisher_default(), 1);
        let cells_topic = topic(node, &names.cells, &namespace, "visualization_msgs", "MarkerArray", &latched_pub)?;
        let contacts_topic = topic(node, &names.contacts, &namespace, "visualization_msgs", "MarkerArray", &reliable(100))?;
        let diag_topic = topic(node, &resolve(remaps, "/diagnostics"), "/", "diagnostic_msgs", "DiagnosticArray", &reliable(100))?;
        let cells = node.create_publisher::<MarkerArray>(&cells_topic, Some(latched_pub.clone())).map_err(pub_err(&names.cells))?;
        let contacts = node.create_publisher::<MarkerArray>(&contacts_topic, None).map_err(pub_err(&names.contacts))?;
        let diagnostics = node.create_publisher::<DiagnosticArray>(&diag_topic, None).map_err(pub_err("/diagnostics"))?;
        let mapping = match params.service_mapping {
            ServiceMapping::Enhanced => RosServiceMapping::Enhanced,
            ServiceMapping::Basic => RosServiceMapping::Basic,
            ServiceMapping::Cyclone => RosServiceMapping::Cyclone,
        };
        let check_states = node
            .create_server::<CheckStatesRequest, CheckStatesResponse>(
                mapping,
                &ros_name(&names.check_states, &namespace)?,
                &ServiceTypeName::new("thickness_collision_msgs", "CheckStates"),
                reliable(100),
                reliable(100),
            )
            .map_err(|e| anyhow!("service {}: {e:?}", names.check_states))?;
        let check_trajectory = node
            .create_server::<CheckTrajectoryRequest, CheckTrajectoryResponse>(
                mapping,
                &ros_name(&names.check_trajectory, &namespace)?,
                &ServiceTypeName::new("thickness_collision_msgs", "CheckTrajectory"),
                reliable(100),
                reliable(100),
            )
            .map_err(|e| anyhow!("service {}: {e:?}", names.check_trajectory))?;
        // MoveIt's service type, so a planner calls it unchanged (remap to /check_state_validity
        // to take move_group's name; never with move_group serving it too).
        let check_state_validity = node
            .create_server::<GetStateValidityRequest, GetStateValidityResponse>(
                mapping,
                &ros_name(&names.check_state_validity, &namespace)?,
                &ServiceTypeName::new("moveit_msgs", "GetStateValidity"),
                reliable(100),
                reliable(100),
            )
            .map_err(|e| anyhow!("service {}: {e:?}", names.check_state_validity))?;
        Ok(Interfaces {
            states,
            tf,
            descriptions,
            semantics,
            clock,
            collisions,
            cells,
            contacts,
            diagnostics,
            check_states,
            check_trajectory,
            check_state_validity,
            names,
        })
    }
}

/// The parameters accepted so far, and where accepted changes go: the set-parameters service
/// only validates (it runs in the spinner's task); the loop rebuilds.
fn parameter_options(params: &Params, changes: smol::channel::Sender<Params>) -> NodeOptions {
    let accepted = Arc::new(Mutex::new(params.clone()));
    let action = move |name: &str, value: &ros2_client::ParameterValue| -> Result<(), String> {
        let mut current = accepted.lock().map_err(|_| "parameter state poisoned".to_string())?;
        let fresh = current.with_value(name, to_json(value)).map_err(|e| e.to_string())?;
        if fresh == *current {
            return Ok(());
        }
        if READ_ONLY.contains(&name) {
            return Err(format!("parameter '{name}' is read-only while the node runs (it shapes the node's topics)"));
        }
        changes.try_send(fresh.clone()).map_err(|_| "the node is shutting down".to_string())?;
        *current = fresh;
        Ok(())
    };
    // ros2-client serves the parameter services with the enhanced mapping only; with another the
    // node serves them itself (param_services.rs).
    let mut options = NodeOptions::new().enable_rosout(true).start_parameter_services(params.service_mapping == ServiceMapping::Enhanced);
    for (name, value) in declarations(params) {
        options = options.declare_parameter(&name, value);
    }
    options.parameter_set_action(Box::new(action))
}

/// What one turn of the loop got.
enum Event {
    /// Joint states are waiting that the receiving thread left to the loop.
    States,
    Tf(TfMessage),
    TfStatic(TfMessage),
    Description(DescriptionMsg),
    Semantic(DescriptionMsg),
    Clock(Time),
    Request(ros2_client::service::RmwRequestId, CheckStatesRequest),
    TrajectoryRequest(ros2_client::service::RmwRequestId, CheckTrajectoryRequest),
    /// The worker checked a trajectory: the answer to send.
    TrajectoryDone(ros2_client::service::RmwRequestId, CheckTrajectoryResponse),
    /// Boxed: a request holds some 450 bytes inline, the other events a fraction of that.
    ValidityRequest(ros2_client::service::RmwRequestId, Box<GetStateValidityRequest>),
    /// The worker checked a state: the answer to send, and why the request was not honoured.
    ValidityDone(ros2_client::service::RmwRequestId, GetStateValidityResponse, Option<String>),
    /// A parameter service request (served here with the basic and cyclone mappings).
    Parameter(ParamRequest),
    /// A sample that could not be read (on the topic or service named).
    ReadFailed(&'static str, ReadError),
    Tick,
}

/// `check_trajectory` requests waiting for or in the worker at most; one past that is answered at
/// once (`valid` false, "busy"), so a flood of requests cannot queue without bound.
const MAX_TRAJECTORIES_PENDING: usize = 8;

/// The worker that checks trajectories off the loop, one at a time, in arrival order.
struct TrajectoryWorker {
    jobs: std::sync::mpsc::SyncSender<(ros2_client::service::RmwRequestId, TrajectoryJob)>,
    done: smol::channel::Receiver<(ros2_client::service::RmwRequestId, CheckTrajectoryResponse)>,
}

impl TrajectoryWorker {
    /// Starts the thread; it ends when the loop drops the worker (a job in progress runs out).
    fn start() -> Result<TrajectoryWorker> {
        let (jobs, queue) = std::sync::mpsc::sync_channel::<(ros2_client::service::RmwRequestId, TrajectoryJob)>(MAX_TRAJECTORIES_PENDING);
        let (finished, done) = smol::channel::unbounded();
        let _ = std::thread::Builder::new()
            .name("check_trajectory".into())
            .spawn(move || {
                while let Ok((id, job)) = queue.recv() {
                    // A panic in the check must not leave the caller without an answer.
                    let answer = crate::limits::contain_panic(|| job.run()).unwrap_or_else(|e| CheckTrajectoryResponse {
                        segment: -1,
                        fraction: -1.0,
                        error: format!("the check failed: {}", e.replace('\n', " ")),
                        ..Default::default()
                    });
                    if finished.send_blocking((id, answer)).is_err() {
                        break;
                    }
                }
            })
            .context("cannot start the check_trajectory worker thread")?;
        Ok(TrajectoryWorker { jobs, done })
    }
}

/// Joint states taken in one turn at most (of the loop, or of the receiving thread): the rest
/// wait for the loop's next turn, so a flood cannot keep the loop from a stop request or the
/// other inputs, nor RustDDS's thread from its other traffic for long.
pub(super) const MAX_STATES_PER_TURN: usize = 256;

/// Joint states the reader keeps while the node is busy.
const STATES_KEPT: usize = 100;

/// Joint states taken in one turn that get a report each. A stall of the machine of a few
/// milliseconds leaves a few dozen waiting at 10 kHz, and the node answers them all (as replay
/// does, one report per state) and catches up; more than this waiting means it is behind, and the
/// oldest share one report (the polyline through them, no publish each) so the newest are
/// answered sooner. At 10 kHz, one report per turn left 1 % of the states without an answer of
/// their own, 32 per turn 0.14 % on a noisy machine (docs/latency.md).
const SEPARATE_REPORTS: usize = 64;

/// The loop's housekeeping period (`/rosout`, `/diagnostics`, the summary for a forced stop).
const TICK: Duration = Duration::from_millis(100);

/// A tick every `period` from a thread of its own; a tick the loop has not taken yet is not
/// doubled. The thread ends at the first tick after the loop drops the receiver.
fn ticks(period: Duration) -> Result<smol::channel::Receiver<()>> {
    let (tx, rx) = smol::channel::bounded(1);
    let _ = std::thread::Builder::new()
        .name("tick".into())
        .spawn(move || loop {
            std::thread::sleep(period);
            if let Err(smol::channel::TrySendError::Closed(())) = tx.try_send(()) {
                break;
            }
        })
        .context("cannot start the tick thread")?;
    Ok(rx)
}

/// How long a stop request waits for the loop (busy building a robot, say) before the process
/// exits without it: SIGTERM is honoured within 2 s whatever the loop is doing. (Exiting is not
/// instant either: a process holding gigabytes took 0.6 s to be torn down.)
const STOP_GRACE: Duration = Duration::from_millis(1000);

/// Contact markers fade half a second after the last report: a node whose input stopped shows no
/// stale contacts.
const CONTACT_MARKER_LIFETIME: crate::msgs::DurationMsg = crate::msgs::DurationMsg { sec: 0, nanosec: 500_000_000 };

/// The node's state between messages.
pub(super) struct NodeState {
    pipeline: Pipeline,
    pub(super) stats: NodeStats,
    log: RateLimitedLog,
    sim_time: Option<Time>,
    last_markers: Option<Instant>,
    last_diag: Instant,
    fqn: String,
    /// Why the last `robot_description` was refused; cleared by the next good one.
    description_error: Option<String>,
    /// The shutdown line as of the last turn, for a stop that cannot wait for the loop.
    summary: Arc<Mutex<String>>,
    memory: MemoryReturn,
}

impl NodeState {
    fn now(&self) -> Time {
        match self.sim_time {
            Some(t) => t,
            None => Time::from_nanos(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as i64)),
        }
    }

    fn world(&self) -> String {
        self.pipeline.params().world_frame.clone()
    }

    /// The line printed at shutdown: messages received, states checked, skips by cause.
    fn shutdown_line(&self) -> String {
        let skipped: Vec<String> = self.pipeline.skipped().iter().map(|(c, n)| format!("{n} {}", c.key())).collect();
        format!(
            "thickness_collision: shutting down ({} states received, {} checked, skipped: {})",
            self.stats.received,
            self.stats.checked,
            if skipped.is_empty() { "none".to_string() } else { skipped.join(", ") }
        )
    }

    /// A sample that could not be read. One that does not decode (a wrong type, a truncated
    /// sequence, a length past the bytes present, text that is not UTF-8) is counted as
    /// `undecodable`, like a bag message replay cannot decode, and warned about with the reason.
    fn on_read_failed(&mut self, what: &'static str, e: &ReadError) {
        match e {
            ReadError::Deserialization { .. } | ReadError::Malformed => {
                self.pipeline.count_skip(SkipCause::Undecodable, 1);
                self.log.warn(what, || format!("message skipped (undecodable): a {what} sample does not decode: {e}"));
            }
            _ => self.log.warn(what, || format!("reading {what} failed: {e}")),
        }
    }

    fn warn_skip(&mut self, skip: &Skip) {
        let (cause, message) = (skip.cause.key(), skip.message.clone());
        self.log.warn(cause, || format!("message skipped ({cause}): {message}"));
    }

    fn warn_pending(&mut self) {
        for w in self.pipeline.take_warnings() {
            self.log.warn("unknown-name", || w);
        }
    }

    fn publish_cells(&mut self, io: &Interfaces) {
        let (max, world, now) = (self.pipeline.params().marker_max_cells.max(0) as usize, self.world(), self.now());
        if io.cells.publish(cell_markers(self.pipeline.checker(), max, &world, now)).is_err() {
            self.log.warn("markers", || format!("publishing {} failed", io.names.cells));
        }
    }

    /// Parameter changes accepted by the service, applied before the next input is handled. Each
    /// accepted change carries every parameter, so only the newest is built: a burst of sets costs
    /// one rebuild.
    fn apply_params(&mut self, io: &Interfaces, changes: &smol::channel::Receiver<Params>) {
        let mut newest = None;
        while let Ok(params) = changes.try_recv() {
            newest = Some(params);
        }
        if let Some(params) = newest {
            self.refresh_summary();
            match self.pipeline.set_params(params) {
                Ok(()) => {
                    let s = self.pipeline.checker().summary();
                    println!(
                        "thickness_collision: parameters changed: {} thin surfaces, {} cells rebuilt in {:.1} ms",
                        s.thin_surfaces,
                        s.cells,
                        s.build_seconds * 1e3
                    );
                    self.publish_cells(io);
                }
                Err(e) => self.log.warn("params", || format!("parameter change not applied, keeping the current model: {e}")),
            }
        }
    }

    fn publish_report(&mut self, io: &Interfaces, states: &[RobotState]) {
        // A report covers every state it was given but those the pipeline counted as skipped
        // (without `check_motion`, all but the newest): those are the states it checked.
        let skipped = |p: &Pipeline| p.skipped().values().sum::<u64>();
        let skipped_before = skipped(&self.pipeline);
        let Some(checked) = self.pipeline.check_path(states) else { return };
        let covered = (states.len() as u64).saturating_sub(skipped(&self.pipeline) - skipped_before);
        self.stats.record_check(checked.report.check_seconds, covered);
        let world = self.world();
        // Never waits: the writer keeps the last N (RustDDS change 10), and this may run on
        // RustDDS's receiving thread (`states_on_receive.rs`).
        if io.collisions.publish(checked.message(&world)).is_err() {
            self.log.warn("publish", || format!("publishing on {} failed", io.names.collisions));
        }
        let rate = self.pipeline.params().marker_rate;
        // marker_rate is validated to [1e-3, 1e4] Hz; the fallback only guards the arithmetic.
        let period = Duration::try_from_secs_f64(1.0 / rate).unwrap_or(Duration::from_secs(1));
        if self.last_markers.is_none_or(|t| t.elapsed() >= period) {
            self.last_markers = Some(Instant::now());
            if io.contacts.publish(contact_markers(&checked.report, &world, checked.stamp, CONTACT_MARKER_LIFETIME)).is_err() {
                self.log.warn("markers", || format!("publishing {} failed", io.names.contacts));
            }
        }
    }

    /// Joint states: everything already waiting (up to [`MAX_STATES_PER_TURN`]) goes through the
    /// pipeline in order (merging partial states). The newest [`SEPARATE_REPORTS`] - 1 good ones
    /// get a report each; one report covers all older ones (the polyline through them with
    /// `check_motion`, else the newest of them, the others stale). A waiting sample that does not
    /// decode is counted and skipped.
    pub(super) fn on_joint_states(&mut self, io: &Interfaces, waiting: Vec<ros2_client::ReadResult<(JointState, MessageInfo)>>) {
        let mut batch = Vec::with_capacity(waiting.len());
        for m in waiting {
            match m {
                Ok((m, _)) => batch.push(m),
                Err(e) => self.on_read_failed("joint_states", &e),
            }
        }
        self.stats.received += batch.len() as u64;
        let mut good = Vec::with_capacity(batch.len());
        for m in &batch {
            match self.pipeline.joint_state(m) {
                Ok(state) => good.push(state),
                Err(skip) => self.warn_skip(&skip),
            }
        }
        self.warn_pending();
        // Past SEPARATE_REPORTS waiting, the oldest beyond the newest SEPARATE_REPORTS - 1 share one.
        let (older, newest) = good.split_at(good.len().saturating_sub(SEPARATE_REPORTS - 1));
        if !older.is_empty() {
            self.publish_report(io, older);
        }
        for state in newest {
            self.publish_report(io, std::slice::from_ref(state));
        }
    }

    fn on_tf(&mut self, io: &Interfaces, msg: TfMessage) {
        self.stats.received += 1;
        match self.pipeline.tf(&msg) {
            Ok(state) => self.publish_report(io, std::slice::from_ref(&state)),
            Err(skip) => self.warn_skip(&skip),
        }
    }

    fn on_tf_static(&mut self, msg: TfMessage) {
        if let Err(skip) = self.pipeline.tf_static(&msg) {
            self.warn_skip(&skip);
        }
    }

    /// A new robot from `robot_description`, built by the pipeline and swapped in whole. A refused
    /// one leaves the current robot running, is warned about (every one: descriptions are rare)
    /// and sets `/diagnostics` to ERROR with the reason until a good one arrives.
    fn on_description(&mut self, io: &Interfaces, msg: DescriptionMsg) {
        self.refresh_summary();
        let source = format!("{} topic", io.names.description);
        let result = match msg {
            DescriptionMsg::Text(text) => self.pipeline.set_robot_description(&text, &source).map_err(|e| e.to_string()),
            DescriptionMsg::TooLarge(n) => Err(format!("{source}: {n} bytes of URDF text, more than the {MAX_DESCRIPTION_BYTES} allowed")),
        };
        match result {
            Ok(()) => {
                let s = self.pipeline.checker().summary();
                println!("thickness_collision: robot from {}: {} links, {} checked", io.names.description, s.robot_links, s.checked_links);
                self.description_error = None;
                self.publish_cells(io);
            }
            Err(e) => {
                let line = refusal_line(&io.names.description, &source, "keeping the current robot", &e);
                eprintln!("[ERROR] thickness_collision: {line}");
                if self.log.pending.len() < 64 {
                    self.log.pending.push(line.clone());
                }
                self.description_error = Some(line);
            }
        }
    }

    /// A new SRDF from `robot_description_semantic`, swapped in whole by the pipeline; a refused
    /// one (it names links or joints the robot lacks) leaves the current matrix, as a refused
    /// description does.
    fn on_semantic(&mut self, io: &Interfaces, msg: DescriptionMsg) {
        self.refresh_summary();
        let source = format!("{} topic", io.names.semantic);
        let result = match msg {
            DescriptionMsg::Text(text) => self.pipeline.set_robot_semantic(&text, &source).map_err(|e| e.to_string()),
            DescriptionMsg::TooLarge(n) => Err(format!("{source}: {n} bytes of SRDF text, more than the {MAX_DESCRIPTION_BYTES} allowed")),
        };
        self.warn_pending();
        match result {
            Ok(()) => {
                println!(
                    "thickness_collision: SRDF from {}: {} self-collision pairs checked",
                    io.names.semantic,
                    self.pipeline.checker().self_pairs().pairs.len()
                );
                self.description_error = None;
            }
            Err(e) => {
                let line = refusal_line(&io.names.semantic, &source, "keeping the current collision matrix", &e);
                eprintln!("[ERROR] thickness_collision: {line}");
                if self.log.pending.len() < 64 {
                    self.log.pending.push(line.clone());
                }
                self.description_error = Some(line);
            }
        }
    }

    fn on_request(&mut self, io: &Interfaces, id: ros2_client::service::RmwRequestId, req: CheckStatesRequest) {
        let reports = self.pipeline.check_request(&req.states);
        for r in reports.iter().filter(|r| !r.error.is_empty()) {
            let e = r.error.clone();
            self.log.warn("service-state", || format!("{}: a state failed closed: {e}", io.names.check_states));
        }
        if io.check_states.send_response(id, CheckStatesResponse { reports }).is_err() {
            self.log.warn("service-send", || format!("sending a {} response failed", io.names.check_states));
        }
    }

    /// A `check_trajectory` request: resolved by the pipeline here (cheap), checked by the worker.
    /// A refused request is answered at once, as is one past [`MAX_TRAJECTORIES_PENDING`].
    fn on_trajectory_request(&mut self, io: &Interfaces, worker: &TrajectoryWorker, id: ros2_client::service::RmwRequestId, req: CheckTrajectoryRequest) {
        let job = self.pipeline.trajectory_job(&req.trajectory);
        drop(req);
        if job.refused().is_none() {
            match worker.jobs.try_send((id, job)) {
                Ok(()) => return,
                Err(std::sync::mpsc::TrySendError::Full(_)) => {
                    let busy = CheckTrajectoryResponse {
                        segment: -1,
                        fraction: -1.0,
                        error: format!("busy: {MAX_TRAJECTORIES_PENDING} check_trajectory requests are waiting; try again later"),
                        ..Default::default()
                    };
                    return self.send_trajectory_answer(io, id, busy);
                }
                Err(std::sync::mpsc::TrySendError::Disconnected(_)) => {
                    let gone =
                        CheckTrajectoryResponse { segment: -1, fraction: -1.0, error: "the check_trajectory worker has stopped".into(), ..Default::default() };
                    return self.send_trajectory_answer(io, id, gone);
                }
            }
        }
        let answer = job.run();
        self.send_trajectory_answer(io, id, answer);
    }

    fn send_trajectory_answer(&mut self, io: &Interfaces, id: ros2_client::service::RmwRequestId, answer: CheckTrajectoryResponse) {
        if !answer.error.is_empty() {
            let e = answer.error.clone();
            self.log.warn("service-trajectory", || format!("{}: not valid: {e}", io.names.check_trajectory));
        }
        if io.check_trajectory.send_response(id, answer).is_err() {
            self.log.warn("service-send", || format!("sending a {} response failed", io.names.check_trajectory));
        }
    }

    /// A `check_state_validity` request: resolved by the pipeline here (cheap), checked by the
    /// worker. A refused request is answered at once, as is one past [`MAX_VALIDITY_PENDING`].
    fn on_validity_request(&mut self, io: &Interfaces, worker: &ValidityWorker, id: ros2_client::service::RmwRequestId, req: Box<GetStateValidityRequest>) {
        let job = self.pipeline.validity_job(&req);
        drop(req);
        if let Some(w) = job.warning() {
            let w = w.to_owned();
            self.log.warn("service-validity-group", || format!("{}: {w}", io.names.check_state_validity));
        }
        if let Some(reason) = job.refused() {
            let reason = reason.to_owned();
            return self.send_validity_answer(io, id, GetStateValidityResponse::default(), Some(reason));
        }
        let reason = match worker.jobs.try_send((id, job)) {
            Ok(()) => return,
            Err(std::sync::mpsc::TrySendError::Full(_)) => format!("busy: {MAX_VALIDITY_PENDING} check_state_validity requests are waiting"),
            Err(std::sync::mpsc::TrySendError::Disconnected(_)) => "the check_state_validity worker has stopped".to_owned(),
        };
        self.send_validity_answer(io, id, GetStateValidityResponse::default(), Some(reason));
    }

    /// Sends an answer; a request not honoured is logged (console and `/rosout`) and counted for
    /// `/diagnostics`, as the response has no text field.
    fn send_validity_answer(&mut self, io: &Interfaces, id: ros2_client::service::RmwRequestId, answer: GetStateValidityResponse, reason: Option<String>) {
        if let Some(reason) = reason {
            self.stats.validity_refused += 1;
            self.log.warn("service-validity", || format!("{}: request not honoured (valid = false): {reason}", io.names.check_state_validity));
        }
        if io.check_state_validity.send_response(id, answer).is_err() {
            self.log.warn("service-send", || format!("sending a {} response failed", io.names.check_state_validity));
        }
    }

    fn on_tick(&mut self, node: &Node, io: &Interfaces) {
        // Warnings go to /rosout too (the console already has them).
        for text in self.log.pending.drain(..) {
            ros2_client::rosout!(*node, ros2_client::ros2::LogLevel::Warn, "{}", text);
        }
        let elapsed = self.last_diag.elapsed();
        if elapsed >= Duration::from_secs(1) {
            self.last_diag = Instant::now();
            let now = self.now();
            let status = diagnostics(&self.fqn, &mut self.stats, self.pipeline.skipped(), self.description_error.as_deref(), elapsed.as_secs_f64(), now);
            if io.diagnostics.publish(status).is_err() {
                self.log.warn("diagnostics", || "publishing /diagnostics failed".into());
            }
            let _ = self.memory.tick();
        }
        self.refresh_summary();
    }

    /// The summary a forced stop prints: refreshed each tick and before a turn that may be long
    /// (a robot or SRDF to build), not per input.
    fn refresh_summary(&self) {
        let line = self.shutdown_line();
        if let Ok(mut summary) = self.summary.lock() {
            *summary = line;
        }
    }
}

/// Runs the node until Ctrl-C or SIGTERM.
pub fn run(params: Params, opts: &RunOptions) -> Result<()> {
    // Before the model is built and DDS starts its threads: the thresholds apply from here on.
    memory_return::fix_allocator_thresholds();
    let params = params.with_overrides(&opts.ros_args.params)?;
    // The robot may come as a robot_description: an SRDF meant for it waits for it.
    let pipeline = Pipeline::new_expecting_description(params, opts.robot.as_deref(), opts.environment.as_deref())?;
    let (dp, domain, discovery) = participant()?;
    let context = Context::from_domain_participant(dp).map_err(|e| anyhow!("ROS context: {e:?}"))?;
    let namespace = opts.ros_args.namespace.clone().unwrap_or_else(|| "/".into());
    let node_name = opts.ros_args.node_name.clone().unwrap_or_else(|| "thickness_collision".into());
    let (changes_tx, changes) = smol::channel::unbounded();
    let mut node = context
        .new_node(
            NodeName::new(&namespace, &node_name).map_err(|e| anyhow!("node name {namespace}/{node_name}: {e:?}"))?,
            parameter_options(pipeline.params(), changes_tx),
        )
        .map_err(|e| anyhow!("cannot create the node: {e:?}"))?;
    let io = Arc::new(Interfaces::build(&mut node, pipeline.params(), &opts.ros_args)?);
    let param_servers = ParamServers::build(&mut node, ros_mapping(pipeline.params().service_mapping))?;

    {
        let s = pipeline.checker().summary();
        let p = pipeline.params();
        println!("thickness_collision: node {} on DDS domain {domain}, discovery range {}", node.fully_qualified_name(), discovery.describe());
        println!("  robot {} ({} links, {} checked)", s.robot_source, s.robot_links, s.checked_links);
        if pipeline.semantic_deferred() {
            println!("  SRDF {} does not fit this robot: it waits for a robot_description it fits", p.robot_semantic_file);
        }
        println!(
            "  environment {} ({} thin surfaces, {} cells, {} solids), built in {:.1} ms",
            s.environment_source,
            s.thin_surfaces,
            s.cells,
            s.solids,
            s.build_seconds * 1e3
        );
        println!("  {}", pipeline.checker().self_pairs().summary(pipeline.checker()));
        let input = match p.pose_source {
            PoseSource::Tf => format!("/tf and /tf_static (tf2_msgs/msg/TFMessage, frame prefix '{}')", p.frame_prefix),
            PoseSource::JointStates => format!("{} (sensor_msgs/msg/JointState)", io.names.joint_states),
        };
        println!(
            "  subscribes {input}, publishes {} (thickness_collision_msgs/msg/CollisionReport), serves {}, {} and {} (moveit_msgs/srv/GetStateValidity)",
            io.names.collisions, io.names.check_states, io.names.check_trajectory, io.names.check_state_validity
        );
    }

    let stop = Arc::new(AtomicBool::new(false));
    let (printed, done) = (Arc::new(AtomicBool::new(false)), Arc::new(AtomicBool::new(false)));
    let summary = Arc::new(Mutex::new(String::new()));
    {
        let (stop, printed, done, summary) = (stop.clone(), printed.clone(), done.clone(), summary.clone());
        // The loop sees the request at its next turn; if it has not shut down within STOP_GRACE
        // (a turn building a robot with a huge mesh takes seconds), the process exits from here,
        // with the counts of the last finished turn.
        ctrlc::set_handler(move || {
            stop.store(true, Ordering::SeqCst);
            let asked = Instant::now();
            while asked.elapsed() < STOP_GRACE {
                if done.load(Ordering::SeqCst) {
                    return;
                }
                std::thread::sleep(Duration::from_millis(10));
            }
            if printed.compare_exchange(false, true, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
                let line = summary.lock().map(|s| s.clone()).unwrap_or_default();
                println!("{line} (forced after {} ms: the loop was busy)", STOP_GRACE.as_millis());
            }
            std::process::exit(0);
        })
        .context("cannot install the Ctrl-C/SIGTERM handler")?;
    }
    let worker = TrajectoryWorker::start()?;
    let validity_worker = ValidityWorker::start()?;
    let spinner = node.spinner().map_err(|e| anyhow!("spinner: {e:?}"))?;
    let fqn = node.fully_qualified_name();
    let state = NodeState {
        pipeline,
        stats: NodeStats::default(),
        log: RateLimitedLog::default(),
        sim_time: None,
        last_markers: None,
        last_diag: Instant::now(),
        fqn,
        description_error: None,
        summary,
        memory: MemoryReturn::new(),
    };

    let use_tf = io.tf.is_some();
    let checking = Arc::new(Mutex::new(Checking::new(state, io.clone())));
    let (on_receive, states_turns) = OnReceive::new(&checking, &io, changes.clone());
    // Poisoned only by a panic in a check, which ends the process anyway.
    let hold = || checking.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let tick_events = ticks(TICK)?;
    smol::block_on(async {
        let spin = smol::spawn(spinner.spin());
        hold().state.publish_cells(&io);
        if !use_tf {
            // Takes what came before and leaves the receiving thread's waker with the reader.
            on_receive.answer_waiting(&mut hold(), &io, false);
        }
        // Every input as one stream of events. `select_all` polls only the sources that woke it
        // (issue 14): a `select!` over the thirteen polled all of them on every turn, and each
        // poll of an idle DDS reader takes its cache twice and stores a waker.
        type Events<'a> = Pin<Box<dyn Stream<Item = Event> + 'a>>;
        fn read<'a, M: 'static + serde::de::DeserializeOwned>(
            s: Option<&'a ros2_client::Subscription<M>>,
            what: &'static str,
            event: fn(M) -> Event,
        ) -> Option<Events<'a>> {
            s.map(|s| -> Events<'a> { Box::pin(s.async_stream().map(move |m| m.map_or_else(|e| Event::ReadFailed(what, e), |(m, _)| event(m)))) })
        }
        let sources: Vec<Option<Events>> = vec![
            // Joint states are read by whoever holds the node's state (`states_on_receive.rs`);
            // this is the receiving thread saying it left them to the loop.
            (!use_tf).then(|| -> Events { Box::pin(states_turns.map(|()| Event::States)) }),
            read(io.tf.as_ref().map(|t| &t.0), "/tf", Event::Tf),
            read(io.tf.as_ref().map(|t| &t.1), "/tf_static", Event::TfStatic),
            read(Some(&io.descriptions), "robot_description", Event::Description),
            read(Some(&io.semantics), "robot_description_semantic", Event::Semantic),
            read(io.clock.as_ref(), "/clock", |m: ClockMsg| Event::Clock(m.clock)),
            Some(Box::pin(
                io.check_states.receive_request_stream().map(|r| r.map_or_else(|e| Event::ReadFailed("check_states", e), |(id, req)| Event::Request(id, req))),
            )),
            Some(Box::pin(
                io.check_trajectory
                    .receive_request_stream()
                    .map(|r| r.map_or_else(|e| Event::ReadFailed("check_trajectory", e), |(id, req)| Event::TrajectoryRequest(id, req))),
            )),
            Some(Box::pin(worker.done.clone().map(|(id, answer)| Event::TrajectoryDone(id, answer)))),
            Some(Box::pin(
                io.check_state_validity
                    .receive_request_stream()
                    .map(|r| r.map_or_else(|e| Event::ReadFailed("check_state_validity", e), |(id, req)| Event::ValidityRequest(id, Box::new(req)))),
            )),
            Some(Box::pin(validity_worker.done.clone().map(|(id, answer, reason)| Event::ValidityDone(id, answer, reason)))),
            param_servers
                .as_ref()
                .map(|p| -> Events { Box::pin(p.requests().map(|r| r.map_or_else(|e| Event::ReadFailed("parameter services", e), Event::Parameter))) }),
            // The tick comes from a thread, not a smol Timer (issue 14): a timer in the reactor
            // made this thread the one waiting on it, so every state woke it through an eventfd
            // and re-armed a timerfd (five syscalls a message more than a futex wake).
            Some(Box::pin(tick_events.map(|()| Event::Tick))),
        ];
        let mut events = futures::stream::select_all(sources.into_iter().flatten());
        // The housekeeping (/rosout, /diagnostics, the summary for a forced stop) runs when the
        // tick has come or is overdue, not per input.
        let (mut tick_due, mut last_tick) = (true, Instant::now());
        while !stop.load(Ordering::SeqCst) {
            if std::mem::take(&mut tick_due) || last_tick.elapsed() >= TICK {
                last_tick = Instant::now();
                hold().state.on_tick(&node, &io);
            }
            // The tick never ends, so neither does this stream.
            let Some(event) = events.next().await else { break };
            // Parameter answers wait on the writer here; the node's state is not held meanwhile.
            let event = match event {
                Event::Parameter(r) => {
                    if let Some(p) = &param_servers {
                        if let Err(what) = p.answer(&node, r).await {
                            hold().state.log.warn("service-send", || format!("sending a {what} response failed"));
                        }
                    }
                    continue;
                }
                event => event,
            };
            let mut held = hold();
            let state = &mut held.state;
            // A parameter change accepted before this input arrived applies to it.
            state.apply_params(&io, &changes);
            match event {
                Event::States => on_receive.answer_waiting(&mut held, &io, false),
                Event::Tf(m) => state.on_tf(&io, m),
                Event::TfStatic(m) => state.on_tf_static(m),
                Event::Description(m) => state.on_description(&io, m),
                Event::Semantic(m) => state.on_semantic(&io, m),
                Event::Clock(t) => state.sim_time = Some(t),
                Event::Request(id, req) => state.on_request(&io, id, req),
                Event::TrajectoryRequest(id, req) => state.on_trajectory_request(&io, &worker, id, req),
                Event::TrajectoryDone(id, answer) => state.send_trajectory_answer(&io, id, answer),
                Event::ValidityRequest(id, req) => state.on_validity_request(&io, &validity_worker, id, req),
                Event::ValidityDone(id, answer, reason) => state.send_validity_answer(&io, id, answer, reason),
                Event::ReadFailed(what, e) => state.on_read_failed(what, &e),
                // Answered above, without the state.
                Event::Parameter(_) => {}
                Event::Tick => tick_due = true,
            }
        }
        on_receive.stop(&checking);
        if printed.compare_exchange(false, true, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
            println!("{}", hold().state.shutdown_line());
        }
        drop(spin);
    });
    // The interfaces go down on this thread, not the receiving one: a waker that took the state
    // just before the stop lets it go within microseconds.
    let waited = Instant::now();
    while Arc::strong_count(&checking) > 1 && waited.elapsed() < STOP_GRACE {
        std::thread::yield_now();
    }
    drop(checking);
    // DDS goes down before the stop counts as done (the participant leaves the domain).
    drop(io);
    drop(node);
    drop(context);
    done.store(true, Ordering::SeqCst);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_description_names_its_topic_once() {
        let source = "/robot_description topic";
        let line = refusal_line("/robot_description", source, "keeping the current robot", "/robot_description topic: malformed URDF: x\ny");
        assert_eq!(line, "/robot_description rejected, keeping the current robot: malformed URDF: x y");
        // An error about another file keeps its own prefix.
        let line = refusal_line("/robot_description", source, "keeping the current robot", "env.urdf: link 'a': bad");
        assert_eq!(line, "/robot_description rejected, keeping the current robot: env.urdf: link 'a': bad");
    }

    #[test]
    fn domain_id_is_0_to_232() {
        assert_eq!(domain_id(None).unwrap(), 0);
        assert_eq!(domain_id(Some("  ")).unwrap(), 0);
        assert_eq!(domain_id(Some("0")).unwrap(), 0);
        assert_eq!(domain_id(Some(" 42 ")).unwrap(), 42);
        assert_eq!(domain_id(Some("232")).unwrap(), 232);
        for bad in ["233", "65535", "65536", "-1", "1.5", "one", "99999999999999999999999"] {
            let e = domain_id(Some(bad)).unwrap_err().to_string();
            assert!(e.contains("ROS_DOMAIN_ID") && e.contains(&format!("'{bad}'")) && e.contains("0 to 232") && !e.contains('\n'), "{bad}: {e}");
        }
    }

    #[test]
    fn ticks_come_and_a_missed_one_is_not_doubled() {
        let rx = ticks(Duration::from_millis(20)).expect("tick thread");
        let started = Instant::now();
        for _ in 0..3 {
            rx.recv_blocking().expect("a tick");
        }
        // The thread started before the clock did, so the third tick may come a little before 60 ms.
        assert!(started.elapsed() >= Duration::from_millis(50), "three ticks of 20 ms in {:?}", started.elapsed());
        // Ten periods not taken leave one tick waiting, not ten.
        std::thread::sleep(Duration::from_millis(200));
        assert!(rx.try_recv().is_ok());
        assert!(rx.try_recv().is_err());
    }
}
