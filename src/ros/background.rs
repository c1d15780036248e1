//! One thread of the lowest priority (Linux's `SCHED_IDLE`, else nice 19) for the loop's long
//! work done with the node's state free: a planning scene's cells and its markers. On two cores
//! the joint states answered meanwhile on the receiving thread would otherwise wait for a core
//! behind it (p99 rose by 1-3 ms at 1 kHz under 10 Hz scene changes with the build on the loop's
//! own thread). At nice 10 a waking thread still waited for the build's slice now and then (p99
//! +1.2 ms, `benches/run_scene_latency.sh`); an idle-class thread is preempted whenever another
//! wakes. It still gets a share of a busy core (the kernel weighs it 3 to a nice-0 thread's
//! 1024), so a saturated host delays a scene change but never loses it.

use std::any::Any;
use std::sync::mpsc;

type Job = Box<dyn FnOnce() + Send>;

/// The thread, fed jobs in order.
pub(super) struct Background {
    jobs: mpsc::Sender<Job>,
}

impl Background {
    pub(super) fn start() -> std::io::Result<Background> {
        let (jobs, queue) = mpsc::channel::<Job>();
        let _ = std::thread::Builder::new().name("background".into()).spawn(move || {
            lower_priority();
            for job in queue {
                job();
            }
        })?;
        Ok(Background { jobs })
    }

    /// `f` run there; the loop awaits it (its other inputs wait, as they did for work done in
    /// place). A panic in `f` is resumed here, on the loop, as if `f` had run here.
    pub(super) async fn run<T: Send + 'static>(&self, f: impl FnOnce() -> T + Send + 'static) -> T {
        let (tx, rx) = smol::channel::bounded::<Result<T, Box<dyn Any + Send>>>(1);
        let job: Job = Box::new(move || {
            let _ = tx.try_send(std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
        });
        // The thread ends only when this sender is dropped, so the job is always taken.
        if self.jobs.send(job).is_err() {
            unreachable!("the background thread ended while its sender lives");
        }
        match rx.recv().await {
            Ok(Ok(value)) => value,
            Ok(Err(panic)) => std::panic::resume_unwind(panic),
            Err(_) => unreachable!("the background thread dropped a job without running it"),
        }
    }
}

/// The idle class for the calling thread only (on Linux a thread's policy and nice value are its
/// own); nice 19 where the idle class is refused (a seccomp profile, say).
fn lower_priority() {
    let param = libc::sched_param { sched_priority: 0 };
    // SAFETY: `param` outlives the call; gettid and setpriority take no pointers. A failure
    // leaves the thread as it was.
    unsafe {
        if libc::sched_setscheduler(0, libc::SCHED_IDLE, &param) != 0 {
            let tid = libc::syscall(libc::SYS_gettid) as libc::id_t;
            let _ = libc::setpriority(libc::PRIO_PROCESS, tid, 19);
        }
    }
}
