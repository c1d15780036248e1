//! What a checked robot link is made of: the convex shapes of its geometry.

use super::geometry_shapes::primitive_shape;
use crate::collision::{ConvexHull, TargetShape};
use crate::math::{Pose, Vector};
use crate::model::{GeometrySpec, MeshData};
use std::sync::Arc;

/// The convex parts of one checked robot link.
#[derive(Clone, Debug)]
pub struct LinkTargets {
    /// Index of the link in the robot model.
    pub link: usize,
    /// Its name.
    pub name: String,
    /// Shapes and their poses in the link frame.
    pub parts: Vec<(TargetShape, Pose)>,
    /// For a robot link, what each part is grown from (a planning scene may set another padding
    /// and scale); empty for an attached object.
    pub(crate) sources: Arc<[PartSource]>,
}

/// What a robot link's part is grown from: its geometry before padding and scale.
#[derive(Clone, Debug)]
pub(crate) enum PartSource {
    Primitive(GeometrySpec),
    /// A mesh as the hull of its vertices, and the mean of those vertices.
    Hull {
        hull: Arc<ConvexHull>,
        centre: Vector,
    },
}

impl PartSource {
    /// The hull of `mesh`'s vertices; `None` when it is flat or empty.
    pub(crate) fn mesh(mesh: &MeshData) -> Option<PartSource> {
        let hull = ConvexHull::from_points(&mesh.vertices)?;
        let centre = mesh.vertices.iter().copied().sum::<Vector>() / mesh.vertices.len() as f64;
        Some(PartSource::Hull { hull: Arc::new(hull), centre })
    }

    /// The part scaled by `scale`, then grown by `padding`; `None` when that is not a usable
    /// convex shape.
    pub(crate) fn sized(&self, scale: f64, padding: f64) -> Option<TargetShape> {
        match self {
            PartSource::Primitive(spec) => primitive_shape(&scaled_spec(spec, scale), padding),
            PartSource::Hull { hull, centre } => {
                let scaled = if scale == 1.0 {
                    (**hull).clone()
                } else {
                    let points: Vec<Vector> = hull.points().iter().map(|p| *centre + (*p - *centre) * scale).collect();
                    ConvexHull::from_points(&points)?
                };
                scaled.padded(padding).map(|h| TargetShape::Polytope(Arc::new(h)))
            }
        }
    }
}

fn scaled_spec(spec: &GeometrySpec, k: f64) -> GeometrySpec {
    match spec {
        GeometrySpec::Box(s) => GeometrySpec::Box([s[0] * k, s[1] * k, s[2] * k]),
        GeometrySpec::Sphere(r) => GeometrySpec::Sphere(r * k),
        GeometrySpec::Capsule { radius, length } => GeometrySpec::Capsule { radius: radius * k, length: length * k },
        GeometrySpec::Cylinder { radius, length } => GeometrySpec::Cylinder { radius: radius * k, length: length * k },
        mesh @ GeometrySpec::Mesh { .. } => mesh.clone(),
    }
}
