//! Per-link padding and scale from a planning scene (`link_padding`, `link_scale`), and the
//! robot's parts regrown with them. A scene's value for a link replaces the `padding`
//! parameter's for that link (as MoveIt's `setLinkPadding` replaces its default padding); scale
//! is applied first, as MoveIt's `scaleAndPadd` does: a primitive about its own origin, a mesh
//! about the mean of its vertices.

use super::checker::Checker;
use super::link_targets::LinkTargets;
use super::world_shapes::WorldShape;
use crate::math::Vector;
use crate::model::MeshData;
use std::collections::BTreeMap;
use std::sync::Arc;

/// The padding and scale a planning scene set for robot links, by link name.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct LinkSizes {
    pub padding: BTreeMap<String, f64>,
    pub scale: BTreeMap<String, f64>,
}

impl LinkSizes {
    pub(crate) fn is_empty(&self) -> bool {
        self.padding.is_empty() && self.scale.is_empty()
    }
}

/// `shape` (an attached object's) scaled by `k` as MoveIt scales it: a primitive about its
/// origin, a mesh about the mean of its vertices.
pub(crate) fn scaled_shape(shape: &WorldShape, k: f64) -> WorldShape {
    if k == 1.0 {
        return shape.clone();
    }
    match shape {
        WorldShape::Box(s) => WorldShape::Box([s[0] * k, s[1] * k, s[2] * k]),
        WorldShape::Sphere(r) => WorldShape::Sphere(r * k),
        WorldShape::Cylinder { height, radius } => WorldShape::Cylinder { height: height * k, radius: radius * k },
        WorldShape::Cone { height, radius } => WorldShape::Cone { height: height * k, radius: radius * k },
        WorldShape::Prism { height, polygon } => WorldShape::Prism { height: height * k, polygon: polygon.iter().map(|[x, y]| [x * k, y * k]).collect() },
        WorldShape::Mesh(m) => {
            let n = m.vertices.len().max(1) as f64;
            let centre = m.vertices.iter().copied().sum::<Vector>() / n;
            let vertices = m.vertices.iter().map(|v| centre + (*v - centre) * k).collect();
            WorldShape::Mesh(Arc::new(MeshData { vertices, triangles: m.triangles.clone() }))
        }
        WorldShape::Plane(p) => WorldShape::Plane(*p),
    }
}

impl Checker {
    /// The padding in force for robot link (or attached object) `name`: the planning scene's for
    /// a robot link when it set one, else the `padding` parameter's.
    pub(crate) fn link_padding(&self, name: &str) -> f64 {
        self.link_sizes.padding.get(name).copied().unwrap_or_else(|| self.params.padding_of(name))
    }

    /// The scale in force for robot link `name`: the planning scene's, else 1.
    pub(crate) fn link_scale(&self, name: &str) -> f64 {
        self.link_sizes.scale.get(name).copied().unwrap_or(1.0)
    }

    /// The robot links' targets with `sizes` in force (those of this checker's own sizes are
    /// rebuilt from their sources); `Err` names the link whose part is no usable shape.
    pub(super) fn robot_targets_sized(&self, sizes: &LinkSizes) -> Result<Vec<LinkTargets>, String> {
        let mut targets = self.targets[..self.robot_targets].to_vec();
        for t in &mut targets {
            let padding = sizes.padding.get(&t.name).copied().unwrap_or_else(|| self.params.padding_of(&t.name));
            let scale = sizes.scale.get(&t.name).copied().unwrap_or(1.0);
            if padding == self.link_padding(&t.name) && scale == self.link_scale(&t.name) {
                continue;
            }
            for (k, ((shape, _), source)) in t.parts.iter_mut().zip(t.sources.iter()).enumerate() {
                *shape = source
                    .sized(scale, padding)
                    .ok_or_else(|| format!("link '{}' part {k}: scale {scale} and padding {padding} leave no usable shape", t.name))?;
            }
        }
        Ok(targets)
    }
}
