//! The latest transform of every frame from `/tf` and `/tf_static`, and world poses from them.

use crate::math::{Pose, Rotation, Vector};
use crate::msgs::TfMessage;
use std::collections::HashMap;

/// Child frame to (parent frame, pose in parent).
#[derive(Default)]
pub(crate) struct TfTree {
    edges: HashMap<String, (String, Pose)>,
}

/// Why a `/tf` message was not applied.
#[derive(Debug, PartialEq)]
pub(crate) enum TfRejection {
    /// The transform of this child frame is not finite or not a rotation.
    NotRigid(String),
    /// This new frame would pass [`TfTree::MAX_FRAMES`].
    TooManyFrames(String),
    /// This child frame is given twice in one message.
    Duplicate(String),
}

impl TfTree {
    /// Frames kept at most (a robot cell has hundreds): a flood of made-up frames must not grow
    /// memory.
    pub(crate) const MAX_FRAMES: usize = 10_000;

    /// Applies every transform of a message, or none: a message with one bad transform would
    /// leave the tree half old, half new.
    pub(crate) fn update(&mut self, msg: &TfMessage) -> Result<(), TfRejection> {
        let mut parsed = Vec::with_capacity(msg.transforms.len());
        let mut new_frames = 0;
        let mut seen = rustc_hash::FxHashSet::default();
        for t in &msg.transforms {
            let (tr, q) = (t.transform.translation, t.transform.rotation);
            let rot = Rotation::from_xyzw(q.x, q.y, q.z, q.w);
            let v = Vector::new(tr.x, tr.y, tr.z);
            if !v.to_array().into_iter().all(crate::limits::is_coordinate) || !rot.is_finite() || (rot.length() - 1.0).abs() > 1e-6 {
                return Err(TfRejection::NotRigid(t.child_frame_id.clone()));
            }
            let child = strip(&t.child_frame_id);
            if !seen.insert(child) {
                return Err(TfRejection::Duplicate(t.child_frame_id.clone()));
            }
            if !self.edges.contains_key(child) {
                new_frames += 1;
                if self.edges.len() + new_frames > Self::MAX_FRAMES {
                    return Err(TfRejection::TooManyFrames(t.child_frame_id.clone()));
                }
            }
            parsed.push((child, strip(&t.header.frame_id), Pose::from_parts(v, rot.normalize())));
        }
        for (child, parent, pose) in parsed {
            let _ = self.edges.insert(child.to_owned(), (parent.to_owned(), pose));
        }
        Ok(())
    }

    /// The pose of `frame` in `world`, if the chain of parents reaches it (at most 256 steps: a
    /// cycle in the input must not loop).
    pub(crate) fn world_pose(&self, frame: &str, world: &str) -> Option<Pose> {
        let (frame, world) = (strip(frame), strip(world));
        if frame == world {
            return Some(Pose::IDENTITY);
        }
        // Composed from the frame up; the first edge is taken as is, so a transform given
        // directly in the world frame reaches the checker bit for bit.
        let (parent, first) = self.edges.get(frame)?;
        let mut pose = *first;
        let mut at = parent.as_str();
        for _ in 0..256 {
            if at == world {
                return Some(pose);
            }
            let (parent, p) = self.edges.get(at)?;
            pose = *p * pose;
            at = parent;
        }
        None
    }
}

fn strip(frame: &str) -> &str {
    frame.trim_start_matches('/')
}
