//! Building a checker: the robot, environment and SRDF files read, then the scene of the
//! environment, the targets of the robot's checked links and the allowed collision matrix built
//! from the loaded models.

use super::checker::{BuildSummary, Checker};
use super::checker_error::CheckerError;
use super::geometry_shapes::{primitive_shape, MeshCache};
use super::link_targets::{LinkTargets, PartSource};
use super::self_pairs::SelfPairs;
use crate::collision::{ConvexHull, ObjectBody, Scene, TargetShape};
use crate::math::pose_from_isometry;
use crate::math::Pose;
use crate::mesh::{MeshTopology, TopologySettings};
use crate::model::MeshData;
use crate::model::{GeometrySpec, ModelError, PackageResolver, Params, RobotModel, Srdf};
use crate::thickness::{Side, ThicknessArea, ThicknessSettings};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// The text of the SRDF file `file` (the parameters' `robot_semantic_file`).
pub(crate) fn read_semantic_file(file: &str) -> Result<String, CheckerError> {
    crate::limits::read_regular_text(Path::new(file), "SRDF", crate::limits::MAX_DESCRIPTION_BYTES)
        .map_err(|e| CheckerError::Srdf(format!("robot_semantic_file: {e}")))
}

impl Checker {
    /// Loads the robot and the environment the parameters name (see [`Params::robot_path`] and
    /// [`Params::environment_path`]), and their SRDF.
    pub fn from_params(params: Params) -> Result<Checker, CheckerError> {
        params.validate()?;
        let resolver = PackageResolver::new(&params.package_map);
        let (robot_path, env_path) = (params.robot_path(), params.environment_path());
        let use_visual = params.use_visual_when_no_collision;
        let robot = RobotModel::from_file(&robot_path, &resolver, use_visual)?;
        let env = RobotModel::from_file(&env_path, &resolver, use_visual)?;
        let checker = Self::build(params, robot, env, robot_path.display().to_string(), env_path.display().to_string())?;
        checker.with_semantic_file()
    }

    /// As [`Checker::from_params`], but with the robot from URDF text (a `robot_description`
    /// message); `source` names it in errors. Mesh paths must be `package://`, `file://` or
    /// absolute.
    pub(crate) fn from_description(params: Params, description: &str, source: &str) -> Result<Checker, CheckerError> {
        params.validate()?;
        let resolver = PackageResolver::new(&params.package_map);
        let env_path = params.environment_path();
        let use_visual = params.use_visual_when_no_collision;
        let robot = RobotModel::from_str(description, source, Path::new("."), &resolver, use_visual)?;
        let env = RobotModel::from_file(&env_path, &resolver, use_visual)?;
        let checker = Self::build(params, robot, env, source.to_owned(), env_path.display().to_string())?;
        checker.with_semantic_file()
    }

    /// A checker for `robot` against a scene built elsewhere (benchmarks, generated worlds), with
    /// the parameters' SRDF.
    pub fn from_robot_and_scene(params: Params, robot: RobotModel, scene: Scene, robot_source: String) -> Result<Checker, CheckerError> {
        params.validate()?;
        let empty = RobotModel::from_str("<robot name=\"empty\"><link name=\"world\"/></robot>", "empty", Path::new("."), &PackageResolver::default(), false)?;
        let mut checker = Self::build(params, robot, empty, robot_source, "generated scene".into())?;
        checker.summary.thin_surfaces = scene.objects().iter().filter(|o| o.area().is_some()).count();
        checker.summary.cells = scene.cell_count();
        checker.allowed = allowed_matrix(&checker.params, &checker.targets, &scene);
        checker.environment_objects = scene.objects().len();
        checker.scene = Arc::new(scene);
        checker.with_semantic_file()
    }

    /// Builds targets and scene from loaded models, with the allowed collision matrix of `srdf`
    /// (the text of the parameters' `robot_semantic_file`, read by the caller; `None`: MoveIt's
    /// default reasoning). Reads the mesh files the models name, nothing else.
    pub fn from_models(
        params: Params,
        robot: RobotModel,
        env: RobotModel,
        robot_source: String,
        environment_source: String,
        srdf: Option<&str>,
    ) -> Result<Checker, CheckerError> {
        params.validate()?;
        let checker = Self::build(params, robot, env, robot_source, environment_source)?;
        match srdf {
            Some(text) => {
                let source = checker.params.robot_semantic_file.clone();
                checker.with_semantic(text, &source)
            }
            None => Ok(checker.with_default_pairs()),
        }
    }

    /// [`Checker::from_models`] for validated parameters, without self pairs yet.
    fn build(params: Params, robot: RobotModel, env: RobotModel, robot_source: String, environment_source: String) -> Result<Checker, CheckerError> {
        let started = Instant::now();
        let mut cache = MeshCache::default();
        let mut summary = BuildSummary { robot_source, environment_source, robot_links: robot.links.len(), ..Default::default() };
        let (scene, environment_frames) = environment_scene(&params, &env, &mut cache, &mut summary)?;
        let targets = robot_targets(&params, &robot, &mut cache, &summary.robot_source)?;
        if targets.is_empty() {
            return Err(no_checked_link(&params, &robot, &summary.robot_source));
        }
        let moving = moving_joints(&robot, &targets);
        let allowed = allowed_matrix(&params, &targets, &scene);
        summary.checked_links = targets.len();
        summary.meshes_read = cache.files_read();
        summary.build_seconds = started.elapsed().as_secs_f64();
        let base = base_isometry(&params.robot_base_pose);
        let scene_objects = scene.objects().len();
        let robot_targets = targets.len();
        Ok(Checker {
            params,
            robot,
            targets,
            scene: Arc::new(scene),
            summary,
            base,
            allowed,
            motion: OnceLock::new(),
            robot_ladders: Vec::new(),
            self_pairs: SelfPairs::default(),
            moving,
            srdf_pairs: None,
            robot_targets,
            environment_objects: scene_objects,
            environment_frames: Arc::new(environment_frames),
            link_sizes: Arc::default(),
        })
    }

    /// This checker with the self pairs of the parameters' `robot_semantic_file`, read now, or
    /// of the default reasoning without one.
    fn with_semantic_file(self) -> Result<Checker, CheckerError> {
        let file = self.params.robot_semantic_file.clone();
        if file.is_empty() {
            return Ok(self.with_default_pairs());
        }
        let text = read_semantic_file(&file)?;
        self.with_semantic(&text, &file)
    }

    fn with_default_pairs(mut self) -> Checker {
        self.self_pairs = SelfPairs::build(&self, None);
        self
    }

    /// The same checker with the allowed collision matrix of SRDF `text` (`source` names it in
    /// errors); the robot and environment are kept. An SRDF naming a link or joint the robot
    /// lacks is refused.
    pub(crate) fn with_semantic(mut self, text: &str, source: &str) -> Result<Checker, CheckerError> {
        self.apply_semantic(text, source)?;
        Ok(self)
    }

    /// This checker with the allowed collision matrix of SRDF `text` in place of its own: robot,
    /// targets and scene are shared or copied, not loaded again (an SRDF that arrives on its topic
    /// after the robot must not cost a second build of a million-cell world).
    pub(crate) fn with_other_semantic(&self, text: &str, source: &str) -> Result<Checker, CheckerError> {
        self.rebuilt(Arc::clone(&self.scene), self.allowed.clone(), SelfPairs::default()).with_semantic(text, source)
    }

    /// This checker with another scene, allowed matrix and self pairs; robot, targets and
    /// motion bounds shared or copied.
    pub(super) fn rebuilt(&self, scene: Arc<Scene>, allowed: Vec<Vec<bool>>, self_pairs: SelfPairs) -> Checker {
        Checker {
            params: self.params.clone(),
            robot: self.robot.clone(),
            targets: self.targets.clone(),
            scene,
            summary: self.summary.clone(),
            base: self.base,
            allowed,
            motion: self.motion.clone(),
            robot_ladders: self.robot_ladders.clone(),
            self_pairs,
            moving: self.moving.clone(),
            srdf_pairs: self.srdf_pairs.clone(),
            robot_targets: self.robot_targets,
            environment_objects: self.environment_objects,
            environment_frames: Arc::clone(&self.environment_frames),
            link_sizes: Arc::clone(&self.link_sizes),
        }
    }

    /// As [`Checker::with_semantic`], in place; on error nothing changes.
    pub(crate) fn apply_semantic(&mut self, text: &str, source: &str) -> Result<(), CheckerError> {
        let srdf = Srdf::parse(text, source, &self.robot).map_err(|e| CheckerError::Srdf(e.to_string()))?;
        self.self_pairs = SelfPairs::build(self, Some(srdf));
        self.srdf_pairs = None;
        Ok(())
    }
}

/// The scene of the environment at its zero state: thin surfaces (cells behind open meshes, and
/// behind closed ones not checked as solids) and convex solids; and the world pose of each of
/// its links (frames planning-scene objects may be placed in).
fn environment_scene(
    params: &Params,
    env: &RobotModel,
    cache: &mut MeshCache,
    summary: &mut BuildSummary,
) -> Result<(Scene, BTreeMap<String, Pose>), CheckerError> {
    let mut scene = Scene::new();
    let env_poses = env
        .forward_kinematics(&vec![0.0; env.joints.len()], &Isometry3::identity())
        .map_err(|e| CheckerError::Model(ModelError::Structure { file: summary.environment_source.clone(), message: e.to_string() }))?;
    let frames = env.links.iter().zip(&env_poses).map(|(l, p)| (l.name.clone(), pose_from_isometry(p))).collect();
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
                    add_environment_mesh(params, &mut scene, &link.name, pose, &data, summary).map_err(|message| CheckerError::Geometry {
                        file: summary.environment_source.clone(),
                        link: link.name.clone(),
                        what: format!("mesh {}", path.display()),
                        message,
                    })?;
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
    Ok((scene, frames))
}

/// One environment mesh into `scene`: a solid (its convex hull) when closed and named in
/// `solid_hull`, else a thin surface. The error is what is wrong with the mesh.
pub(super) fn add_environment_mesh(
    params: &Params,
    scene: &mut Scene,
    name: &str,
    pose: crate::math::Pose,
    data: &MeshData,
    summary: &mut BuildSummary,
) -> Result<(), String> {
    let _ = scene.add_body(name.to_owned(), pose, Arc::new(environment_mesh_body(params, name, data, summary)?));
    Ok(())
}

/// What [`add_environment_mesh`] adds, in the object's frame: its hull, or its cells.
pub(super) fn environment_mesh_body(params: &Params, name: &str, data: &MeshData, summary: &mut BuildSummary) -> Result<ObjectBody, String> {
    let mesh = MeshTopology::build(&data.vertices, &data.triangles, &TopologySettings::default()).map_err(|e| e.to_string())?;
    let closed = mesh.report.boundary_edges == 0 && mesh.report.non_manifold_edges == 0;
    if closed && params.is_solid_hull(name) {
        let hull = ConvexHull::from_points(&data.vertices).ok_or_else(|| "its convex hull is flat".to_owned())?;
        summary.solids += 1;
        return Ok(ObjectBody::Solid(TargetShape::Polytope(Arc::new(hull))));
    }
    let (thickness, side) = params.surface_settings(name);
    // A closed mesh has an inside: its cells go inward.
    let side = if closed { Side::Back } else { side };
    let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness, side, ..Default::default() }).map_err(|e| e.to_string())?;
    summary.cells += area.cells.len();
    summary.thin_surfaces += 1;
    Ok(ObjectBody::surface(area))
}

/// The targets of the robot's checked links (with geometry and matching `checked_links`), each
/// part grown by the link's padding; `file` names the robot in errors.
fn robot_targets(params: &Params, robot: &RobotModel, cache: &mut MeshCache, file: &str) -> Result<Vec<LinkTargets>, CheckerError> {
    let mut targets = Vec::new();
    for (li, link) in robot.links.iter().enumerate() {
        if link.geometry.is_empty() || !params.is_checked(&link.name) {
            continue;
        }
        let padding = params.padding_of(&link.name);
        let (mut parts, mut sources) = (Vec::new(), Vec::new());
        for g in &link.geometry {
            let source = link_source(&g.spec, cache, file, &link.name)?;
            let shape = source.sized(1.0, padding).ok_or_else(|| {
                let (what, message) = match &g.spec {
                    GeometrySpec::Mesh { path, .. } => (format!("mesh {}", path.display()), "padding failed"),
                    spec => (format!("{spec:?}"), "not a usable convex shape"),
                };
                CheckerError::Geometry { file: file.to_owned(), link: link.name.clone(), what, message: message.into() }
            })?;
            parts.push((shape, pose_from_isometry(&g.origin)));
            sources.push(source);
        }
        targets.push(LinkTargets { link: li, name: link.name.clone(), parts, sources: sources.into() });
    }
    Ok(targets)
}

/// What one geometry of robot link `link` is grown from: a mesh as its convex hull.
fn link_source(spec: &GeometrySpec, cache: &mut MeshCache, file: &str, link: &str) -> Result<PartSource, CheckerError> {
    match spec {
        GeometrySpec::Mesh { path, scale } => {
            let data = cache.get(path, *scale).map_err(|error| CheckerError::Mesh { file: file.to_owned(), link: link.to_owned(), error })?;
            PartSource::mesh(&data).ok_or_else(|| CheckerError::Geometry {
                file: file.to_owned(),
                link: link.to_owned(),
                what: format!("mesh {}", path.display()),
                message: "its convex hull is flat or empty".into(),
            })
        }
        spec => Ok(PartSource::Primitive(spec.clone())),
    }
}

/// `allowed[target][object]`: the pairs `allowed_collisions` never reports.
pub(super) fn allowed_matrix(params: &Params, targets: &[LinkTargets], scene: &Scene) -> Vec<Vec<bool>> {
    targets.iter().map(|t| scene.objects().iter().map(|o| params.is_allowed(&t.name, &o.name)).collect()).collect()
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
pub(super) fn moving_joints(robot: &RobotModel, targets: &[LinkTargets]) -> Vec<bool> {
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
