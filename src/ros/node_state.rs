//! The node's behaviour: its state between messages, and one short handler per input, each
//! handing the input to the [`Pipeline`] and publishing what it returns. Nothing here decides an
//! answer, and nothing here waits: the loop (`node_run.rs`) or the receiving thread
//! (`states_on_receive.rs`) calls a handler with the state held.

use super::description_msg::{refusal_line, DescriptionMsg};
use super::diagnostics::{diagnostics, NodeStats};
use super::interfaces::{Event, Interfaces};
use super::memory_return::MemoryReturn;
use super::motion_ladder::MotionLadder;
use super::rate_limited_log::RateLimitedLog;
use super::workers::Workers;
use crate::checker::Checker;
use crate::limits::MAX_DESCRIPTION_BYTES;
use crate::markers::{cell_markers, contact_markers};
use crate::model::Params;
use crate::msgs::moveit::{GetStateValidityRequest, GetStateValidityResponse};
use crate::msgs::planning_scene::{ApplyPlanningSceneResponse, GetPlanningSceneRequest, GetPlanningSceneResponse};
use crate::msgs::{CheckStatesRequest, CheckStatesResponse};
use crate::msgs::{CheckTrajectoryRequest, CheckTrajectoryResponse, JointState, TfMessage, Time};
use crate::pipeline::{BuiltScene, Pipeline, RobotState, ScenePlan, Skip, SkipCause};
use ros2_client::service::RmwRequestId;
use ros2_client::{MessageInfo, Node, ReadError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Joint states taken in one turn that get a report each. A stall of the machine of a few
/// milliseconds leaves a few dozen waiting at 10 kHz, and the node answers them all (as replay
/// does, one report per state) and catches up; more than this waiting means it is behind, and the
/// oldest share one report (the polyline through them, no publish each) so the newest are
/// answered sooner. At 10 kHz, one report per turn left 1 % of the states without an answer of
/// their own, 32 per turn 0.14 % on a noisy machine (docs/latency.md).
const SEPARATE_REPORTS: usize = 64;

/// Contact markers fade half a second after the last report: a node whose input stopped shows no
/// stale contacts.
const CONTACT_MARKER_LIFETIME: crate::msgs::DurationMsg = crate::msgs::DurationMsg { sec: 0, nanosec: 500_000_000 };

/// A planning-scene input accepted, its cells still to build.
pub(super) struct PendingScene {
    plan: ScenePlan,
    /// The `apply_planning_scene` request to answer once it is in force.
    reply: Option<RmwRequestId>,
}

/// The cell markers of a checker, drawn and sent without the node's state held: for a scene of
/// many objects that takes milliseconds, and states are answered meanwhile.
pub(super) struct CellsToDraw {
    checker: Arc<Checker>,
    max: usize,
    world: String,
    now: Time,
}

impl CellsToDraw {
    /// Draws and sends them; false when the writer refused.
    pub(super) fn publish(self, io: &Interfaces) -> bool {
        io.cells.publish(cell_markers(&self.checker, self.max, &self.world, self.now)).is_ok()
    }
}

/// A [`PendingScene`] built (by whoever does not hold the node's state).
pub(super) struct BuiltPending {
    scene: BuiltScene,
    reply: Option<RmwRequestId>,
}

impl PendingScene {
    pub(super) fn build(self) -> BuiltPending {
        BuiltPending { scene: self.plan.build(), reply: self.reply }
    }
}

/// The node's state between messages.
pub(super) struct NodeState {
    pipeline: Pipeline,
    /// Prepares the motion checks of each robot put in force here.
    ladder: MotionLadder,
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
    /// The state of node `fqn` at start; `summary` is where [`NodeState::refresh_summary`] writes.
    pub(super) fn new(pipeline: Pipeline, ladder: MotionLadder, fqn: String, summary: Arc<Mutex<String>>) -> NodeState {
        NodeState {
            pipeline,
            ladder,
            stats: NodeStats::default(),
            log: RateLimitedLog::default(),
            sim_time: None,
            last_markers: None,
            last_diag: Instant::now(),
            fqn,
            description_error: None,
            summary,
            memory: MemoryReturn::new(),
        }
    }

    /// One input. Joint states, parameter requests and ticks are the loop's own (`node_run.rs`).
    pub(super) fn on_event(&mut self, io: &Interfaces, workers: &Workers, event: Event) {
        match event {
            Event::Tf(m) => self.on_tf(io, m),
            Event::TfStatic(m) => self.on_tf_static(m),
            Event::Description(m) => self.on_description(io, m),
            Event::Semantic(m) => self.on_semantic(io, m),
            Event::Clock(t) => self.sim_time = Some(t),
            Event::Request(id, req) => self.on_request(io, id, req),
            Event::TrajectoryRequest(id, req) => self.on_trajectory_request(io, workers, id, req),
            Event::TrajectoryDone(id, answer) => self.send_trajectory_answer(io, id, answer),
            Event::ValidityRequest(id, req) => self.on_validity_request(io, workers, id, req),
            Event::ValidityDone(id, answer, reason) => self.send_validity_answer(io, id, answer, reason),
            // Prepared here, built without the state held, installed here (`node_run.rs`).
            Event::CollisionObject(_) | Event::AttachedObject(_) | Event::Scene(_) | Event::SceneWorld(_) | Event::ApplyScene(..) => {
                if self.take_scene_event(io, event).is_some_and(|pending| self.finish_scene(io, pending.build())) {
                    self.publish_cells(io);
                }
            }
            Event::GetScene(id, req) => self.on_get_scene(io, id, req),
            Event::ReadFailed(what, e) => self.on_read_failed(what, &e),
            Event::States | Event::Parameter(_) | Event::Tick => {}
        }
    }

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
    pub(super) fn shutdown_line(&self) -> String {
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

    /// A response the loop could not send (`what` names the service).
    pub(super) fn on_send_failed(&mut self, what: &str) {
        self.log.warn("service-send", || format!("sending a {what} response failed"));
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

    pub(super) fn publish_cells(&mut self, io: &Interfaces) {
        if !self.cells_to_draw().publish(io) {
            self.on_cells_failed(io);
        }
    }

    /// What the cell markers of the checker in force need, to be drawn and sent with the state
    /// free.
    pub(super) fn cells_to_draw(&self) -> CellsToDraw {
        let max = self.pipeline.params().marker_max_cells.max(0) as usize;
        CellsToDraw { checker: Arc::clone(self.pipeline.checker()), max, world: self.world(), now: self.now() }
    }

    pub(super) fn on_cells_failed(&mut self, io: &Interfaces) {
        self.log.warn("markers", || format!("publishing {} failed", io.names.cells));
    }

    /// Parameter changes accepted by the service, applied before the next input is handled. Each
    /// accepted change carries every parameter, so only the newest is built: a burst of sets costs
    /// one rebuild.
    pub(super) fn apply_params(&mut self, io: &Interfaces, changes: &smol::channel::Receiver<Params>) {
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
                    self.ladder.prepare(self.pipeline.checker());
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
        // Never waits, and so may run on RustDDS's receiving thread (`states_on_receive.rs`): the
        // patched KEEP_LAST writer drops its oldest sample instead of waiting for acknowledgements.
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

    /// Joint states: everything taken in one turn goes through the pipeline in order (merging
    /// partial states). The newest [`SEPARATE_REPORTS`] - 1 good ones get a report each; one
    /// report covers all older ones (the polyline through them with `check_motion`, else the
    /// newest of them, the others stale). A waiting sample that does not decode is counted and
    /// skipped.
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

    /// A robot text (`language`: URDF or SRDF) from `topic`, handed to `set` on the pipeline.
    /// Err: the refusal's source (for [`refusal_line`]) and its error.
    fn take_text<E: ToString>(
        &mut self,
        topic: &str,
        language: &str,
        msg: DescriptionMsg,
        set: fn(&mut Pipeline, &str, &str) -> Result<(), E>,
    ) -> Result<(), (String, String)> {
        // Building a robot may take seconds: a forced stop meanwhile tells the counts so far.
        self.refresh_summary();
        let source = format!("{topic} topic");
        let result = match msg {
            DescriptionMsg::Text(text) => set(&mut self.pipeline, &text, &source).map_err(|e| e.to_string()),
            DescriptionMsg::TooLarge(n) => Err(format!("{source}: {n} bytes of {language} text, more than the {MAX_DESCRIPTION_BYTES} allowed")),
        };
        result.map_err(|e| (source, e))
    }

    /// A refused robot text: logged (every one: they are rare) and `/diagnostics` at ERROR with
    /// the reason until a good one arrives; the current robot keeps running.
    fn refuse_text(&mut self, topic: &str, what_stays: &str, (source, error): (String, String)) {
        let line = refusal_line(topic, &source, what_stays, &error);
        self.log.error(line.clone());
        self.description_error = Some(line);
    }

    /// A new robot from `robot_description`, built by the pipeline and swapped in whole.
    fn on_description(&mut self, io: &Interfaces, msg: DescriptionMsg) {
        match self.take_text(&io.names.description, "URDF", msg, Pipeline::set_robot_description) {
            Ok(()) => {
                let s = self.pipeline.checker().summary();
                println!("thickness_collision: robot from {}: {} links, {} checked", io.names.description, s.robot_links, s.checked_links);
                self.ladder.prepare(self.pipeline.checker());
                self.description_error = None;
                self.publish_cells(io);
            }
            Err(refused) => self.refuse_text(&io.names.description, "keeping the current robot", refused),
        }
    }

    /// A new SRDF from `robot_description_semantic`, swapped in whole by the pipeline; a refused
    /// one (it names links or joints the robot lacks) leaves the current matrix.
    fn on_semantic(&mut self, io: &Interfaces, msg: DescriptionMsg) {
        let result = self.take_text(&io.names.semantic, "SRDF", msg, Pipeline::set_robot_semantic);
        self.warn_pending();
        match result {
            Ok(()) => {
                let pairs = self.pipeline.checker().self_pairs().pairs.len();
                println!("thickness_collision: SRDF from {}: {pairs} self-collision pairs checked", io.names.semantic);
                self.description_error = None;
            }
            Err(refused) => self.refuse_text(&io.names.semantic, "keeping the current collision matrix", refused),
        }
    }

    /// A planning-scene input ([`Event::is_scene`]) prepared by the pipeline (validated, frames
    /// resolved at the current state): the plan whose cells are still to build, `None` when it was
    /// refused (warned, counted, an `apply_planning_scene` answered false) or is no scene input.
    pub(super) fn take_scene_event(&mut self, io: &Interfaces, event: Event) -> Option<PendingScene> {
        let (prepared, reply) = match event {
            Event::CollisionObject(m) => (self.pipeline.prepare_collision_object(&m), None),
            Event::AttachedObject(m) => (self.pipeline.prepare_attached_collision_object(&m), None),
            Event::Scene(m) => (self.pipeline.prepare_planning_scene(&m), None),
            Event::SceneWorld(m) => (self.pipeline.prepare_planning_scene_world(&m), None),
            Event::ApplyScene(id, req) => (self.pipeline.prepare_planning_scene(&req.scene), Some(id)),
            _ => return None,
        };
        self.warn_pending();
        match prepared {
            Ok(plan) => Some(PendingScene { plan, reply }),
            Err(skip) => {
                self.warn_skip(&skip);
                self.answer_apply(io, reply, false);
                None
            }
        }
    }

    /// A built scene put in force, or its refusal warned about; an `apply_planning_scene`
    /// answered once the change is in force. True when it is (its cell markers still to be
    /// sent: the caller draws them).
    pub(super) fn finish_scene(&mut self, io: &Interfaces, built: BuiltPending) -> bool {
        let installed = self.pipeline.install_scene(built.scene);
        // In force now: the caller waits for this answer, not for the markers.
        self.answer_apply(io, built.reply, installed.is_ok());
        self.refresh_summary();
        match installed {
            Ok(()) => true,
            Err(skip) => {
                self.warn_skip(&skip);
                false
            }
        }
    }

    fn answer_apply(&mut self, io: &Interfaces, reply: Option<RmwRequestId>, success: bool) {
        let (Some(id), Some(doors)) = (reply, &io.scene) else { return };
        if doors.apply.send_response(id, ApplyPlanningSceneResponse { success }).is_err() {
            self.on_send_failed(&io.names.apply_planning_scene);
        }
    }

    /// `get_planning_scene`: the scene in force, the components asked for.
    fn on_get_scene(&mut self, io: &Interfaces, id: RmwRequestId, req: GetPlanningSceneRequest) {
        let scene = self.pipeline.planning_scene_message(req.components.components, self.now());
        let Some(doors) = &io.scene else { return };
        if doors.get.send_response(id, GetPlanningSceneResponse { scene }).is_err() {
            self.on_send_failed(&io.names.get_planning_scene);
        }
    }

    /// `check_states`: checked here, on the loop (a few states; the caller waits for all of them).
    fn on_request(&mut self, io: &Interfaces, id: RmwRequestId, req: CheckStatesRequest) {
        let reports = self.pipeline.check_request(&req.states);
        for r in reports.iter().filter(|r| !r.error.is_empty()) {
            let e = r.error.clone();
            self.log.warn("service-state", || format!("{}: a state failed closed: {e}", io.names.check_states));
        }
        if io.check_states.send_response(id, CheckStatesResponse { reports }).is_err() {
            self.on_send_failed(&io.names.check_states);
        }
    }

    /// `check_trajectory`: resolved by the pipeline here (cheap), checked by its worker.
    fn on_trajectory_request(&mut self, io: &Interfaces, workers: &Workers, id: RmwRequestId, req: CheckTrajectoryRequest) {
        let job = self.pipeline.trajectory_job(&req);
        drop(req);
        if let Some(answer) = workers.trajectory.take(id, job) {
            self.send_trajectory_answer(io, id, answer);
        }
    }

    fn send_trajectory_answer(&mut self, io: &Interfaces, id: RmwRequestId, answer: CheckTrajectoryResponse) {
        if !answer.error.is_empty() {
            let e = answer.error.clone();
            self.log.warn("service-trajectory", || format!("{}: not valid: {e}", io.names.check_trajectory));
        }
        if io.check_trajectory.send_response(id, answer).is_err() {
            self.on_send_failed(&io.names.check_trajectory);
        }
    }

    /// `check_state_validity`: resolved by the pipeline here (cheap), checked by its worker.
    fn on_validity_request(&mut self, io: &Interfaces, workers: &Workers, id: RmwRequestId, req: Box<GetStateValidityRequest>) {
        let job = self.pipeline.validity_job(&req);
        drop(req);
        if let Some(w) = job.warning() {
            let w = w.to_owned();
            self.log.warn("service-validity-group", || format!("{}: {w}", io.names.check_state_validity));
        }
        if let Some((answer, reason)) = workers.validity.take(id, job) {
            self.send_validity_answer(io, id, answer, reason);
        }
    }

    /// Sends an answer; a request not honoured is logged (console and `/rosout`) and counted for
    /// `/diagnostics`, as the response has no text field.
    fn send_validity_answer(&mut self, io: &Interfaces, id: RmwRequestId, answer: GetStateValidityResponse, reason: Option<String>) {
        if let Some(reason) = reason {
            self.stats.validity_refused += 1;
            self.log.warn("service-validity", || format!("{}: request not honoured (valid = false): {reason}", io.names.check_state_validity));
        }
        if io.check_state_validity.send_response(id, answer).is_err() {
            self.on_send_failed(&io.names.check_state_validity);
        }
    }

    /// The housekeeping: queued warnings to `/rosout`, and `/diagnostics` once a second.
    pub(super) fn on_tick(&mut self, node: &Node, io: &Interfaces) {
        // Warnings go to /rosout too (the console already has them).
        for text in self.log.take_queued() {
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
