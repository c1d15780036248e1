//! Clearance per link: how near each checked link is to the environment, when the
//! `clearance_threshold` parameter asks for it.

use super::link_targets::LinkTargets;
use super::state_report::ReportClearance;
use crate::collision::{Contact, Scene, Target};
use crate::math::{Pose, Real, Vector};

/// The clearance of one link (all its parts) within `threshold` of the objects it is checked
/// against (`allowed[object]` false), or `None` when nothing is that close. A colliding link
/// (`contact`, its deepest contact) reports minus that contact's depth, with both points at the
/// contact point, so that the distance is signed and agrees with the contacts.
pub(crate) fn link_clearance(
    scene: &Scene,
    allowed: &[bool],
    link: &LinkTargets,
    link_pose: Pose,
    contact: Option<&Contact>,
    threshold: Real,
) -> Option<ReportClearance> {
    if !(threshold > 0.0) {
        return None;
    }
    let report = |object: usize, triangle: u32, distance: Real, on_link: Vector, on_object: Vector| ReportClearance {
        link_name: link.name.clone(),
        object_name: scene.objects()[object].name.clone(),
        triangle: scene.reported_triangle(object, triangle),
        distance,
        point_on_link: on_link.to_array(),
        point_on_object: on_object.to_array(),
    };
    let nearest = |threshold: Real| {
        let mut best: Option<crate::collision::Clearance> = None;
        for (shape, offset) in &link.parts {
            let target = Target::new(shape.clone(), link_pose * *offset);
            let limit = best.map_or(threshold, |b| b.distance);
            if let Some(c) = scene.clearance_filtered(&target, limit, |oi| !allowed[oi]) {
                if best.is_none_or(|b| c.distance < b.distance) {
                    best = Some(c);
                }
            }
        }
        best
    };
    if let Some(c) = contact {
        // The contact point, or where its clipped region was degenerate, the midpoint of the
        // nearest points GJK/EPA find (the link touches, so they are within rounding).
        let point = c.position.or_else(|| nearest(1e-9).map(|n| (n.point1 + n.point2) * 0.5)).unwrap_or(Vector::splat(Real::NAN));
        return Some(report(c.object, c.triangle, -c.depth, point, point));
    }
    nearest(threshold).map(|n| report(n.object, n.triangle, n.distance, n.point1, n.point2))
}
