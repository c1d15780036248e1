//! The shapes of planning-scene objects as the checks see them: each object exactly as an
//! environment URDF link of its id would be (a mesh with a boundary is a thin surface with cells,
//! with `thin_surfaces`' thickness and side for its id; a closed mesh named in `solid_hull` is
//! its hull; primitives are solids).

use super::checker::BuildSummary;
use super::checker_build::environment_mesh_body;
use super::geometry_shapes::primitive_shape;
use crate::collision::{ConvexHull, ObjectBody, Scene, TargetShape};
use crate::math::{Pose, Vector};
use crate::model::{GeometrySpec, MeshData, Params};
use crate::thickness::Side;
use std::sync::Arc;

/// A shape of a planning-scene object, as `shape_msgs` define it (metres, in the shape's frame,
/// centred on its bounding box).
#[derive(Clone, Debug)]
pub(crate) enum WorldShape {
    /// Full side lengths.
    Box([f64; 3]),
    Sphere(f64),
    /// Along z.
    Cylinder {
        height: f64,
        radius: f64,
    },
    /// Along z, its tip at `+height / 2`.
    Cone {
        height: f64,
        radius: f64,
    },
    /// The polygon (x, y, counter-clockwise) extruded by `height / 2` both ways along z.
    Prism {
        height: f64,
        polygon: Vec<[f64; 2]>,
    },
    /// Triangles whose front is the side their vertices wind counter-clockwise around (shared:
    /// a moved object keeps its mesh, and the cells built for it).
    Mesh(Arc<MeshData>),
    /// `shape_msgs/Plane`: the points `x` with `a x + b y + c z + d = 0`, its front the side
    /// `(a, b, c)` points to; a thin surface without an edge near the robot (see [`plane_mesh`]).
    Plane([f64; 4]),
}

/// Half the side of the square that stands for an infinite plane (metres): 10 km, so every
/// point a robot reaches within 1e4 m of the plane's foot point sees no edge, while the cells'
/// arithmetic keeps its precision (1e4 m x 1e-16).
pub(crate) const PLANE_HALF_SIDE: f64 = 1e4;

/// A plane as two triangles winding counter-clockwise around its normal: the square of
/// [`PLANE_HALF_SIDE`] centred on the plane's point nearest the shape's origin. `None` for a
/// normal that is zero or not finite.
pub(crate) fn plane_mesh(coef: &[f64; 4]) -> Option<MeshData> {
    let n = Vector::new(coef[0], coef[1], coef[2]);
    let len = n.length();
    if !(len.is_finite() && len > 1e-12 && coef[3].is_finite()) {
        return None;
    }
    let n = n / len;
    let foot = -n * (coef[3] / len);
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let h = PLANE_HALF_SIDE;
    let vertices = vec![foot - u * h - v * h, foot + u * h - v * h, foot + u * h + v * h, foot - u * h + v * h];
    Some(MeshData { vertices, triangles: vec![[0, 1, 2], [0, 2, 3]] })
}

/// Corners of the polygon around a cone's base: circumscribed, so that the hull holds the cone
/// (it reaches at most `radius * (1 / cos(pi / 64) - 1)`, 0.12 % of the radius, beyond it).
const CONE_SIDES: usize = 64;

/// What decides a mesh's body besides its triangles: thickness, side, and whether it is a hull.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BodySettings {
    thickness: f64,
    side: Side,
    hull: bool,
}

struct CachedBody {
    mesh: Arc<MeshData>,
    hash: u64,
    settings: BodySettings,
    body: Arc<ObjectBody>,
    used: bool,
}

/// The bodies built for planning-scene meshes, found again by the mesh (the same one, or one of
/// the same content) and the settings that decide them, so that moving an object, or adding it
/// again with the same geometry as `move_group` does after a move, builds no cells. Holds only
/// the bodies of the scene in force (see [`BodyCache::keep_used`]).
#[derive(Default)]
pub(crate) struct BodyCache {
    entries: Vec<CachedBody>,
    /// Bodies built (not found) since the cache was made: what a test of the cache counts.
    pub(crate) built: usize,
}

impl BodyCache {
    /// The body for `mesh` under `settings`, built now if no entry has it.
    fn body(&mut self, params: &Params, id: &str, mesh: &Arc<MeshData>, summary: &mut BuildSummary) -> Result<Arc<ObjectBody>, String> {
        let (thickness, side) = params.surface_settings(id);
        let settings = BodySettings { thickness, side, hull: params.is_solid_hull(id) };
        let same = self.entries.iter().position(|e| e.settings == settings && Arc::ptr_eq(&e.mesh, mesh));
        let hash = mesh_hash(mesh);
        let found = same.or_else(|| self.entries.iter().position(|e| e.settings == settings && e.hash == hash && *e.mesh == **mesh));
        if let Some(i) = found {
            let entry = &mut self.entries[i];
            entry.used = true;
            count(&entry.body, summary);
            return Ok(Arc::clone(&entry.body));
        }
        let body = Arc::new(environment_mesh_body(params, id, mesh, summary)?);
        self.built += 1;
        self.entries.push(CachedBody { mesh: Arc::clone(mesh), hash, settings, body: Arc::clone(&body), used: true });
        Ok(body)
    }

    /// Forgets the bodies no build used since the last call, and starts the next round.
    pub(crate) fn keep_used(&mut self) {
        self.entries.retain(|e| e.used);
        for e in &mut self.entries {
            e.used = false;
        }
    }
}

/// A plane's body: the cells of [`plane_mesh`], with the thickness and side of the object's id,
/// each cell's triangle `u32::MAX` (a plane has no triangles of its own).
fn plane_body(params: &Params, id: &str, coef: &[f64; 4], summary: &mut BuildSummary) -> Option<ObjectBody> {
    let mut body = environment_mesh_body(params, id, &plane_mesh(coef)?, summary).ok()?;
    if let ObjectBody::Surface { area, .. } = &mut body {
        for cell in &mut area.cells {
            cell.triangle = u32::MAX;
        }
    }
    Some(body)
}

/// A body found in the cache counts in the summary as if it had been built.
fn count(body: &ObjectBody, summary: &mut BuildSummary) {
    match body {
        ObjectBody::Surface { area, .. } => {
            summary.thin_surfaces += 1;
            summary.cells += area.cells.len();
        }
        ObjectBody::Solid(_) => summary.solids += 1,
    }
}

/// A hash of a mesh's content (the bits of its coordinates and its indices): a few hundred
/// microseconds for 100,000 triangles, against the tens of milliseconds its cells cost.
fn mesh_hash(mesh: &MeshData) -> u64 {
    let mut h: u64 = mesh.vertices.len() as u64 ^ ((mesh.triangles.len() as u64) << 32);
    let mut mix = |x: u64| h = (h.rotate_left(5) ^ x).wrapping_mul(0x517c_c1b7_2722_0a95);
    for v in &mesh.vertices {
        mix(v.x.to_bits());
        mix(v.y.to_bits());
        mix(v.z.to_bits());
    }
    for t in &mesh.triangles {
        mix(u64::from(t[0]) | (u64::from(t[1]) << 32));
        mix(u64::from(t[2]));
    }
    h
}

/// Adds one object's shapes to `scene` under the object's id, at `object_pose` and each shape's
/// pose relative to it, a mesh's body from `cache` when it holds it. The error is what is wrong
/// with a shape, naming it by its index.
pub(crate) fn add_world_object(
    params: &Params,
    scene: &mut Scene,
    cache: &mut BodyCache,
    id: &str,
    object_pose: &Pose,
    shapes: &[(WorldShape, Pose)],
    summary: &mut BuildSummary,
) -> Result<(), String> {
    // `triangle` counts over the object's meshes in order (at most 2,000,000 in all).
    let mut triangles = 0u32;
    for (k, (shape, pose)) in shapes.iter().enumerate() {
        let pose = *object_pose * *pose;
        if let WorldShape::Mesh(data) = shape {
            let body = cache.body(params, id, data, summary).map_err(|e| format!("shape {k} (a mesh): {e}"))?;
            let _ = scene.add_body_counted(id.to_owned(), pose, body, triangles);
            triangles = triangles.saturating_add(u32::try_from(data.triangles.len()).unwrap_or(u32::MAX));
            continue;
        }
        if let WorldShape::Plane(coef) = shape {
            let body = plane_body(params, id, coef, summary).ok_or_else(|| format!("shape {k} (a plane): not a plane (its normal is zero or not finite)"))?;
            let _ = scene.add_body(id.to_owned(), pose, Arc::new(body));
            continue;
        }
        let solid = solid(shape).ok_or_else(|| format!("shape {k} ({shape_kind}): not a usable convex shape", shape_kind = kind(shape)))?;
        let _ = scene.add_solid(id.to_owned(), pose, solid);
        summary.solids += 1;
    }
    Ok(())
}

fn kind(shape: &WorldShape) -> &'static str {
    match shape {
        WorldShape::Box(_) => "a box",
        WorldShape::Sphere(_) => "a sphere",
        WorldShape::Cylinder { .. } => "a cylinder",
        WorldShape::Cone { .. } => "a cone",
        WorldShape::Prism { .. } => "a prism",
        WorldShape::Mesh(_) => "a mesh",
        WorldShape::Plane(_) => "a plane",
    }
}

/// A shape of an attached object as a robot link's part: a mesh as the hull of its vertices,
/// every shape grown by `padding`; `None` when it is not a usable convex shape.
pub(crate) fn attached_part(shape: &WorldShape, padding: f64) -> Option<TargetShape> {
    let grown = |hull: Option<ConvexHull>| hull.and_then(|h| h.padded(padding)).map(|h| TargetShape::Polytope(Arc::new(h)));
    match shape {
        WorldShape::Box(size) => primitive_shape(&GeometrySpec::Box(*size), padding),
        WorldShape::Sphere(r) => primitive_shape(&GeometrySpec::Sphere(*r), padding),
        WorldShape::Cylinder { height, radius } => primitive_shape(&GeometrySpec::Cylinder { radius: *radius, length: *height }, padding),
        WorldShape::Mesh(m) => grown(ConvexHull::from_points(&m.vertices)),
        WorldShape::Plane(_) => None,
        WorldShape::Cone { .. } | WorldShape::Prism { .. } => match solid(shape)? {
            TargetShape::Polytope(h) => grown(Some((*h).clone())),
            _ => None,
        },
    }
}

/// A primitive as a solid; `None` when its sizes are not positive and finite (a prism's polygon
/// is taken as its convex hull).
fn solid(shape: &WorldShape) -> Option<TargetShape> {
    let hull = |points: Vec<Vector>| ConvexHull::from_points(&points).map(|h| TargetShape::Polytope(Arc::new(h)));
    match shape {
        WorldShape::Box(size) => primitive_shape(&GeometrySpec::Box(*size), 0.0),
        WorldShape::Sphere(r) => primitive_shape(&GeometrySpec::Sphere(*r), 0.0),
        WorldShape::Cylinder { height, radius } => primitive_shape(&GeometrySpec::Cylinder { radius: *radius, length: *height }, 0.0),
        WorldShape::Cone { height, radius } => {
            if !(*height > 0.0 && *radius > 0.0 && height.is_finite() && radius.is_finite()) {
                return None;
            }
            let out = radius / (std::f64::consts::PI / CONE_SIDES as f64).cos();
            let mut points: Vec<Vector> = (0..CONE_SIDES)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / CONE_SIDES as f64;
                    Vector::new(out * a.cos(), out * a.sin(), -height / 2.0)
                })
                .collect();
            points.push(Vector::new(0.0, 0.0, height / 2.0));
            hull(points)
        }
        WorldShape::Prism { height, polygon } => {
            if !(*height > 0.0 && height.is_finite()) || polygon.iter().flatten().any(|x| !x.is_finite()) {
                return None;
            }
            hull(polygon.iter().flat_map(|[x, y]| [Vector::new(*x, *y, -height / 2.0), Vector::new(*x, *y, height / 2.0)]).collect())
        }
        WorldShape::Mesh(_) | WorldShape::Plane(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::super::checker_build::add_environment_mesh;
    use super::*;
    use crate::collision::{CollideSettings, Target};
    use crate::mesh::generate;

    /// An object made of a box and an open mesh gives, for random targets, the same contacts as
    /// the environment link of the same name and geometry (its box a URDF primitive, its mesh
    /// read as a mesh file would be): the same objects, depths, normals and points.
    #[test]
    fn an_object_is_checked_as_the_environment_link_of_its_id() {
        let params = Params::default();
        let (v, t) = generate::flat_grid(8, 8, 1.0, 1.0);
        let mesh = MeshData { vertices: v.clone(), triangles: t.clone() };
        let object_pose = Pose::from_translation(Vector::new(0.3, -0.2, 0.1));
        let box_pose = Pose::from_translation(Vector::new(0.0, 0.0, 0.5));
        let shapes = [(WorldShape::Box([0.2, 0.3, 0.4]), box_pose), (WorldShape::Mesh(Arc::new(mesh.clone())), Pose::IDENTITY)];
        let mut world = Scene::new();
        let mut summary = BuildSummary::default();
        add_world_object(&params, &mut world, &mut BodyCache::default(), "shelf", &object_pose, &shapes, &mut summary).unwrap();
        assert_eq!((summary.solids, summary.thin_surfaces, summary.cells), (1, 1, t.len()));
        // The twin: what an environment link "shelf" with a box and that mesh builds.
        let mut twin = Scene::new();
        let _ = twin.add_solid("shelf", object_pose * box_pose, primitive_shape(&GeometrySpec::Box([0.2, 0.3, 0.4]), 0.0).unwrap());
        add_environment_mesh(&params, &mut twin, "shelf", object_pose, &mesh, &mut BuildSummary::default()).unwrap();
        let mut rng = oorandom::Rand64::new(32);
        let mut r = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let mut colliding = 0;
        for _ in 0..400 {
            let at = Vector::new(r(0.2, 1.4), r(-0.3, 0.9), r(-0.1, 0.7));
            let target = Target::new(TargetShape::cuboid(Vector::new(r(0.01, 0.1), r(0.01, 0.1), r(0.01, 0.1))).unwrap(), Pose::from_translation(at));
            let (a, b) = (world.collide(&target, &CollideSettings::default()), twin.collide(&target, &CollideSettings::default()));
            assert_eq!((&a.objects, &a.contacts), (&b.objects, &b.contacts), "at {at:?}");
            colliding += a.in_collision() as usize;
        }
        assert!(colliding > 40 && colliding < 360, "{colliding} of 400 collide: the cases must mix");
    }

    /// A cone's hull holds the cone and lies within 0.2 % of its radius of it; a prism's hull is
    /// its polygon extruded; bad sizes are refused, naming the shape.
    #[test]
    fn cones_and_prisms_become_hulls() {
        let cone = solid(&WorldShape::Cone { height: 0.4, radius: 0.1 }).unwrap();
        let TargetShape::Polytope(h) = &cone else { panic!("a cone is a hull") };
        for p in h.points() {
            assert!((p.z - 0.2).abs() < 1e-12 || (p.z + 0.2).abs() < 1e-12, "{p:?}");
            let r = p.truncate().length();
            assert!(r < 1e-12 || (r > 0.1 && r < 0.1002), "{p:?}");
        }
        let prism = solid(&WorldShape::Prism { height: 0.2, polygon: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] }).unwrap();
        assert_eq!(prism.local_aabb().maxs, Vector::new(1.0, 1.0, 0.1));
        let mut scene = Scene::new();
        let e = add_world_object(
            &Params::default(),
            &mut scene,
            &mut BodyCache::default(),
            "x",
            &Pose::IDENTITY,
            &[(WorldShape::Sphere(-1.0), Pose::IDENTITY)],
            &mut BuildSummary::default(),
        );
        assert_eq!(e, Err("shape 0 (a sphere): not a usable convex shape".to_owned()));
    }
}
