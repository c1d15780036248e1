//! Files turned into the plain data the core takes: URDF robots and environments, mesh files,
//! `package://` URIs, the parameters file, and forward kinematics.

mod bundled;
pub mod collada_guard;
#[cfg(feature = "testing")]
pub mod example_workcell;
pub mod mesh_file;
mod package;
mod params;
mod params_file;
mod robot;
mod robot_parse;
mod srdf;
mod xacro;
pub mod xml_guard;

pub use self::bundled::bundled_config_dir;
pub use self::package::{PackageError, PackageResolver};
pub use self::params::{glob_match, InputFiles, MissingJoint, Padding, Params, ParamsError, PoseSource, ServiceMapping, ThinSurfaces};
pub use self::params_file::{node_fqn, LoadedParams, DEFAULT_NODE_FQN};
pub use self::robot::{GeometrySpec, JointKind, JointModel, LinkGeometry, LinkModel, Mimic, ModelError, PositionsError, RobotModel};
pub use self::srdf::{Srdf, SrdfError};
