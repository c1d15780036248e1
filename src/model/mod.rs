//! Files turned into the plain data the core takes: URDF robots and environments, mesh files,
//! `package://` URIs, the parameters file, and forward kinematics.

mod bundled;
mod collada_guard;
#[cfg(feature = "testing")]
pub mod example_workcell;
// Crate-visible for `fuzz_access`, which hands the fuzz harness the parser behind `read_mesh`.
mod glob;
pub(crate) mod mesh_file;
mod package;
mod params;
mod params_file;
mod robot;
mod robot_parse;
mod srdf;
mod xacro;
mod xml_guard;

pub use self::bundled::bundled_config_dir;
#[cfg(feature = "ros")]
pub(crate) use self::glob::glob_match;
pub(crate) use self::mesh_file::scale_mesh;
#[cfg(feature = "testing")]
pub use self::mesh_file::write_obj;
pub use self::mesh_file::{read_mesh, MeshData, MeshFileError};
pub use self::package::{PackageError, PackageResolver};
pub use self::params::{InputFiles, MissingJoint, Padding, Params, ParamsError, PoseSource, ServiceMapping, ThinSurfaces};
pub use self::params_file::{node_fqn, LoadedParams, DEFAULT_NODE_FQN};
pub(crate) use self::robot::PoseKinematics;
pub use self::robot::{GeometrySpec, JointKind, JointModel, LinkGeometry, LinkModel, Mimic, ModelError, PositionsError, RobotModel};
pub use self::srdf::{Srdf, SrdfError};
