//! Why an input message gave no checked state: one name per cause, counted the same way by the
//! node (in `/diagnostics`), replay (in its summary) and `check`.

/// A cause of a skipped message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[non_exhaustive]
pub enum SkipCause {
    /// The payload does not decode as the topic's type.
    Undecodable,
    /// A joint state whose `name` and `position` differ in length.
    Lengths,
    /// A joint position that is NaN or infinite.
    NonFinite,
    /// A joint named twice in one state, or a frame given twice in one `/tf` message (which one
    /// is meant cannot be told).
    DuplicateName,
    /// An actuated joint never received, under `missing_joint: reject`.
    MissingJoint,
    /// Under `missing_joint: last`, a joint that moves a checked link not received yet.
    Incomplete,
    /// A transform that is not finite or not a rotation, or a new frame past the frame limit.
    BadTransform,
    /// A `/tf` message that names none of the robot's frames (another robot's, a sensor's), or a
    /// joint state that names none of its actuated joints.
    NotOurRobot,
    /// A checked link whose frame does not reach `world_frame` yet.
    Unreachable,
    /// A state overtaken by a newer one before the node could check it (the node only).
    Stale,
    /// A planning-scene message whose `header.frame_id` (or a fixed frame's parent) is no known
    /// frame, or names a robot link while the robot's state is unknown.
    SceneFrame,
    /// A planning-scene object with a field that cannot be used: non-finite vertices or poses,
    /// out-of-range triangle indices, shape and pose arrays of different lengths, an unknown
    /// shape type, wrong dimensions, a link padding or scale out of range.
    SceneGeometry,
    /// A `REMOVE` or `MOVE` of an id the scene does not hold.
    SceneUnknownId,
    /// An object operation that is not ADD, REMOVE, APPEND or MOVE.
    SceneOperation,
    /// An object id that is empty, or names a link of the robot or the environment.
    SceneId,
    /// Past the scene's bounds: triangles per object or in all, objects.
    SceneBounds,
    /// An octomap in a planning-scene message: refused (the rest of the message applies).
    SceneOctomap,
}

impl SkipCause {
    /// Every cause, in the order reports list them.
    pub const ALL: [SkipCause; 17] = [
        SkipCause::Undecodable,
        SkipCause::Lengths,
        SkipCause::NonFinite,
        SkipCause::DuplicateName,
        SkipCause::MissingJoint,
        SkipCause::Incomplete,
        SkipCause::BadTransform,
        SkipCause::NotOurRobot,
        SkipCause::Unreachable,
        SkipCause::Stale,
        SkipCause::SceneFrame,
        SkipCause::SceneGeometry,
        SkipCause::SceneUnknownId,
        SkipCause::SceneOperation,
        SkipCause::SceneId,
        SkipCause::SceneBounds,
        SkipCause::SceneOctomap,
    ];

    /// A refused planning-scene message (not a state message).
    pub fn is_scene(self) -> bool {
        self.key().starts_with("scene_")
    }

    /// The name used in `/diagnostics` keys, summaries and logs.
    pub fn key(self) -> &'static str {
        match self {
            SkipCause::Undecodable => "undecodable",
            SkipCause::Lengths => "lengths",
            SkipCause::NonFinite => "non_finite",
            SkipCause::DuplicateName => "duplicate_name",
            SkipCause::MissingJoint => "missing_joint",
            SkipCause::Incomplete => "incomplete",
            SkipCause::BadTransform => "bad_transform",
            SkipCause::NotOurRobot => "not_our_robot",
            SkipCause::Unreachable => "unreachable",
            SkipCause::Stale => "stale",
            SkipCause::SceneFrame => "scene_frame",
            SkipCause::SceneGeometry => "scene_geometry",
            SkipCause::SceneUnknownId => "scene_unknown_id",
            SkipCause::SceneOperation => "scene_operation",
            SkipCause::SceneId => "scene_id",
            SkipCause::SceneBounds => "scene_bounds",
            SkipCause::SceneOctomap => "scene_octomap",
        }
    }
}

/// A message that gave no state: the cause (counted) and what was wrong (for the log, and the
/// `error` of a fail-closed report).
#[derive(Clone, Debug, PartialEq)]
pub struct Skip {
    /// The cause.
    pub cause: SkipCause,
    /// What was wrong, naming the field and value.
    pub message: String,
}
