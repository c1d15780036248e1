//! A `moveit_msgs/CollisionObject`'s geometry read into the world's terms: its object pose (or
//! MoveIt's "empty" pose), and its shapes in the order primitives, meshes, planes, each with its
//! pose (identity where the message gives fewer poses than shapes, as MoveIt reads it). Whatever
//! cannot be checked is refused with the object and field named; nothing is guessed.

use super::planning_world::AddObject;
use crate::checker::WorldShape;
use crate::limits::is_coordinate;
use crate::math::{Pose, Rotation, Vector};
use crate::model::MeshData;
use crate::msgs::planning_scene::{CollisionObject, SolidPrimitive};
use crate::msgs::PoseMsg;

/// Triangles one object may hold over all its meshes.
pub(crate) const MAX_OBJECT_TRIANGLES: usize = 2_000_000;

/// A pose of the message as a rigid transform, or why not (`field` names it in the error).
pub(crate) fn pose_of(msg: &PoseMsg, id: &str, field: &str) -> Result<Pose, String> {
    let (p, q) = (msg.position, msg.orientation);
    let rot = Rotation::from_xyzw(q.x, q.y, q.z, q.w);
    let v = Vector::new(p.x, p.y, p.z);
    if !v.to_array().into_iter().all(is_coordinate) || !rot.is_finite() || (rot.length() - 1.0).abs() > 1e-6 {
        return Err(format!("collision object '{id}': {field}: not a rigid pose (a finite position within 1e5 m and a unit quaternion are needed)"));
    }
    Ok(Pose::from_parts(v, rot.normalize()))
}

/// MoveIt's `isEmpty(Pose)`: zero position and the identity orientation.
fn is_empty(msg: &PoseMsg) -> bool {
    let (p, q) = (msg.position, msg.orientation);
    p.x == 0.0 && p.y == 0.0 && p.z == 0.0 && q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 1.0
}

/// The geometry of an `ADD` or `APPEND`, placed under `header` (the pose of its
/// `header.frame_id` in the world, resolved by the caller).
pub(crate) fn object_to_add(msg: &CollisionObject, header: Pose) -> Result<AddObject<WorldShape>, String> {
    let id = msg.id.as_str();
    for (what, shapes, poses) in [
        ("primitive_poses", msg.primitives.len(), msg.primitive_poses.len()),
        ("mesh_poses", msg.meshes.len(), msg.mesh_poses.len()),
        ("plane_poses", msg.planes.len(), msg.plane_poses.len()),
    ] {
        if poses > shapes {
            return Err(format!("collision object '{id}': {what}: {poses} poses for {shapes} shapes (at most one pose per shape)"));
        }
    }
    if msg.subframe_names.len() != msg.subframe_poses.len() {
        return Err(format!(
            "collision object '{id}': {} subframe_names for {} subframe_poses (one pose per name)",
            msg.subframe_names.len(),
            msg.subframe_poses.len()
        ));
    }
    let shape_pose = |poses: &[PoseMsg], k: usize, what: &str| poses.get(k).map_or(Ok(Pose::IDENTITY), |p| pose_of(p, id, &format!("{what}[{k}]")));
    let mut shapes = Vec::with_capacity(msg.primitives.len() + msg.meshes.len());
    for (k, p) in msg.primitives.iter().enumerate() {
        shapes.push((primitive(p, id, k)?, shape_pose(&msg.primitive_poses, k, "primitive_poses")?));
    }
    let mut triangles = 0;
    for (k, m) in msg.meshes.iter().enumerate() {
        triangles += m.triangles.len();
        if triangles > MAX_OBJECT_TRIANGLES {
            return Err(format!("collision object '{id}': meshes: more than {MAX_OBJECT_TRIANGLES} triangles"));
        }
        shapes.push((mesh(m, id, k)?, shape_pose(&msg.mesh_poses, k, "mesh_poses")?));
    }
    for (k, p) in msg.planes.iter().enumerate() {
        let c = p.coef;
        let normal = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        if !(c.iter().all(|x| x.is_finite()) && normal > 1e-12 && (c[3] / normal).abs() <= 1e5) {
            return Err(format!("collision object '{id}': planes[{k}].coef: {c:?} is not a plane (a finite non-zero normal, the plane within 1e5 m)"));
        }
        shapes.push((WorldShape::Plane(c), shape_pose(&msg.plane_poses, k, "plane_poses")?));
    }
    let pose = if is_empty(&msg.pose) { None } else { Some(pose_of(&msg.pose, id, "pose")?) };
    let subframes = msg
        .subframe_names
        .iter()
        .zip(&msg.subframe_poses)
        .enumerate()
        .map(|(k, (n, p))| Ok((n.clone(), pose_of(p, id, &format!("subframe_poses[{k}]"))?)))
        .collect::<Result<_, String>>()?;
    Ok(AddObject { header, pose, shapes, subframes })
}

fn primitive(p: &SolidPrimitive, id: &str, k: usize) -> Result<WorldShape, String> {
    let d = &p.dimensions;
    let need = |n: usize, what: &str| {
        if d.len() == n {
            Ok(())
        } else {
            Err(format!("collision object '{id}': primitives[{k}]: a {what} takes {n} dimensions, the message gives {}", d.len()))
        }
    };
    // The sizes URDF primitives may have: past 1e4 m contact arithmetic loses its precision,
    // below 1e-6 m a shape is degenerate.
    let [lo, hi] = crate::limits::LENGTH_RANGE;
    if let Some((i, v)) = d.iter().enumerate().find(|(_, v)| !(lo..=hi).contains(*v)) {
        return Err(format!("collision object '{id}': primitives[{k}].dimensions[{i}]: {v:?} is not a size from {lo:e} to {hi:e} m"));
    }
    let shape = match p.kind {
        SolidPrimitive::BOX => need(3, "box").map(|_| WorldShape::Box([d[0], d[1], d[2]])),
        SolidPrimitive::SPHERE => need(1, "sphere").map(|_| WorldShape::Sphere(d[0])),
        SolidPrimitive::CYLINDER => need(2, "cylinder").map(|_| WorldShape::Cylinder { height: d[0], radius: d[1] }),
        SolidPrimitive::CONE => need(2, "cone").map(|_| WorldShape::Cone { height: d[0], radius: d[1] }),
        SolidPrimitive::PRISM => {
            need(1, "prism")?;
            let polygon: Vec<[f64; 2]> = p.polygon.points.iter().map(|q| [q.x as f64, q.y as f64]).collect();
            if let Some(i) = polygon.iter().position(|[x, y]| !(x.is_finite() && y.is_finite() && x.abs() <= hi && y.abs() <= hi)) {
                return Err(format!("collision object '{id}': primitives[{k}].polygon.points[{i}]: not finite within {hi} m"));
            }
            if polygon.len() < 3 {
                return Err(format!("collision object '{id}': primitives[{k}]: a prism's polygon needs 3 points or more, the message gives {}", polygon.len()));
            }
            Ok(WorldShape::Prism { height: d[0], polygon })
        }
        other => Err(format!("collision object '{id}': primitives[{k}]: type {other} is not a shape (BOX=1, SPHERE=2, CYLINDER=3, CONE=4, PRISM=5)")),
    }?;
    Ok(shape)
}

fn mesh(m: &crate::msgs::planning_scene::ShapeMesh, id: &str, k: usize) -> Result<WorldShape, String> {
    let mut vertices = Vec::with_capacity(m.vertices.len());
    for (i, p) in m.vertices.iter().enumerate() {
        let v = Vector::new(p.x, p.y, p.z);
        if !v.to_array().into_iter().all(is_coordinate) {
            return Err(format!("collision object '{id}': meshes[{k}].vertices[{i}]: not finite within 1e5 m"));
        }
        vertices.push(v);
    }
    let n = vertices.len();
    let mut triangles = Vec::with_capacity(m.triangles.len());
    for (i, t) in m.triangles.iter().enumerate() {
        if let Some(bad) = t.vertex_indices.iter().find(|&&x| x as usize >= n) {
            return Err(format!("collision object '{id}': meshes[{k}].triangles[{i}]: vertex index {bad} of {n} vertices"));
        }
        triangles.push(t.vertex_indices);
    }
    if triangles.is_empty() {
        return Err(format!("collision object '{id}': meshes[{k}]: no triangles"));
    }
    Ok(WorldShape::Mesh(std::sync::Arc::new(MeshData { vertices, triangles })))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::planning_scene::{MeshTriangle, Point32, Polygon, ShapeMesh};
    use crate::msgs::{Point, Quaternion};

    fn pose(x: f64) -> PoseMsg {
        PoseMsg { position: Point { x, y: 0.0, z: 0.0 }, orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } }
    }

    fn primitive(kind: u8, dimensions: &[f64]) -> SolidPrimitive {
        SolidPrimitive { kind, dimensions: dimensions.to_vec(), ..Default::default() }
    }

    fn sheet() -> ShapeMesh {
        let p = |x, y| Point { x, y, z: 0.0 };
        ShapeMesh { vertices: vec![p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)], triangles: vec![MeshTriangle { vertex_indices: [0, 1, 2] }] }
    }

    /// Shapes in the order primitives, meshes, with their poses or identity where the message
    /// gives fewer; the default pose is MoveIt's empty one.
    #[test]
    fn shapes_and_poses_as_moveit_reads_them() {
        let msg = CollisionObject {
            id: "fixture".into(),
            pose: pose(0.0),
            primitives: vec![primitive(SolidPrimitive::BOX, &[0.1, 0.2, 0.3]), primitive(SolidPrimitive::CONE, &[0.4, 0.1])],
            primitive_poses: vec![pose(1.0)],
            meshes: vec![sheet()],
            ..Default::default()
        };
        let add = object_to_add(&msg, Pose::IDENTITY).unwrap();
        assert!(add.pose.is_none(), "zero position and identity orientation are MoveIt's empty pose");
        let kinds: Vec<String> = add.shapes.iter().map(|(s, _)| format!("{s:?}").split(['(', ' ']).next().unwrap_or_default().to_owned()).collect();
        assert_eq!(kinds, ["Box", "Cone", "Mesh"]);
        assert_eq!(add.shapes.iter().map(|(_, p)| p.translation.x).collect::<Vec<_>>(), [1.0, 0.0, 0.0]);
        let placed = object_to_add(&CollisionObject { pose: pose(2.0), ..msg }, Pose::IDENTITY).unwrap();
        assert_eq!(placed.pose.map(|p| p.translation.x), Some(2.0));
    }

    /// Each bad field is refused with the object and the field named.
    #[test]
    fn bad_fields_are_refused_by_name() {
        let base = CollisionObject { id: "o".into(), pose: pose(0.0), ..Default::default() };
        let refusal = |msg: CollisionObject| object_to_add(&msg, Pose::IDENTITY).err().unwrap_or_default();
        let cases: Vec<(CollisionObject, &str)> = vec![
            (
                CollisionObject { primitives: vec![primitive(SolidPrimitive::BOX, &[0.1])], ..base.clone() },
                "primitives[0]: a box takes 3 dimensions, the message gives 1",
            ),
            (CollisionObject { primitives: vec![primitive(9, &[0.1])], ..base.clone() }, "primitives[0]: type 9 is not a shape"),
            (
                CollisionObject { primitives: vec![primitive(SolidPrimitive::SPHERE, &[1e154])], ..base.clone() },
                "primitives[0].dimensions[0]: 1e154 is not a size",
            ),
            (
                CollisionObject { primitives: vec![primitive(SolidPrimitive::BOX, &[0.1, 0.0, 0.1])], ..base.clone() },
                "dimensions[1]: 0.0 is not a size from 1e-6 to 1e4 m",
            ),
            (CollisionObject { primitives: vec![primitive(SolidPrimitive::PRISM, &[0.1])], ..base.clone() }, "a prism's polygon needs 3 points"),
            (CollisionObject { primitive_poses: vec![pose(0.0)], ..base.clone() }, "primitive_poses: 1 poses for 0 shapes"),
            (CollisionObject { planes: vec![Default::default()], ..base.clone() }, "planes[0].coef: [0.0, 0.0, 0.0, 0.0] is not a plane"),
            (
                CollisionObject { meshes: vec![ShapeMesh { triangles: vec![MeshTriangle { vertex_indices: [0, 1, 7] }], ..sheet() }], ..base.clone() },
                "meshes[0].triangles[0]: vertex index 7 of 3 vertices",
            ),
            (
                CollisionObject { meshes: vec![ShapeMesh { vertices: vec![Point { x: f64::NAN, y: 0.0, z: 0.0 }; 3], ..sheet() }], ..base.clone() },
                "meshes[0].vertices[0]: not finite",
            ),
            (
                CollisionObject {
                    meshes: vec![sheet()],
                    pose: PoseMsg { orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 2.0 }, ..pose(0.0) },
                    ..base.clone()
                },
                "pose: not a rigid pose",
            ),
            (CollisionObject { meshes: vec![sheet()], subframe_names: vec!["tip".into()], ..base.clone() }, "1 subframe_names for 0 subframe_poses"),
        ];
        for (msg, needle) in cases {
            let e = refusal(msg);
            assert!(e.starts_with("collision object 'o': ") && e.contains(needle), "{e:?} should say {needle:?}");
        }
        let prism = SolidPrimitive { polygon: Polygon { points: vec![Point32::default(); 3] }, ..primitive(SolidPrimitive::PRISM, &[0.1]) };
        assert!(object_to_add(&CollisionObject { primitives: vec![prism], ..base }, Pose::IDENTITY).is_ok());
    }
}
