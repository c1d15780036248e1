//! Files: meshes (and, later, URDF) turned into the plain data the core takes.

pub mod mesh_file;
