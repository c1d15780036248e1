//! The environment: objects with their cells in a BVH, and the queries against them.

use super::cell_tree::CellTree;
use super::collector::{AllHits, AnyHit, Collector, DeepestHit};
use super::report::{CollideSettings, TargetReport};
use super::target::{Target, TargetShape};
use super::target_view::{transformed_box, TargetView};
use crate::math::{Aabb, Pose};
use crate::thickness::ThicknessArea;
use parry3d_f64::bounding_volume::BoundingVolume;
use std::sync::Arc;

/// What an environment object is made of.
// A scene holds a handful of objects; boxing the surface would add an indirection to every query.
#[allow(clippy::large_enum_variant)]
pub enum ObjectBody {
    /// A thin surface: its cells in a BVH.
    Surface {
        /// The cells, in the object's frame.
        area: ThicknessArea,
        /// Broad phase over the cells, with bounds on their normals.
        tree: CellTree,
    },
    /// A convex solid (a URDF primitive or a mesh checked as its hull), checked with parry's
    /// GJK/EPA; its contacts have `triangle = u32::MAX`.
    Solid(TargetShape),
}

impl ObjectBody {
    /// A thin surface of these cells, in the object's frame; the cells are reordered for the
    /// broad phase (see [`CellTree::build`]).
    pub(crate) fn surface(mut area: ThicknessArea) -> ObjectBody {
        let tree = CellTree::build(&mut area.cells);
        ObjectBody::Surface { area, tree }
    }
}

/// One environment object, fixed in the world.
pub struct SceneObject {
    /// The object's name (reported in contacts).
    pub name: String,
    /// The pose of the object's frame in the world.
    pub pose: Pose,
    /// Its geometry (shared: a planning-scene object that moves keeps its cells).
    pub body: Arc<ObjectBody>,
    /// Its bounding box in the world (a first, cheap reject per target).
    pub(super) world_aabb: Aabb,
    /// Added to its cells' triangle indices in reports: a planning-scene object's meshes count
    /// their triangles on from the meshes before them (0 for the environment's).
    pub(crate) triangle_base: u32,
}

impl SceneObject {
    /// The cells, for a thin surface.
    pub fn area(&self) -> Option<&ThicknessArea> {
        match &*self.body {
            ObjectBody::Surface { area, .. } => Some(area),
            ObjectBody::Solid(_) => None,
        }
    }

    /// Bytes of the broad-phase tree (for memory reports); 0 for solids.
    pub fn bvh_memory(&self) -> usize {
        match &*self.body {
            ObjectBody::Surface { tree, .. } => tree.memory(),
            ObjectBody::Solid(_) => 0,
        }
    }
}

/// The world box of `body` placed at `pose` (invalid for a surface without cells).
fn world_box(body: &ObjectBody, pose: &Pose) -> Aabb {
    match body {
        ObjectBody::Surface { tree, .. } if tree.is_empty() => Aabb::new_invalid(),
        ObjectBody::Surface { tree, .. } => transformed_box(&tree.root_aabb(), pose),
        ObjectBody::Solid(shape) => transformed_box(&shape.local_aabb(), pose),
    }
}

/// Environment objects and the queries of convex targets against them.
// Objects are shared, so that a scene of the same environment with other planning-scene objects
// is made without copying any cells.
#[derive(Clone, Default)]
pub struct Scene {
    objects: Vec<Arc<SceneObject>>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Scene {
        Scene::default()
    }

    /// Adds a thin surface whose cells are given in the object's frame, placed at `pose` in the
    /// world. Returns the object's index.
    /// The area's cells are reordered for the broad phase (see [`CellTree::build`]).
    pub fn add_surface(&mut self, name: impl Into<String>, pose: Pose, area: ThicknessArea) -> usize {
        self.add_body(name, pose, Arc::new(ObjectBody::surface(area)))
    }

    /// Adds a convex solid placed at `pose` in the world. Returns the object's index.
    pub fn add_solid(&mut self, name: impl Into<String>, pose: Pose, shape: TargetShape) -> usize {
        self.add_body(name, pose, Arc::new(ObjectBody::Solid(shape)))
    }

    /// Adds a body built before (perhaps placed elsewhere in another scene) at `pose`. Returns
    /// the object's index.
    pub(crate) fn add_body(&mut self, name: impl Into<String>, pose: Pose, body: Arc<ObjectBody>) -> usize {
        let world_aabb = world_box(&body, &pose);
        self.objects.push(Arc::new(SceneObject { name: name.into(), pose, body, world_aabb, triangle_base: 0 }));
        self.objects.len() - 1
    }

    /// Moves object `index` to `pose`, its cells shared, not rebuilt. False when there is no
    /// such object.
    pub fn set_pose(&mut self, index: usize, pose: Pose) -> bool {
        let Some(old) = self.objects.get(index) else { return false };
        let world_aabb = world_box(&old.body, &pose);
        let moved = SceneObject { name: old.name.clone(), pose, body: old.body.clone(), world_aabb, triangle_base: old.triangle_base };
        self.objects[index] = Arc::new(moved);
        true
    }

    /// Removes object `index` (the later ones move down by one), returning it.
    pub fn remove(&mut self, index: usize) -> Option<Arc<SceneObject>> {
        (index < self.objects.len()).then(|| self.objects.remove(index))
    }

    /// [`Scene::add_body`] for a mesh whose triangles are counted from `triangle_base` on.
    pub(crate) fn add_body_counted(&mut self, name: impl Into<String>, pose: Pose, body: Arc<ObjectBody>, triangle_base: u32) -> usize {
        let i = self.add_body(name, pose, body);
        if let Some(o) = self.objects.get_mut(i).and_then(Arc::get_mut) {
            o.triangle_base = triangle_base;
        }
        i
    }

    /// The triangle index a report gives for cell triangle `triangle` of object `object`
    /// (`u32::MAX`, a solid's or a plane's, stays).
    pub(crate) fn reported_triangle(&self, object: usize, triangle: u32) -> u32 {
        match self.objects.get(object) {
            Some(o) if triangle != u32::MAX => triangle.saturating_add(o.triangle_base),
            _ => triangle,
        }
    }

    /// The objects, in the order they were added.
    pub fn objects(&self) -> &[Arc<SceneObject>] {
        &self.objects
    }

    /// The first `count` objects of this scene, then those of `more` (shared, not copied).
    pub(crate) fn prefix_with(&self, count: usize, more: &Scene) -> Scene {
        Scene { objects: self.objects.iter().take(count).chain(&more.objects).cloned().collect() }
    }

    /// Checks one target against every object.
    ///
    /// ```
    /// use thickness_collision::collision::{CollideSettings, Scene, Target, TargetShape};
    /// use thickness_collision::math::{Pose, Vector};
    /// use thickness_collision::mesh::{generate, MeshTopology, TopologySettings};
    /// use thickness_collision::thickness::{ThicknessArea, ThicknessSettings};
    /// let (v, t) = generate::flat_grid(10, 10, 1.0, 1.0);
    /// let mesh = MeshTopology::build(&v, &t, &TopologySettings::default()).unwrap();
    /// let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }).unwrap();
    /// let mut scene = Scene::new();
    /// scene.add_surface("sheet", Pose::IDENTITY, area);
    /// // A 4 cm box wholly behind the sheet (its top 5 mm below the surface): a mesh checker
    /// // sees nothing, the cells see it 45 mm deep.
    /// let cube = TargetShape::cuboid(Vector::splat(0.02)).unwrap();
    /// let link = Target::new(cube, Pose::from_translation(Vector::new(0.5, 0.5, -0.025)));
    /// let report = scene.collide(&link, &CollideSettings::default());
    /// assert!(report.in_collision());
    /// assert!((report.deepest().unwrap().depth - 0.045).abs() < 1e-9);
    /// ```
    pub fn collide(&self, target: &Target, settings: &CollideSettings) -> TargetReport {
        self.collide_filtered(target, settings, |_| true)
    }

    /// Checks one target against the objects for which `check(object index)` is true.
    pub fn collide_filtered(&self, target: &Target, settings: &CollideSettings, check: impl Fn(usize) -> bool) -> TargetReport {
        if settings.flag_only {
            let need_sat = settings.all_contacts || settings.least_overlap;
            return self.query(target, &check, AnyHit { report: TargetReport::default(), least_overlap: need_sat }).report;
        }
        if settings.all_contacts {
            return self.query(target, &check, AllHits::default()).report;
        }
        self.query(target, &check, DeepestHit::new(settings.least_overlap)).into_report()
    }

    /// The one walk of every query: the objects for which `check(object index)` is true, whose
    /// boxes come within the collector's reach of the target's, handed to the collector until it
    /// has its answer.
    pub(crate) fn query<C: Collector>(&self, target: &Target, check: &impl Fn(usize) -> bool, mut collector: C) -> C {
        let target_aabb = target.aabb_in(&target.pose);
        for (oi, object) in self.objects.iter().enumerate() {
            let reach = collector.reach();
            if !check(oi) || !object.world_aabb.loosened(reach).intersects(&target_aabb) {
                continue;
            }
            let flow = match &*object.body {
                ObjectBody::Solid(shape) => {
                    // Bounding boxes first: GJK costs ~2 us, and most links are nowhere near.
                    let target_in_object = object.pose.inv_mul(&target.pose);
                    if !target.aabb_in(&target_in_object).loosened(reach).intersects(&shape.local_aabb()) {
                        continue;
                    }
                    collector.solid(oi, target, &object.pose, shape)
                }
                ObjectBody::Surface { area, tree } => {
                    if tree.is_empty() {
                        continue;
                    }
                    collector.surface(oi, area, tree, &TargetView::new(target, &object.pose, area.side, &target_aabb))
                }
            };
            if flow.is_break() {
                break;
            }
        }
        collector
    }

    /// Total number of cells over all thin surfaces.
    pub fn cell_count(&self) -> usize {
        self.objects.iter().filter_map(|o| o.area()).map(|a| a.cells.len()).sum()
    }
}
