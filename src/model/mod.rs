//! Files: meshes (and, later, URDF) turned into the plain data the core takes.

pub mod example_workcell;
pub mod mesh_file;
