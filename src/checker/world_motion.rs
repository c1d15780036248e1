//! Motions between link poses (the node's `/tf` input): each link moves along the straight line
//! between its two positions and the shortest rotation between its two orientations, at constant
//! speed in `s`.
//!
//! The bound: a point `p` of link `k` (in the link's frame) is at `t(s) + R(s) p`. Between two
//! values of `s` the translation moves by `|Δs|·|Δt_k|`, and the rotation by an angle
//! `|Δs|·θ_k` about one axis, which moves `p` by at most `|Δs|·θ_k·|p|` (a chord is shorter than
//! its arc). So `|Δt_k| + θ_k·reach_k` bounds the speed of every point of the link, with
//! `reach_k` the farthest point of its targets from the link's origin. The rotation is
//! interpolated as `q0·exp(s·log(q0⁻¹q1))` exactly, not by a normalised lerp (whose angular speed
//! exceeds `θ_k` in the middle).

use super::checker::Checker;
use super::joint_state::StateError;
use super::motion_sweep::{MotionPath, MotionReport};
use super::state_report::StateReport;
use crate::math::{Pose, Real, Rotation, Vector};

/// One link's motion: from `start`, translation `shift` and rotation `angle` about `axis` (in
/// the start frame), both scaled by `s`.
#[derive(Clone, Copy)]
struct LinkMotion {
    start: Pose,
    shift: Vector,
    axis: Vector,
    angle: Real,
}

impl LinkMotion {
    fn new(from: Pose, to: Pose) -> LinkMotion {
        let mut rel = from.rotation.inverse() * to.rotation;
        if rel.w < 0.0 {
            rel = -rel;
        }
        let v = Vector::new(rel.x, rel.y, rel.z);
        let sin = v.length();
        let (axis, angle) = if sin > 0.0 { (v / sin, 2.0 * sin.atan2(rel.w)) } else { (Vector::X, 0.0) };
        LinkMotion { start: from, shift: to.translation - from.translation, axis, angle }
    }

    fn at(&self, s: f64) -> Pose {
        let rotation =
            if self.angle == 0.0 { self.start.rotation } else { (self.start.rotation * Rotation::from_axis_angle(self.axis, s * self.angle)).normalize() };
        Pose::from_parts(self.start.translation + self.shift * s, rotation)
    }
}

/// A motion of link poses.
struct WorldPath<'a> {
    checker: &'a Checker,
    /// Per link of the model: its motion, for checked links.
    links: Vec<Option<LinkMotion>>,
    speeds: Vec<Real>,
}

impl MotionPath for WorldPath<'_> {
    fn speeds(&self) -> &[Real] {
        &self.speeds
    }

    fn link_poses(&self, s: f64) -> Result<Vec<Option<Pose>>, String> {
        Ok(self.links.iter().map(|m| m.map(|m| m.at(s))).collect())
    }

    fn report_at(&self, s: f64) -> StateReport {
        let poses: Vec<Option<Pose>> = self.links.iter().map(|m| m.map(|m| m.at(s))).collect();
        self.checker.check_world_poses(&poses).unwrap_or_else(|e| StateReport::failed(e.to_string()))
    }
}

impl Checker {
    /// Checks the motion between two sets of link world poses (indexed like `robot().links`, as
    /// for [`Checker::check_world_poses`]; `None` = a link without a pose). Every checked link
    /// needs a pose in both, else the report fails closed with `error`. Each link moves along the
    /// straight line between its two positions and the shortest rotation between its two
    /// orientations; "free" and "colliding" mean what they mean for [`Checker::check_motion`].
    pub fn check_world_motion(&self, from: &[Option<Pose>], to: &[Option<Pose>]) -> MotionReport {
        let failed = |e: StateError| MotionReport { report: StateReport { motion: true, ..StateReport::failed(e.to_string()) }, ..Default::default() };
        let n = self.robot().links.len();
        for world in [from, to] {
            if world.len() != n {
                return failed(StateError::Poses { expected: n, got: world.len() });
            }
        }
        let mut links = vec![None; n];
        let bounds = self.motion_bounds();
        let mut speeds = Vec::with_capacity(self.targets().len());
        for (ti, t) in self.targets().iter().enumerate() {
            let (Some(a), Some(b)) = (from[t.link], to[t.link]) else {
                return failed(StateError::NoPose(t.name.clone()));
            };
            for p in [a, b] {
                if !p.translation.is_finite() || !p.rotation.is_finite() || (p.rotation.length() - 1.0).abs() > 1e-6 {
                    return failed(StateError::BadTransform(t.name.clone()));
                }
            }
            let m = LinkMotion::new(a, b);
            links[t.link] = Some(m);
            speeds.push(m.shift.length() + m.angle * bounds.reach[ti]);
        }
        self.sweep_motion(&WorldPath { checker: self, links, speeds })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_interpolation_runs_from_one_pose_to_the_other_at_constant_angular_speed() {
        let from = Pose::from_parts(Vector::new(1.0, 2.0, 3.0), Rotation::from_axis_angle(Vector::new(0.3, -1.2, 2.0).normalize(), 2.5));
        let to = Pose::from_parts(Vector::new(-1.0, 0.5, 3.0), Rotation::from_axis_angle(Vector::new(-2.0, 0.4, -2.9).normalize(), -1.9));
        let m = LinkMotion::new(from, to);
        assert!(m.at(0.0).rotation.angle_between(from.rotation) < 1e-9);
        assert!(m.at(1.0).rotation.angle_between(to.rotation) < 1e-9);
        assert!((m.at(1.0).translation - to.translation).length() < 1e-12);
        assert!(m.angle <= std::f64::consts::PI + 1e-12 && (m.angle - from.rotation.angle_between(to.rotation)).abs() < 1e-9);
        for k in 0..10 {
            let (s0, s1) = (k as f64 / 10.0, (k + 1) as f64 / 10.0);
            assert!((m.at(s0).rotation.angle_between(m.at(s1).rotation) - 0.1 * m.angle).abs() < 1e-9);
        }
    }
}
