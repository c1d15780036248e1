//! Loading the robot and the environment and checking states against them.

use super::joint_state::{resolve_positions, StateError};
use super::motion::MotionBounds;
use super::self_collision::SelfPairs;
use super::state_report::{ObjectType, ReportContact, StateReport};
use crate::collision::{CollideSettings, ConvexHull, Scene, Target, TargetShape};
use crate::math::{pose_from_isometry, Pose, Vector};
use crate::mesh::{MeshTopology, TopologySettings};
use crate::model::mesh_file::{read_mesh, scale_mesh, MeshData, MeshFileError};
use crate::model::{bundled_config_dir, GeometrySpec, JointKind, ModelError, PackageResolver, Params, ParamsError, RobotModel, Srdf};
use crate::thickness::{Side, ThicknessArea, ThicknessSettings};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Why a checker cannot be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckerError {
    /// Bad parameters.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// Bad URDF.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A mesh file of a link cannot be used. (The mesh error is part of the message, not a
    /// `source`: printed as a chain it would repeat itself.)
    #[error("{file}: link '{link}': {error}")]
    Mesh {
        /// The URDF (or `robot_description`) naming the mesh.
        file: String,
        /// Link.
        link: String,
        /// Why.
        error: MeshFileError,
    },
    /// Building panicked (a defect, in this crate or a dependency): contained, so the robot in
    /// use stays.
    #[error("building the checker failed: {0}")]
    Panicked(String),
    /// The SRDF cannot be read or does not fit the robot.
    #[error("{0}")]
    Srdf(String),
    /// No link of the robot would be checked: every state would be reported free.
    #[error("{file}: robot '{robot}' has no link to check: {cause}")]
    NoCheckedLink {
        /// The URDF (or `robot_description`).
        file: String,
        /// The robot's name.
        robot: String,
        /// Why no link is checked, and what to change.
        cause: String,
    },
    /// A geometry of a link is not usable.
    #[error("{file}: link '{link}': {what}: {message}")]
    Geometry {
        /// The URDF (or `robot_description`).
        file: String,
        /// Link.
        link: String,
        /// The geometry: `mesh <file>`, or the primitive with its sizes.
        what: String,
        /// What is wrong.
        message: String,
    },
}

/// The convex parts of one checked robot link.
#[derive(Clone, Debug)]
pub struct LinkTargets {
    /// Index of the link in the robot model.
    pub link: usize,
    /// Its name.
    pub name: String,
    /// Shapes and their poses in the link frame.
    pub parts: Vec<(TargetShape, Pose)>,
}

/// What a state check asks of the scene: the deepest contact of each link, without the least
/// overlap, which a state report does not carry.
const CHECK_SETTINGS: CollideSettings = CollideSettings { all_contacts: false, flag_only: false, least_overlap: false };

/// What was loaded (printed by the CLI and the node at start).
#[derive(Clone, Debug, Default)]
pub struct BuildSummary {
    /// Robot file (or `robot_description`).
    pub robot_source: String,
    /// Environment file.
    pub environment_source: String,
    /// Links of the robot.
    pub robot_links: usize,
    /// Links checked (with geometry and matching `checked_links`).
    pub checked_links: usize,
    /// Thin surfaces (meshes with cells).
    pub thin_surfaces: usize,
    /// Convex solids.
    pub solids: usize,
    /// Cells in all thin surfaces.
    pub cells: usize,
    /// Mesh files read (each once).
    pub meshes_read: usize,
    /// Seconds to load and build everything.
    pub build_seconds: f64,
}

/// Robot, environment, targets and scene: everything needed to check a state. Built once from
/// validated parameters and never changed after (a new robot or new parameters build a new one),
/// so its parts stay consistent with each other.
pub struct Checker {
    params: Params,
    robot: RobotModel,
    targets: Vec<LinkTargets>,
    /// Shared by the checkers that differ only in their self pairs (an SRDF that arrives later).
    scene: Arc<Scene>,
    summary: BuildSummary,
    base: Isometry3<f64>,
    /// `allowed[target index][object index]`.
    allowed: Vec<Vec<bool>>,
    /// Levers and grown parts for motion checks, built on the first motion.
    motion: std::sync::OnceLock<MotionBounds>,
    /// The link pairs checked against each other.
    self_pairs: SelfPairs,
    /// `moving[j]`: joint `j` takes a position from joint states and moves a checked link (itself,
    /// or through a mimic). A state is complete when all of these are known.
    moving: Vec<bool>,
}

/// Mesh files read once per build.
#[derive(Default)]
struct MeshCache {
    meshes: HashMap<PathBuf, Arc<MeshData>>,
}

impl MeshCache {
    /// The mesh at `path` with `scale` applied (winding reversed for mirroring scales).
    fn get(&mut self, path: &Path, scale: [f64; 3]) -> Result<MeshData, MeshFileError> {
        let data = match self.meshes.get(path) {
            Some(d) => d.clone(),
            None => {
                let d = Arc::new(read_mesh(path, Vector::ONE)?);
                let _ = self.meshes.insert(path.to_owned(), d.clone());
                d
            }
        };
        scale_mesh(&data, Vector::from_array(scale), path)
    }
}

/// The target of a URDF primitive grown by `padding`; `None` for meshes and for sizes that are not
/// positive and finite.
fn primitive_shape(spec: &GeometrySpec, padding: f64) -> Option<TargetShape> {
    let shape = match spec {
        GeometrySpec::Box(s) => TargetShape::cuboid(Vector::new(s[0], s[1], s[2]) * 0.5 + Vector::splat(padding))?,
        GeometrySpec::Sphere(r) => TargetShape::Sphere { radius: r + padding },
        GeometrySpec::Capsule { radius, length } => TargetShape::Capsule { half_height: length / 2.0, radius: radius + padding },
        GeometrySpec::Cylinder { radius, length } => TargetShape::Cylinder { half_height: length / 2.0 + padding, radius: radius + padding },
        GeometrySpec::Mesh { .. } => return None,
    };
    shape.is_valid().then_some(shape)
}

/// Why `robot` has no checked link, with what would change it.
fn no_checked_link(params: &Params, robot: &RobotModel, file: &str) -> CheckerError {
    let with_geometry: Vec<&str> = robot.links.iter().filter(|l| !l.geometry.is_empty()).map(|l| l.name.as_str()).collect();
    let cause = if !with_geometry.is_empty() {
        format!(
            "checked_links {:?} matches none of its {} links with collision geometry ({})",
            params.checked_links,
            with_geometry.len(),
            crate::limits::name_list(&with_geometry)
        )
    } else if robot.visual_only_links > 0 && !params.use_visual_when_no_collision {
        format!(
            "none of its {} links has <collision> geometry ({} have <visual> only: set use_visual_when_no_collision: true to check those)",
            robot.links.len(),
            robot.visual_only_links
        )
    } else {
        format!("none of its {} links has collision or visual geometry", robot.links.len())
    };
    CheckerError::NoCheckedLink { file: file.to_owned(), robot: robot.name.clone(), cause }
}

/// Which joints move a checked link: the actuated joints on the path from each checked link to
/// the root, a mimic standing for the joint it follows.
fn moving_joints(robot: &RobotModel, targets: &[LinkTargets]) -> Vec<bool> {
    let mut moving = vec![false; robot.joints.len()];
    for t in targets {
        let mut link = t.link;
        // The joints form a tree (checked at load): at most one step per link.
        for _ in 0..robot.links.len() {
            let Some(j) = robot.parent_joint(link) else { break };
            let joint = &robot.joints[j];
            let driver = joint.mimic.map_or(j, |m| m.joint);
            if robot.joints[driver].is_actuated() {
                moving[driver] = true;
            }
            link = joint.parent;
        }
    }
    moving
}

/// `robot_base_pose` (x y z roll pitch yaw) as an isometry; `Params::validate` ensures six values.
fn base_isometry(p: &[f64]) -> Isometry3<f64> {
    match *p {
        [x, y, z, roll, pitch, yaw] => Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::from_euler_angles(roll, pitch, yaw)),
        _ => Isometry3::identity(),
    }
}

impl Checker {
    /// The parameters in force.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The robot.
    pub fn robot(&self) -> &RobotModel {
        &self.robot
    }

    /// The checked links' targets, in model order.
    pub fn targets(&self) -> &[LinkTargets] {
        &self.targets
    }

    /// The environment.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// What was loaded.
    pub fn summary(&self) -> &BuildSummary {
        &self.summary
    }

    /// The pose of the robot's root link in the world (`robot_base_pose`).
    pub fn base_pose(&self) -> &Isometry3<f64> {
        &self.base
    }

    /// Whether joint `j` (model index) moves a checked link and takes its position from joint
    /// states: the joints a state must give before it can be checked.
    pub fn moves_checked_link(&self, j: usize) -> bool {
        self.moving.get(j).copied().unwrap_or(false)
    }

    /// Names `file` as the parameters' SRDF of a checker whose SRDF was applied from text held
    /// elsewhere (the pipeline's, for a robot that comes as a description).
    pub(crate) fn set_semantic_file_name(&mut self, file: String) {
        self.params.robot_semantic_file = file;
    }

    /// The self-collision pairs and the SRDF they come from.
    pub fn self_pairs(&self) -> &SelfPairs {
        &self.self_pairs
    }

    /// The same checker with the allowed collision matrix of SRDF `text` (`source` names it in
    /// errors); the robot and environment are kept. An SRDF naming a link or joint the robot
    /// lacks is refused.
    pub fn with_semantic(mut self, text: &str, source: &str) -> Result<Checker, CheckerError> {
        self.apply_semantic(text, source)?;
        Ok(self)
    }

    /// This checker with the allowed collision matrix of SRDF `text` in place of its own: robot,
    /// targets and scene are shared or copied, not loaded again (an SRDF that arrives on its topic
    /// after the robot must not cost a second build of a million-cell world).
    pub fn with_other_semantic(&self, text: &str, source: &str) -> Result<Checker, CheckerError> {
        let checker = Checker {
            params: self.params.clone(),
            robot: self.robot.clone(),
            targets: self.targets.clone(),
            scene: Arc::clone(&self.scene),
            summary: self.summary.clone(),
            base: self.base,
            allowed: self.allowed.clone(),
            motion: self.motion.clone(),
            self_pairs: SelfPairs::default(),
            moving: self.moving.clone(),
        };
        checker.with_semantic(text, source)
    }

    /// As [`Checker::with_semantic`], in place; on error nothing changes.
    pub fn apply_semantic(&mut self, text: &str, source: &str) -> Result<(), CheckerError> {
        let srdf = Srdf::parse(text, source, &self.robot).map_err(|e| CheckerError::Srdf(e.to_string()))?;
        self.self_pairs = SelfPairs::build(self, Some(srdf));
        Ok(())
    }

    pub(crate) fn motion_bounds(&self) -> &MotionBounds {
        self.motion.get_or_init(|| MotionBounds::new(&self.robot, &self.targets, self.params.motion_tolerance))
    }

    /// Target `ti` (a part of a checked link, posed) against the scene, without the objects the
    /// link may touch.
    pub(crate) fn collide_target(&self, ti: usize, target: &Target, settings: &CollideSettings) -> crate::collision::TargetReport {
        self.scene.collide_filtered(target, settings, |oi| !self.allowed[ti][oi])
    }

    /// Loads the robot and the environment named by the parameters (or the overrides), with
    /// the bundled example workcell as the default for both.
    pub fn from_params(params: Params, robot: Option<&Path>, environment: Option<&Path>) -> Result<Checker, CheckerError> {
        params.validate()?;
        let resolver = PackageResolver::new(&params.package_map);
        let config = bundled_config_dir();
        let pick = |over: Option<&Path>, param: &str, default: &str| -> PathBuf {
            over.map(Path::to_owned).unwrap_or_else(|| if param.is_empty() { config.join(default) } else { PathBuf::from(param) })
        };
        let robot_path = pick(robot, &params.robot_description_file, "example_workcell/robot.urdf");
        let env_path = pick(environment, &params.environment_file, "example_workcell/environment.urdf");
        let use_visual = params.use_visual_when_no_collision;
        let robot = RobotModel::from_file(&robot_path, &resolver, use_visual)?;
        let env = RobotModel::from_file(&env_path, &resolver, use_visual)?;
        Self::from_models(params, robot, env, robot_path.display().to_string(), env_path.display().to_string())
    }

    /// As [`Checker::from_params`], but with the robot from URDF text (a `robot_description`
    /// message); `source` names it in errors. Mesh paths must be `package://`, `file://` or
    /// absolute.
    pub fn from_description(params: Params, description: &str, source: &str, environment: Option<&Path>) -> Result<Checker, CheckerError> {
        params.validate()?;
        let resolver = PackageResolver::new(&params.package_map);
        let env_path = environment.map(Path::to_owned).unwrap_or_else(|| {
            if params.environment_file.is_empty() {
                bundled_config_dir().join("example_workcell/environment.urdf")
            } else {
                PathBuf::from(&params.environment_file)
            }
        });
        let use_visual = params.use_visual_when_no_collision;
        let robot = RobotModel::from_str(description, source, Path::new("."), &resolver, use_visual)?;
        let env = RobotModel::from_file(&env_path, &resolver, use_visual)?;
        Self::from_models(params, robot, env, source.to_owned(), env_path.display().to_string())
    }

    /// A checker for `robot` against a scene built elsewhere (benchmarks, generated worlds).
    pub fn from_robot_and_scene(params: Params, robot: RobotModel, scene: Scene, robot_source: String) -> Result<Checker, CheckerError> {
        params.validate()?;
        let empty = RobotModel::from_str("<robot name=\"empty\"><link name=\"world\"/></robot>", "empty", Path::new("."), &PackageResolver::default(), false)?;
        let mut checker = Self::from_models(params, robot, empty, robot_source, "generated scene".into())?;
        checker.summary.thin_surfaces = scene.objects().iter().filter(|o| o.area().is_some()).count();
        checker.summary.cells = scene.cell_count();
        checker.allowed = checker.targets.iter().map(|t| scene.objects().iter().map(|o| checker.params.is_allowed(&t.name, &o.name)).collect()).collect();
        checker.scene = Arc::new(scene);
        Ok(checker)
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

    /// Builds targets and scene from loaded models (the node's path for `robot_description`).
    pub fn from_models(params: Params, robot: RobotModel, env: RobotModel, robot_source: String, environment_source: String) -> Result<Checker, CheckerError> {
        params.validate()?;
        let started = Instant::now();
        let mut cache = MeshCache::default();
        let mut summary = BuildSummary { robot_source, environment_source, robot_links: robot.links.len(), ..Default::default() };

        let mut scene = Scene::new();
        let env_poses = env
            .forward_kinematics(&vec![0.0; env.joints.len()], &Isometry3::identity())
            .map_err(|e| CheckerError::Model(ModelError::Structure { file: summary.environment_source.clone(), message: e.to_string() }))?;
        for (li, link) in env.links.iter().enumerate() {
            for g in &link.geometry {
                let pose = pose_from_isometry(&(env_poses[li] * g.origin));
                match &g.spec {
                    GeometrySpec::Mesh { path, scale } => {
                        let data = cache.get(path, *scale).map_err(|error| CheckerError::Mesh {
                            file: summary.environment_source.clone(),
                            link: link.name.clone(),
                            error,
                        })?;
                        let geo = |message: String| CheckerError::Geometry {
                            file: summary.environment_source.clone(),
                            link: link.name.clone(),
                            what: format!("mesh {}", path.display()),
                            message,
                        };
                        let mesh = MeshTopology::build(&data.vertices, &data.triangles, &TopologySettings::default()).map_err(|e| geo(e.to_string()))?;
                        let closed = mesh.report.boundary_edges == 0 && mesh.report.non_manifold_edges == 0;
                        if closed && params.is_solid_hull(&link.name) {
                            let hull = ConvexHull::from_points(&data.vertices).ok_or_else(|| geo("its convex hull is flat".into()))?;
                            let _ = scene.add_solid(link.name.clone(), pose, TargetShape::Polytope(Arc::new(hull)));
                            summary.solids += 1;
                        } else {
                            let (thickness, side) = params.surface_settings(&link.name);
                            // A closed mesh has an inside: its cells go inward.
                            let side = if closed { Side::Back } else { side };
                            let area =
                                ThicknessArea::build(&mesh, &ThicknessSettings { thickness, side, ..Default::default() }).map_err(|e| geo(e.to_string()))?;
                            summary.cells += area.cells.len();
                            let _ = scene.add_surface(link.name.clone(), pose, area);
                            summary.thin_surfaces += 1;
                        }
                    }
                    spec => {
                        let shape = primitive_shape(spec, 0.0).ok_or_else(|| CheckerError::Geometry {
                            file: summary.environment_source.clone(),
                            link: link.name.clone(),
                            what: format!("{spec:?}"),
                            message: "not a usable convex shape".into(),
                        })?;
                        let _ = scene.add_solid(link.name.clone(), pose, shape);
                        summary.solids += 1;
                    }
                }
            }
        }

        let mut targets = Vec::new();
        for (li, link) in robot.links.iter().enumerate() {
            if link.geometry.is_empty() || !params.is_checked(&link.name) {
                continue;
            }
            let padding = params.padding_of(&link.name);
            let mut parts = Vec::new();
            for g in &link.geometry {
                let shape = match &g.spec {
                    GeometrySpec::Mesh { path, scale } => {
                        let data = cache.get(path, *scale).map_err(|error| CheckerError::Mesh {
                            file: summary.robot_source.clone(),
                            link: link.name.clone(),
                            error,
                        })?;
                        let geo = |message: &str| CheckerError::Geometry {
                            file: summary.robot_source.clone(),
                            link: link.name.clone(),
                            what: format!("mesh {}", path.display()),
                            message: message.into(),
                        };
                        let hull = ConvexHull::from_points(&data.vertices).ok_or_else(|| geo("its convex hull is flat or empty"))?;
                        let hull = hull.padded(padding).ok_or_else(|| geo("padding failed"))?;
                        TargetShape::Polytope(Arc::new(hull))
                    }
                    spec => primitive_shape(spec, padding).ok_or_else(|| CheckerError::Geometry {
                        file: summary.robot_source.clone(),
                        link: link.name.clone(),
                        what: format!("{spec:?}"),
                        message: "not a usable convex shape".into(),
                    })?,
                };
                parts.push((shape, pose_from_isometry(&g.origin)));
            }
            targets.push(LinkTargets { link: li, name: link.name.clone(), parts });
        }
        if targets.is_empty() {
            return Err(no_checked_link(&params, &robot, &summary.robot_source));
        }
        let moving = moving_joints(&robot, &targets);
        let allowed = targets.iter().map(|t| scene.objects().iter().map(|o| params.is_allowed(&t.name, &o.name)).collect()).collect();
        summary.checked_links = targets.len();
        summary.meshes_read = cache.meshes.len();
        summary.build_seconds = started.elapsed().as_secs_f64();
        let base = base_isometry(&params.robot_base_pose);
        let semantic_file = params.robot_semantic_file.clone();
        let checker = Checker {
            params,
            robot,
            targets,
            scene: Arc::new(scene),
            summary,
            base,
            allowed,
            motion: std::sync::OnceLock::new(),
            self_pairs: SelfPairs::default(),
            moving,
        };
        if semantic_file.is_empty() {
            let mut checker = checker;
            checker.self_pairs = SelfPairs::build(&checker, None);
            return Ok(checker);
        }
        let text = crate::limits::read_regular_text(Path::new(&semantic_file), "SRDF", crate::limits::MAX_DESCRIPTION_BYTES)
            .map_err(|e| CheckerError::Srdf(format!("robot_semantic_file: {e}")))?;
        checker.with_semantic(&text, &semantic_file)
    }

    /// Checks a joint state given by name, on its own: an unknown name is an error, and a joint
    /// it lacks is at 0 (an error under `missing_joint: reject`). Positions outside limits are
    /// flagged in the report.
    pub fn check_joints(&self, names: &[String], positions: &[f64]) -> Result<StateReport, StateError> {
        let q = resolve_positions(&self.robot, names, positions, self.params.missing_joint)?;
        self.check_positions(&q)
    }

    /// Which links collide, and nothing more: each link stops at its first colliding cell, and
    /// its contact carries only link and object names (no depth, point or normal). The
    /// like-for-like counterpart of a boolean `collide` in FCL or coal.
    pub fn check_joints_flags(&self, names: &[String], positions: &[f64]) -> Result<StateReport, StateError> {
        let q = resolve_positions(&self.robot, names, positions, self.params.missing_joint)?;
        self.check_positions_with(&q, &CollideSettings { flag_only: true, least_overlap: false, ..Default::default() })
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
        report.out_of_limits = self
            .robot
            .joints
            .iter()
            .zip(q)
            .filter(|(j, v)| matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) && (**v < j.limits[0] - 1e-12 || **v > j.limits[1] + 1e-12))
            .map(|(j, _)| j.name.clone())
            .collect();
        report.check_seconds = started.elapsed().as_secs_f64();
        Ok(report)
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
            let mut best: Option<crate::collision::Contact> = None;
            for (shape, offset) in &lt.parts {
                let target = Target::new(shape.clone(), link_pose * *offset);
                let r = self.scene.collide_filtered(&target, settings, |oi| !self.allowed[ti][oi]);
                if settings.flag_only {
                    if let Some(c) = r.contacts.first() {
                        best = Some(*c);
                        break;
                    }
                    continue;
                }
                if let Some(c) = r.deepest() {
                    if best.as_ref().is_none_or(|b| c.depth > b.depth) {
                        best = Some(*c);
                    }
                }
            }
            if !settings.flag_only {
                let threshold = self.params.clearance_threshold;
                report.clearances.extend(super::clearance::link_clearance(&self.scene, &self.allowed[ti], lt, link_pose, best.as_ref(), threshold));
            }
            if let Some(c) = best {
                report.contacts.push(ReportContact {
                    link_name: lt.name.clone(),
                    object_name: self.scene.objects()[c.object].name.clone(),
                    triangle: c.triangle,
                    depth: c.depth,
                    position: c.position.map(|p| p.to_array()),
                    normal: c.normal.to_array(),
                    object_type: ObjectType::Environment,
                });
            }
        }
        // Every colliding self pair, in flag-only checks too (which links collide must not
        // depend on the mode; a pair costs a bounding-ball test when apart).
        report.contacts.extend(self.self_contacts(world));
        report.in_collision = !report.contacts.is_empty();
        report
    }
}
