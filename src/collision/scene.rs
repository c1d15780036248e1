//! The environment: objects with their cells in a BVH, and the queries against them.

use super::cell_contact::{normal_axis, LocalPair};
use super::report::{CollideSettings, Contact, TargetReport};
use super::target::{Target, TargetShape};
use crate::math::{Aabb, Pose, Real, Vector};
use crate::thickness::ThicknessArea;
use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};

/// What an environment object is made of.
pub enum ObjectBody {
    /// A thin surface: its cells in a BVH.
    Surface {
        /// The cells, in the object's frame.
        area: ThicknessArea,
        /// Broad phase over the cells' bounding boxes.
        bvh: Bvh,
    },
    /// A convex solid (a URDF primitive or a mesh checked as its hull), checked with parry's
    /// GJK/EPA; its contacts have `triangle = u32::MAX`.
    Solid(TargetShape),
}

/// One environment object, fixed in the world.
pub struct SceneObject {
    /// The object's name (reported in contacts).
    pub name: String,
    /// The pose of the object's frame in the world.
    pub pose: Pose,
    /// Its geometry.
    pub body: ObjectBody,
    /// Its bounding box in the world (a first, cheap reject per target).
    world_aabb: Aabb,
}

/// The world box of a box given in a frame posed at `pose`.
fn transformed_aabb(local: &Aabb, pose: &Pose) -> Aabb {
    let c = *pose * local.center();
    let h = local.half_extents();
    let m = parry3d_f64::math::Matrix::from_quat(pose.rotation);
    let e = Vector::new(m.row(0).abs().dot(h), m.row(1).abs().dot(h), m.row(2).abs().dot(h));
    Aabb::new(c - e, c + e)
}

impl SceneObject {
    /// The cells, for a thin surface.
    pub fn area(&self) -> Option<&ThicknessArea> {
        match &self.body {
            ObjectBody::Surface { area, .. } => Some(area),
            ObjectBody::Solid(_) => None,
        }
    }

    /// Bytes of the BVH (for memory reports); 0 for solids.
    pub fn bvh_memory(&self) -> usize {
        match &self.body {
            ObjectBody::Surface { bvh, .. } => bvh.total_memory_size(),
            ObjectBody::Solid(_) => 0,
        }
    }
}

/// Environment objects and the queries of convex targets against them.
#[derive(Default)]
pub struct Scene {
    objects: Vec<SceneObject>,
}

/// The bounding box of a cell; parry's BVH compares with `<=`, so no rounding is needed in f64.
fn cell_aabb(cell: &crate::thickness::ThicknessCell) -> Aabb {
    let v = cell.vertices();
    let (lo, hi) = v.iter().fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    Aabb::new(lo, hi)
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Scene {
        Scene::default()
    }

    /// Adds a thin surface whose cells are given in the object's frame, placed at `pose` in the
    /// world. Returns the object's index.
    pub fn add_surface(&mut self, name: impl Into<String>, pose: Pose, area: ThicknessArea) -> usize {
        let aabbs: Vec<Aabb> = area.cells.iter().map(cell_aabb).collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
        let world_aabb = if aabbs.is_empty() { Aabb::new_invalid() } else { transformed_aabb(&bvh.root_aabb(), &pose) };
        self.objects.push(SceneObject { name: name.into(), pose, body: ObjectBody::Surface { area, bvh }, world_aabb });
        self.objects.len() - 1
    }

    /// Adds a convex solid placed at `pose` in the world. Returns the object's index.
    pub fn add_solid(&mut self, name: impl Into<String>, pose: Pose, shape: TargetShape) -> usize {
        let world_aabb = transformed_aabb(&shape.local_aabb(), &pose);
        self.objects.push(SceneObject { name: name.into(), pose, body: ObjectBody::Solid(shape), world_aabb });
        self.objects.len() - 1
    }

    /// The objects, in the order they were added.
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
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
        let mut report = TargetReport::default();
        let nan = Vector::splat(Real::NAN);
        let rot = target.pose.rotation;
        let mut deepest: Option<Contact> = None;
        // Candidates that the normal axis does not separate: (depth if colliding, cell index).
        let mut survivors: Vec<(Real, u32, Vector)> = Vec::new();
        let target_aabb = target.aabb_in(&target.pose);
        for (oi, object) in self.objects.iter().enumerate() {
            if !check(oi) || !object.world_aabb.intersects(&target_aabb) {
                continue;
            }
            let (area, bvh) = match &object.body {
                ObjectBody::Surface { area, bvh } => (area, bvh),
                ObjectBody::Solid(shape) => {
                    // Bounding boxes first: GJK costs ~2 us, and most links are nowhere near.
                    let target_in_object = object.pose.inv_mul(&target.pose);
                    if !target.aabb_in(&target_in_object).intersects(&shape.local_aabb()) {
                        continue;
                    }
                    report.candidates += 1;
                    if let Some(contact) = collide_solid(target, oi, &object.pose, shape) {
                        report.objects.push(oi);
                        if settings.flag_only {
                            report.contacts.push(contact);
                            return report;
                        }
                        if settings.all_contacts {
                            report.contacts.push(contact);
                        } else if deepest.as_ref().map_or(true, |d| contact.depth > d.depth) {
                            deepest = Some(contact);
                        }
                    }
                    continue;
                }
            };
            let target_in_object = object.pose.inv_mul(&target.pose);
            let object_in_target = target_in_object.inverse();
            let aabb = target.aabb_in(&target_in_object);
            let side = area.side;
            survivors.clear();
            let mut hint = [u32::MAX; 2];
            for leaf in bvh.intersect_aabb(&aabb) {
                report.candidates += 1;
                if let Some((push, depth)) = normal_axis(target, &area.cells[leaf as usize], side, &object_in_target, &mut hint) {
                    if settings.flag_only {
                        // A yes/no question: the first cell that collides answers it.
                        let cell = &area.cells[leaf as usize];
                        if let Some(sat) = LocalPair::new(target, cell, &object_in_target).sat() {
                            let nan = Vector::splat(Real::NAN);
                            report.objects.push(oi);
                            report.contacts.push(Contact { object: oi, triangle: cell.triangle, depth, normal: target.pose.rotation * push, position: nan, overlap: sat.overlap, axis: target.pose.rotation * sat.axis });
                            return report;
                        }
                        continue;
                    }
                    survivors.push((depth, leaf, push));
                }
            }
            if !settings.all_contacts {
                // Deepest first: the first colliding cell is this object's deepest contact, and
                // cells shallower than the deepest found so far need no SAT once the object is
                // known to collide. On a link pushed through a wall this skips ~99% of the SATs.
                survivors.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
            }
            let mut hit_object = false;
            for &(depth, leaf, push) in &survivors {
                let cell = &area.cells[leaf as usize];
                let pair = LocalPair::new(target, cell, &object_in_target);
                let Some(sat) = pair.sat() else { continue };
                hit_object = true;
                let mut contact = Contact { object: oi, triangle: cell.triangle, depth, normal: rot * push, position: nan, overlap: sat.overlap, axis: rot * sat.axis };
                if settings.all_contacts {
                    contact.position = pair.point(push).map_or(nan, |p| target.pose * p);
                    report.contacts.push(contact);
                } else {
                    if deepest.as_ref().map_or(true, |d| depth > d.depth) {
                        contact.position = pair.point(push).map_or(nan, |p| target.pose * p);
                        deepest = Some(contact);
                    }
                    break;
                }
            }
            if hit_object {
                report.objects.push(oi);
            }
        }
        report.contacts.extend(deepest);
        report
    }

    /// Total number of cells over all thin surfaces.
    pub fn cell_count(&self) -> usize {
        self.objects.iter().filter_map(|o| o.area()).map(|a| a.cells.len()).sum()
    }

    /// Checks several targets (one report each, in order).
    pub fn collide_many(&self, targets: &[Target], settings: &CollideSettings) -> Vec<TargetReport> {
        targets.iter().map(|t| self.collide(t, settings)).collect()
    }
}

/// A target against a convex solid, with parry's GJK/EPA: the depth is the penetration depth, the
/// normal the direction that pushes the target out, the point midway between the two witnesses.
fn collide_solid(target: &Target, object: usize, object_pose: &Pose, shape: &TargetShape) -> Option<Contact> {
    let c = target.shape.with_parry(|s1, o1| {
        shape.with_parry(|s2, o2| parry3d_f64::query::contact(&(target.pose * *o1), s1, &(*object_pose * *o2), s2, 0.0).ok().flatten())
    })?;
    if !(c.dist < 0.0) {
        return None;
    }
    let normal = -c.normal1;
    Some(Contact { object, triangle: u32::MAX, depth: -c.dist, normal, position: (c.point1 + c.point2) * 0.5, overlap: -c.dist, axis: normal })
}
