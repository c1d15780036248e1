//! A kinematic tree from URDF (`urdf-rs` parses; everything else is here): links with their
//! collision geometry, joints with limits and mimics, and forward kinematics in `nalgebra` f64.

use super::package::{PackageError, PackageResolver};
use super::xml_guard::{check_xml, for_each_tag, Tag};
use crate::limits::{
    contain_panic, is_coordinate, is_length, name_list, read_regular_text, InputFileError, LENGTH_RANGE, MAX_COORDINATE, MAX_DESCRIPTION_BYTES,
};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The geometry of one collision (or visual) element, in the link frame after `origin`.
#[derive(Clone, Debug, PartialEq)]
pub enum GeometrySpec {
    /// Full sizes (metres).
    Box([f64; 3]),
    /// Along local z.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Full length.
        length: f64,
    },
    /// Along local z.
    Capsule {
        /// Radius.
        radius: f64,
        /// Length of the segment.
        length: f64,
    },
    /// A ball.
    Sphere(f64),
    /// A mesh file (resolved path) and its scale.
    Mesh {
        /// Resolved file.
        path: PathBuf,
        /// Per-axis scale.
        scale: [f64; 3],
    },
}

/// One geometry element of a link.
#[derive(Clone, Debug)]
pub struct LinkGeometry {
    /// Pose of the geometry in the link frame.
    pub origin: Isometry3<f64>,
    /// The shape.
    pub spec: GeometrySpec,
}

/// A link.
#[derive(Clone, Debug)]
pub struct LinkModel {
    /// Name.
    pub name: String,
    /// Collision geometry (or visual, where configured and collision is absent).
    pub geometry: Vec<LinkGeometry>,
}

/// The motion a joint allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis, limited.
    Revolute,
    /// Rotation about the axis, unlimited.
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// No motion.
    Fixed,
    /// Six degrees of freedom; placed at its origin (joint states cannot carry it; use `/tf`).
    Floating,
    /// Motion in a plane; placed at its origin (as `Floating`).
    Planar,
}

/// A mimic relation: `q = multiplier * q[joint] + offset`.
#[derive(Clone, Copy, Debug)]
pub struct Mimic {
    /// Index of the joint followed.
    pub joint: usize,
    /// Multiplier.
    pub multiplier: f64,
    /// Offset.
    pub offset: f64,
}

/// A joint.
#[derive(Clone, Debug)]
pub struct JointModel {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: JointKind,
    /// Parent link index.
    pub parent: usize,
    /// Child link index.
    pub child: usize,
    /// Pose of the joint frame in the parent link frame.
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub axis: Unit<Vector3<f64>>,
    /// Lower and upper limits (radians or metres; infinite when absent or continuous).
    pub limits: [f64; 2],
    /// Mimic relation, if any.
    pub mimic: Option<Mimic>,
}

impl JointModel {
    /// Whether the joint takes a position from a joint state (not fixed, not a mimic).
    pub fn is_actuated(&self) -> bool {
        matches!(self.kind, JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic) && self.mimic.is_none()
    }
}

/// Joint positions that forward kinematics cannot use.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum PositionsError {
    /// Not one position per joint of the model.
    #[error("{got} joint positions for a model of {expected} joints")]
    Length {
        /// Joints of the model.
        expected: usize,
        /// Positions given.
        got: usize,
    },
    /// A position is NaN or infinite.
    #[error("joint '{joint}' has a non-finite position {value}")]
    NonFinite {
        /// The joint.
        joint: String,
        /// Its value.
        value: f64,
    },
}

/// A URDF that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The file cannot be read (missing, not a regular file, too large).
    #[error("{0}")]
    Input(Box<InputFileError>),
    /// urdf-rs rejected the XML.
    #[error("{file}: malformed URDF: {message}")]
    Urdf {
        /// File (or `robot_description`).
        file: String,
        /// What urdf-rs said.
        message: String,
    },
    /// A mesh URI of a link does not resolve. (The package error is part of the message, not a
    /// `source`: printed as a chain it would repeat itself.)
    #[error("{file}: link '{link}': {error}")]
    Package {
        /// File.
        file: String,
        /// Link.
        link: String,
        /// Why.
        error: PackageError,
    },
    /// The text is unexpanded xacro (urdf-rs would read past its macros: a robot with nothing
    /// to check).
    #[error("{file}: unexpanded xacro ({evidence}); expand it first (`xacro {file} > robot.urdf`) or publish the expanded URDF on robot_description")]
    Xacro {
        /// File (or `robot_description`).
        file: String,
        /// What marks it as xacro, with its line.
        evidence: String,
    },
    /// The joints do not form a tree.
    #[error("{file}: {message}")]
    Structure {
        /// File.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A number in the URDF is NaN, infinite or out of its domain.
    #[error("{file}: {what} has an invalid value {}", crate::limits::show_number(*.value))]
    Value {
        /// File.
        file: String,
        /// Where.
        what: String,
        /// The value.
        value: f64,
    },
}

/// A robot (or an environment) as a kinematic tree.
#[derive(Clone, Debug)]
pub struct RobotModel {
    /// The robot's name.
    pub name: String,
    /// Links.
    pub links: Vec<LinkModel>,
    /// Links with `<visual>` but no `<collision>` geometry whose visuals were not used (said when
    /// nothing is left to check).
    pub visual_only_links: usize,
    /// Joints.
    pub joints: Vec<JointModel>,
    /// The root link.
    pub root: usize,
    /// Joints in an order where every joint's parent link is placed before it.
    order: Vec<usize>,
    /// Per link: the joint whose child it is (none for the root).
    parent_joint: Vec<Option<usize>>,
    link_index: HashMap<String, usize>,
    joint_index: HashMap<String, usize>,
}

fn rpy(v: [f64; 3]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_euler_angles(v[0], v[1], v[2])
}

fn isometry(p: &urdf_rs::Pose) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]), rpy(p.rpy.0))
}

/// Attributes that hold numbers, by element; each whitespace-separated word must parse.
const NUMERIC_ATTRIBUTES: &[(&str, &[&str])] = &[
    ("origin", &["xyz", "rpy"]),
    ("axis", &["xyz"]),
    ("box", &["size"]),
    ("cylinder", &["radius", "length"]),
    ("capsule", &["radius", "length"]),
    ("sphere", &["radius"]),
    ("mesh", &["scale"]),
    ("limit", &["lower", "upper", "effort", "velocity"]),
    ("mimic", &["multiplier", "offset"]),
];

const SHAPES: [&str; 5] = ["box", "cylinder", "capsule", "sphere", "mesh"];

/// Checks what urdf-rs would accept silently or report in its own terms: a number that does not
/// parse (urdf-rs drops the word and counts the rest), and a `<geometry>` without exactly one
/// shape.
fn check_urdf_tags(text: &str) -> Result<(), String> {
    // (line, depth, shapes seen) of the open <geometry>.
    let mut geometry: Option<(usize, usize, Vec<String>)> = None;
    let mut depth = 0usize;
    for_each_tag(text, |t: &Tag| {
        if t.end {
            depth = depth.saturating_sub(1);
        }
        if let Some((line, d, shapes)) = &geometry {
            if (t.end || t.empty) && t.name == "geometry" && (t.empty || depth == *d) {
                let shapes = if t.empty { Vec::new() } else { shapes.clone() };
                let line = if t.empty { t.line } else { *line };
                if shapes.len() != 1 {
                    let found = if shapes.is_empty() { "no shape".to_string() } else { format!("{} shapes ({})", shapes.len(), name_list(&shapes)) };
                    return Err(format!("line {line}: <geometry> has {found}; expected exactly one of {}", SHAPES.join(", ")));
                }
                geometry = None;
            }
        } else if t.name == "geometry" && t.empty {
            return Err(format!("line {}: <geometry> has no shape; expected exactly one of {}", t.line, SHAPES.join(", ")));
        }
        if t.end {
            return Ok(());
        }
        if let Some((_, d, shapes)) = &mut geometry {
            if depth == *d + 1 {
                shapes.push(t.name.to_owned());
            }
        }
        if let Some((_, names)) = NUMERIC_ATTRIBUTES.iter().find(|(e, _)| *e == t.name) {
            for (key, value) in &t.attributes {
                if names.contains(key) {
                    if let Some(word) = value.split_whitespace().find(|w| w.parse::<f64>().is_err()) {
                        return Err(format!("line {}: <{} {key}=\"{value}\">: '{word}' is not a number", t.line, t.name));
                    }
                }
            }
        }
        if t.name == "geometry" && !t.empty {
            geometry = Some((t.line, depth, Vec::new()));
        }
        if !t.empty {
            depth += 1;
        }
        Ok(())
    })
}

impl RobotModel {
    /// Loads a URDF file; relative mesh paths resolve from its folder.
    pub fn from_file(path: &Path, resolver: &PackageResolver, use_visual: bool) -> Result<RobotModel, ModelError> {
        let text = read_regular_text(path, "URDF file", MAX_DESCRIPTION_BYTES).map_err(|e| ModelError::Input(Box::new(e)))?;
        let base = path.parent().unwrap_or(Path::new("."));
        Self::from_str(&text, &path.display().to_string(), base, resolver, use_visual)
    }

    /// Parses URDF text (`file` names it in errors; relative paths resolve from `base_dir`).
    pub fn from_str(text: &str, file: &str, base_dir: &Path, resolver: &PackageResolver, use_visual: bool) -> Result<RobotModel, ModelError> {
        let malformed = |message: String| ModelError::Urdf { file: file.into(), message };
        if text.len() as u64 > MAX_DESCRIPTION_BYTES {
            return Err(malformed(format!("{} bytes, more than the {MAX_DESCRIPTION_BYTES} allowed", text.len())));
        }
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        check_xml(text.as_bytes()).map_err(|e| malformed(e.to_string()))?;
        if let Some(evidence) = super::xacro::xacro_evidence(text, file) {
            return Err(ModelError::Xacro { file: file.into(), evidence });
        }
        check_urdf_tags(text).map_err(malformed)?;
        let urdf = contain_panic(|| urdf_rs::read_from_string(text))
            .map_err(|panic| malformed(format!("urdf-rs failed on this text ({panic})")))?
            .map_err(|e| malformed(crate::limits::first_line(&e.to_string())))?;
        let structure = |message: String| ModelError::Structure { file: file.into(), message };
        if urdf.links.is_empty() {
            return Err(structure("the robot has no links".into()));
        }
        let mut link_index = HashMap::new();
        let mut links = Vec::with_capacity(urdf.links.len());
        let visual_only_links = if use_visual { 0 } else { urdf.links.iter().filter(|l| l.collision.is_empty() && !l.visual.is_empty()).count() };
        for (i, l) in urdf.links.iter().enumerate() {
            if link_index.insert(l.name.clone(), i).is_some() {
                return Err(structure(format!("link '{}' is defined twice", l.name)));
            }
            let elements: Vec<(&urdf_rs::Pose, &urdf_rs::Geometry)> = if l.collision.is_empty() && use_visual {
                l.visual.iter().map(|v| (&v.origin, &v.geometry)).collect()
            } else {
                l.collision.iter().map(|c| (&c.origin, &c.geometry)).collect()
            };
            let mut geometry = Vec::new();
            for (origin, g) in elements {
                let bad = |what: &str, value: f64| ModelError::Value { file: file.into(), what: format!("link '{}' {what}", l.name), value };
                if let Some(v) = origin.xyz.0.iter().find(|v| !is_coordinate(**v)) {
                    return Err(bad(&format!("origin xyz (allowed: |x| <= {MAX_COORDINATE:e} m)"), *v));
                }
                if let Some(v) = origin.rpy.0.iter().find(|v| !v.is_finite()) {
                    return Err(bad("origin rpy", *v));
                }
                let positive = |what: &str, v: f64| {
                    if is_length(v) {
                        Ok(v)
                    } else {
                        Err(bad(&format!("{what} (allowed: {:e} to {:e} m)", LENGTH_RANGE[0], LENGTH_RANGE[1]), v))
                    }
                };
                let spec = match g {
                    urdf_rs::Geometry::Box { size } => {
                        GeometrySpec::Box([positive("box size", size[0])?, positive("box size", size[1])?, positive("box size", size[2])?])
                    }
                    urdf_rs::Geometry::Cylinder { radius, length } => {
                        GeometrySpec::Cylinder { radius: positive("cylinder radius", *radius)?, length: positive("cylinder length", *length)? }
                    }
                    urdf_rs::Geometry::Capsule { radius, length } => GeometrySpec::Capsule {
                        radius: positive("capsule radius", *radius)?,
                        length: if *length == 0.0 { 0.0 } else { positive("capsule length", *length)? },
                    },
                    urdf_rs::Geometry::Sphere { radius } => GeometrySpec::Sphere(positive("sphere radius", *radius)?),
                    urdf_rs::Geometry::Mesh { filename, scale } => {
                        let path =
                            resolver.resolve(filename, base_dir).map_err(|error| ModelError::Package { file: file.into(), link: l.name.clone(), error })?;
                        let scale = scale.map_or([1.0; 3], |s| s.0);
                        if let Some(s) = scale.iter().find(|s| !(s.is_finite() && **s != 0.0 && s.abs() <= MAX_COORDINATE)) {
                            return Err(bad(&format!("mesh scale (allowed: non-zero, |s| <= {MAX_COORDINATE:e})"), *s));
                        }
                        GeometrySpec::Mesh { path, scale }
                    }
                };
                geometry.push(LinkGeometry { origin: isometry(origin), spec });
            }
            links.push(LinkModel { name: l.name.clone(), geometry });
        }
        let mut joint_index = HashMap::new();
        let mut joints = Vec::with_capacity(urdf.joints.len());
        let mut parent_of = vec![None; links.len()];
        for (i, j) in urdf.joints.iter().enumerate() {
            let find = |name: &str, role: &str| {
                link_index.get(name).copied().ok_or_else(|| structure(format!("joint '{}' names {role} link '{name}', which does not exist", j.name)))
            };
            let (parent, child) = (find(&j.parent.link, "parent")?, find(&j.child.link, "child")?);
            if joint_index.insert(j.name.clone(), i).is_some() {
                return Err(structure(format!("joint '{}' is defined twice", j.name)));
            }
            if let Some(other) = parent_of[child].replace(i) {
                return Err(structure(format!("link '{}' is the child of two joints ('{}' and '{}')", j.child.link, urdf.joints[other].name, j.name)));
            }
            let kind = match j.joint_type {
                urdf_rs::JointType::Revolute => JointKind::Revolute,
                urdf_rs::JointType::Continuous => JointKind::Continuous,
                urdf_rs::JointType::Prismatic => JointKind::Prismatic,
                urdf_rs::JointType::Fixed => JointKind::Fixed,
                urdf_rs::JointType::Floating | urdf_rs::JointType::Spherical => JointKind::Floating,
                urdf_rs::JointType::Planar => JointKind::Planar,
            };
            let a = Vector3::from(j.axis.xyz.0);
            // Scaled by its largest component before normalising: `1e160 0 0` would overflow
            // the squared norm and give a non-unit rotation.
            let largest = a.amax();
            let axis = match Unit::try_new(a / largest, 1e-12) {
                Some(axis) if largest.is_finite() && largest > 0.0 => axis,
                _ if matches!(kind, JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic) => {
                    return Err(structure(format!("joint '{}' has a zero or invalid axis {:?}", j.name, j.axis.xyz.0)));
                }
                _ => Vector3::z_axis(),
            };
            let bad = |what: String, value: f64| ModelError::Value { file: file.into(), what: format!("joint '{}' {what}", j.name), value };
            if let Some(v) = j.origin.xyz.0.iter().find(|v| !is_coordinate(**v)) {
                return Err(bad(format!("origin xyz (allowed: |x| <= {MAX_COORDINATE:e} m)"), *v));
            }
            if let Some(v) = j.origin.rpy.0.iter().find(|v| !v.is_finite()) {
                return Err(bad("origin rpy".into(), *v));
            }
            let limits = match kind {
                JointKind::Revolute | JointKind::Prismatic => {
                    let [lower, upper] = [j.limit.lower, j.limit.upper];
                    if let Some(v) = [lower, upper].into_iter().find(|v| !is_coordinate(*v)) {
                        return Err(bad(format!("limit (allowed: finite, |x| <= {MAX_COORDINATE:e})"), v));
                    }
                    if lower > upper {
                        return Err(structure(format!("joint '{}' has limit lower {lower} above upper {upper}", j.name)));
                    }
                    [lower, upper]
                }
                _ => [f64::NEG_INFINITY, f64::INFINITY],
            };
            joints.push(JointModel { name: j.name.clone(), kind, parent, child, origin: isometry(&j.origin), axis, limits, mimic: None });
        }
        for (i, j) in urdf.joints.iter().enumerate() {
            if let Some(m) = &j.mimic {
                let target = *joint_index.get(&m.joint).ok_or_else(|| structure(format!("joint '{}' mimics '{}', which does not exist", j.name, m.joint)))?;
                let (multiplier, offset) = (m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0));
                for (what, v) in [("multiplier", multiplier), ("offset", offset)] {
                    if !(v.is_finite() && v.abs() <= MAX_COORDINATE) {
                        return Err(ModelError::Value {
                            file: file.into(),
                            what: format!("joint '{}' mimic {what} (allowed: finite, |x| <= {MAX_COORDINATE:e})", j.name),
                            value: v,
                        });
                    }
                }
                joints[i].mimic = Some(Mimic { joint: target, multiplier, offset });
            }
        }
        let roots: Vec<usize> = (0..links.len()).filter(|&l| parent_of[l].is_none()).collect();
        let root = match roots[..] {
            [r] => r,
            [] => return Err(structure("the joints form a cycle: no root link".into())),
            _ => {
                let names: Vec<&str> = roots.iter().map(|&r| links[r].name.as_str()).collect();
                return Err(structure(format!("{} root links, one allowed (join them with fixed joints): {}", names.len(), name_list(&names))));
            }
        };
        // Breadth-first from the root: parents before children.
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
        for (i, j) in joints.iter().enumerate() {
            children[j.parent].push(i);
        }
        let mut order = Vec::with_capacity(joints.len());
        let mut queue = std::collections::VecDeque::from([root]);
        while let Some(l) = queue.pop_front() {
            for &j in &children[l] {
                order.push(j);
                queue.push_back(joints[j].child);
            }
        }
        if order.len() != joints.len() {
            return Err(structure("the joints form a cycle".into()));
        }
        for j in &joints {
            if let Some(m) = j.mimic {
                if joints[m.joint].mimic.is_some() {
                    return Err(structure(format!("joint '{}' mimics '{}', which is itself a mimic", j.name, joints[m.joint].name)));
                }
            }
        }
        let mut parent_joint = vec![None; links.len()];
        for (j, joint) in joints.iter().enumerate() {
            parent_joint[joint.child] = Some(j);
        }
        Ok(RobotModel { name: urdf.name, links, visual_only_links, joints, root, order, parent_joint, link_index, joint_index })
    }

    /// The joint whose child link `link` is; `None` for the root (or an index out of range).
    pub fn parent_joint(&self, link: usize) -> Option<usize> {
        self.parent_joint.get(link).copied().flatten()
    }

    /// Index of a link by name.
    pub fn link(&self, name: &str) -> Option<usize> {
        self.link_index.get(name).copied()
    }

    /// Index of a joint by name.
    pub fn joint(&self, name: &str) -> Option<usize> {
        self.joint_index.get(name).copied()
    }

    /// The error [`RobotModel::forward_kinematics`] would give for `positions`, without the poses.
    pub fn validate_positions(&self, positions: &[f64]) -> Result<(), PositionsError> {
        if positions.len() != self.joints.len() {
            return Err(PositionsError::Length { expected: self.joints.len(), got: positions.len() });
        }
        if let Some((j, v)) = positions.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(PositionsError::NonFinite { joint: self.joints[j].name.clone(), value: *v });
        }
        Ok(())
    }

    /// The world pose of every link, given a position for every joint (indexed like `joints`;
    /// ignored for fixed, floating and planar joints and for mimics, whose value is derived) and
    /// the pose of the root link in the world.
    ///
    /// A slice of the wrong length, or a non-finite position, is an error naming it.
    pub fn forward_kinematics(&self, positions: &[f64], base: &Isometry3<f64>) -> Result<Vec<Isometry3<f64>>, PositionsError> {
        self.validate_positions(positions)?;
        let mut poses = vec![Isometry3::identity(); self.links.len()];
        poses[self.root] = *base;
        for &ji in &self.order {
            let j = &self.joints[ji];
            let q = match j.mimic {
                Some(m) => m.multiplier * positions[m.joint] + m.offset,
                None => positions[ji],
            };
            let motion = match j.kind {
                JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_axis_angle(&j.axis, q)),
                JointKind::Prismatic => Isometry3::from_parts(Translation3::from(j.axis.into_inner() * q), UnitQuaternion::identity()),
                JointKind::Fixed | JointKind::Floating | JointKind::Planar => Isometry3::identity(),
            };
            poses[j.child] = poses[j.parent] * j.origin * motion;
        }
        Ok(poses)
    }
}
