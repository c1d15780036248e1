//! Why a checker cannot be built.

use crate::model::MeshFileError;
use crate::model::{ModelError, ParamsError};

/// Why a checker cannot be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckerError {
    /// Bad parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// Bad URDF.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A mesh file of a link cannot be used. (The mesh error is part of the message, not a
    /// `source`: printed as a chain it would repeat itself.)
    #[error("{file}: link '{link}': {error}")]
    Mesh {
        /// The URDF (or `robot_description`) naming the mesh.
        file: String,
        /// Link.
        link: String,
        /// Why.
        error: MeshFileError,
    },
    /// A planning-scene object that cannot be checked: the scene in force stays.
    #[error("collision object '{id}': {message}")]
    WorldObject {
        /// The object's id.
        id: String,
        /// Why.
        message: String,
    },
    /// A planning scene's `link_padding` / `link_scale` that leave a robot link without a usable
    /// shape: the scene in force stays.
    #[error("planning scene: link_padding / link_scale: {0}")]
    LinkSize(String),
    /// Building panicked (a defect, in this crate or a dependency): contained, so the robot in
    /// use stays.
    #[error("building the checker failed: {0}")]
    Panicked(String),
    /// The SRDF cannot be read or does not fit the robot.
    #[error("{0}")]
    Srdf(String),
    /// No link of the robot would be checked: every state would be reported free.
    #[error("{file}: robot '{robot}' has no link to check: {cause}")]
    NoCheckedLink {
        /// The URDF (or `robot_description`).
        file: String,
        /// The robot's name.
        robot: String,
        /// Why no link is checked, and what to change.
        cause: String,
    },
    /// A geometry of a link is not usable.
    #[error("{file}: link '{link}': {what}: {message}")]
    Geometry {
        /// The URDF (or `robot_description`).
        file: String,
        /// Link.
        link: String,
        /// The geometry: `mesh <file>`, or the primitive with its sizes.
        what: String,
        /// What is wrong.
        message: String,
    },
}
