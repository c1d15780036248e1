//! URDF geometry turned into shapes: mesh files read once per build, primitives as targets.

use crate::collision::TargetShape;
use crate::math::Vector;
use crate::model::GeometrySpec;
use crate::model::{read_mesh, scale_mesh, MeshData, MeshFileError};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Mesh files read once per build.
#[derive(Default)]
pub(super) struct MeshCache {
    meshes: HashMap<PathBuf, Arc<MeshData>>,
}

impl MeshCache {
    /// The mesh at `path` with `scale` applied (winding reversed for mirroring scales).
    pub(super) fn get(&mut self, path: &Path, scale: [f64; 3]) -> Result<MeshData, MeshFileError> {
        let data = match self.meshes.get(path) {
            Some(d) => d.clone(),
            None => {
                let d = Arc::new(read_mesh(path, Vector::ONE)?);
                let _ = self.meshes.insert(path.to_owned(), d.clone());
                d
            }
        };
        scale_mesh(&data, Vector::from_array(scale), path)
    }

    /// How many files were read.
    pub(super) fn files_read(&self) -> usize {
        self.meshes.len()
    }
}

/// The target of a URDF primitive grown by `padding`; `None` for meshes and for sizes that are not
/// positive and finite.
pub(super) fn primitive_shape(spec: &GeometrySpec, padding: f64) -> Option<TargetShape> {
    let shape = match spec {
        GeometrySpec::Box(s) => TargetShape::cuboid(Vector::new(s[0], s[1], s[2]) * 0.5 + Vector::splat(padding))?,
        GeometrySpec::Sphere(r) => TargetShape::Sphere { radius: r + padding },
        GeometrySpec::Capsule { radius, length } => TargetShape::Capsule { half_height: length / 2.0, radius: radius + padding },
        GeometrySpec::Cylinder { radius, length } => TargetShape::Cylinder { half_height: length / 2.0 + padding, radius: radius + padding },
        GeometrySpec::Mesh { .. } => return None,
    };
    shape.is_valid().then_some(shape)
}
