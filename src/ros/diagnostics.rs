//! The node's `/diagnostics` status and the counters behind it.

use crate::msgs::{DiagnosticArray, DiagnosticStatus, Header, KeyValue, Time};
use crate::pipeline::SkipCause;
use std::collections::BTreeMap;

/// Counters the node keeps for `/diagnostics` (skips are counted by the pipeline).
#[derive(Default)]
pub(crate) struct NodeStats {
    /// Input messages received since start (states, `/tf`).
    pub received: u64,
    /// States checked since start.
    pub checked: u64,
    /// Sum of check times since the last status (seconds).
    pub check_sum: f64,
    /// Maximum check time since the last status.
    pub check_max: f64,
    /// Checks since the last status.
    pub window_checks: u64,
    /// Joint states taken and answered on RustDDS's receiving thread (`states_on_receive.rs`);
    /// the rest of `received` went through the node's loop.
    pub taken_on_receive: u64,
    /// Received count at the last status.
    pub last_received: u64,
    /// `check_state_validity` requests answered `valid = false` without a check (refused, busy,
    /// or the check failed) since start.
    pub validity_refused: u64,
}

impl NodeStats {
    /// Counts one check that took `seconds` and covered `states` states (a motion report covers
    /// every state that waited for it).
    pub(crate) fn record_check(&mut self, seconds: f64, states: u64) {
        self.checked += states;
        self.window_checks += 1;
        self.check_sum += seconds;
        self.check_max = self.check_max.max(seconds);
    }
}

/// `DiagnosticStatus` levels.
const OK: u8 = 0;
const WARN: u8 = 1;
const ERROR: u8 = 2;

/// The node's status: input rate, skips by cause and check time over the last `seconds`. Any
/// skip other than a stale one (a bad or foreign message) raises the level to WARN; a refused
/// `robot_description` (`description_error`, until a good one arrives) to ERROR, with its error
/// line as the message: the node is checking a robot other than the one described.
pub(crate) fn diagnostics(
    node: &str,
    stats: &mut NodeStats,
    skipped: &BTreeMap<SkipCause, u64>,
    description_error: Option<&str>,
    seconds: f64,
    stamp: Time,
) -> DiagnosticArray {
    let rate = (stats.received - stats.last_received) as f64 / seconds.max(1e-9);
    let mean = if stats.window_checks > 0 { stats.check_sum / stats.window_checks as f64 } else { 0.0 };
    let total: u64 = skipped.iter().filter(|(c, _)| !c.is_scene()).map(|(_, n)| n).sum();
    let scene_refused: u64 = skipped.iter().filter(|(c, _)| c.is_scene()).map(|(_, n)| n).sum();
    let bad: u64 = skipped.iter().filter(|(c, _)| **c != SkipCause::Stale).map(|(_, n)| n).sum();
    let kv = |k: &str, v: String| KeyValue { key: k.into(), value: v };
    let mut values = vec![
        kv("input_rate_hz", format!("{rate:.3}")),
        kv("states_received", stats.received.to_string()),
        kv("states_checked", stats.checked.to_string()),
        kv("states_skipped", total.to_string()),
        kv("states_taken_on_receive", stats.taken_on_receive.to_string()),
        kv("check_seconds_mean", format!("{mean:.9}")),
        kv("check_seconds_max", format!("{:.9}", stats.check_max)),
    ];
    for cause in SkipCause::ALL {
        values.push(kv(&format!("skipped_{}", cause.key()), skipped.get(&cause).copied().unwrap_or(0).to_string()));
    }
    values.push(kv("scene_refused", scene_refused.to_string()));
    values.push(kv("robot_description_error", description_error.unwrap_or_default().to_owned()));
    values.push(kv("check_state_validity_refused", stats.validity_refused.to_string()));
    let counts = format!("{rate:.1} states/s, {total} skipped, {scene_refused} scene messages refused ({bad} bad or foreign in all)");
    let (level, message) = match description_error {
        Some(e) => (ERROR, e.to_owned()),
        None => (if bad > 0 { WARN } else { OK }, counts),
    };
    let status = DiagnosticStatus { level, name: format!("{node}: collision checks"), message, hardware_id: String::new(), values };
    stats.last_received = stats.received;
    stats.check_sum = 0.0;
    stats.check_max = 0.0;
    stats.window_checks = 0;
    DiagnosticArray { header: Header { stamp, frame_id: String::new() }, status: vec![status] }
}
