//! Joint states answered on the thread that receives them.
//!
//! RustDDS reads every sample on its event-loop thread. Handed from there to the node's loop, each
//! state would cost a thread wake-up before it was checked, a hand-over a Fast DDS node does not
//! pay (its listener answers on the receiving thread). The joint-states reader's waker is an
//! [`OnReceive`]: RustDDS calls it on its event-loop thread once the sample is stored, and when the
//! node's state is free it takes the waiting states, checks them and publishes the reports right
//! there (the patched DataWriter sends a new sample from the caller's thread, so the report leaves
//! from there too). When the loop holds the state (a service request, a tick, a robot being built)
//! or a parameter change is waiting, it only passes the turn to the loop, which takes the states
//! once it is done: the event loop never waits for the node and never builds a model.
//!
//! `TC_CHECK_ON_RECEIVE=0` in the environment always passes the turn (every state handed to the
//! loop), for measuring one against the other (`benches/run_latency.sh`).

use super::interfaces::Interfaces;
use super::node_state::NodeState;
use crate::model::Params;
use crate::msgs::JointState;
use futures::stream::Stream;
use ros2_client::{MessageInfo, ReadResult};
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::task::{Context, Poll, Wake, Waker};

/// Joint states taken in one turn at most (of the loop, or of the receiving thread): the rest
/// wait for the loop's next turn, so a flood cannot keep the loop from a stop request or the
/// other inputs, nor RustDDS's thread from its other traffic for long.
const MAX_STATES_PER_TURN: usize = 256;

/// The joint-states reader as a stream that owns its subscription (through the interfaces), so it
/// can live beside the node's state.
type StatesStream = Pin<Box<dyn Stream<Item = ReadResult<(JointState, MessageInfo)>> + Send>>;

/// The node's state and its joint-states reader, held together: whoever holds them takes every
/// waiting state and answers it, so states are answered once each and in order on either thread.
pub(super) struct Checking {
    pub(super) state: NodeState,
    states: StatesStream,
}

impl Checking {
    pub(super) fn new(state: NodeState, io: Arc<Interfaces>) -> Checking {
        let states: StatesStream = Box::pin(futures::stream::unfold(io, |io| async move {
            let m = io.states.async_take().await;
            Some((m, io))
        }));
        Checking { state, states }
    }
}

/// The joint-states reader's waker (see the module comment).
pub(super) struct OnReceive {
    // Weak: the reader holds this waker, and the interfaces hold the reader.
    checking: Weak<Mutex<Checking>>,
    io: Weak<Interfaces>,
    changes: smol::channel::Receiver<Params>,
    to_loop: smol::channel::Sender<()>,
    stopped: AtomicBool,
    on_receive: bool,
}

impl OnReceive {
    /// The waker, and the loop's end of its hand-over: one `()` means "states are waiting".
    pub(super) fn new(
        checking: &Arc<Mutex<Checking>>,
        io: &Arc<Interfaces>,
        changes: smol::channel::Receiver<Params>,
    ) -> (Arc<OnReceive>, smol::channel::Receiver<()>) {
        let (to_loop, turns) = smol::channel::bounded(1);
        let on_receive = std::env::var("TC_CHECK_ON_RECEIVE").map_or(true, |v| v != "0");
        let waker = OnReceive { checking: Arc::downgrade(checking), io: Arc::downgrade(io), changes, to_loop, stopped: AtomicBool::new(false), on_receive };
        (Arc::new(waker), turns)
    }

    /// Takes the waiting states (up to [`MAX_STATES_PER_TURN`]) and answers them, leaving this
    /// waker with the reader for the next one. With more waiting than that, the rest is the
    /// loop's next turn, so neither thread is held by a flood. `receiving_thread`: called there
    /// (counted for `/diagnostics`), not by the loop.
    pub(super) fn answer_waiting(self: &Arc<Self>, checking: &mut Checking, io: &Interfaces, receiving_thread: bool) {
        // Polling stores this waker in the reader through the reader's waker lock. On the
        // receiving thread this runs inside RustDDS's wake of the previous waker: the patched
        // reader takes the waker out of that lock before waking it (`vendor/rustdds/PATCHES.md`,
        // "woken outside its lock"), without which this poll would wait on a lock its own thread
        // holds, and the event loop would stop for good.
        let waker = Waker::from(self.clone());
        let mut cx = Context::from_waker(&waker);
        let mut waiting = Vec::new();
        while waiting.len() < MAX_STATES_PER_TURN {
            match checking.states.as_mut().poll_next(&mut cx) {
                Poll::Ready(Some(m)) => waiting.push(m),
                Poll::Ready(None) | Poll::Pending => break,
            }
        }
        let more = waiting.len() == MAX_STATES_PER_TURN;
        if !waiting.is_empty() {
            if receiving_thread {
                // As `received` counts them: a sample that does not decode is counted
                // `undecodable`, not received (counting it here made taken exceed received).
                checking.state.stats.taken_on_receive += waiting.iter().filter(|m| m.is_ok()).count() as u64;
            }
            checking.state.on_joint_states(io, waiting);
        }
        if more {
            self.pass_to_loop();
        }
    }

    /// After this returns, no state is answered on the receiving thread any more (the loop can
    /// take the interfaces down).
    pub(super) fn stop(&self, checking: &Mutex<Checking>) {
        self.stopped.store(true, Ordering::SeqCst);
        // One answering now finishes first: it holds the lock.
        drop(checking.lock());
    }

    fn pass_to_loop(&self) {
        // Full: a turn is already due, and it takes everything waiting.
        let _ = self.to_loop.try_send(());
    }
}

impl Wake for OnReceive {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    /// Called on RustDDS's event-loop thread once every datagram it read together is stored (the
    /// patched reader wakes after the batch, not per sample): a node that fell behind finds
    /// every state that waited, and the oldest can share one report.
    fn wake_by_ref(self: &Arc<Self>) {
        if self.stopped.load(Ordering::SeqCst) {
            return;
        }
        // A parameter change is applied (perhaps a rebuild, seconds) by the loop, before the states.
        if !self.on_receive || !self.changes.is_empty() {
            return self.pass_to_loop();
        }
        let Some(checking) = self.checking.upgrade() else { return };
        // Busy (the loop holds it) or poisoned (the loop reports that): the loop's turn.
        let Ok(mut held) = checking.try_lock() else { return self.pass_to_loop() };
        // Checked under the lock: `stop` has taken and released it when it is set.
        if self.stopped.load(Ordering::SeqCst) {
            return;
        }
        let Some(io) = self.io.upgrade() else { return };
        // A panic here would end RustDDS's thread and leave a node that hears nothing; on the
        // loop's thread it ends the process, and so it does here (the hook has printed it).
        if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.answer_waiting(&mut held, &io, true))).is_err() {
            eprintln!("[ERROR] thickness_collision: a joint state's check panicked on the receiving thread; exiting");
            std::process::exit(101);
        }
    }
}
