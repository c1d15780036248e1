//! How near a motion check's contact really came: parry's GJK distance from the link a contact
//! names to the object it names (a cell of a thin surface, a solid, or another link of the robot),
//! the least over a few configurations of the robot. The motion oracles use it to judge a
//! "colliding" answer whose samples all stay free (a near miss, allowed within
//! `motion_tolerance`).

use parry3d_f64::query;
use parry3d_f64::shape::{ConvexPolyhedron, Shape};
use thickness_collision::checker::Checker;
use thickness_collision::collision::{ObjectBody, TargetShape};
use thickness_collision::math::pose_from_isometry;

fn hull(shape: &TargetShape) -> ConvexPolyhedron {
    match shape {
        TargetShape::Polytope(h) => h.as_parry().clone(),
        other => panic!("the near-miss oracle measures mesh links only, not {other:?}"),
    }
}

/// The least distance from link `link` to object `object` (for a thin surface, the cell of its
/// `triangle`; a link of the robot for a self contact) over the configurations `qs`.
pub fn nearest_to_contact(c: &Checker, link: &str, object: &str, triangle: u32, qs: &[Vec<f64>]) -> f64 {
    let robot = c.robot();
    let ti = c.targets().iter().position(|t| t.name == link).unwrap();
    let mut nearest = f64::INFINITY;
    if let Some(tj) = c.targets().iter().position(|t| t.name == object) {
        for q in qs {
            let poses = robot.forward_kinematics(q, c.base_pose()).unwrap();
            let (pa, pb) = (pose_from_isometry(&poses[c.targets()[ti].link]), pose_from_isometry(&poses[c.targets()[tj].link]));
            for (sa, oa) in &c.targets()[ti].parts {
                for (sb, ob) in &c.targets()[tj].parts {
                    let d = query::distance(&(pa * *oa), &hull(sa), &(pb * *ob), &hull(sb)).unwrap();
                    nearest = nearest.min(d.distance);
                }
            }
        }
        return nearest;
    }
    let object = c.scene().objects().iter().find(|o| o.name == object).unwrap();
    let other: Box<dyn Shape> = match &*object.body {
        ObjectBody::Surface { area, .. } => {
            let cell = area.cells.iter().find(|cell| cell.triangle == triangle).unwrap();
            Box::new(ConvexPolyhedron::from_convex_hull(&cell.distinct_vertices()).unwrap())
        }
        ObjectBody::Solid(shape) => Box::new(hull(shape)),
    };
    for q in qs {
        let poses = robot.forward_kinematics(q, c.base_pose()).unwrap();
        let link = pose_from_isometry(&poses[c.targets()[ti].link]);
        for (shape, offset) in &c.targets()[ti].parts {
            let d = query::distance(&(link * *offset), &hull(shape), &object.pose, &*other).unwrap();
            nearest = nearest.min(d.distance);
        }
    }
    nearest
}
