//! One thread that prepares the motion checks of each robot the node puts in force
//! ([`Checker::prepare_motion_checks`]): the robot it starts with, and one that comes later as a
//! `robot_description` or with new parameters, which would otherwise build its grown links
//! rung by rung inside its first motion requests (for the Panda 0.35 s in all). A MoveIt user's
//! robot usually comes that way.
//!
//! The thread holds a checker only while it builds: a robot replaced before its turn is skipped
//! and freed, and of several queued only the newest is built.

use crate::checker::Checker;
use std::sync::{mpsc, Arc, Weak};

pub(super) struct MotionLadder {
    queue: mpsc::Sender<Weak<Checker>>,
}

impl MotionLadder {
    pub(super) fn start() -> std::io::Result<MotionLadder> {
        let (queue, robots) = mpsc::channel::<Weak<Checker>>();
        // Normal priority, as the requests that need a rung first wait for it.
        let _detached = std::thread::Builder::new().name("motion ladder".into()).spawn(move || {
            while let Ok(mut robot) = robots.recv() {
                while let Ok(newer) = robots.try_recv() {
                    robot = newer;
                }
                if let Some(checker) = robot.upgrade() {
                    checker.prepare_motion_checks();
                }
            }
        })?;
        Ok(MotionLadder { queue })
    }

    /// `checker`'s ladder built on the thread, unless a newer one comes first or it is dropped.
    pub(super) fn prepare(&self, checker: &Arc<Checker>) {
        // The thread ends only when this sender is dropped.
        let _ = self.queue.send(Arc::downgrade(checker));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Params;
    use std::time::{Duration, Instant};

    fn bundled_arm() -> Arc<Checker> {
        Arc::new(Checker::from_params(Params::default()).expect("the bundled workcell builds"))
    }

    fn within_a_minute(what: &str, done: impl Fn() -> bool) {
        let start = Instant::now();
        while !done() {
            assert!(start.elapsed() < Duration::from_secs(60), "{what}: not within a minute");
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// A robot put in force gets its ladder; one dropped is not kept alive by the thread.
    #[test]
    fn the_thread_prepares_the_robot_in_force_and_keeps_none() {
        let ladder = MotionLadder::start().unwrap();
        let first = bundled_arm();
        assert!(!first.motion_checks_prepared());
        ladder.prepare(&first);
        within_a_minute("the first robot's ladder", || first.motion_checks_prepared());
        // A robot replaced at once: freed once the node lets it go, prepared or not.
        let (second, third) = (bundled_arm(), bundled_arm());
        let gone = Arc::downgrade(&second);
        ladder.prepare(&second);
        ladder.prepare(&third);
        drop(second);
        within_a_minute("the replaced robot freed", || gone.upgrade().is_none());
        within_a_minute("the newest robot's ladder", || third.motion_checks_prepared());
    }
}
