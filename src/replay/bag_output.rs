//! Replay's output bag: `/collisions`, and what a viewer needs to draw the recording beside it
//! (markers, the robot, its poses). Messages are built and written on a thread of their own: the
//! replay loop only hands over each report and the link poses, so the writing (some 2 kB per
//! state) can run on a second core (docs/benchmarks.md: what it costs when none is free).

use super::bag_reader::BagMessage;
use super::bag_writer::{BagWriter, TopicId};
use super::output_error::OutputError;
use crate::checker::Checker;
use crate::markers::{cell_markers, contact_markers};
use crate::model::PoseSource;
use crate::msgs::{DurationMsg, MarkerArray, StringMsg, TfMessage, Time, COLLISION_REPORT_TYPE, MARKER_ARRAY_TYPE, STRING_TYPE, TF_MESSAGE_TYPE};
use crate::pipeline::{link_transforms, CheckedState, Pipeline, RobotState};
use std::path::Path;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Arc;
use std::thread::JoinHandle;

/// The topic a `robot_description` is recorded on.
pub(super) const DESCRIPTION_TOPIC: &str = "/robot_description";

/// Jobs handed over at once: one wake-up of the writer per batch, not per report (a send per
/// report cost the loop 4 % in futex wake-ups).
const BATCH: usize = 256;
/// Batches queued before the loop waits for the writer: enough to ride out a slow write, few
/// enough that memory stays small (a job is a report and a dozen poses).
const QUEUE: usize = 16;

/// What the writer thread is asked to write.
enum Job {
    /// An input message copied as it is.
    Raw {
        topic: Copied,
        data: Vec<u8>,
        log_time: i64,
    },
    Cells(MarkerArray, i64),
    Description(StringMsg, i64),
    /// The robot of the joint positions to come (at the start, and after it changed).
    Robot(Arc<Checker>),
    /// A report, and the joint positions it was checked at (joint-state input with the view on):
    /// the writer computes the link poses, so the loop pays for one small copy.
    Report {
        checked: CheckedState,
        joints: Option<Vec<f64>>,
        log_time: i64,
    },
}

#[derive(Clone, Copy)]
enum Copied {
    Tf,
    TfStatic,
    Description,
}

/// The loop's side of the output bag.
pub(super) struct OutputBag {
    jobs: Option<SyncSender<Vec<Job>>>,
    /// Batches the writer is done with, emptied (and freed) here on the loop's thread and reused.
    /// The loop allocated every report in them; freed on the writer thread they went back to the
    /// loop's malloc arena under its lock, and the two threads took turns on it: with the markers
    /// on, malloc and free were a fifth of the loop's time (perf, docs/benchmarks.md).
    done: Receiver<Vec<Job>>,
    batch: Vec<Job>,
    writer: Option<JoinHandle<Result<(), OutputError>>>,
    view: Option<ViewState>,
}

/// What the loop keeps to feed the viewer topics.
struct ViewState {
    /// The input is `/tf`: it is copied (with `/tf_static`). For joint states the poses the check
    /// computed are written instead, and a `/tf` recorded beside them is not copied: the same
    /// link frames would get a second parent.
    copy_tf: bool,
    /// The input has a `/robot_description`: it is copied, and the robot's file is not written.
    copy_description: bool,
    /// The cells (and the robot's file) are written with the first message.
    started: bool,
    /// The robot the writer was last told of.
    robot: Option<Arc<Checker>>,
}

/// The writer thread's state.
struct Writer {
    bag: BagWriter,
    world: String,
    /// Put before each link's name in `/tf`.
    frame_prefix: String,
    collisions: TopicId,
    topics: Option<ViewTopics>,
    /// The robot of the joint positions in reports (`Job::Robot`).
    robot: Option<Arc<Checker>>,
    /// The `/tf` message written per report, reused: its frame names stay while the robot does.
    poses: TfMessage,
}

struct ViewTopics {
    contacts: TopicId,
    cells: TopicId,
    description: TopicId,
    tf: TopicId,
    tf_static: TopicId,
}

impl OutputBag {
    /// Creates the bag in `dir` (which must not exist) and starts its writer. `view`: the
    /// markers, `/tf` and `/robot_description` beside `/collisions`; `world` and `frame_prefix`
    /// name the frames.
    pub(super) fn create(
        dir: &Path,
        input_topics: &[(String, String)],
        pose_source: PoseSource,
        world: &str,
        frame_prefix: &str,
        view: bool,
    ) -> Result<OutputBag, OutputError> {
        let mut bag = BagWriter::create(dir)?;
        let collisions = bag.add_topic("/collisions", COLLISION_REPORT_TYPE, false)?;
        let topics = if view {
            Some(ViewTopics {
                contacts: bag.add_topic("/collision_markers/contacts", MARKER_ARRAY_TYPE, false)?,
                cells: bag.add_topic("/collision_markers/cells", MARKER_ARRAY_TYPE, true)?,
                description: bag.add_topic(DESCRIPTION_TOPIC, STRING_TYPE, true)?,
                tf: bag.add_topic("/tf", TF_MESSAGE_TYPE, false)?,
                tf_static: bag.add_topic("/tf_static", TF_MESSAGE_TYPE, true)?,
            })
        } else {
            None
        };
        let has = |topic: &str, ty: &str| input_topics.iter().any(|(t, y)| t == topic && (y.is_empty() || y == ty));
        let state = view.then(|| ViewState {
            copy_tf: pose_source == PoseSource::Tf,
            copy_description: has(DESCRIPTION_TOPIC, STRING_TYPE),
            started: false,
            robot: None,
        });
        let (jobs, queue) = sync_channel(QUEUE);
        // Room for every batch there can be: the writer never waits to hand one back.
        let (done_tx, done) = sync_channel(QUEUE + 2);
        let writer =
            Writer { bag, world: world.to_owned(), frame_prefix: frame_prefix.to_owned(), collisions, topics, robot: None, poses: TfMessage::default() };
        let handle = std::thread::Builder::new().name("bag writer".into()).spawn(move || writer.run(queue, done_tx)).map_err(OutputError::Thread)?;
        Ok(OutputBag { jobs: Some(jobs), done, batch: Vec::with_capacity(BATCH), writer: Some(handle), view: state })
    }

    fn send(&mut self, job: Job) -> Result<(), OutputError> {
        self.batch.push(job);
        if self.batch.len() < BATCH {
            return Ok(());
        }
        self.flush()
    }

    fn flush(&mut self) -> Result<(), OutputError> {
        let next = match self.done.try_recv() {
            Ok(mut written) => {
                written.clear();
                written
            }
            Err(_) => Vec::with_capacity(BATCH),
        };
        // Any further returned batches are freed here too.
        while let Ok(written) = self.done.try_recv() {
            drop(written);
        }
        let batch = std::mem::replace(&mut self.batch, next);
        let sent = self.jobs.as_ref().map(|j| j.send(batch));
        match sent {
            Some(Ok(())) => Ok(()),
            // The writer stopped on an error: finishing tells which.
            _ => Err(self.stop().err().unwrap_or(OutputError::Stopped)),
        }
    }

    /// Every input message before it is replayed: at the first, the cells (once, at the bag's
    /// start) and the robot's URDF when the bag has none of its own; the input's `/tf`,
    /// `/tf_static` and `/robot_description` are copied as they are.
    pub(super) fn input(&mut self, pipeline: &Pipeline, m: &BagMessage) -> Result<(), OutputError> {
        let Some(view) = self.view.as_mut() else { return Ok(()) };
        let mut jobs = Vec::new();
        if !view.started {
            view.started = true;
            let params = pipeline.params();
            let cells = cell_markers(pipeline.checker(), params.marker_max_cells.max(0) as usize, &params.world_frame, Time::from_nanos(m.log_time));
            jobs.push(Job::Cells(cells, m.log_time));
            if !view.copy_description {
                let urdf = pipeline.robot_urdf().map_err(OutputError::Description)?;
                jobs.push(Job::Description(StringMsg { data: urdf }, m.log_time));
            }
        }
        let topic = match m.topic.as_str() {
            "/tf" if view.copy_tf => Some(Copied::Tf),
            "/tf_static" if view.copy_tf => Some(Copied::TfStatic),
            DESCRIPTION_TOPIC if view.copy_description => Some(Copied::Description),
            _ => None,
        };
        if let Some(topic) = topic {
            jobs.push(Job::Raw { topic, data: m.data.clone(), log_time: m.log_time });
        }
        jobs.into_iter().try_for_each(|j| self.send(j))
    }

    /// A report, and (for joint states, with the view on) the joint positions it was checked at.
    pub(super) fn report(&mut self, pipeline: &Pipeline, state: &RobotState, checked: CheckedState, log_time: i64) -> Result<(), OutputError> {
        let mut joints = None;
        let mut robot = None;
        if let Some(view) = self.view.as_mut().filter(|v| !v.copy_tf) {
            if let Some(q) = state.joint_positions() {
                if !view.robot.as_ref().is_some_and(|c| Arc::ptr_eq(c, pipeline.checker())) {
                    view.robot = Some(pipeline.checker().clone());
                    robot = Some(Job::Robot(pipeline.checker().clone()));
                }
                joints = Some(q.to_vec());
            }
        }
        if let Some(r) = robot {
            self.send(r)?;
        }
        self.send(Job::Report { checked, joints, log_time })
    }

    /// Waits for the writer to write everything, finish the MCAP file and `metadata.yaml`.
    pub(super) fn finish(mut self) -> Result<(), OutputError> {
        self.flush()?;
        self.stop()
    }

    fn stop(&mut self) -> Result<(), OutputError> {
        drop(self.jobs.take());
        match self.writer.take() {
            Some(h) => h.join().map_err(|_| OutputError::Panicked)?,
            None => Ok(()),
        }
    }
}

impl Writer {
    fn run(mut self, queue: Receiver<Vec<Job>>, done: SyncSender<Vec<Job>>) -> Result<(), OutputError> {
        for batch in queue {
            for job in &batch {
                self.write(job)?;
            }
            // Never blocks: if the loop has stopped taking them, the batch is freed here.
            let _ = done.try_send(batch);
        }
        let _ = self.bag.finish()?;
        Ok(())
    }

    fn write(&mut self, job: &Job) -> Result<(), OutputError> {
        let topics = self.topics.as_ref();
        match (job, topics) {
            (Job::Report { checked, joints, log_time }, _) => {
                self.bag.write(self.collisions, &checked.message(&self.world), *log_time)?;
                let Some(t) = topics else { return Ok(()) };
                // Lifetime zero: each report's DELETEALL replaces the one before, however far apart.
                let markers = contact_markers(&checked.report, &self.world, checked.stamp, DurationMsg::default());
                self.bag.write_with(t.contacts, |w| w.marker_array(&markers), *log_time)?;
                if let (Some(q), Some(checker)) = (joints, &self.robot) {
                    if link_transforms(checker, &self.world, &self.frame_prefix, q, checked.stamp, &mut self.poses) {
                        let poses = &self.poses;
                        self.bag.write_with(t.tf, |w| w.tf_message(poses), *log_time)?;
                    }
                }
                Ok(())
            }
            (Job::Robot(checker), _) => {
                self.robot = Some(checker.clone());
                // Another robot's frame names must not be reused.
                self.poses = TfMessage::default();
                Ok(())
            }
            (Job::Cells(cells, log_time), Some(t)) => self.bag.write(t.cells, cells, *log_time),
            (Job::Description(d, log_time), Some(t)) => self.bag.write(t.description, d, *log_time),
            (Job::Raw { topic, data, log_time }, Some(t)) => {
                let id = match topic {
                    Copied::Tf => t.tf,
                    Copied::TfStatic => t.tf_static,
                    Copied::Description => t.description,
                };
                self.bag.write_raw(id, data, *log_time)
            }
            // Viewer messages are only made with the viewer topics.
            (_, None) => Ok(()),
        }
    }
}
