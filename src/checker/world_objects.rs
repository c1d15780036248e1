//! A checker with a planning scene's objects beside its environment.

use super::checker::{BuildSummary, Checker};
use super::checker_build::{allowed_matrix, moving_joints};
use super::checker_error::CheckerError;
use super::collision_matrix::CollisionMatrix;
use super::link_sizes::{scaled_shape, LinkSizes};
use super::link_targets::LinkTargets;
use super::world_shapes::{add_world_object, attached_part, BodyCache, WorldShape};
use crate::collision::Scene;
use crate::math::Pose;
use crate::model::Params;
use std::sync::Arc;

/// An object attached to a robot link: checked as a collision element of a fixed child link of
/// `link` named `id` would be, against the environment and the world objects, and against every
/// robot link but `link` and `touch_links`.
pub(crate) struct Attached<'a> {
    pub id: &'a str,
    pub link: &'a str,
    /// Shapes with their poses in the link's frame.
    pub shapes: &'a [(WorldShape, Pose)],
    pub touch_links: &'a [String],
}

impl Checker {
    /// This checker with the planning scene's `objects` (id, pose in the world, shapes with their
    /// poses relative to it) after the environment's (those of an earlier call
    /// replaced), each checked exactly as an environment link of its id would be, with the same
    /// `allowed_collisions`. An id that names an environment object or a robot link is refused,
    /// as is a shape that cannot be used. The build summary stays the environment's.
    /// Mesh bodies come from `cache` when it holds them (those no longer used are forgotten).
    #[cfg(test)]
    pub(crate) fn with_world<'a>(
        &self,
        objects: impl IntoIterator<Item = (&'a str, &'a Pose, &'a [(WorldShape, Pose)])>,
        cache: &mut BodyCache,
    ) -> Result<Checker, CheckerError> {
        self.with_scene(objects, &[], None, &LinkSizes::default(), cache)
    }

    /// [`Checker::with_world`], with `attached` objects on the robot's links (those of an earlier
    /// call replaced), the planning scene's allowed collision `matrix` in place of the SRDF's
    /// (see [`Checker::with_targets`]) and its link `sizes` (see [`LinkSizes`]).
    pub(crate) fn with_scene<'a>(
        &self,
        objects: impl IntoIterator<Item = (&'a str, &'a Pose, &'a [(WorldShape, Pose)])>,
        attached: &[Attached],
        matrix: Option<&CollisionMatrix>,
        sizes: &LinkSizes,
        cache: &mut BodyCache,
    ) -> Result<Checker, CheckerError> {
        let robot = self.robot_targets_sized(sizes).map_err(CheckerError::LinkSize)?;
        let environment = &self.scene.objects()[..self.environment_objects];
        let mut added = Scene::new();
        for (id, pose, shapes) in objects {
            let refuse = |message: &str| CheckerError::WorldObject { id: id.to_owned(), message: message.to_owned() };
            if environment.iter().any(|o| o.name == id) {
                return Err(refuse("the id names an object of the environment"));
            }
            if self.robot.link(id).is_some() {
                return Err(refuse("the id names a link of the robot"));
            }
            add_world_object(&self.params, &mut added, cache, id, pose, shapes, &mut BuildSummary::default()).map_err(|m| refuse(&m))?;
        }
        cache.keep_used();
        let scene = self.scene.prefix_with(self.environment_objects, &added);
        let sizes = (*sizes != *self.link_sizes).then(|| Arc::new(sizes.clone()));
        self.with_targets(Arc::new(scene), robot, sizes, attached, matrix)
    }

    /// This checker with `attached` objects on the robot's links in place of its own (a
    /// `check_state_validity` request's), the scene and `matrix` kept.
    pub(crate) fn with_attached(&self, attached: &[Attached], matrix: Option<&CollisionMatrix>) -> Result<Checker, CheckerError> {
        self.with_targets(Arc::clone(&self.scene), self.targets[..self.robot_targets].to_vec(), None, attached, matrix)
    }

    /// The targets of the robot's links (`robot`, sized by `sizes` when they are new) and of
    /// `attached`, against `scene`. Without a `matrix`
    /// the robot's pairs are the SRDF's (or the default reasoning's); with one, every pair it
    /// does not allow is checked, and a link and an object it allows are not. `allowed_collisions`
    /// allows on top of either; an attached object never meets its own link or touch links.
    fn with_targets(
        &self,
        scene: Arc<Scene>,
        robot: Vec<LinkTargets>,
        sizes: Option<Arc<LinkSizes>>,
        attached: &[Attached],
        matrix: Option<&CollisionMatrix>,
    ) -> Result<Checker, CheckerError> {
        let sizes = sizes.unwrap_or_else(|| Arc::clone(&self.link_sizes));
        let mut targets = robot;
        for a in attached {
            targets.extend(self.attached_target(a, &sizes)?);
        }
        let mut allowed = allowed_matrix(&self.params, &targets, &scene);
        let mut pairs = self.self_pairs.clone();
        // The robot's own pairs: the SRDF's, also when a matrix stood in for them until now.
        let srdf_pairs = self.srdf_pairs.clone().unwrap_or_else(|| Arc::new(pairs.pairs.iter().copied().filter(|&(_, b)| b < self.robot_targets).collect()));
        pairs.pairs = srdf_pairs.to_vec();
        if let Some(m) = matrix {
            for (row, t) in allowed.iter_mut().zip(&targets) {
                for (cell, o) in row.iter_mut().zip(scene.objects()) {
                    *cell |= m.allows(&t.name, &o.name);
                }
            }
            let both = |a: &str, b: &str| self.params.is_allowed(a, b) || self.params.is_allowed(b, a) || m.allows(a, b);
            pairs.pairs = (0..self.robot_targets)
                .flat_map(|a| (a + 1..self.robot_targets).map(move |b| (a, b)))
                .filter(|&(a, b)| !both(&targets[a].name, &targets[b].name))
                .collect();
        }
        if self.params.self_collision {
            let pass = |a: &str, b: &str| matrix.is_none_or(|m| !m.allows(a, b));
            pairs.pairs.extend(
                attached_pairs(&self.params, &targets, self.robot_targets, attached).into_iter().filter(|&(a, b)| pass(&targets[a].name, &targets[b].name)),
            );
            pairs.pairs.sort_unstable();
        } else {
            pairs.pairs.clear();
        }
        let mut checker = self.rebuilt(scene, allowed, pairs);
        checker.srdf_pairs = matrix.map(|_| srdf_pairs);
        let resized = !Arc::ptr_eq(&sizes, &self.link_sizes);
        checker.link_sizes = sizes;
        if resized || targets.len() != self.robot_targets || self.targets.len() != self.robot_targets {
            // Motion bounds and the joints a state must give follow the targets.
            checker.moving = moving_joints(&self.robot, &targets);
            checker.motion = std::sync::OnceLock::new();
            // The robot's links keep their parts unless resized: their ladders carry over.
            checker.robot_ladders = match self.motion.get() {
                _ if resized => Vec::new(),
                Some(bounds) => bounds.grown[..self.robot_targets].to_vec(),
                None => self.robot_ladders.clone(),
            };
            checker.targets = targets;
        }
        Ok(checker)
    }

    /// The target of an attached object (none when `checked_links` leaves its id out), its
    /// parts as a robot link's: a mesh as the hull of its vertices, grown by `padding` for its id;
    /// when the scene's `sizes` set a padding or scale for its link, those (as MoveIt sizes an
    /// attached body as its link).
    fn attached_target(&self, a: &Attached, sizes: &LinkSizes) -> Result<Option<LinkTargets>, CheckerError> {
        let refuse = |message: String| CheckerError::WorldObject { id: a.id.to_owned(), message };
        let link = self.robot.link(a.link).ok_or_else(|| refuse(format!("link '{}' is not a link of the robot", a.link)))?;
        if self.robot.link(a.id).is_some() || self.environment_frames.contains_key(a.id) {
            return Err(refuse("the id names a link of the robot or the environment".into()));
        }
        if !self.params.is_checked(a.id) {
            return Ok(None);
        }
        let padding = sizes.padding.get(a.link).copied().unwrap_or_else(|| self.params.padding_of(a.id));
        let scale = sizes.scale.get(a.link).copied().unwrap_or(1.0);
        let parts = a
            .shapes
            .iter()
            .enumerate()
            .map(|(k, (shape, pose))| {
                attached_part(&scaled_shape(shape, scale), padding).map(|s| (s, *pose)).ok_or_else(|| refuse(format!("shape {k}: not a usable convex shape")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Some(LinkTargets { link, name: a.id.to_owned(), parts, sources: Arc::new([]) }))
    }
}

impl Checker {
    /// The allowed collision matrix in force as names and rows: the checked links and attached
    /// objects, then the scene's objects (each name once); a pair of targets is allowed when it
    /// is not checked, a target and an object when none of the object's shapes is checked
    /// against it; two objects are never checked against each other.
    pub(crate) fn collision_matrix_in_force(&self) -> (Vec<String>, Vec<Vec<bool>>) {
        let mut names: Vec<String> = self.targets.iter().map(|t| t.name.clone()).collect();
        let objects = self.scene.objects();
        for o in objects {
            if !names.contains(&o.name) {
                names.push(o.name.clone());
            }
        }
        let n = self.targets.len();
        let mut rows = vec![vec![true; names.len()]; names.len()];
        for a in 0..n {
            for b in 0..n {
                rows[a][b] = a == b || !self.self_pairs.pairs.contains(&(a.min(b), a.max(b)));
            }
            for (k, name) in names.iter().enumerate().skip(n) {
                let checked = objects.iter().enumerate().any(|(oi, o)| o.name == *name && !self.allowed[a][oi]);
                rows[a][k] = !checked;
                rows[k][a] = !checked;
            }
        }
        (names, rows)
    }
}

/// The self pairs of the attached objects (targets from `first` on): each against every robot
/// link but its own and its touch links, and against the objects attached to other links;
/// `allowed_collisions` allows a pair either way round, as for two robot links.
fn attached_pairs(params: &Params, targets: &[LinkTargets], first: usize, attached: &[Attached]) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for b in first..targets.len() {
        let Some(a_spec) = attached.iter().find(|a| a.id == targets[b].name) else { continue };
        for (a, t) in targets[..b].iter().enumerate() {
            let touch = a_spec.touch_links.contains(&t.name);
            let allowed = params.is_allowed(&t.name, &targets[b].name) || params.is_allowed(&targets[b].name, &t.name);
            if t.link != targets[b].link && !touch && !allowed {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checker::test_points::assert_same_motions;
    use crate::math::Vector;
    use crate::mesh::generate;
    use crate::model::{read_mesh, MeshData, PackageResolver, Params, RobotModel};
    use std::fmt::Write as _;

    /// The bundled workcell with a planning-scene object (a box and an open sheet) gives, for
    /// random joint states, the same reports as the workcell whose environment URDF has a link of
    /// the object's id with the same box and the sheet as an OBJ file; an id that names an
    /// environment object or a robot link is refused.
    #[test]
    fn an_object_is_checked_as_its_urdf_twin() {
        let params = Params::default();
        let base = Checker::from_params(params.clone()).unwrap();
        let (v, t) = generate::flat_grid(6, 6, 0.5, 0.5);
        let dir = std::env::temp_dir().join(format!("tc_world_objects_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut obj = String::new();
        for p in &v {
            let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
        }
        for f in &t {
            let _ = writeln!(obj, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1);
        }
        std::fs::write(dir.join("fixture.obj"), obj).unwrap();
        // The mesh as the file reader gives it (single-precision coordinates), so that both sides
        // hold the same triangles: on a flat sheet, rounding alone picks another of equally deep cells.
        let sheet: MeshData = read_mesh(&dir.join("fixture.obj"), Vector::ONE).unwrap();
        assert_eq!(sheet.triangles.len(), t.len());
        let sheet_pose = Pose::from_translation(Vector::new(-0.1, 0.2, 0.1));
        let shapes = [(WorldShape::Box([0.3, 0.2, 0.1]), Pose::from_translation(Vector::new(0.0, 0.0, 0.2))), (WorldShape::Mesh(Arc::new(sheet)), sheet_pose)];
        let object_pose = Pose::from_translation(Vector::new(0.35, 0.0, 0.3));
        let with = base.with_world([("fixture", &object_pose, &shapes[..])], &mut BodyCache::default()).unwrap();
        let env_path = params.environment_path();
        let env_text = std::fs::read_to_string(&env_path).unwrap();
        let link = format!(
            "<link name=\"fixture\"><collision><origin xyz=\"0 0 0.2\"/><geometry><box size=\"0.3 0.2 0.1\"/></geometry></collision><collision><origin xyz=\"-0.1 0.2 0.1\"/><geometry><mesh filename=\"{}\"/></geometry></collision></link><joint name=\"fixture_joint\" type=\"fixed\"><parent link=\"world\"/><child link=\"fixture\"/><origin xyz=\"0.35 0 0.3\"/></joint></robot>",
            dir.join("fixture.obj").display()
        );
        let twin_text = env_text.replacen("</robot>", &link, 1);
        let resolver = PackageResolver::default();
        let env = RobotModel::from_str(&twin_text, "twin.urdf", env_path.parent().unwrap(), &resolver, false).unwrap();
        let robot = RobotModel::from_file(&params.robot_path(), &resolver, false).unwrap();
        let twin = Checker::from_models(params, robot, env, "robot".into(), "twin".into(), None).unwrap();
        let _ = std::fs::remove_dir_all(&dir);

        let names: Vec<String> = with.robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
        let mut rng = oorandom::Rand64::new(7);
        let (mut colliding, mut with_fixture) = (0, 0);
        for _ in 0..300 {
            let q: Vec<f64> = names.iter().map(|_| -2.0 + 4.0 * rng.rand_float()).collect();
            let (mut a, mut b) = (with.check_joints(&names, &q).unwrap(), twin.check_joints(&names, &q).unwrap());
            (a.check_seconds, b.check_seconds) = (0.0, 0.0);
            assert_eq!(a, b, "at {q:?}");
            colliding += a.in_collision as usize;
            with_fixture += a.contacts.iter().any(|c| c.object_name == "fixture") as usize;
        }
        assert!(with_fixture > 10 && colliding < 300, "{with_fixture} states touch the fixture, {colliding} of 300 collide");
        let refusal = |id: &str| base.with_world([(id, &object_pose, &shapes[..])], &mut BodyCache::default()).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(refusal("guard_sheet").contains("names an object of the environment"), "{}", refusal("guard_sheet"));
        assert!(refusal("base_link").contains("names a link of the robot"), "{}", refusal("base_link"));
    }

    /// Attaching an object keeps the robot links' growth ladders (the same rungs, shared, none
    /// built again) and gives the object a ladder of its own; detaching keeps them too. The
    /// attached checker's motions answer as those of one whose ladders were all built anew.
    #[test]
    fn attaching_and_detaching_keep_the_robot_links_ladders() {
        let base = Checker::from_params(Params::default()).unwrap();
        base.prepare_motion_checks();
        let robot_targets = base.robot_targets;
        let link = base.targets()[robot_targets - 1].name.clone();
        let shapes = [(WorldShape::Box([0.05, 0.05, 0.2]), Pose::from_translation(crate::math::Vector::new(0.0, 0.0, 0.1)))];
        let attached = [Attached { id: "tool", link: &link, shapes: &shapes, touch_links: &[] }];
        type Object<'a> = (&'a str, &'a Pose, &'a [(WorldShape, Pose)]);
        let none: Vec<Object> = Vec::new();
        let attach = |from: &Checker, what: &[Attached]| from.with_scene(none.clone(), what, None, &LinkSizes::default(), &mut BodyCache::default()).unwrap();
        let with = attach(&base, &attached);
        let fresh = attach(&Checker::from_params(Params::default()).unwrap(), &attached);
        assert_eq!(with.targets().len(), robot_targets + 1);
        let shared = |c: &Checker| (0..robot_targets).all(|t| Arc::ptr_eq(&c.motion_bounds().grown[t], &base.motion_bounds().grown[t]));
        assert!(shared(&with) && !shared(&fresh));
        assert!(with.motion_bounds().grown[robot_targets].iter().flatten().all(|rung| rung.get().is_none()), "the object's ladder is its own");
        let detached = attach(&with, &[]);
        assert_eq!(detached.targets().len(), robot_targets);
        assert!(shared(&detached));

        assert!(assert_same_motions(&with, &fresh, 48, 60) > 0, "some motions collide");
    }
}
