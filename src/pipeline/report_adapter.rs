//! A checked state to what leaves the pipeline: the `CollisionReport` message (node, replay's
//! output bag) and the JSON object (`check --json`, replay's `--jsonl`). One conversion each, so
//! every door writes the same fields.

use crate::checker::{ReportClearance, ReportContact, StateReport};
use crate::msgs::{ClearanceMsg, CollisionReport, ContactMsg, Header, Point, Time, Vector3};
use serde::Serialize;

/// A report with the stamp of the input it answers.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedState {
    /// The input's stamp (a joint state's header stamp; the latest stamp of a `/tf` message).
    pub stamp: Time,
    /// What the check found, or why it could not be made (`error`).
    pub report: StateReport,
}

#[derive(Serialize)]
struct StampedJson<'a> {
    stamp: i64,
    #[serde(flatten)]
    report: &'a StateReport,
}

impl CheckedState {
    /// The message, in `frame` (the `world_frame` in force).
    pub fn message(&self, frame: &str) -> CollisionReport {
        report_message(&self.report, self.stamp, frame)
    }

    /// One JSON object on one line: `{"stamp": ns, "in_collision": ..., "contacts": [...],
    /// "out_of_limits": [...] (when not empty), "error": "..."}`.
    pub fn json(&self) -> String {
        // Strings, numbers and vectors only: serialising to a String cannot fail.
        serde_json::to_string(&StampedJson { stamp: self.stamp.as_nanos(), report: &self.report }).unwrap_or_default()
    }
}

/// The `CollisionReport` message of a report.
pub fn report_message(report: &StateReport, stamp: Time, frame: &str) -> CollisionReport {
    let v = |a: [f64; 3]| Vector3 { x: a[0], y: a[1], z: a[2] };
    let contact = |c: &ReportContact| ContactMsg {
        link_name: c.link_name.clone(),
        object_name: c.object_name.clone(),
        triangle: c.triangle,
        depth: c.depth,
        // A message has no "absent": a point that was not computed (flags-only checks, which
        // never reach a message) would be NaN.
        position: v(c.position.unwrap_or([f64::NAN; 3])),
        normal: v(c.normal),
        object_type: c.object_type.code(),
        link_type: c.link_type.code(),
    };
    CollisionReport {
        header: Header { stamp, frame_id: frame.to_owned() },
        in_collision: report.in_collision,
        contacts: report.contacts.iter().map(contact).collect(),
        check_seconds: report.check_seconds,
        error: report.error.clone(),
        motion: report.motion,
        fraction: report.fraction.filter(|_| report.motion && report.in_collision).unwrap_or(-1.0),
        clearances: report.clearances.iter().map(clearance_message).collect(),
    }
}

/// The `Clearance` message of one link's clearance.
pub(crate) fn clearance_message(c: &ReportClearance) -> ClearanceMsg {
    let p = |a: [f64; 3]| Point { x: a[0], y: a[1], z: a[2] };
    ClearanceMsg {
        link_name: c.link_name.clone(),
        object_name: c.object_name.clone(),
        triangle: c.triangle,
        distance: c.distance,
        point_on_link: p(c.point_on_link),
        point_on_object: p(c.point_on_object),
    }
}
