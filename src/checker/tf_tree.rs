//! The latest transform of every frame from `/tf` and `/tf_static`, and world poses from them
//! (shared by the node and the replay).

use crate::math::{Pose, Rotation, Vector};
use crate::msgs::TfMessage;
use std::collections::HashMap;

/// Child frame to (parent frame, pose in parent).
#[derive(Default)]
pub struct TfTree {
    edges: HashMap<String, (String, Pose)>,
}

impl TfTree {
    /// Frames kept at most (a robot cell has hundreds).
    pub const MAX_FRAMES: usize = 10_000;

    /// Records every transform of a message; returns the child frames that were not finite, or
    /// new frames past [`TfTree::MAX_FRAMES`] (a flood of made-up frames must not grow memory).
    pub fn update(&mut self, msg: &TfMessage) -> Vec<String> {
        let mut bad = Vec::new();
        for t in &msg.transforms {
            if self.edges.len() >= Self::MAX_FRAMES && !self.edges.contains_key(strip(&t.child_frame_id)) {
                bad.push(t.child_frame_id.clone());
                continue;
            }
            let (tr, q) = (t.transform.translation, t.transform.rotation);
            let rot = Rotation::from_xyzw(q.x, q.y, q.z, q.w);
            let v = Vector::new(tr.x, tr.y, tr.z);
            if !v.is_finite() || !rot.is_finite() || (rot.length() - 1.0).abs() > 1e-6 {
                bad.push(t.child_frame_id.clone());
                continue;
            }
            let _ = self.edges.insert(strip(&t.child_frame_id).to_owned(), (strip(&t.header.frame_id).to_owned(), Pose::from_parts(v, rot)));
        }
        bad
    }

    /// The pose of `frame` in `world`, if the chain of parents reaches it (at most 256 steps).
    pub fn world_pose(&self, frame: &str, world: &str) -> Option<Pose> {
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
