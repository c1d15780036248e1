//! Checking one robot state (joint positions or link world poses) against the scene and the
//! robot's own links.

use super::checker::Checker;
use super::clearance::link_clearance;
use super::joint_state::{resolve_positions, StateError};
use super::state_report::{ObjectType, ReportContact, StateReport};
use crate::collision::{CollideSettings, Contact, Target};
use crate::math::{pose_from_isometry, Pose};
use crate::model::JointKind;
use std::time::Instant;

/// What a state check asks of the scene: the deepest contact of each link, without the least
/// overlap, which a state report does not carry.
const CHECK_SETTINGS: CollideSettings = CollideSettings { all_contacts: false, flag_only: false, least_overlap: false };

impl Checker {
    /// Checks a joint state given by name, on its own: an unknown name is an error, and a joint
    /// it lacks is at 0 (an error under `missing_joint: reject`). Positions outside limits are
    /// flagged in the report.
    pub fn check_joints(&self, names: &[String], positions: &[f64]) -> Result<StateReport, StateError> {
        let q = self.positions(names, positions)?;
        self.check_positions(&q)
    }

    /// Positions for every joint of the model (indexed like `robot().joints`) from a named state,
    /// as [`Checker::check_joints`] resolves them: mimic joints from their master, a joint the
    /// state lacks at 0 (an error under `missing_joint: reject`).
    pub fn positions(&self, names: &[String], positions: &[f64]) -> Result<Vec<f64>, StateError> {
        resolve_positions(&self.robot, names, positions, self.params.missing_joint)
    }

    /// Which links collide, and nothing more: each link stops at its first colliding cell, and
    /// its contact carries only link and object names (no depth, point or normal). The
    /// like-for-like counterpart of a boolean `collide` in FCL or coal.
    pub fn check_joints_flags(&self, names: &[String], positions: &[f64]) -> Result<StateReport, StateError> {
        let q = self.positions(names, positions)?;
        self.check_positions_with(&q, &CollideSettings { flag_only: true, least_overlap: false, ..Default::default() })
    }

    /// Checks many joint states at once, each on its own as [`Checker::check_joints`] does, on
    /// all cores with the `parallel` feature. Reports come back in input order.
    pub fn check_joints_batch<S: AsRef<[String]> + Sync, P: AsRef<[f64]> + Sync>(&self, states: &[(S, P)]) -> Vec<Result<StateReport, StateError>> {
        let one = |(names, positions): &(S, P)| self.check_joints(names.as_ref(), positions.as_ref());
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            states.par_iter().map(one).collect()
        }
        #[cfg(not(feature = "parallel"))]
        {
            states.iter().map(one).collect()
        }
    }

    /// Checks a position for every joint of the model (indexed like `robot().joints`).
    pub fn check_positions(&self, q: &[f64]) -> Result<StateReport, StateError> {
        self.check_positions_with(q, &CHECK_SETTINGS)
    }

    fn check_positions_with(&self, q: &[f64], settings: &CollideSettings) -> Result<StateReport, StateError> {
        let started = Instant::now();
        let poses = self.robot.forward_kinematics(q, &self.base)?;
        let world: Vec<Option<Pose>> = poses.iter().map(|p| Some(pose_from_isometry(p))).collect();
        let mut report = self.check_link_poses(&world, settings);
        report.out_of_limits = self.out_of_limits(q);
        report.check_seconds = started.elapsed().as_secs_f64();
        Ok(report)
    }

    /// The revolute and prismatic joints of `q` outside their limits, by name.
    pub(super) fn out_of_limits(&self, q: &[f64]) -> Vec<String> {
        self.robot
            .joints
            .iter()
            .zip(q)
            .filter(|(j, v)| matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) && (**v < j.limits[0] - 1e-12 || **v > j.limits[1] + 1e-12))
            .map(|(j, _)| j.name.clone())
            .collect()
    }

    /// The report of the state at `world` as [`Checker::check_link_poses`] gives it, when only
    /// target `ti` against the environment (or, with `other`, self pair `(ti, other)`) can
    /// collide there: a motion blocked at a stretch has cleared every other target and pair over
    /// stretches that cover the stretch's start. No clearances (a report with them is a full
    /// check).
    pub(super) fn blocked_state_report(&self, world: &[Option<Pose>], ti: usize, other: Option<usize>) -> StateReport {
        let mut report = StateReport::default();
        let contact = match (other, world[self.targets[ti].link]) {
            (None, Some(pose)) => self.link_contact(ti, pose, &CHECK_SETTINGS).map(|c| self.environment_contact(ti, &c)),
            (Some(tb), _) => self.self_pair_contact(world, ti, tb),
            (None, None) => None,
        };
        report.contacts.extend(contact);
        report.in_collision = !report.contacts.is_empty();
        report
    }

    /// A link's contact with the environment as a report gives it.
    fn environment_contact(&self, ti: usize, c: &Contact) -> ReportContact {
        ReportContact {
            link_name: self.targets[ti].name.clone(),
            object_name: self.scene.objects()[c.object].name.clone(),
            triangle: self.scene.reported_triangle(c.object, c.triangle),
            depth: c.depth,
            position: c.position.map(|p| p.to_array()),
            normal: c.normal.to_array(),
            object_type: ObjectType::Environment,
            link_type: self.target_kind(ti),
        }
    }

    /// Checks the links at given world poses (indexed like `robot().links`). Every checked link
    /// needs a pose: a state with a checked link's pose unknown cannot be called free.
    pub fn check_world_poses(&self, world: &[Option<Pose>]) -> Result<StateReport, StateError> {
        let started = Instant::now();
        if world.len() != self.robot.links.len() {
            return Err(StateError::Poses { expected: self.robot.links.len(), got: world.len() });
        }
        for t in &self.targets {
            match world[t.link] {
                None => return Err(StateError::NoPose(t.name.clone())),
                Some(p) => {
                    let q = p.rotation;
                    if !p.translation.is_finite() || !q.is_finite() || (q.length() - 1.0).abs() > 1e-6 {
                        return Err(StateError::BadTransform(t.name.clone()));
                    }
                }
            }
        }
        let mut report = self.check_link_poses(world, &CHECK_SETTINGS);
        report.check_seconds = started.elapsed().as_secs_f64();
        Ok(report)
    }

    /// The deepest contact of every checked link at the given world poses.
    fn check_link_poses(&self, world: &[Option<Pose>], settings: &CollideSettings) -> StateReport {
        let mut report = StateReport::default();
        for (ti, lt) in self.targets.iter().enumerate() {
            let Some(link_pose) = world[lt.link] else { continue };
            let best = self.link_contact(ti, link_pose, settings);
            if !settings.flag_only {
                let threshold = self.params.clearance_threshold;
                report.clearances.extend(link_clearance(&self.scene, &self.allowed[ti], lt, link_pose, best.as_ref(), threshold));
            }
            if let Some(c) = best {
                report.contacts.push(self.environment_contact(ti, &c));
            }
        }
        // Every colliding self pair, in flag-only checks too (which links collide must not
        // depend on the mode; a pair costs a bounding-ball test when apart).
        report.contacts.extend(self.self_contacts(world));
        report.in_collision = !report.contacts.is_empty();
        report
    }

    /// The deepest contact of target `ti` at `link_pose` over all its parts (flag-only: the
    /// first found).
    fn link_contact(&self, ti: usize, link_pose: Pose, settings: &CollideSettings) -> Option<Contact> {
        let mut best: Option<Contact> = None;
        for (shape, offset) in &self.targets[ti].parts {
            let target = Target::new(shape.clone(), link_pose * *offset);
            let r = self.collide_target(ti, &target, settings);
            if settings.flag_only {
                if let Some(c) = r.contacts.first() {
                    return Some(*c);
                }
                continue;
            }
            if let Some(c) = r.deepest() {
                if best.as_ref().is_none_or(|b| c.depth > b.depth) {
                    best = Some(*c);
                }
            }
        }
        best
    }
}
