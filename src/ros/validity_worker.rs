//! The thread that answers `check_state_validity` (`moveit_msgs/srv/GetStateValidity`) off the
//! node's event loop, one request at a time in arrival order. The pipeline decides the answer
//! ([`crate::pipeline::ValidityJob`]); this only carries jobs in and answers out.

use crate::msgs::moveit::GetStateValidityResponse;
use crate::pipeline::ValidityJob;
use anyhow::{Context as _, Result};
use ros2_client::service::RmwRequestId;

/// Requests waiting for or in the worker at most; one past that is answered at once (`valid`
/// false, the reason "busy" in the log), so a flood cannot queue without bound. A discrete check
/// takes milliseconds: a planner's burst of checks fits.
pub const MAX_VALIDITY_PENDING: usize = 64;

/// A finished check: the request, its response, and why it could not be honoured (for the log).
pub type ValidityDone = (RmwRequestId, GetStateValidityResponse, Option<String>);

/// The worker: jobs in, answers out.
pub struct ValidityWorker {
    /// Jobs to check.
    pub jobs: std::sync::mpsc::SyncSender<(RmwRequestId, ValidityJob)>,
    /// Answers ready to send.
    pub done: smol::channel::Receiver<ValidityDone>,
}

impl ValidityWorker {
    /// Starts the thread; it ends when the loop drops the worker (a job in progress runs out).
    pub fn start() -> Result<ValidityWorker> {
        let (jobs, queue) = std::sync::mpsc::sync_channel::<(RmwRequestId, ValidityJob)>(MAX_VALIDITY_PENDING);
        let (finished, done) = smol::channel::unbounded();
        let _ = std::thread::Builder::new()
            .name("check_state_validity".into())
            .spawn(move || {
                while let Ok((id, job)) = queue.recv() {
                    // A panic in the check must not leave the caller without an answer.
                    let (response, reason) = crate::limits::contain_panic(|| job.run())
                        .unwrap_or_else(|e| (GetStateValidityResponse::default(), Some(format!("the check failed: {}", e.replace('\n', " ")))));
                    if finished.send_blocking((id, response, reason)).is_err() {
                        break;
                    }
                }
            })
            .context("cannot start the check_state_validity worker thread")?;
        Ok(ValidityWorker { jobs, done })
    }
}
