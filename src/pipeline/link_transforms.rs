//! A state's link poses as `/tf`, for viewers that draw the robot where it was checked.

use crate::checker::Checker;
use crate::msgs::{Header, Quaternion, TfMessage, Time, Transform, TransformStamped, Vector3};

/// The world pose of every link at joint positions `q` of `checker`'s robot (forward kinematics,
/// as the check computes them) as a `/tf` message into `out`: `world` to each link's frame
/// (`prefix` + name), stamped `stamp`. False (and `out` untouched) when `q` does not fit the robot.
///
/// The frame names already in `out` are kept (a replay writing one message per state then
/// allocates no strings): pass an empty message after the checker changed, or the names may be
/// another robot's.
pub(crate) fn link_transforms(checker: &Checker, world: &str, prefix: &str, q: &[f64], stamp: Time, out: &mut TfMessage) -> bool {
    let robot = checker.robot();
    let Ok(poses) = robot.forward_kinematics(q, checker.base_pose()) else { return false };
    // A root link named like the world frame would be its own parent.
    let own = world.strip_prefix(prefix).and_then(|name| robot.link(name));
    let links = robot.links.iter().zip(&poses).enumerate().filter(|(i, _)| Some(*i) != own).map(|(_, l)| l);
    let mut n = 0;
    for (link, pose) in links {
        // The length alone is compared: comparing the names cost 7 % of a replay.
        if out.transforms.get(n).is_none_or(|t| t.child_frame_id.len() != prefix.len() + link.name.len()) {
            out.transforms.truncate(n);
            out.transforms.push(TransformStamped {
                header: Header { stamp, frame_id: world.to_owned() },
                child_frame_id: format!("{prefix}{}", link.name),
                transform: Transform::default(),
            });
        }
        let (t, r) = (pose.translation.vector, pose.rotation.coords);
        let entry = &mut out.transforms[n];
        entry.header.stamp = stamp;
        entry.transform = Transform { translation: Vector3 { x: t.x, y: t.y, z: t.z }, rotation: Quaternion { x: r.x, y: r.y, z: r.z, w: r.w } };
        n += 1;
    }
    out.transforms.truncate(n);
    true
}
