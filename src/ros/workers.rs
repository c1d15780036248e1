//! The threads that answer service requests off the node's loop, so a long check never stalls the
//! live stream. The pipeline resolves a request on the loop (validation and the current joint
//! state: no geometry) into a job; a [`Worker`] checks jobs one at a time in arrival order and
//! hands the answers back to the loop, which sends them.
//!
//! One rule for every kind of job: a job the pipeline refused is answered on the loop (it runs
//! without a check), and one past the kind's [`OffLoopJob::MAX_PENDING`] is answered at once
//! ("busy"), so a flood of requests cannot queue without bound. A new kind is an [`OffLoopJob`]
//! impl and a field in [`Workers`].

use super::interfaces::{Event, Events};
use crate::msgs::moveit::GetStateValidityResponse;
use crate::msgs::CheckTrajectoryResponse;
use crate::pipeline::{TrajectoryJob, ValidityJob};
use anyhow::{Context as _, Result};
use futures::StreamExt;
use ros2_client::service::RmwRequestId;
use std::sync::mpsc::{SyncSender, TrySendError};

/// `check_trajectory` requests waiting for or in the worker at most.
pub(super) const MAX_TRAJECTORIES_PENDING: usize = 8;

/// `check_state_validity` requests waiting for or in the worker at most. A discrete check takes
/// milliseconds: a planner's burst of checks fits.
pub(super) const MAX_VALIDITY_PENDING: usize = 64;

/// Why a worker did not take a job.
pub(super) enum NotTaken {
    /// [`OffLoopJob::MAX_PENDING`] jobs are waiting or in the worker.
    Busy,
    /// The worker's thread has ended.
    Stopped,
}

/// A request checked off the loop, and how its service answers when it is not.
pub(super) trait OffLoopJob: Send + 'static {
    /// The answer the loop sends.
    type Answer: Send + 'static;
    /// The service's name (and its thread's).
    const SERVICE: &'static str;
    /// Jobs waiting for or in the worker at most.
    const MAX_PENDING: usize;
    /// Whether the pipeline refused the request ([`OffLoopJob::run`] is then immediate).
    fn refused(&self) -> bool;
    /// The check.
    fn run(&self) -> Self::Answer;
    /// The answer when the check panicked (`error` says how, on one line).
    fn failed(error: String) -> Self::Answer;
    /// The answer when the worker did not take the job.
    fn not_taken(why: NotTaken) -> Self::Answer;
    /// The answer as the loop's event.
    fn done(id: RmwRequestId, answer: Self::Answer) -> Event;
}

/// One worker thread: jobs in, answers out.
pub(super) struct Worker<J: OffLoopJob> {
    jobs: SyncSender<(RmwRequestId, J)>,
    done: smol::channel::Receiver<(RmwRequestId, J::Answer)>,
}

impl<J: OffLoopJob> Worker<J> {
    /// Starts the thread; it ends when the loop drops the worker (a job in progress runs out).
    fn start() -> Result<Worker<J>> {
        let (jobs, queue) = std::sync::mpsc::sync_channel::<(RmwRequestId, J)>(J::MAX_PENDING);
        let (finished, done) = smol::channel::unbounded();
        let _ = std::thread::Builder::new()
            .name(J::SERVICE.into())
            .spawn(move || {
                while let Ok((id, job)) = queue.recv() {
                    // A panic in the check must not leave the caller without an answer.
                    let answer =
                        crate::limits::contain_panic(|| job.run()).unwrap_or_else(|e| J::failed(format!("the check failed: {}", e.replace('\n', " "))));
                    if finished.send_blocking((id, answer)).is_err() {
                        break;
                    }
                }
            })
            .with_context(|| format!("cannot start the {} worker thread", J::SERVICE))?;
        Ok(Worker { jobs, done })
    }

    /// Hands the job to the thread; `Some` is the answer to send now (refused, busy, or the
    /// thread gone).
    pub(super) fn take(&self, id: RmwRequestId, job: J) -> Option<J::Answer> {
        if job.refused() {
            return Some(job.run());
        }
        match self.jobs.try_send((id, job)) {
            Ok(()) => None,
            Err(TrySendError::Full(_)) => Some(J::not_taken(NotTaken::Busy)),
            Err(TrySendError::Disconnected(_)) => Some(J::not_taken(NotTaken::Stopped)),
        }
    }

    fn answers(&self) -> Events<'static> {
        Box::pin(self.done.clone().map(|(id, answer)| J::done(id, answer)))
    }
}

/// A failed or refused trajectory answer: no segment, no fraction, the reason in `error`.
fn trajectory_error(error: String) -> CheckTrajectoryResponse {
    CheckTrajectoryResponse { segment: -1, fraction: -1.0, error, ..Default::default() }
}

impl OffLoopJob for TrajectoryJob {
    type Answer = CheckTrajectoryResponse;
    const SERVICE: &'static str = "check_trajectory";
    const MAX_PENDING: usize = MAX_TRAJECTORIES_PENDING;

    fn refused(&self) -> bool {
        TrajectoryJob::refused(self).is_some()
    }
    fn run(&self) -> CheckTrajectoryResponse {
        TrajectoryJob::run(self)
    }
    fn failed(error: String) -> CheckTrajectoryResponse {
        trajectory_error(error)
    }
    fn not_taken(why: NotTaken) -> CheckTrajectoryResponse {
        trajectory_error(match why {
            NotTaken::Busy => format!("busy: {MAX_TRAJECTORIES_PENDING} check_trajectory requests are waiting; try again later"),
            NotTaken::Stopped => "the check_trajectory worker has stopped".into(),
        })
    }
    fn done(id: RmwRequestId, answer: CheckTrajectoryResponse) -> Event {
        Event::TrajectoryDone(id, answer)
    }
}

/// The response has no text field: `valid` false, and the reason for the log (`send_validity_answer`).
impl OffLoopJob for ValidityJob {
    type Answer = (GetStateValidityResponse, Option<String>);
    const SERVICE: &'static str = "check_state_validity";
    const MAX_PENDING: usize = MAX_VALIDITY_PENDING;

    fn refused(&self) -> bool {
        ValidityJob::refused(self).is_some()
    }
    fn run(&self) -> Self::Answer {
        ValidityJob::run(self)
    }
    fn failed(error: String) -> Self::Answer {
        (GetStateValidityResponse::default(), Some(error))
    }
    fn not_taken(why: NotTaken) -> Self::Answer {
        let reason = match why {
            NotTaken::Busy => format!("busy: {MAX_VALIDITY_PENDING} check_state_validity requests are waiting"),
            NotTaken::Stopped => "the check_state_validity worker has stopped".to_owned(),
        };
        (GetStateValidityResponse::default(), Some(reason))
    }
    fn done(id: RmwRequestId, (answer, reason): Self::Answer) -> Event {
        Event::ValidityDone(id, answer, reason)
    }
}

/// Every worker of the node.
pub(super) struct Workers {
    pub(super) trajectory: Worker<TrajectoryJob>,
    pub(super) validity: Worker<ValidityJob>,
}

impl Workers {
    /// Starts every worker's thread.
    pub(super) fn start() -> Result<Workers> {
        Ok(Workers { trajectory: Worker::start()?, validity: Worker::start()? })
    }

    /// Every worker's answers, one stream each.
    pub(super) fn events(&self) -> Vec<Events<'static>> {
        vec![self.trajectory.answers(), self.validity.answers()]
    }
}
