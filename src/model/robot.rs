//! A kinematic tree (read from URDF in `robot_parse`): links with their collision geometry,
//! joints with limits and mimics, and forward kinematics in `nalgebra` f64.

use super::package::PackageError;
use crate::limits::InputFileError;
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::PathBuf;

/// The geometry of one collision (or visual) element, in the link frame after `origin`.
#[derive(Clone, Debug, PartialEq)]
pub enum GeometrySpec {
    /// Full sizes (metres).
    Box([f64; 3]),
    /// Along local z.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Full length.
        length: f64,
    },
    /// Along local z.
    Capsule {
        /// Radius.
        radius: f64,
        /// Length of the segment.
        length: f64,
    },
    /// A ball.
    Sphere(f64),
    /// A mesh file (resolved path) and its scale.
    Mesh {
        /// Resolved file.
        path: PathBuf,
        /// Per-axis scale.
        scale: [f64; 3],
    },
}

/// One geometry element of a link.
#[derive(Clone, Debug)]
pub struct LinkGeometry {
    /// Pose of the geometry in the link frame.
    pub origin: Isometry3<f64>,
    /// The shape.
    pub spec: GeometrySpec,
}

/// A link.
#[derive(Clone, Debug)]
pub struct LinkModel {
    /// Name.
    pub name: String,
    /// Collision geometry (or visual, where configured and collision is absent).
    pub geometry: Vec<LinkGeometry>,
}

/// The motion a joint allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis, limited.
    Revolute,
    /// Rotation about the axis, unlimited.
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// No motion.
    Fixed,
    /// Six degrees of freedom; placed at its origin (joint states cannot carry it; use `/tf`).
    Floating,
    /// Motion in a plane; placed at its origin (as `Floating`).
    Planar,
}

/// A mimic relation: `q = multiplier * q[joint] + offset`.
#[derive(Clone, Copy, Debug)]
pub struct Mimic {
    /// Index of the joint followed.
    pub joint: usize,
    /// Multiplier.
    pub multiplier: f64,
    /// Offset.
    pub offset: f64,
}

/// A joint.
#[derive(Clone, Debug)]
pub struct JointModel {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: JointKind,
    /// Parent link index.
    pub parent: usize,
    /// Child link index.
    pub child: usize,
    /// Pose of the joint frame in the parent link frame.
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub axis: Unit<Vector3<f64>>,
    /// Lower and upper limits (radians or metres; infinite when absent or continuous).
    pub limits: [f64; 2],
    /// Mimic relation, if any.
    pub mimic: Option<Mimic>,
}

impl JointModel {
    /// Whether the joint takes a position from a joint state (not fixed, not a mimic).
    pub fn is_actuated(&self) -> bool {
        matches!(self.kind, JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic) && self.mimic.is_none()
    }
}

/// Joint positions that forward kinematics cannot use.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum PositionsError {
    /// Not one position per joint of the model.
    #[error("{got} joint positions for a model of {expected} joints")]
    Length {
        /// Joints of the model.
        expected: usize,
        /// Positions given.
        got: usize,
    },
    /// A position is NaN or infinite.
    #[error("joint '{joint}' has a non-finite position {value}")]
    NonFinite {
        /// The joint.
        joint: String,
        /// Its value.
        value: f64,
    },
}

/// A URDF that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The file cannot be read (missing, not a regular file, too large).
    #[error("{0}")]
    Input(Box<InputFileError>),
    /// urdf-rs rejected the XML.
    #[error("{file}: malformed URDF: {message}")]
    Urdf {
        /// File (or `robot_description`).
        file: String,
        /// What urdf-rs said.
        message: String,
    },
    /// A mesh URI of a link does not resolve. (The package error is part of the message, not a
    /// `source`: printed as a chain it would repeat itself.)
    #[error("{file}: link '{link}': {error}")]
    Package {
        /// File.
        file: String,
        /// Link.
        link: String,
        /// Why.
        error: PackageError,
    },
    /// The text is unexpanded xacro (urdf-rs would read past its macros: a robot with nothing
    /// to check).
    #[error("{file}: unexpanded xacro ({evidence}); expand it first (`xacro {file} > robot.urdf`) or publish the expanded URDF on robot_description")]
    Xacro {
        /// File (or `robot_description`).
        file: String,
        /// What marks it as xacro, with its line.
        evidence: String,
    },
    /// The joints do not form a tree.
    #[error("{file}: {message}")]
    Structure {
        /// File.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A number in the URDF is NaN, infinite or out of its domain.
    #[error("{file}: {what} has an invalid value {}", crate::limits::show_number(*.value))]
    Value {
        /// File.
        file: String,
        /// Where.
        what: String,
        /// The value.
        value: f64,
    },
}

/// A robot (or an environment) as a kinematic tree.
#[derive(Clone, Debug)]
pub struct RobotModel {
    /// The robot's name.
    pub name: String,
    /// Links.
    pub links: Vec<LinkModel>,
    /// Links with `<visual>` but no `<collision>` geometry whose visuals were not used (said when
    /// nothing is left to check).
    pub visual_only_links: usize,
    /// Joints.
    pub joints: Vec<JointModel>,
    /// The root link.
    pub root: usize,
    /// Joints in an order where every joint's parent link is placed before it.
    pub(super) order: Vec<usize>,
    /// Per link: the joint whose child it is (none for the root).
    pub(super) parent_joint: Vec<Option<usize>>,
    pub(super) link_index: HashMap<String, usize>,
    pub(super) joint_index: HashMap<String, usize>,
}

/// The joints' origins and axes in the geometry's types (see [`RobotModel::forward_poses`]).
#[derive(Clone, Debug)]
pub(crate) struct PoseKinematics {
    origins: Vec<crate::math::Pose>,
    axes: Vec<crate::math::Vector>,
}

impl PoseKinematics {
    /// Joint `j`'s axis in its child link's frame.
    pub(crate) fn axis(&self, j: usize) -> crate::math::Vector {
        self.axes[j]
    }
}

impl RobotModel {
    /// The joints' frames for [`RobotModel::forward_poses`].
    pub(crate) fn pose_kinematics(&self) -> PoseKinematics {
        PoseKinematics {
            origins: self.joints.iter().map(|j| crate::math::pose_from_isometry(&j.origin)).collect(),
            axes: self.joints.iter().map(|j| crate::math::Vector::new(j.axis.x, j.axis.y, j.axis.z)).collect(),
        }
    }

    /// [`RobotModel::forward_kinematics`] in the geometry's types, for a loop that poses the
    /// robot at every step (a motion check): `position(j)` is joint `j`'s position, every one
    /// finite (the caller has validated the states it interpolates). Every link gets a pose.
    pub(crate) fn forward_poses(&self, frames: &PoseKinematics, position: impl Fn(usize) -> f64, base: crate::math::Pose) -> Vec<Option<crate::math::Pose>> {
        use crate::math::{Pose, Rotation};
        let mut poses = vec![Some(Pose::IDENTITY); self.links.len()];
        poses[self.root] = Some(base);
        for &ji in &self.order {
            let j = &self.joints[ji];
            let q = match j.mimic {
                Some(m) => m.multiplier * position(m.joint) + m.offset,
                None => position(ji),
            };
            // The order places every parent first: its pose is set.
            let origin = poses[j.parent].unwrap_or(Pose::IDENTITY) * frames.origins[ji];
            poses[j.child] = Some(match j.kind {
                JointKind::Revolute | JointKind::Continuous => {
                    origin * Pose::from_parts(crate::math::Vector::ZERO, Rotation::from_axis_angle(frames.axes[ji], q))
                }
                JointKind::Prismatic => origin * Pose::from_parts(frames.axes[ji] * q, Rotation::IDENTITY),
                JointKind::Fixed | JointKind::Floating | JointKind::Planar => origin,
            });
        }
        poses
    }

    /// The joint whose child link `link` is; `None` for the root (or an index out of range).
    pub(crate) fn parent_joint(&self, link: usize) -> Option<usize> {
        self.parent_joint.get(link).copied().flatten()
    }

    /// Index of a link by name.
    pub fn link(&self, name: &str) -> Option<usize> {
        self.link_index.get(name).copied()
    }

    /// Index of a joint by name.
    pub fn joint(&self, name: &str) -> Option<usize> {
        self.joint_index.get(name).copied()
    }

    /// The error [`RobotModel::forward_kinematics`] would give for `positions`, without the poses.
    pub(crate) fn validate_positions(&self, positions: &[f64]) -> Result<(), PositionsError> {
        if positions.len() != self.joints.len() {
            return Err(PositionsError::Length { expected: self.joints.len(), got: positions.len() });
        }
        if let Some((j, v)) = positions.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(PositionsError::NonFinite { joint: self.joints[j].name.clone(), value: *v });
        }
        Ok(())
    }

    /// The world pose of every link, given a position for every joint (indexed like `joints`;
    /// ignored for fixed, floating and planar joints and for mimics, whose value is derived) and
    /// the pose of the root link in the world.
    ///
    /// A slice of the wrong length, or a non-finite position, is an error naming it.
    pub fn forward_kinematics(&self, positions: &[f64], base: &Isometry3<f64>) -> Result<Vec<Isometry3<f64>>, PositionsError> {
        self.validate_positions(positions)?;
        let mut poses = vec![Isometry3::identity(); self.links.len()];
        poses[self.root] = *base;
        for &ji in &self.order {
            let j = &self.joints[ji];
            let q = match j.mimic {
                Some(m) => m.multiplier * positions[m.joint] + m.offset,
                None => positions[ji],
            };
            let motion = match j.kind {
                JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_axis_angle(&j.axis, q)),
                JointKind::Prismatic => Isometry3::from_parts(Translation3::from(j.axis.into_inner() * q), UnitQuaternion::identity()),
                JointKind::Fixed | JointKind::Floating | JointKind::Planar => Isometry3::identity(),
            };
            poses[j.child] = poses[j.parent] * j.origin * motion;
        }
        Ok(poses)
    }
}
