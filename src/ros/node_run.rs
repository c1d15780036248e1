//! The node's life: start, the loop that hands every input to the node's state, and shutdown.
//! The DDS wiring is `interfaces.rs`, the behaviour `node_state.rs`, the work off the loop
//! `workers.rs`. Joint states are mostly answered before they reach the loop, on the thread that
//! received them, whenever the loop is not holding the node's state (`states_on_receive.rs`).

use super::background::Background;
use super::interfaces::{Event, Events, Interfaces};
use super::memory_return;
use super::motion_ladder::MotionLadder;
use super::node_state::{NodeState, PendingScene};
use super::param_services::{ros_mapping, ParamServers};
use super::param_values::{parameter_options, ReadOnly};
use super::participant::participant;
use super::ros_args::RosArgs;
use super::states_on_receive::{Checking, OnReceive};
use super::workers::Workers;
use crate::model::{Params, PoseSource};
use crate::pipeline::Pipeline;
use anyhow::{anyhow, Context as _, Result};
use futures::StreamExt;
use ros2_client::{Context, Node, NodeName};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How the node was started.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// `--ros-args`.
    pub ros_args: RosArgs,
}

/// The loop's housekeeping period (`/rosout`, `/diagnostics`, the summary for a forced stop).
const TICK: Duration = Duration::from_millis(100);

/// The least time between two cell-marker messages sent for planning-scene changes. Each is up
/// to 2.9 MB (`marker_max_cells`), fragmented and sent by the DDS thread that also receives the
/// joint states: sent per change at 20 changes a second they raised the states' p99 by ~0.8 ms
/// (`benches/run_scene_latency.sh`). The newest scene is always drawn, at most this late.
const CELLS_GAP: Duration = Duration::from_millis(500);

/// How long a stop request waits for the loop (busy building a robot, say) before the process
/// exits without it: SIGTERM is honoured within 2 s whatever the loop is doing. (Exiting is not
/// instant either: a process holding gigabytes took 0.6 s to be torn down.)
const STOP_GRACE: Duration = Duration::from_millis(1000);

/// A tick every `period` from a thread of its own; a tick the loop has not taken yet is not
/// doubled. The thread ends at the first tick after the loop drops the receiver.
///
/// A thread, not a smol Timer: a timer in the reactor made the loop's thread the one waiting on
/// it, so every state woke it through an eventfd and re-armed a timerfd (five syscalls a message
/// more than a futex wake).
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

/// A stop request (Ctrl-C or SIGTERM), and what its handler needs when the loop cannot honour it
/// within [`STOP_GRACE`].
struct Stop {
    requested: Arc<AtomicBool>,
    /// The shutdown line is printed (by the loop or the handler, once).
    printed: Arc<AtomicBool>,
    /// DDS is down: the handler lets the process end by itself.
    done: Arc<AtomicBool>,
    /// The shutdown line as of the last finished turn (`NodeState::refresh_summary`).
    summary: Arc<Mutex<String>>,
}

impl Stop {
    /// Installs the handler. The loop sees the request at its next turn; if it has not shut
    /// down within STOP_GRACE (a turn building a robot with a huge mesh takes seconds), the
    /// process exits from the handler, with the counts of the last finished turn.
    fn install() -> Result<Stop> {
        let stop = Stop {
            requested: Arc::new(AtomicBool::new(false)),
            printed: Arc::new(AtomicBool::new(false)),
            done: Arc::new(AtomicBool::new(false)),
            summary: Arc::new(Mutex::new(String::new())),
        };
        let (requested, printed, done, summary) = (stop.requested.clone(), stop.printed.clone(), stop.done.clone(), stop.summary.clone());
        ctrlc::set_handler(move || {
            requested.store(true, Ordering::SeqCst);
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
        Ok(stop)
    }

    fn requested(&self) -> bool {
        self.requested.load(Ordering::SeqCst)
    }

    /// Prints the shutdown line unless the handler already has.
    fn print_once(&self, line: impl FnOnce() -> String) {
        if self.printed.compare_exchange(false, true, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
            println!("{}", line());
        }
    }
}

/// What the node serves, printed once at start.
fn print_banner(pipeline: &Pipeline, node: &Node, io: &Interfaces, domain: u16, discovery: &str) {
    let s = pipeline.checker().summary();
    let p = pipeline.params();
    println!("thickness_collision: node {} on DDS domain {domain}, discovery range {discovery}", node.fully_qualified_name());
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
    // Before the line that ends the banner (the one that says what it serves).
    let door = |name: &str, parameter: &str| if name.is_empty() { format!("closed ({parameter} empty)") } else { name.to_owned() };
    println!(
        "  robot description: {}; SRDF: {}",
        door(&io.names.description, "robot_description_topic"),
        door(&io.names.semantic, "robot_description_semantic_topic")
    );
    if !p.read_only_parameters.is_empty() {
        println!("  read-only parameters: {}", p.read_only_parameters.join(", "));
    }
    if io.scene.is_some() {
        let n = &io.names;
        println!(
            "  planning scene: subscribes {}, {}, {}, {} (moveit_msgs), answers {} and {}",
            n.collision_object, n.attached_collision_object, n.planning_scene, n.planning_scene_world, n.apply_planning_scene, n.get_planning_scene
        );
    }
    let input = match p.pose_source {
        PoseSource::Tf => format!("/tf and /tf_static (tf2_msgs/msg/TFMessage, frame prefix '{}')", p.frame_prefix),
        PoseSource::JointStates => format!("{} (sensor_msgs/msg/JointState)", io.names.joint_states),
    };
    println!(
        "  subscribes {input}, publishes {} (thickness_collision_msgs/msg/CollisionReport), serves {}, {} and {} (moveit_msgs/srv/GetStateValidity)",
        io.names.collisions, io.names.check_states, io.names.check_trajectory, io.names.check_state_validity
    );
}

/// Runs the node until Ctrl-C or SIGTERM.
pub fn run(params: Params, opts: &RunOptions) -> Result<()> {
    // Before the model is built and DDS starts its threads: the thresholds apply from here on.
    memory_return::fix_allocator_thresholds();
    let params = params.with_overrides(&opts.ros_args.params)?;
    // The robot may come as a robot_description: an SRDF meant for it waits for it.
    let pipeline = Pipeline::new_expecting_description(params)?;
    // The motion checks' grown links, built beside the start rather than by the first requests
    // (a request that needs one first waits only for that one); again for each new robot.
    let ladder = MotionLadder::start().context("cannot start the motion ladder's thread")?;
    ladder.prepare(pipeline.checker());
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
    let param_servers = ParamServers::build(&mut node, ros_mapping(pipeline.params().service_mapping), ReadOnly::of(pipeline.params()))?;
    print_banner(&pipeline, &node, &io, domain, &discovery.describe());
    let stop = Stop::install()?;
    let workers = Workers::start()?;
    let background = Background::start().context("cannot start the background thread")?;
    let spinner = node.spinner().map_err(|e| anyhow!("spinner: {e:?}"))?;
    let state = NodeState::new(pipeline, ladder, node.fully_qualified_name(), stop.summary.clone());
    let checking = Arc::new(Mutex::new(Checking::new(state, io.clone())));
    let (on_receive, states_turns) = OnReceive::new(&checking, &io, changes.clone());
    let running = Running {
        node: &node,
        io: &io,
        param_servers: param_servers.as_ref(),
        workers: &workers,
        background: &background,
        checking: &checking,
        on_receive: &on_receive,
        changes: &changes,
        cells: Cell::new(CellMarkers { stale: false, sent: None }),
    };
    running.serve(&stop, spinner, states_turns)?;
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
    stop.done.store(true, Ordering::SeqCst);
    Ok(())
}

/// What the loop works with.
struct Running<'a> {
    node: &'a Node,
    io: &'a Arc<Interfaces>,
    param_servers: Option<&'a ParamServers>,
    workers: &'a Workers,
    background: &'a Background,
    checking: &'a Arc<Mutex<Checking>>,
    on_receive: &'a Arc<OnReceive>,
    changes: &'a smol::channel::Receiver<Params>,
    cells: Cell<CellMarkers>,
}

/// Whether the cell markers on the wire are behind the scene in force, and when the last went.
#[derive(Clone, Copy)]
struct CellMarkers {
    stale: bool,
    sent: Option<Instant>,
}

impl Running<'_> {
    /// The node's state, held. Poisoned only by a panic in a check, which ends the process anyway.
    fn hold(&self) -> std::sync::MutexGuard<'_, Checking> {
        self.checking.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Answers the joint states waiting and leaves the receiving thread's waker with the reader,
    /// before the loop lets go of the state for a while.
    fn rearm(&self, held: &mut Checking) {
        if self.io.tf.is_none() {
            self.on_receive.answer_waiting(held, self.io, false);
        }
    }

    /// A scene change built on the background thread and installed here; its cells drawn now
    /// or, within [`CELLS_GAP`] of the last drawing, at a later tick.
    async fn build_scene(&self, pending: PendingScene) {
        let built = self.background.run(move || pending.build()).await;
        let installed = {
            let mut held = self.hold();
            let installed = held.state.finish_scene(self.io, built);
            self.rearm(&mut held);
            installed
        };
        if installed {
            self.cells.set(CellMarkers { stale: true, ..self.cells.get() });
            self.draw_cells_when_due().await;
        }
    }

    /// The cell markers of the scene in force, drawn and serialised on the background thread
    /// (milliseconds for a large scene), when they are stale and the gap has passed.
    async fn draw_cells_when_due(&self) {
        let CellMarkers { stale, sent } = self.cells.get();
        if !stale || sent.is_some_and(|t| t.elapsed() < CELLS_GAP) {
            return;
        }
        self.cells.set(CellMarkers { stale: false, sent: Some(Instant::now()) });
        let cells = self.hold().state.cells_to_draw();
        let shared = Arc::clone(self.io);
        if !self.background.run(move || cells.publish(&shared)).await {
            self.hold().state.on_cells_failed(self.io);
        }
    }

    /// Every input as one stream of events. `select_all` polls only the sources that woke it (a
    /// `select!` over all of them polled each on every turn, and each poll of an idle DDS reader
    /// takes its cache twice and stores a waker).
    fn events(&self, states_turns: smol::channel::Receiver<()>, ticks: smol::channel::Receiver<()>) -> impl futures::Stream<Item = Event> + Unpin + '_ {
        let mut sources: Vec<Events> = Vec::new();
        if self.io.tf.is_none() {
            // Joint states are read by whoever holds the node's state (`states_on_receive.rs`);
            // this is the receiving thread saying it left them to the loop.
            sources.push(Box::pin(states_turns.map(|()| Event::States)));
        }
        sources.extend(self.io.events());
        sources.extend(self.workers.events());
        if let Some(p) = self.param_servers {
            sources.push(Box::pin(p.requests().map(|r| r.map_or_else(|e| Event::ReadFailed("parameter services", e), Event::Parameter))));
        }
        sources.push(Box::pin(ticks.map(|()| Event::Tick)));
        futures::stream::select_all(sources)
    }

    /// The loop, until a stop is requested; then no state is answered on the receiving thread
    /// any more.
    fn serve(&self, stop: &Stop, spinner: ros2_client::Spinner, states_turns: smol::channel::Receiver<()>) -> Result<()> {
        let (io, on_receive) = (self.io, self.on_receive);
        let tick_events = ticks(TICK)?;
        smol::block_on(async {
            let spin = smol::spawn(spinner.spin());
            self.hold().state.publish_cells(io);
            if io.tf.is_none() {
                // Takes what came before and leaves the receiving thread's waker with the reader.
                on_receive.answer_waiting(&mut self.hold(), io, false);
            }
            let mut events = self.events(states_turns, tick_events);
            // The housekeeping (/rosout, /diagnostics, the summary for a forced stop) runs when
            // the tick has come or is overdue, not per input.
            let (mut tick_due, mut last_tick) = (true, Instant::now());
            while !stop.requested() {
                if std::mem::take(&mut tick_due) || last_tick.elapsed() >= TICK {
                    last_tick = Instant::now();
                    self.hold().state.on_tick(self.node, io);
                    self.draw_cells_when_due().await;
                }
                // The tick never ends, so neither does this stream.
                let Some(event) = events.next().await else { break };
                // Parameter answers wait on the writer here; the node's state is not held meanwhile.
                if let Event::Parameter(r) = event {
                    if let Some(p) = self.param_servers {
                        if let Err(what) = p.answer(self.node, r).await {
                            self.hold().state.on_send_failed(what);
                        }
                    }
                    continue;
                }
                // A planning-scene input: its cells are built with the state free, so the states
                // that arrive meanwhile are answered (on the receiving thread) against the scene
                // in force; nothing else changes the checker before it is installed.
                if event.is_scene() {
                    let pending = {
                        let mut held = self.hold();
                        held.state.apply_params(io, self.changes);
                        let pending = held.state.take_scene_event(io, event);
                        // A state that came while the lock was held passed its turn to this loop
                        // and left no waker with the reader: re-armed here, the states that come
                        // during the build and the drawing are answered on the receiving thread.
                        self.rearm(&mut held);
                        pending
                    };
                    if let Some(pending) = pending {
                        self.build_scene(pending).await;
                    }
                    continue;
                }
                let mut held = self.hold();
                // A parameter change accepted before this input arrived applies to it.
                held.state.apply_params(io, self.changes);
                match event {
                    Event::States => on_receive.answer_waiting(&mut held, io, false),
                    Event::Tick => tick_due = true,
                    event => held.state.on_event(io, self.workers, event),
                }
            }
            on_receive.stop(self.checking);
            stop.print_once(|| self.hold().state.shutdown_line());
            drop(spin);
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
