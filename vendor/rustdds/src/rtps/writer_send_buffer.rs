use std::{
  cmp::max,
  collections::BTreeMap,
  net::{SocketAddr, UdpSocket},
  sync::{
    atomic::{AtomicI32, Ordering},
    Arc, Condvar, Mutex,
  },
  time::{Duration as StdDuration, Instant},
};
use core::task::Waker;

#[allow(unused_imports)]
use log::{debug, error, trace, warn};

use speedy::Endianness;

use crate::{
  dds::{ddsdata::DDSData, with_key::datawriter::WriteOptions},
  rtps::MessageBuilder,
  structure::{
    cache_change::CacheChange,
    guid::{EntityId, GUID},
    sequence_number::SequenceNumber,
  },
};

/// thickness_collision patch (PATCHES.md, change 12): what a `DataWriter` needs to put a new
/// sample on the wire from its own thread, without waking the event loop first. The Writer
/// (event loop) sets it whenever its matched readers change, and only when every one of them is
/// reached by plain IPv4 unicast (no multicast, no security, no extra destinations); otherwise
/// it is `None` and every sample goes through the event loop as before.
pub(crate) struct DirectRoute {
  /// The participant's unicast sender socket (non-blocking), shared with its `UDPSender`.
  pub socket: Arc<UdpSocket>,
  /// Every matched reader's destination, deduplicated, as `send_message_to_readers` would
  /// send a DATA to all readers.
  pub destinations: Vec<SocketAddr>,
  pub endianness: Endianness,
  /// The largest payload sent unfragmented to all readers (the Writer's own bound).
  pub max_payload: usize,
  /// The Writer's heartbeat counter, for reliable writers: their DATA carries a HEARTBEAT.
  pub heartbeat_counter: Option<Arc<AtomicI32>>,
}

/// Result of an admission attempt into the [`WriterSendBuffer`].
pub(crate) enum Admission {
  /// The sample was admitted and given this sequence number. It now lives in
  /// the send buffer and is ready for the Writer (event loop) to transmit.
  Admitted(SequenceNumber),
  /// The reliable send window is full and no room became available within the
  /// allotted blocking time. The sample was *not* stored.
  WouldBlock,
}

// The actual shared state. Guarded by a single Mutex; the Condvar is signalled
// whenever the reliable acknowledgement frontier advances or the window grows,
// i.e. whenever a previously-blocked producer (or a `wait_for_acknowledgments`
// waiter) might be able to make progress.
struct Inner {
  // --- the send buffer proper (replaces the old HistoryBuffer) ---
  // Keyed by SequenceNumber, which is allocated here under the lock and is thus
  // strictly monotonic and unique. This is the single source of truth for the
  // Writer's outgoing samples (send, repair, fragmentation, eviction).
  changes: BTreeMap<SequenceNumber, CacheChange>,
  first_seq: SequenceNumber, // oldest still retained (default 1)
  last_seq: SequenceNumber,  // latest allocated (default 0 == nothing yet)

  // --- flow control ---
  // Maximum number of unacknowledged samples a reliable writer may have
  // outstanding before `write` must block/fail.
  window_limit: usize,
  // The acknowledgement frontier: the smallest `all_acked_before` over all
  // matched *reliable* readers. Only meaningful when `reliable_readers_present`.
  // Maintained by the Writer (event loop) via `set_acked_frontier`.
  acked_before: SequenceNumber,
  reliable_readers_present: bool,

  // nonblocking-transmit: the unsent backlog limit. The Writer advances
  // `sent_frontier` as it actually transmits samples; when the network socket
  // congests, `sent_frontier` stalls, the backlog `(sent_frontier, last_seq]`
  // fills, and admission blocks -- back-pressure reaching the application.
  // Applies to reliable *and* best-effort writers; built-in/discovery are
  // exempt so discovery never stalls.
  // (see src/rtps/nonblocking_transmit_design.md)
  backlog_limit: usize,
  // Highest sequence number the Writer has actually put on the wire.
  sent_frontier: SequenceNumber,

  // Hard upper bound on the number of retained samples for *non-blocking*
  // (best-effort, DDS-default) writes. Because such writes are never throttled
  // at admission (see `has_room`), and eviction otherwise only happens on the
  // periodic (6 s) cache-cleaning timer, the buffer would grow without bound
  // when the application produces faster than the socket drains. We therefore
  // apply KeepLast-style "newest wins" eviction directly on insert: once the
  // buffer exceeds `max_retain`, the oldest samples are dropped. Derived from
  // the writer's History depth / ResourceLimits (same value as `window_limit`).
  // Does NOT apply to reliable / opted-in writers, which are bounded by the
  // send window / unsent-backlog and must retain samples for repair.
  max_retain: usize,

  // Wakers of async producers / ack-waiters parked because the window was full
  // or acknowledgements were still pending. Drained (woken) on any advance.
  wakers: Vec<Waker>,

  // thickness_collision patch (change 12): the route for sending from the producer's thread,
  // and the highest sequence number sent that way. A sample is sent directly only when every
  // earlier one is already on the wire (`sent_frontier` is just below it), so any sample at
  // or below `direct_through` that the Writer has not yet passed was sent directly.
  direct: Option<DirectRoute>,
  direct_through: SequenceNumber,
}

struct Shared {
  inner: Mutex<Inner>,
  // Signalled together with `wakers` whenever progress may be possible.
  progress: Condvar,
  // Fixed for the lifetime of the writer.
  writer_guid: GUID,
  reliable_writer: bool,
  is_builtin: bool,
  // True for VOLATILE durability (the DDS default). When true, a reliable writer
  // with no matched reliable reader trims KeepLast on insert (there is no
  // late-joiner to serve, so retaining unacked samples is pointless). When false
  // (TRANSIENT_LOCAL / TRANSIENT / PERSISTENT) the writer must retain samples for
  // late-joining readers, so pre-match trimming is disabled.
  volatile: bool,
  // thickness_collision patch (PATCHES.md, change 10): History is KEEP_LAST. Such a writer never
  // waits for acknowledgements: it keeps the newest `max_retain` (the depth) samples, drops the
  // oldest even if a reader has not acknowledged them, and that reader gets a GAP for them.
  keep_last: bool,
  topic_name: String,
}

/// A shared, flow-controlled buffer of samples between a `DataWriter`
/// (producer, application threads) and its RTPS `Writer` (consumer, event
/// loop).
///
/// The producer side allocates a sequence number and inserts a sample only when
/// the reliable send window has room (synchronous admission, no round-trip).
/// The consumer side transmits unsent samples, advances the acknowledgement
/// frontier as ACKNACKs arrive, and evicts acknowledged samples. Both sides
/// hold a cloned handle to the same `Arc`.
#[derive(Clone)]
pub(crate) struct WriterSendBuffer {
  shared: Arc<Shared>,
}

impl WriterSendBuffer {
  #[allow(clippy::too_many_arguments)]
  pub fn new(
    writer_guid: GUID,
    topic_name: String,
    reliable_writer: bool,
    is_builtin: bool,
    volatile: bool,
    keep_last: bool, // thickness_collision patch (change 10)
    window_limit: usize,
    backlog_limit: usize,
    max_retain: usize,
  ) -> Self {
    Self {
      shared: Arc::new(Shared {
        inner: Mutex::new(Inner {
          changes: BTreeMap::new(),
          first_seq: SequenceNumber::new(1),
          last_seq: SequenceNumber::new(0),
          window_limit: window_limit.max(1),
          acked_before: SequenceNumber::new(1),
          reliable_readers_present: false,
          backlog_limit: backlog_limit.max(1),
          sent_frontier: SequenceNumber::new(0),
          max_retain: max_retain.max(1),
          wakers: Vec::new(),
          direct: None,
          direct_through: SequenceNumber::new(0),
        }),
        progress: Condvar::new(),
        writer_guid,
        reliable_writer,
        is_builtin,
        volatile,
        keep_last,
        topic_name,
      }),
    }
  }

  // --- predicates (must be called while holding the lock) ---

  // Is there room to admit one more sample right now?
  //
  // `may_block` is `true` for reliable writers and for best-effort writes that
  // opted in via `WriteOptions::best_effort_may_block`. When `false` (a
  // best-effort write that must not block, the DDS default) admission is never
  // throttled: congested samples are dropped later at the socket instead.
  fn has_room(shared: &Shared, inner: &Inner, may_block: bool) -> bool {
    if shared.is_builtin {
      // Built-in (discovery) writers must never stall.
      return true;
    }

    if !may_block {
      // Best-effort write that must not block (DDS v1.4 2.2.2.4.2.11 default).
      // Never throttle admission.
      return true;
    }

    // nonblocking-transmit: unsent-backlog limit. Applies to reliable writers
    // and to best-effort writers that opted in -- when the socket cannot drain,
    // the application is back-pressured instead of dropping. Samples in
    // (sent_frontier, last_seq].
    let unsent = i64::from(inner.last_seq) - i64::from(inner.sent_frontier);
    if unsent >= inner.backlog_limit as i64 {
      return false;
    }

    // thickness_collision patch (change 10): nor have KEEP_LAST writers. Waiting here let one
    // reader that stopped acknowledging (a stopped or hung process, still matched until its
    // lease ends) stop the writer for every other reader after `window_limit` samples, where DDS
    // drops the oldest samples of a KEEP_LAST history instead (`insert_locked` trims them).
    if !shared.reliable_writer || !inner.reliable_readers_present || shared.keep_last {
      // Best-effort and "no reliable reader yet" writers have no acknowledgement
      // window to wait on; the backlog limit above is their only throttle.
      return true;
    }
    // Number of unacknowledged samples in [acked_before, last_seq].
    let unacked = i64::from(inner.last_seq) - i64::from(inner.acked_before) + 1;
    unacked < inner.window_limit as i64
  }

  // Wake every parked producer / ack-waiter. Called after any state change that
  // could let someone make progress.
  fn wake_all(inner: &mut Inner, progress: &Condvar) {
    for w in inner.wakers.drain(..) {
      w.wake();
    }
    progress.notify_all();
  }

  // --- producer side ---

  /// Synchronous admission. Blocks the calling thread until there is room in
  /// the reliable send window, or `timeout` elapses. On success the sample is
  /// stored and its sequence number returned. Built-in / best-effort writers
  /// always admit immediately.
  pub fn admit_blocking(
    &self,
    write_options: WriteOptions,
    data: DDSData,
    timeout: Option<StdDuration>,
  ) -> Admission {
    let shared = &*self.shared;
    let mut inner = shared.inner.lock().unwrap();

    // Reliable writers always back-pressure; best-effort only if this write
    // opted in via `best_effort_may_block`.
    let may_block = shared.reliable_writer || write_options.best_effort_may_block();

    let deadline = timeout.map(|t| Instant::now() + t);
    loop {
      if Self::has_room(shared, &inner, may_block) {
        let seq = Self::insert_locked(shared, &mut inner, write_options, data, may_block);
        Self::send_direct_locked(shared, &mut inner, seq);
        return Admission::Admitted(seq);
      }
      // Window full: wait for an acknowledgement to free up space.
      match deadline {
        None => {
          inner = shared.progress.wait(inner).unwrap();
        }
        Some(deadline) => {
          let now = Instant::now();
          if now >= deadline {
            return Admission::WouldBlock;
          }
          let (guard, _timeout_result) =
            shared.progress.wait_timeout(inner, deadline - now).unwrap();
          inner = guard;
        }
      }
    }
  }

  /// Non-blocking admission for async writers. On success returns the allocated
  /// sequence number. On a full window returns the (write_options, data) back
  /// so the caller can retry later, and registers `waker` to be woken when
  /// room becomes available.
  pub fn try_admit(
    &self,
    write_options: WriteOptions,
    data: DDSData,
    waker: &Waker,
  ) -> Result<SequenceNumber, (WriteOptions, DDSData)> {
    let shared = &*self.shared;
    let mut inner = shared.inner.lock().unwrap();
    let may_block = shared.reliable_writer || write_options.best_effort_may_block();
    if Self::has_room(shared, &inner, may_block) {
      let seq = Self::insert_locked(shared, &mut inner, write_options, data, may_block);
      Self::send_direct_locked(shared, &mut inner, seq);
      Ok(seq)
    } else {
      register_waker(&mut inner.wakers, waker);
      Err((write_options, data))
    }
  }

  fn insert_locked(
    shared: &Shared,
    inner: &mut Inner,
    write_options: WriteOptions,
    data: DDSData,
    may_block: bool,
  ) -> SequenceNumber {
    let seq = inner.last_seq.plus_1();
    let cc = CacheChange::new(shared.writer_guid, seq, write_options, data);
    inner.changes.insert(seq, cc);
    inner.last_seq = seq;

    // KeepLast "newest wins" bound. Applied on insert for:
    //  - non-blocking best-effort writes: never throttled at admission (`has_room`
    //    returns true), and the only other eviction path is the periodic
    //    cache-cleaning timer, which starves under a sustained flood -- so without
    //    this the buffer grows without bound (confirmed multi-GB leak);
    //  - reliable writers with NO matched reliable reader yet: there is nobody to
    //    repair to, so retaining unacknowledged samples is pointless. A reliable
    //    writer that produces flat-out before discovery completes (discovery is
    //    CPU-starved under load and can lag ~1 s) would otherwise race thousands of
    //    samples ahead, and when the reader finally matches it faces a huge
    //    unacknowledged backlog that must be recovered via repair at the slow (100
    //    ms) heartbeat cadence -- collapsing reliable throughput. Trimming to
    //    KeepLast here keeps only the recent samples (correct for volatile
    //    durability); once a reliable reader matches, `reliable_readers_present`
    //    flips true and we retain everything again for repair.
    // Built-in (discovery) writers are always exempt to never lose discovery data.
    // thickness_collision patch (change 10): and a reliable KEEP_LAST writer always, since it
    // does not wait for acknowledgements (`has_room`). The repair path answers a request for a
    // trimmed sequence number with a GAP (below `first_seq`), and heartbeats announce
    // `first_seq`, so the reader that missed them moves on.
    let trim_keep_last = !shared.is_builtin
      && (!may_block
        || (shared.reliable_writer && shared.volatile && !inner.reliable_readers_present)
        || (shared.reliable_writer && shared.keep_last));
    if trim_keep_last {
      while inner.changes.len() > inner.max_retain {
        // BTreeMap keeps keys sorted, so the first entry is the oldest SN.
        let oldest = match inner.changes.keys().next().copied() {
          Some(sn) => sn,
          None => break,
        };
        inner.changes.remove(&oldest);
        inner.first_seq = oldest.plus_1();
      }
    }
    seq
  }

  // thickness_collision patch (change 12): send the sample just admitted from this (the
  // producer's) thread when the Writer has nothing older left to send. Before this every sample
  // went producer thread -> doorbell -> event-loop thread -> socket: one thread wake-up on the
  // path of every sample, tens of microseconds at the tail when the scheduler is busy. The
  // datagram is what the Writer's push would send to all readers (INFO_TS, DATA, and a HEARTBEAT
  // for a reliable writer). If any destination does not take it, nothing is recorded and the
  // Writer sends it the usual way (a reader that got it twice drops the duplicate). The caller
  // still rings the doorbell: the Writer does the readers' bookkeeping for a directly sent
  // sample, and keeps sample order, since it passes it only in sequence.
  fn send_direct_locked(shared: &Shared, inner: &mut Inner, seq: SequenceNumber) {
    let Some(route) = inner.direct.as_ref() else {
      return;
    };
    // (No route is ever set for a built-in writer: `Writer::direct_route`.)
    if inner.sent_frontier.plus_1() != seq {
      return;
    }
    let Some(cc) = inner.changes.get(&seq) else {
      return;
    };
    if cc.write_options.to_single_reader().is_some()
      || cc.data_value.payload_size() > route.max_payload
    {
      return;
    }
    let mut builder = MessageBuilder::new();
    if let Some(ts) = cc.write_options.source_timestamp() {
      builder = builder.ts_msg(route.endianness, Some(ts));
    }
    builder = builder.data_msg(
      cc,
      EntityId::UNKNOWN,
      shared.writer_guid,
      route.endianness,
      None,
    );
    if let Some(counter) = &route.heartbeat_counter {
      builder = builder.heartbeat_msg(
        shared.writer_guid.entity_id,
        inner.first_seq,
        inner.last_seq,
        counter.fetch_add(1, Ordering::SeqCst),
        route.endianness,
        EntityId::UNKNOWN,
        false, // final_flag: readers acknowledge, as after the Writer's own push
        false, // liveliness_flag
      );
    }
    let buffer = match builder
      .add_header_and_build(shared.writer_guid.prefix)
      .write_to_vec_fast(route.endianness)
    {
      Ok(buffer) => buffer,
      Err(e) => {
        debug!("direct send: serializing failed ({e:?}); the Writer sends it");
        return;
      }
    };
    for destination in &route.destinations {
      if let Err(e) = route.socket.send_to(&buffer, destination) {
        trace!("direct send to {destination} failed ({e}); the Writer sends it");
        return;
      }
    }
    inner.sent_frontier = seq;
    inner.direct_through = seq;
  }

  /// thickness_collision patch (change 12): set or clear the route for direct sends (Writer).
  pub fn set_direct_route(&self, route: Option<DirectRoute>) {
    self.shared.inner.lock().unwrap().direct = route;
  }

  /// thickness_collision patch (change 12): the highest sequence number sent directly.
  pub fn direct_through(&self) -> SequenceNumber {
    self.shared.inner.lock().unwrap().direct_through
  }

  // --- consumer side (Writer / event loop) ---

  /// Update the reliable acknowledgement frontier. `acked_before` is the
  /// minimum `all_acked_before` over all matched reliable readers, and
  /// `present` tells whether any reliable reader is currently matched. Wakes
  /// blocked producers / ack-waiters when the frontier advances or a reader
  /// goes away.
  ///
  /// A reader that has not sent an ACKNACK yet reports `all_acked_before == 0`.
  /// Sequence numbers start at 1, so the frontier is never below 1: anything
  /// lower would count a sample that does not exist against the send window.
  pub fn set_acked_frontier(&self, acked_before: Option<SequenceNumber>) {
    let shared = &*self.shared;
    let mut inner = shared.inner.lock().unwrap();
    let advanced = match acked_before {
      Some(sn) => {
        let sn = max(sn, SequenceNumber::new(1));
        let adv = sn > inner.acked_before || !inner.reliable_readers_present;
        inner.acked_before = sn;
        inner.reliable_readers_present = true;
        adv
      }
      None => {
        // No reliable readers (any more). Everything counts as acknowledged.
        let adv = inner.reliable_readers_present;
        inner.reliable_readers_present = false;
        adv
      }
    };
    if advanced {
      Self::wake_all(&mut inner, &shared.progress);
    }
  }

  /// nonblocking-transmit: advance the "actually transmitted" frontier. Called
  /// by the Writer as it puts samples on the wire. Wakes producers parked on a
  /// full unsent backlog when the frontier advances.
  pub fn set_sent_frontier(&self, sent_frontier: SequenceNumber) {
    let shared = &*self.shared;
    let mut inner = shared.inner.lock().unwrap();
    if sent_frontier > inner.sent_frontier {
      inner.sent_frontier = sent_frontier;
      Self::wake_all(&mut inner, &shared.progress);
    }
  }

  /// The sequence number of the latest allocated sample (0 if none yet).
  pub fn last_change_sequence_number(&self) -> SequenceNumber {
    self.shared.inner.lock().unwrap().last_seq
  }

  /// Number of samples currently retained in the buffer. Test-only.
  #[cfg(test)]
  pub fn retained_len(&self) -> usize {
    self.shared.inner.lock().unwrap().changes.len()
  }

  /// The lowest sequence number still retained (or the next-to-be-written if
  /// the buffer is empty).
  pub fn first_change_sequence_number(&self) -> SequenceNumber {
    self.shared.inner.lock().unwrap().first_seq
  }

  /// Fetch a clone of the sample with the given sequence number, if retained.
  /// Returns an owned `CacheChange` (a cheap `Bytes`-backed clone) so the
  /// caller can serialize and transmit without holding the lock.
  pub fn get_by_sn(&self, sn: SequenceNumber) -> Option<CacheChange> {
    self.shared.inner.lock().unwrap().changes.get(&sn).cloned()
  }

  /// Evict all samples with sequence number strictly less than `remove_before`.
  pub fn remove_changes_before(&self, remove_before: SequenceNumber) {
    let shared = &*self.shared;
    let mut inner = shared.inner.lock().unwrap();
    let count_before = inner.changes.len();
    inner.changes = inner.changes.split_off(&remove_before);
    if remove_before > inner.first_seq {
      inner.first_seq = remove_before;
    }
    let count_after = inner.changes.len();
    if count_before != count_after {
      debug!(
        "WriterSendBuffer: removed {} change(s) before {:?} topic={}",
        count_before - count_after,
        remove_before,
        shared.topic_name
      );
    }
  }

  // --- wait_for_acknowledgments support ---

  /// Has every matched reliable reader acknowledged everything up to and
  /// including `target`? Also true when there are no reliable readers.
  pub fn is_acked_through(&self, target: SequenceNumber) -> bool {
    let inner = self.shared.inner.lock().unwrap();
    !inner.reliable_readers_present || inner.acked_before > target
  }

  /// Synchronously wait until everything up to `target` is acknowledged, or
  /// `max_wait` elapses. Returns `true` if acknowledged.
  pub fn wait_for_acked_through(&self, target: SequenceNumber, max_wait: StdDuration) -> bool {
    let shared = &*self.shared;
    let mut inner = shared.inner.lock().unwrap();
    let deadline = Instant::now() + max_wait;
    loop {
      if !inner.reliable_readers_present || inner.acked_before > target {
        return true;
      }
      let now = Instant::now();
      if now >= deadline {
        return false;
      }
      let (guard, _to) = shared.progress.wait_timeout(inner, deadline - now).unwrap();
      inner = guard;
    }
  }

  /// Register `waker` to be notified when the acknowledgement frontier advances
  /// (used by the async `wait_for_acknowledgments` future).
  pub fn register_ack_waker(&self, waker: &Waker) {
    let mut inner = self.shared.inner.lock().unwrap();
    register_waker(&mut inner.wakers, waker);
  }
}

// Avoid storing duplicate wakers for the same task.
fn register_waker(wakers: &mut Vec<Waker>, waker: &Waker) {
  if !wakers.iter().any(|w| w.will_wake(waker)) {
    wakers.push(waker.clone());
  }
}

#[cfg(test)]
mod tests {
  use std::time::Duration as StdDuration;

  use super::*;
  use crate::{
    dds::{ddsdata::DDSData, with_key::datawriter::WriteOptionsBuilder},
    messages::submessages::elements::serialized_payload::SerializedPayload,
    structure::guid::GUID,
    RepresentationIdentifier,
  };

  fn sample() -> DDSData {
    DDSData::new(SerializedPayload::new(
      RepresentationIdentifier::CDR_LE,
      vec![0u8; 8],
    ))
  }

  fn admit_now(buf: &WriterSendBuffer, opts: WriteOptions) -> bool {
    matches!(
      buf.admit_blocking(opts, sample(), Some(StdDuration::ZERO)),
      Admission::Admitted(_)
    )
  }

  fn may_block_opts() -> WriteOptions {
    WriteOptionsBuilder::new()
      .best_effort_may_block(true)
      .build()
  }

  // thickness_collision patch (change 12): a sample goes out from the admitting thread only
  // with a route, only when every older sample is on the wire, and only unfragmented; a
  // datagram the Writer would have sent (RTPS header, the DATA with the payload, a HEARTBEAT).
  #[test]
  fn a_sample_is_sent_directly_only_when_nothing_older_is_unsent() {
    let receiver = UdpSocket::bind("127.0.0.1:0").unwrap();
    receiver.set_nonblocking(true).unwrap();
    let sender = UdpSocket::bind("127.0.0.1:0").unwrap();
    sender.set_nonblocking(true).unwrap();
    let route = |max_payload| DirectRoute {
      socket: Arc::new(sender.try_clone().unwrap()),
      destinations: vec![receiver.local_addr().unwrap()],
      endianness: Endianness::LittleEndian,
      max_payload,
      heartbeat_counter: Some(Arc::new(AtomicI32::new(1))),
    };
    let payload = |len| {
      DDSData::new(SerializedPayload::new(
        RepresentationIdentifier::CDR_LE,
        vec![0xAB; len],
      ))
    };
    let admit = |buf: &WriterSendBuffer, len| {
      matches!(
        buf.admit_blocking(
          WriteOptions::default(),
          payload(len),
          Some(StdDuration::ZERO)
        ),
        Admission::Admitted(_)
      )
    };
    let received = || {
      let mut datagram = [0u8; 2048];
      // Loopback delivers before send_to returns; a short wait covers a slow scheduler.
      for _ in 0..200 {
        match receiver.recv(&mut datagram) {
          Ok(n) => return Some(datagram[..n].to_vec()),
          Err(_) => std::thread::sleep(StdDuration::from_millis(1)),
        }
      }
      None
    };
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ true,
      /* is_builtin */ false,
      /* volatile */ true,
      /* keep_last */ true,
      /* window_limit */ 100,
      /* backlog_limit */ 100,
      /* max_retain */ 100,
    );

    // No route: the Writer sends it.
    assert!(admit(&buf, 8)); // 1
    assert_eq!(buf.direct_through(), SequenceNumber::new(0));
    assert!(received().is_none());

    // A route, but sample 1 is not on the wire yet: 2 waits for the Writer too.
    buf.set_direct_route(Some(route(1000)));
    assert!(admit(&buf, 8)); // 2
    assert_eq!(buf.direct_through(), SequenceNumber::new(0));
    assert!(received().is_none());

    // The Writer sent 1 and 2: 3 goes out directly, and 4 after it.
    buf.set_sent_frontier(SequenceNumber::new(2));
    for sn in [3, 4] {
      assert!(admit(&buf, 8));
      assert_eq!(buf.direct_through(), SequenceNumber::new(sn));
      let datagram = received().expect("a datagram from the admitting thread");
      assert_eq!(&datagram[..4], b"RTPS");
      assert!(
        datagram.windows(8).any(|w| w == [0xAB; 8]),
        "the payload is in it"
      );
      assert!(
        datagram.len() > 4 + 16 + 24 + 8 + 28,
        "header, DATA and HEARTBEAT"
      );
    }

    // Too large for one datagram: left to the Writer, which fragments it; nothing after it
    // goes out directly until the Writer has sent it.
    assert!(admit(&buf, 2000)); // 5
    assert!(admit(&buf, 8)); // 6
    assert_eq!(buf.direct_through(), SequenceNumber::new(4));
    assert!(received().is_none());

    // A destination that refuses the datagram (an IPv6 address on an IPv4 socket): nothing
    // recorded, the Writer sends it.
    buf.set_sent_frontier(SequenceNumber::new(6));
    let mut refusing = route(1000);
    refusing.destinations = vec!["[::1]:7400".parse().unwrap()];
    buf.set_direct_route(Some(refusing));
    assert!(admit(&buf, 8)); // 7
    assert_eq!(buf.direct_through(), SequenceNumber::new(4));
  }

  // A matched reliable reader that has not sent an ACKNACK yet reports
  // `all_acked_before == 0`. Sequence numbers start at 1, so that frontier
  // leaves nothing unacknowledged on a fresh writer: the window must still
  // admit `window_limit` samples.
  #[test]
  fn unacknowledged_reader_frontier_leaves_full_window() {
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ true,
      /* is_builtin */ false,
      /* volatile */ true,
      /* keep_last */ false,
      /* window_limit */ 1,
      /* backlog_limit */ 1000,
      /* max_retain */ 1,
    );
    buf.set_acked_frontier(Some(SequenceNumber::zero()));

    assert!(admit_now(&buf, WriteOptions::default())); // seq 1
    assert!(!admit_now(&buf, WriteOptions::default())); // window full

    // The reader's first ACKNACK acknowledges seq 1.
    buf.set_acked_frontier(Some(SequenceNumber::new(2)));
    assert!(admit_now(&buf, WriteOptions::default())); // seq 2
  }

  // nonblocking-transmit: a best-effort writer that opted in via
  // `best_effort_may_block` is throttled by the unsent-backlog limit once the
  // socket stops draining, and released when the Writer advances the sent
  // frontier.
  #[test]
  fn backlog_limit_backpressures_best_effort_when_may_block() {
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ false,
      /* is_builtin */ false,
      /* volatile */ true,
      /* keep_last */ false,
      /* window_limit */ 1000,
      /* backlog_limit */ 2,
      /* max_retain */ 1000,
    );

    // Nothing sent yet: backlog fills after two admissions.
    assert!(admit_now(&buf, may_block_opts())); // seq 1
    assert!(admit_now(&buf, may_block_opts())); // seq 2
    assert!(!admit_now(&buf, may_block_opts())); // backlog full (2 unsent, limit 2)

    // The Writer transmits seq 1; backlog drops to 1, room opens for one more.
    buf.set_sent_frontier(SequenceNumber::new(1));
    assert!(admit_now(&buf, may_block_opts())); // seq 3
    assert!(!admit_now(&buf, may_block_opts())); // full again (2 unsent: seq
                                                 // 2,3)
  }

  // By default (`best_effort_may_block == false`, DDS v1.4 2.2.2.4.2.11) a
  // best-effort write is never throttled at admission, even when the backlog is
  // already full -- congested samples are dropped later at the socket instead.
  #[test]
  fn backlog_limit_ignored_for_best_effort_by_default() {
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ false,
      /* is_builtin */ false,
      /* volatile */ true,
      /* keep_last */ false,
      /* window_limit */ 1000,
      /* backlog_limit */ 1,
      /* max_retain */ 1000,
    );
    // Default WriteOptions => best_effort_may_block == false => never blocks.
    assert!(admit_now(&buf, WriteOptions::default()));
    assert!(admit_now(&buf, WriteOptions::default()));
    assert!(admit_now(&buf, WriteOptions::default())); // still admitted despite
                                                       // full backlog
  }

  // Built-in (discovery) writers must never be throttled by the backlog.
  #[test]
  fn backlog_limit_exempts_builtin() {
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      false,
      /* is_builtin */ true,
      /* volatile */ true,
      /* keep_last */ false,
      1000,
      /* backlog_limit */ 1,
      /* max_retain */ 1000,
    );
    assert!(admit_now(&buf, may_block_opts()));
    assert!(admit_now(&buf, may_block_opts()));
    assert!(admit_now(&buf, may_block_opts())); // still admitted despite tiny
                                                // backlog limit
  }

  // A best-effort (non-blocking, DDS-default) writer is never throttled at
  // admission, but the retained buffer must stay bounded by `max_retain`
  // (KeepLast "newest wins"): the leak fix. Every write is admitted, yet the
  // buffer never holds more than `max_retain` samples, and it retains the
  // newest ones (oldest are evicted on insert).
  #[test]
  fn best_effort_default_bounded_by_max_retain() {
    let max_retain = 4;
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ false,
      /* is_builtin */ false,
      /* volatile */ true,
      /* keep_last */ false,
      /* window_limit */ 1000,
      /* backlog_limit */ 1000,
      max_retain,
    );

    for _ in 0..100 {
      // Default WriteOptions => best-effort, non-blocking => always admitted.
      assert!(admit_now(&buf, WriteOptions::default()));
      // Invariant after every insert: never exceeds the retain bound.
      assert!(buf.retained_len() <= max_retain);
    }

    // Exactly `max_retain` retained, and they are the newest sequence numbers.
    assert_eq!(buf.retained_len(), max_retain);
    let last = buf.last_change_sequence_number();
    assert_eq!(last, SequenceNumber::new(100));
    let first = buf.first_change_sequence_number();
    assert_eq!(first, SequenceNumber::new(100 - max_retain as i64 + 1));
    // Newest is retained, an evicted older one is gone.
    assert!(buf.get_by_sn(last).is_some());
    assert!(buf.get_by_sn(SequenceNumber::new(1)).is_none());
  }

  // thickness_collision patch (change 10): a reliable KEEP_LAST writer whose
  // matched reader acknowledges nothing is never held at the window: it keeps
  // admitting, retains its newest `depth` samples and drops older ones, also
  // when durable (a late joiner gets the newest `depth`, as KEEP_LAST says).
  #[test]
  fn keep_last_reliable_writer_never_waits_for_a_silent_reader() {
    for volatile in [true, false] {
      let depth = 4;
      let buf = WriterSendBuffer::new(
        GUID::GUID_UNKNOWN,
        "t".to_string(),
        /* reliable_writer */ true,
        /* is_builtin */ false,
        volatile,
        /* keep_last */ true,
        /* window_limit */ 8,
        /* backlog_limit */ 1000,
        /* max_retain */ depth,
      );
      // Matched, and never acknowledges anything.
      buf.set_acked_frontier(Some(SequenceNumber::new(1)));
      for _ in 0..100 {
        assert!(admit_now(&buf, WriteOptions::default()));
        assert!(buf.retained_len() <= depth);
      }
      assert_eq!(buf.last_change_sequence_number(), SequenceNumber::new(100));
      assert_eq!(buf.first_change_sequence_number(), SequenceNumber::new(97));
      assert!(buf.get_by_sn(SequenceNumber::new(96)).is_none());
    }
  }

  // A durable (non-VOLATILE) reliable writer must NOT drop on insert even before
  // a reader matches: it retains samples for late-joining readers. The
  // `max_retain` bound does not apply to it.
  #[test]
  fn durable_reliable_writer_not_trimmed_before_match() {
    let max_retain = 2;
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ true,
      /* is_builtin */ false,
      /* volatile */ false, // TRANSIENT_LOCAL etc: keep for late joiners
      /* keep_last */ false,
      /* window_limit */ 1000,
      /* backlog_limit */ 1000,
      max_retain,
    );
    // No reliable readers matched yet => admission not window-throttled.
    for _ in 0..10 {
      assert!(admit_now(&buf, WriteOptions::default()));
    }
    // Durable path keeps everything for potential late-joiner delivery / repair
    // despite tiny max_retain.
    assert_eq!(buf.retained_len(), 10);
  }

  // A VOLATILE reliable writer with no matched reliable reader trims KeepLast on
  // insert: there is no late joiner to serve, so retaining unacknowledged samples
  // is pointless and would create a huge post-match repair backlog (the reliable
  // flat-out throughput fix). Once a reliable reader matches
  // (`set_acked_frontier(Some(..))`), trimming stops and everything is retained
  // for repair.
  #[test]
  fn volatile_reliable_writer_trimmed_until_reader_matches() {
    let max_retain = 4;
    let buf = WriterSendBuffer::new(
      GUID::GUID_UNKNOWN,
      "t".to_string(),
      /* reliable_writer */ true,
      /* is_builtin */ false,
      /* volatile */ true,
      /* keep_last */ false,
      /* window_limit */ 1000,
      /* backlog_limit */ 1000,
      max_retain,
    );
    // No reliable reader yet: admitted freely (backlog has room) but trimmed to
    // KeepLast so the buffer cannot balloon before discovery completes.
    for _ in 0..100 {
      assert!(admit_now(&buf, WriteOptions::default()));
      assert!(buf.retained_len() <= max_retain);
    }
    assert_eq!(buf.retained_len(), max_retain);

    // A reliable reader matches: from now on the writer retains everything for
    // repair (no trimming), even past max_retain.
    buf.set_acked_frontier(Some(SequenceNumber::new(101)));
    for _ in 0..10 {
      assert!(admit_now(&buf, WriteOptions::default()));
    }
    assert_eq!(buf.retained_len(), max_retain + 10);
  }
}
