//! RViz / Foxglove markers of the thin surfaces' cells and of a report's contacts. The node
//! publishes them live and replay writes them into its output bag: one builder for both, so a
//! recording looks like the running node.

use crate::checker::{Checker, StateReport};
use crate::collision::{ObjectBody, TargetShape};
use crate::msgs::{ColorRgba, DurationMsg, Header, Marker, MarkerArray, Point, PoseMsg, Time, Vector3};

/// `visualization_msgs/Marker` types and actions used here.
const ARROW: i32 = 0;
const SPHERE: i32 = 2;
const CYLINDER: i32 = 3;
const SPHERE_LIST: i32 = 7;
const TEXT_VIEW_FACING: i32 = 9;
const TRIANGLE_LIST: i32 = 11;
const DELETEALL: i32 = 3;

/// Depth drawn fully red; shallower contacts shade from yellow. A fixed scale, so one colour means
/// one depth in every message of a recording.
pub(crate) const FULL_DEPTH_COLOR: f64 = 0.05;

/// Shortest normal arrow drawn: a near miss (depth 0 in a motion) still shows its direction.
const MIN_ARROW: f64 = 0.005;

fn point(v: crate::math::Vector) -> Point {
    Point { x: v.x, y: v.y, z: v.z }
}

fn header(frame: &str, stamp: Time) -> Header {
    Header { stamp, frame_id: frame.to_owned() }
}

/// The scene for a viewer: a `DELETEALL` first (an object removed from the planning scene
/// disappears), then one triangle-list marker per thin surface with the faces of its cells (world
/// frame, namespace `cells/<object>`), at most `max_cells` cells in all (the first ones of each
/// object in turn), and one marker per convex solid (namespace `solids/<object>`: a sphere or
/// cylinder, or the hull's triangles).
pub(crate) fn cell_markers(checker: &Checker, max_cells: usize, frame: &str, stamp: Time) -> MarkerArray {
    let mut markers = vec![Marker { header: header(frame, stamp), action: DELETEALL, pose: PoseMsg::default(), ..Default::default() }];
    let mut left = max_cells;
    for (id, object) in checker.scene().objects().iter().enumerate() {
        let Some(area) = object.area() else { continue };
        let mut points = Vec::new();
        for cell in area.cells.iter().take(left) {
            let v = cell.vertices().map(|p| object.pose * p);
            let [b0, b1, b2, f0, f1, f2] = v;
            let mut tri = vec![[b0, b2, b1], [f0, f1, f2]];
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                tri.push([v[i], v[j], v[3 + j]]);
                tri.push([v[i], v[3 + j], v[3 + i]]);
            }
            points.extend(tri.into_iter().flatten().map(point));
        }
        left -= area.cells.len().min(left);
        markers.push(Marker {
            header: header(frame, stamp),
            ns: format!("cells/{}", object.name),
            id: id as i32,
            kind: TRIANGLE_LIST,
            pose: PoseMsg::default(),
            scale: Vector3 { x: 1.0, y: 1.0, z: 1.0 },
            color: ColorRgba { r: 1.0, g: 0.55, b: 0.0, a: 0.35 },
            points,
            ..Default::default()
        });
    }
    for (id, object) in checker.scene().objects().iter().enumerate() {
        let ObjectBody::Solid(shape) = &*object.body else { continue };
        markers.push(solid_marker(
            shape,
            &object.pose,
            Marker { header: header(frame, stamp), ns: format!("solids/{}", object.name), id: id as i32, ..Default::default() },
        ));
    }
    MarkerArray { markers }
}

/// A convex solid at `pose` as a marker (`base` gives header, namespace and id): a sphere, a
/// cylinder (a capsule drawn as the cylinder around it), or a polytope's triangles in the world.
fn solid_marker(shape: &TargetShape, pose: &crate::math::Pose, base: Marker) -> Marker {
    let color = ColorRgba { r: 0.45, g: 0.55, b: 0.7, a: 0.5 };
    let (t, r) = (pose.translation, pose.rotation);
    let at = PoseMsg { position: Point { x: t.x, y: t.y, z: t.z }, orientation: crate::msgs::Quaternion { x: r.x, y: r.y, z: r.z, w: r.w } };
    let round = |kind: i32, d: f64, h: f64| Marker { kind, pose: at, scale: Vector3 { x: d, y: d, z: h }, color, ..base.clone() };
    match shape {
        TargetShape::Sphere { radius } => round(SPHERE, 2.0 * radius, 2.0 * radius),
        TargetShape::Cylinder { half_height, radius } => round(CYLINDER, 2.0 * radius, 2.0 * half_height),
        TargetShape::Capsule { half_height, radius } => round(CYLINDER, 2.0 * radius, 2.0 * (half_height + radius)),
        TargetShape::Polytope(hull) | TargetShape::Swept { core: hull, .. } => {
            let (v, tris) = hull.vertices_and_triangles();
            let points = tris.iter().flatten().map(|&i| point(*pose * crate::math::Vector::from_array(v[i as usize]))).collect();
            Marker { kind: TRIANGLE_LIST, pose: PoseMsg::default(), scale: Vector3 { x: 1.0, y: 1.0, z: 1.0 }, color, points, ..base }
        }
    }
}

/// Yellow at depth 0 to red at [`FULL_DEPTH_COLOR`] and beyond.
pub(crate) fn depth_color(depth: f64) -> ColorRgba {
    let s = (depth / FULL_DEPTH_COLOR).clamp(0.0, 1.0) as f32;
    ColorRgba { r: 1.0, g: 0.9 * (1.0 - s), b: 0.0, a: 1.0 }
}

/// The contacts of one report: a `DELETEALL` first (a viewer then shows this report's contacts
/// only), the contact points as one sphere list coloured by depth (namespace `contacts`), an arrow
/// per contact from its point along its normal, as long as its depth (`normals`), and the link and
/// object as text at the point (`labels`). A report without contacts gives the `DELETEALL` alone.
/// `lifetime` zero keeps them until the next report's `DELETEALL`.
pub(crate) fn contact_markers(report: &StateReport, frame: &str, stamp: Time, lifetime: DurationMsg) -> MarkerArray {
    let base = Marker { header: header(frame, stamp), lifetime, pose: PoseMsg::default(), ..Default::default() };
    let mut markers = vec![Marker { action: DELETEALL, lifetime: DurationMsg::default(), ..base.clone() }];
    // A flags-only contact has no point to draw.
    let drawn: Vec<_> = report.contacts.iter().filter_map(|c| c.position.map(|p| (c, p))).collect();
    if drawn.is_empty() {
        return MarkerArray { markers };
    }
    let at = |p: [f64; 3]| Point { x: p[0], y: p[1], z: p[2] };
    markers.push(Marker {
        ns: "contacts".into(),
        kind: SPHERE_LIST,
        scale: Vector3 { x: 0.02, y: 0.02, z: 0.02 },
        color: ColorRgba { r: 1.0, g: 0.0, b: 0.0, a: 1.0 },
        points: drawn.iter().map(|(_, p)| at(*p)).collect(),
        colors: drawn.iter().map(|(c, _)| depth_color(c.depth)).collect(),
        ..base.clone()
    });
    for (i, (c, p)) in drawn.iter().enumerate() {
        let n = c.normal;
        let length = c.depth.max(MIN_ARROW);
        markers.push(Marker {
            ns: "normals".into(),
            id: i as i32,
            kind: ARROW,
            // Shaft and head diameters, head length (metres).
            scale: Vector3 { x: 0.004, y: 0.008, z: 0.008f64.min(length) },
            color: depth_color(c.depth),
            points: vec![at(*p), at([p[0] + n[0] * length, p[1] + n[1] * length, p[2] + n[2] * length])],
            ..base.clone()
        });
        markers.push(Marker {
            ns: "labels".into(),
            id: i as i32,
            kind: TEXT_VIEW_FACING,
            pose: PoseMsg { position: at(*p), ..Default::default() },
            // Text height (metres).
            scale: Vector3 { x: 0.0, y: 0.0, z: 0.025 },
            color: ColorRgba { r: 1.0, g: 1.0, b: 1.0, a: 1.0 },
            text: format!("{} x {} ({:.1} mm)", c.link_name, c.object_name, c.depth * 1e3),
            ..base.clone()
        });
    }
    MarkerArray { markers }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checker::ReportContact;

    #[test]
    fn contact_markers_clear_then_draw_every_contact() {
        let contact = |depth: f64, x: f64| ReportContact {
            link_name: "forearm".into(),
            object_name: "guard".into(),
            depth,
            position: Some([x, 0.0, 1.0]),
            normal: [0.0, 0.0, 1.0],
            triangle: 7,
            object_type: Default::default(),
            link_type: crate::checker::ObjectType::RobotLink,
        };
        let report = StateReport { in_collision: true, contacts: vec![contact(0.01, 0.5), contact(0.2, -0.5)], ..Default::default() };
        let m = contact_markers(&report, "world", Time { sec: 3, nanosec: 4 }, DurationMsg::default()).markers;
        assert_eq!(m[0].action, DELETEALL);
        assert_eq!(m.len(), 1 + 1 + 2 * 2);
        assert_eq!(m[1].points.iter().map(|p| p.x).collect::<Vec<_>>(), [0.5, -0.5]);
        assert_eq!(m[1].colors[1], ColorRgba { r: 1.0, g: 0.0, b: 0.0, a: 1.0 }, "past the full depth: red");
        let arrow = &m[2];
        assert_eq!(arrow.kind, ARROW);
        assert!((arrow.points[1].z - arrow.points[0].z - 0.01).abs() < 1e-15, "along the normal, as long as the depth");
        assert_eq!(m[3].text, "forearm x guard (10.0 mm)");
        assert!(m.iter().all(|k| k.header.frame_id == "world" && k.header.stamp == Time { sec: 3, nanosec: 4 }));
        let free = contact_markers(&StateReport::default(), "world", Time::default(), DurationMsg::default());
        assert_eq!(free.markers.len(), 1, "a free state clears the picture");
    }
}
