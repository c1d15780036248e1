//! The entries of the node's request services: `check_trajectory` and `check_state_validity`,
//! with the invariants every answer must keep.

use crate::fixtures::{fresh_pipeline_with_one_joint, workcell};
use thickness_collision::fuzz_access::{GetStateValidityRequest, GetStateValidityResponse, PipelineAccess};
use thickness_collision::msgs::CheckTrajectoryRequest;
use thickness_collision::replay::decode_cdr;

/// Points of a fuzzed trajectory checked against the workcell (all of them are validated, and
/// checked against an empty environment).
const TRAJECTORY_POINTS_ON_WORKCELL: usize = 4;

/// Joint travel (radians or metres, summed over the joints) of the longest segment up to which a
/// trajectory is walked: a segment of made-up positions (7e44 rad, as the fuzzer makes them) needs
/// the motion check's full 2^20 sub-intervals, 5 s even against an empty environment, which would
/// leave the fuzzer a handful of runs. Longer ones are only validated.
const TRAJECTORY_TRAVEL_WALKED: f64 = 20.0;

/// A `check_trajectory` request: a CDR payload (with its 4-byte encapsulation header) decoded as
/// the node decodes it, resolved against a fresh pipeline that has merged one partial joint state
/// (so joints left out come from the current state, others from `missing_joint`); when no segment
/// travels more than [`TRAJECTORY_TRAVEL_WALKED`], walked in full against an empty environment and
/// its first [`TRAJECTORY_POINTS_ON_WORKCELL`] points against the workcell.
pub fn check_trajectory(data: &[u8]) {
    let Ok(request) = decode_cdr::<CheckTrajectoryRequest>(data) else { return };
    let pipeline = fresh_pipeline_with_one_joint();
    let job = pipeline.trajectory_job(&request);
    let travel = request.trajectory.points.windows(2).map(|w| w[0].positions.iter().zip(&w[1].positions).map(|(a, b)| (b - a).abs()).sum::<f64>());
    let short = travel.fold(0.0, f64::max) <= TRAJECTORY_TRAVEL_WALKED;
    if !short && job.refused().is_none() {
        return;
    }
    // A refused request is answered without a check, whatever its travel.
    let answer = job.run();
    // A refused request is never valid, and says why.
    assert!(answer.valid || !answer.error.is_empty() || answer.segment >= 0 || answer.segment == -2, "an invalid answer without a cause: {answer:?}");
    assert!(!answer.valid || (answer.segment == -1 && answer.error.is_empty()), "a valid answer with a segment or an error: {answer:?}");
    if short {
        let mut head = request;
        head.trajectory.points.truncate(TRAJECTORY_POINTS_ON_WORKCELL);
        let _ = workcell().check_trajectory(&head);
    }
}

/// What every `check_state_validity` answer must be: refused (a reason) means not valid and no
/// contacts; otherwise valid exactly when there are no contacts; never cost sources or
/// constraint results.
pub fn assert_validity_answer(answer: &GetStateValidityResponse, reason: Option<&str>) {
    assert!(answer.cost_sources.is_empty() && answer.constraint_result.is_empty(), "cost sources or constraint results: {answer:?}");
    match reason {
        Some(r) => assert!(!answer.valid && answer.contacts.is_empty() && !r.is_empty() && !r.contains('\n'), "refused ({r}) but {answer:?}"),
        None => assert_eq!(answer.valid, answer.contacts.is_empty(), "valid with contacts, or not valid without: {answer:?}"),
    }
}

/// A `check_state_validity` request (`moveit_msgs/srv/GetStateValidity`): a CDR payload (with its
/// 4-byte encapsulation header) decoded as the node decodes it, resolved against a fresh pipeline
/// that has merged one partial joint state (joints left out from the merged state or
/// `missing_joint`) and checked against an empty environment, then against the workcell; the
/// answers' invariants asserted.
pub fn check_state_validity(data: &[u8]) {
    let Ok(request) = decode_cdr::<GetStateValidityRequest>(data) else { return };
    let pipeline = fresh_pipeline_with_one_joint();
    let (answer, reason) = pipeline.check_validity(&request);
    assert_validity_answer(&answer, reason.as_deref());
    let (answer, reason) = workcell().check_validity(&request);
    assert_validity_answer(&answer, reason.as_deref());
}
