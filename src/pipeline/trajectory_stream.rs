//! Trajectories arriving on a topic (replay's `--trajectory-topic`, as a
//! `joint_trajectory_controller` receives them on `~/joint_trajectory`): each resolved against
//! the joint state in force when it arrives (its approach starts there) and checked as executed
//! until the next one arrives, which preempts it from its own start, as the controller replaces
//! its trajectory; the last one runs to its end. One answer per trajectory, the same as
//! `check_trajectory` and `check --trajectory` give for it (with the same start state).

use super::trajectory::{Outcome, TrajectoryJob};
use super::Pipeline;
use crate::msgs::{CheckTrajectoryRequest, JointTrajectory};
use serde_json::json;

/// One trajectory's answer.
#[derive(Clone, Debug)]
pub struct StreamedTrajectory {
    /// Its index among the trajectories received (0 first).
    pub index: usize,
    /// When it was received (the bag's log time, nanoseconds).
    pub log_time: i64,
    /// Seconds after its start when the next trajectory preempted it; `None` when it ran to its
    /// end.
    pub preempted_after: Option<f64>,
    /// The answer, and the report at its first contact.
    pub outcome: Outcome,
}

impl StreamedTrajectory {
    /// One JSON object: `check --trajectory --json`'s keys (see [`outcome_json`]) and `trajectory`
    /// (the index), `log_time` and `preempted_after`.
    pub fn json(&self) -> serde_json::Value {
        let mut v = outcome_json(&self.outcome);
        if let Some(o) = v.as_object_mut() {
            let _ = o.insert("trajectory".into(), json!(self.index));
            let _ = o.insert("log_time".into(), json!(self.log_time));
            let _ = o.insert("preempted_after".into(), json!(self.preempted_after));
        }
        v
    }
}

/// A trajectory's answer as `check --trajectory --json` prints it: `in_collision`, `time` (seconds
/// on the `time_from_start` scale; `null` when free or not found), `segment` (`null` when free or
/// refused; -2 the approach), `fraction`, `contacts` (as `check --json`), `clearances` (the
/// smallest per link over the path, with `clearance_threshold`), `error`.
pub fn outcome_json((response, report): &Outcome) -> serde_json::Value {
    let time = response.time_from_start.sec as f64 + response.time_from_start.nanosec as f64 * 1e-9;
    let contact_found = !response.valid && response.fraction >= 0.0;
    let contacts = report.as_ref().map_or(json!([]), |r| serde_json::to_value(&r.contacts).unwrap_or_default());
    let point = |p: &crate::msgs::Point| [p.x, p.y, p.z];
    let clearances: Vec<serde_json::Value> = response
        .clearances
        .iter()
        .map(|c| {
            json!({"link_name": c.link_name, "object_name": c.object_name, "triangle": c.triangle, "distance": c.distance,
                   "point_on_link": point(&c.point_on_link), "point_on_object": point(&c.point_on_object)})
        })
        .collect();
    json!({
        "clearances": clearances,
        "in_collision": !response.valid,
        "time": contact_found.then_some(time),
        "segment": (!response.valid && response.segment != -1).then_some(response.segment),
        "fraction": contact_found.then_some(response.fraction),
        "contacts": contacts,
        "error": response.error,
    })
}

/// The trajectory being executed: checked once the next one arrives (or the stream ends).
#[derive(Debug, Default)]
pub struct TrajectoryStream {
    pending: Option<(usize, i64, TrajectoryJob)>,
    received: usize,
}

impl TrajectoryStream {
    /// A trajectory received at `log_time`: resolved now against `pipeline`'s current state; the
    /// answer for the one it preempts, if any.
    pub fn receive(&mut self, pipeline: &Pipeline, trajectory: JointTrajectory, log_time: i64) -> Option<StreamedTrajectory> {
        let job = pipeline.trajectory_job(&CheckTrajectoryRequest { trajectory, ..Default::default() });
        let done = self.pending.take().map(|(index, started, older)| {
            let until = log_time.saturating_sub(started);
            StreamedTrajectory { index, log_time: started, preempted_after: Some(until as f64 * 1e-9), outcome: older.run_until(until) }
        });
        self.pending = Some((self.received, log_time, job));
        self.received += 1;
        done
    }

    /// The stream ended: the answer for the last trajectory, run to its end.
    pub fn finish(&mut self) -> Option<StreamedTrajectory> {
        self.pending.take().map(|(index, log_time, job)| StreamedTrajectory { index, log_time, preempted_after: None, outcome: job.run_with_report() })
    }
}
