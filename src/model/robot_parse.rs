//! URDF text turned into a [`RobotModel`]: the text guarded (size, XML shape, xacro left
//! unexpanded, numbers that do not parse), parsed by `urdf-rs`, then every link, geometry and
//! joint checked and the tree ordered from its root.

use super::package::PackageResolver;
use super::robot::{GeometrySpec, JointKind, JointModel, LinkGeometry, LinkModel, Mimic, ModelError, RobotModel};
use super::xml_guard::{check_xml, for_each_tag, Tag};
use crate::limits::{contain_panic, is_coordinate, is_length, name_list, read_regular_text, LENGTH_RANGE, MAX_COORDINATE, MAX_DESCRIPTION_BYTES};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::Path;

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
        let urdf = parse_urdf(text, file)?;
        let structure = |message: String| ModelError::Structure { file: file.into(), message };
        if urdf.links.is_empty() {
            return Err(structure("the robot has no links".into()));
        }
        let visual_only_links = if use_visual { 0 } else { urdf.links.iter().filter(|l| l.collision.is_empty() && !l.visual.is_empty()).count() };
        let reader = UrdfReader { file, base_dir, resolver, use_visual };
        let (links, link_index) = reader.links(&urdf.links)?;
        let ReadJoints { mut joints, joint_index, parent_of } = reader.joints(&urdf.joints, &link_index, links.len())?;
        reader.mimics(&urdf.joints, &joint_index, &mut joints)?;
        let root = root_link(&links, &parent_of).map_err(structure)?;
        let order = joint_order(root, &links, &joints).map_err(structure)?;
        let mut parent_joint = vec![None; links.len()];
        for (j, joint) in joints.iter().enumerate() {
            parent_joint[joint.child] = Some(j);
        }
        Ok(RobotModel { name: urdf.name, links, visual_only_links, joints, root, order, parent_joint, link_index, joint_index })
    }
}

/// The URDF `urdf-rs` reads from `text`, once the text passed the guards it cannot be trusted
/// with.
fn parse_urdf(text: &str, file: &str) -> Result<urdf_rs::Robot, ModelError> {
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
    contain_panic(|| urdf_rs::read_from_string(text))
        .map_err(|panic| malformed(format!("urdf-rs failed on this text ({panic})")))?
        .map_err(|e| malformed(crate::limits::first_line(&e.to_string())))
}

/// The joints of a URDF as read (mimics not yet resolved), their indices by name, and per link
/// the joint whose child it is.
struct ReadJoints {
    joints: Vec<JointModel>,
    joint_index: HashMap<String, usize>,
    parent_of: Vec<Option<usize>>,
}

/// What the links and joints of one URDF are read with.
struct UrdfReader<'a> {
    file: &'a str,
    base_dir: &'a Path,
    resolver: &'a PackageResolver,
    use_visual: bool,
}

impl UrdfReader<'_> {
    fn structure(&self, message: String) -> ModelError {
        ModelError::Structure { file: self.file.into(), message }
    }

    /// The links, each with its collision geometry (its visual one instead, where configured
    /// and collision is absent), and their indices by name.
    fn links(&self, urdf: &[urdf_rs::Link]) -> Result<(Vec<LinkModel>, HashMap<String, usize>), ModelError> {
        let mut link_index = HashMap::new();
        let mut links = Vec::with_capacity(urdf.len());
        for (i, l) in urdf.iter().enumerate() {
            if link_index.insert(l.name.clone(), i).is_some() {
                return Err(self.structure(format!("link '{}' is defined twice", l.name)));
            }
            let elements: Vec<(&urdf_rs::Pose, &urdf_rs::Geometry)> = if l.collision.is_empty() && self.use_visual {
                l.visual.iter().map(|v| (&v.origin, &v.geometry)).collect()
            } else {
                l.collision.iter().map(|c| (&c.origin, &c.geometry)).collect()
            };
            let mut geometry = Vec::new();
            for (origin, g) in elements {
                geometry.push(self.geometry(&l.name, origin, g)?);
            }
            links.push(LinkModel { name: l.name.clone(), geometry });
        }
        Ok((links, link_index))
    }

    /// One geometry element of link `link`, its pose and sizes checked.
    fn geometry(&self, link: &str, origin: &urdf_rs::Pose, g: &urdf_rs::Geometry) -> Result<LinkGeometry, ModelError> {
        let bad = |what: &str, value: f64| ModelError::Value { file: self.file.into(), what: format!("link '{link}' {what}"), value };
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
                let path = self.resolver.resolve(filename, self.base_dir).map_err(|error| ModelError::Package {
                    file: self.file.into(),
                    link: link.to_owned(),
                    error,
                })?;
                let scale = scale.map_or([1.0; 3], |s| s.0);
                if let Some(s) = scale.iter().find(|s| !(s.is_finite() && **s != 0.0 && s.abs() <= MAX_COORDINATE)) {
                    return Err(bad(&format!("mesh scale (allowed: non-zero, |s| <= {MAX_COORDINATE:e})"), *s));
                }
                GeometrySpec::Mesh { path, scale }
            }
        };
        Ok(LinkGeometry { origin: isometry(origin), spec })
    }

    /// The joints, each between two links of `link_index`, a link the child of one joint at most.
    fn joints(&self, urdf: &[urdf_rs::Joint], link_index: &HashMap<String, usize>, link_count: usize) -> Result<ReadJoints, ModelError> {
        let mut joint_index = HashMap::new();
        let mut joints = Vec::with_capacity(urdf.len());
        let mut parent_of = vec![None; link_count];
        for (i, j) in urdf.iter().enumerate() {
            let find = |name: &str, role: &str| {
                link_index.get(name).copied().ok_or_else(|| self.structure(format!("joint '{}' names {role} link '{name}', which does not exist", j.name)))
            };
            let (parent, child) = (find(&j.parent.link, "parent")?, find(&j.child.link, "child")?);
            if joint_index.insert(j.name.clone(), i).is_some() {
                return Err(self.structure(format!("joint '{}' is defined twice", j.name)));
            }
            if let Some(other) = parent_of[child].replace(i) {
                return Err(self.structure(format!("link '{}' is the child of two joints ('{}' and '{}')", j.child.link, urdf[other].name, j.name)));
            }
            joints.push(self.joint(j, parent, child)?);
        }
        Ok(ReadJoints { joints, joint_index, parent_of })
    }

    /// One joint between links `parent` and `child`, its axis, origin and limits checked.
    fn joint(&self, j: &urdf_rs::Joint, parent: usize, child: usize) -> Result<JointModel, ModelError> {
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
                return Err(self.structure(format!("joint '{}' has a zero or invalid axis {:?}", j.name, j.axis.xyz.0)));
            }
            _ => Vector3::z_axis(),
        };
        let bad = |what: String, value: f64| ModelError::Value { file: self.file.into(), what: format!("joint '{}' {what}", j.name), value };
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
                    return Err(self.structure(format!("joint '{}' has limit lower {lower} above upper {upper}", j.name)));
                }
                [lower, upper]
            }
            _ => [f64::NEG_INFINITY, f64::INFINITY],
        };
        Ok(JointModel { name: j.name.clone(), kind, parent, child, origin: isometry(&j.origin), axis, limits, mimic: None })
    }

    /// Every `<mimic>`: the joint it follows, with a finite multiplier and offset.
    fn mimics(&self, urdf: &[urdf_rs::Joint], joint_index: &HashMap<String, usize>, joints: &mut [JointModel]) -> Result<(), ModelError> {
        for (i, j) in urdf.iter().enumerate() {
            if let Some(m) = &j.mimic {
                let target =
                    *joint_index.get(&m.joint).ok_or_else(|| self.structure(format!("joint '{}' mimics '{}', which does not exist", j.name, m.joint)))?;
                let (multiplier, offset) = (m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0));
                for (what, v) in [("multiplier", multiplier), ("offset", offset)] {
                    if !(v.is_finite() && v.abs() <= MAX_COORDINATE) {
                        return Err(ModelError::Value {
                            file: self.file.into(),
                            what: format!("joint '{}' mimic {what} (allowed: finite, |x| <= {MAX_COORDINATE:e})", j.name),
                            value: v,
                        });
                    }
                }
                joints[i].mimic = Some(Mimic { joint: target, multiplier, offset });
            }
        }
        Ok(())
    }
}

/// The one link that is no joint's child.
fn root_link(links: &[LinkModel], parent_of: &[Option<usize>]) -> Result<usize, String> {
    let roots: Vec<usize> = (0..links.len()).filter(|&l| parent_of[l].is_none()).collect();
    match roots[..] {
        [r] => Ok(r),
        [] => Err("the joints form a cycle: no root link".into()),
        _ => {
            let names: Vec<&str> = roots.iter().map(|&r| links[r].name.as_str()).collect();
            Err(format!("{} root links, one allowed (join them with fixed joints): {}", names.len(), name_list(&names)))
        }
    }
}

/// The joints breadth-first from the root (parents before children); refuses a cycle and a
/// mimic of a mimic.
fn joint_order(root: usize, links: &[LinkModel], joints: &[JointModel]) -> Result<Vec<usize>, String> {
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
        return Err("the joints form a cycle".into());
    }
    for j in joints {
        if let Some(m) = j.mimic {
            if joints[m.joint].mimic.is_some() {
                return Err(format!("joint '{}' mimics '{}', which is itself a mimic", j.name, joints[m.joint].name));
            }
        }
    }
    Ok(order)
}
