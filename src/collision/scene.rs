//! The environment: objects with their cells in a BVH, and the queries against them.

use super::cell_contact::{normal_axis_deeper, quick_decide, LocalPair, NormalAxis, RecentAxes};
use super::cell_tree::{transformed_box, CellTree, TargetView};
use super::gjk::{self, Verdict};
use super::report::{CollideSettings, Contact, LeastOverlap, TargetReport};
use super::sat::SatOverlap;
use super::convex_hull::MANY;
use super::target::{Target, TargetShape};
use crate::math::{Aabb, Pose, Real, Vector};
use crate::thickness::{ThicknessArea, ThicknessCell};
use parry3d_f64::bounding_volume::BoundingVolume;

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

impl SceneObject {
    /// The cells, for a thin surface.
    pub fn area(&self) -> Option<&ThicknessArea> {
        match &self.body {
            ObjectBody::Surface { area, .. } => Some(area),
            ObjectBody::Solid(_) => None,
        }
    }

    /// Its bounding box in the world.
    pub(crate) fn world_aabb(&self) -> &Aabb {
        &self.world_aabb
    }

    /// Bytes of the broad-phase tree (for memory reports); 0 for solids.
    pub fn bvh_memory(&self) -> usize {
        match &self.body {
            ObjectBody::Surface { tree, .. } => tree.memory(),
            ObjectBody::Solid(_) => 0,
        }
    }
}

/// Environment objects and the queries of convex targets against them.
#[derive(Default)]
pub struct Scene {
    objects: Vec<SceneObject>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Scene {
        Scene::default()
    }

    /// Adds a thin surface whose cells are given in the object's frame, placed at `pose` in the
    /// world. Returns the object's index.
    /// The area's cells are reordered for the broad phase (see [`CellTree::build`]).
    pub fn add_surface(&mut self, name: impl Into<String>, pose: Pose, mut area: ThicknessArea) -> usize {
        let tree = CellTree::build(&mut area.cells);
        let world_aabb = if tree.is_empty() { Aabb::new_invalid() } else { transformed_box(&tree.root_aabb(), &pose) };
        self.objects.push(SceneObject { name: name.into(), pose, body: ObjectBody::Surface { area, tree }, world_aabb });
        self.objects.len() - 1
    }

    /// Adds a convex solid placed at `pose` in the world. Returns the object's index.
    pub fn add_solid(&mut self, name: impl Into<String>, pose: Pose, shape: TargetShape) -> usize {
        let world_aabb = transformed_box(&shape.local_aabb(), &pose);
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
        let rot = target.pose.rotation;
        let mut deepest: Option<Contact> = None;
        let target_aabb = target.aabb_in(&target.pose);
        for (oi, object) in self.objects.iter().enumerate() {
            if !check(oi) || !object.world_aabb.intersects(&target_aabb) {
                continue;
            }
            let (area, tree) = match &object.body {
                ObjectBody::Surface { area, tree } => (area, tree),
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
                        } else if deepest.as_ref().is_none_or(|d| contact.depth > d.depth) {
                            deepest = Some(contact);
                        }
                    }
                    continue;
                }
            };
            if tree.is_empty() {
                continue;
            }
            let view = TargetView::new(target, &object.pose, area.side, &target_aabb);
            let pos12 = view.object_in_target;
            let side = area.side;
            let mut recent = RecentAxes::default();
            let mut hit_object = false;
            if settings.flag_only || settings.all_contacts {
                // Every cell that can meet the target, depth first through the tree, the child
                // nearer the target's centre first: a yes/no question ends at the first cell that
                // collides, most likely under the target (on the motion benchmark, where most
                // such questions are asked, a test that hit cost ~24 µs walking the tree left
                // first).
                let mut stack: Vec<u32> = Vec::with_capacity(64);
                if tree.bound(0, &view).is_some() {
                    stack.push(0);
                }
                while let Some(node) = stack.pop() {
                    if let Some(children) = tree.children(node) {
                        let boxes = children.map(|child| tree.node_box(child));
                        let keep = boxes.map(|(centre, half)| !recent.separate_box(centre, half));
                        let [a, b] = tree.bounds(children, keep, &view);
                        let mut next = [(Real::NEG_INFINITY, 0u32); 2];
                        let mut n = 0;
                        for ((child, bound), (centre, _)) in children.into_iter().zip([a, b]).zip(boxes) {
                            if bound.is_some() {
                                tree.prefetch(child);
                                next[n] = (-(centre - view.centre).length_squared(), child);
                                n += 1;
                            }
                        }
                        if n == 2 && next[0].0 > next[1].0 {
                            next.swap(0, 1);
                        }
                        stack.extend(next.into_iter().take(n).map(|(_, child)| child));
                        continue;
                    }
                    for (index, slab) in tree.leaf_cells(node) {
                        report.candidates += 1;
                        if !CellTree::slab_meets_target_box(slab, &view) || recent.separate_box(slab.centre(), slab.half()) {
                            continue;
                        }
                        let Some((push, depth)) = normal_axis_deeper(target, slab, side, &view.rotation, pos12.translation, Real::NEG_INFINITY) else {
                            continue;
                        };
                        let cell = &area.cells[index as usize];
                        let (hit, sat) = decide(&view, cell, &mut recent, settings.all_contacts || settings.least_overlap);
                        if !hit {
                            continue;
                        }
                        hit_object = true;
                        let least = sat.map(|s| LeastOverlap { overlap: s.overlap, axis: rot * s.axis });
                        let mut contact = Contact { object: oi, triangle: cell.triangle, depth, normal: rot * push, position: None, least };
                        if settings.flag_only {
                            // A yes/no question: the first cell that collides answers it.
                            report.objects.push(oi);
                            report.contacts.push(contact);
                            return report;
                        }
                        contact.position = LocalPair::new(target, cell, &pos12).point(push).map(|p| target.pose * p);
                        report.contacts.push(contact);
                    }
                }
            } else if let Some((depth, leaf, push, sat)) = deepest_cell(tree, area, &view, &mut report.candidates, settings.least_overlap) {
                hit_object = true;
                if deepest.as_ref().is_none_or(|d| depth > d.depth) {
                    let cell = &area.cells[leaf as usize];
                    let position = LocalPair::new(target, cell, &pos12).point(push).map(|p| target.pose * p);
                    let least = sat.map(|s| LeastOverlap { overlap: s.overlap, axis: rot * s.axis });
                    deepest = Some(Contact { object: oi, triangle: cell.triangle, depth, normal: rot * push, position, least });
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
}

/// A target against a convex solid, with parry's GJK/EPA: the depth is the penetration depth, the
/// normal the direction that pushes the target out, the point midway between the two witnesses.
fn collide_solid(target: &Target, object: usize, object_pose: &Pose, shape: &TargetShape) -> Option<Contact> {
    let c = target
        .shape
        .with_parry(|s1, o1| shape.with_parry(|s2, o2| parry3d_f64::query::contact(&(target.pose * *o1), s1, &(*object_pose * *o2), s2, 0.0).ok().flatten()))?;
    if !(c.dist < 0.0) {
        return None;
    }
    let normal = -c.normal1;
    Some(Contact {
        object,
        triangle: u32::MAX,
        depth: -c.dist,
        normal,
        position: Some((c.point1 + c.point2) * 0.5),
        least: Some(LeastOverlap { overlap: -c.dist, axis: normal }),
    })
}

/// How much deeper than the deepest contact found a subtree's bound must be to be searched: the
/// reported contact is the deepest to within this (metres), and flat patches, whose bound equals
/// their depth up to rounding, are not searched again and again.
const DEPTH_TOLERANCE: Real = 1e-9;

/// A node waiting in the search, with the bound on its cells' depths.
struct Pending(Real, u32);

/// The deepest colliding cell of one surface: `(depth, cell index, push-out normal, SAT result)`
/// in the target's frame. Depth first, the child with the deeper bound first, and a subtree is
/// skipped when its bound cannot beat the deepest collision found. (A best-first search with a
/// heap, which stops at the first bound that cannot, measured 2 % slower on the Panda benchmark:
/// with these bounds it expands nearly the same nodes, and pays for the heap.) Pairs are decided by
/// [`decide`]'s quick tests and GJK where they can; with `least_overlap` the winner's full SAT
/// gives its least overlap (and, were it to disagree with them, the search is run again with the
/// SAT alone deciding).
fn deepest_cell(
    tree: &CellTree,
    area: &ThicknessArea,
    view: &TargetView,
    candidates: &mut usize,
    least_overlap: bool,
) -> Option<(Real, u32, Vector, Option<SatOverlap>)> {
    let (depth, leaf, push, sat) = deepest_search(tree, area, view, candidates, true)?;
    if sat.is_some() || !least_overlap {
        return Some((depth, leaf, push, sat));
    }
    if let Some(sat) = LocalPair::new(view.target, &area.cells[leaf as usize], &view.object_in_target).sat() {
        return Some((depth, leaf, push, Some(sat)));
    }
    // A quick verdict and the SAT disagreed (rounding on a razor-thin overlap): search again
    // with the SAT alone deciding.
    deepest_search(tree, area, view, candidates, false)
}

fn deepest_search(
    tree: &CellTree,
    area: &ThicknessArea,
    view: &TargetView,
    candidates: &mut usize,
    quick: bool,
) -> Option<(Real, u32, Vector, Option<SatOverlap>)> {
    let mut best: Option<(Real, u32, Vector, Option<SatOverlap>)> = None;
    let mut best_depth = Real::NEG_INFINITY;
    let mut stack: Vec<Pending> = Vec::with_capacity(64);
    if let Some(b) = tree.bound(0, view) {
        stack.push(Pending(b, 0));
    }
    let mut leaf_hits: Vec<(Real, u32, Vector)> = Vec::with_capacity(8);
    let mut recent = RecentAxes::default();
    while let Some(Pending(bound, node)) = stack.pop() {
        if bound <= best_depth + DEPTH_TOLERANCE {
            continue;
        }
        if let Some(children) = tree.children(node) {
            let mut next = [Pending(Real::NEG_INFINITY, 0), Pending(Real::NEG_INFINITY, 0)];
            let mut n = 0;
            let keep = children.map(|child| {
                let (centre, half) = tree.node_box(child);
                !recent.separate_box(centre, half)
            });
            for (child, bound) in children.into_iter().zip(tree.bounds(children, keep, view)) {
                if let Some(b) = bound {
                    if b > best_depth + DEPTH_TOLERANCE {
                        tree.prefetch(child);
                        next[n] = Pending(b, child);
                        n += 1;
                    }
                }
            }
            // The deeper bound on top of the stack.
            if n == 2 && next[0].0 > next[1].0 {
                next.swap(0, 1);
            }
            stack.extend(next.into_iter().take(n));
            continue;
        }
        leaf_hits.clear();
        let leaf = tree.leaf_view(node, view);
        // The cells that pass their bound and boxes, then their support queries together (a
        // leaf holds at most MANY cells: `cell_tree` asserts it).
        let mut axes = [(0u32, NormalAxis::default()); MANY];
        let mut dirs = [Vector::ZERO; MANY];
        let mut count = 0;
        for (index, slab) in tree.leaf_cells(node) {
            *candidates += 1;
            if slab.depth_bound(&leaf) <= best_depth + DEPTH_TOLERANCE {
                continue;
            }
            if !CellTree::slab_meets_target_box(slab, view) || recent.separate_box(slab.centre(), slab.half()) {
                continue;
            }
            let axis = NormalAxis::new(view.target, slab, area.side, &view.rotation, view.object_in_target.translation);
            dirs[count] = axis.first_query();
            axes[count] = (index, axis);
            count += 1;
        }
        let mut supports = [0.0; MANY];
        view.target.shape.support_many(&dirs[..count], &mut supports[..count]);
        for ((index, axis), first) in axes[..count].iter().zip(supports) {
            if let Some((push, depth)) = axis.finish(view.target, first, best_depth + DEPTH_TOLERANCE) {
                leaf_hits.push((depth, *index, push));
            }
        }
        // Deepest first: the first that collides is the leaf's deepest contact. Picked one by
        // one, as the first pick usually settles the leaf.
        while let Some(k) = (0..leaf_hits.len()).max_by(|&a, &b| leaf_hits[a].0.total_cmp(&leaf_hits[b].0)) {
            let (depth, leaf, push) = leaf_hits.swap_remove(k);
            let cell = &area.cells[leaf as usize];
            let (hit, sat) = decide(view, cell, &mut recent, !quick);
            if hit {
                best = Some((depth, leaf, push, sat));
                best_depth = depth;
                break;
            }
        }
    }
    best
}

/// Whether a target and a cell whose normal axis does not separate them collide. Quick tests
/// first ([`quick_decide`]), then for hulls a GJK whose verdicts carry their proofs
/// ([`gjk::hull_cell`]); the SAT when neither can tell, or to confirm a "yes" when `need_sat` (its
/// least overlap is wanted). Separating axes found are remembered in `recent`. Returns the
/// verdict and the SAT's result when it ran.
fn decide(view: &TargetView, cell: &ThicknessCell, recent: &mut RecentAxes, need_sat: bool) -> (bool, Option<SatOverlap>) {
    match quick_decide(view, cell, recent) {
        Some(false) => return (false, None),
        Some(true) if !need_sat => return (true, None),
        _ => {}
    }
    // A separating axis (target frame) found below, kept for the neighbouring cells.
    let mut remember = |axis: Vector| {
        let axis = view.object_in_target.rotation.inverse() * axis;
        recent.remember(axis, view.extent_along(axis));
    };
    if let TargetShape::Polytope(hull) = &view.target.shape {
        match gjk::hull_cell(hull, &cell.vertices().map(|v| view.object_in_target * v)) {
            // With `need_sat` the SAT below confirms it and gives the least overlap.
            Verdict::Overlap if !need_sat => return (true, None),
            Verdict::Overlap | Verdict::Unknown => {}
            Verdict::Apart(axis) => {
                remember(axis.normalize());
                return (false, None);
            }
        }
    }
    match LocalPair::new(view.target, cell, &view.object_in_target).sat_or_axis() {
        Ok(sat) => (true, Some(sat)),
        Err(separating) => {
            if let Some(axis) = separating {
                remember(axis);
            }
            (false, None)
        }
    }
}
