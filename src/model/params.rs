//! The parameters: one ROS 2 parameters YAML read by the CLI and the node alike.
//!
//! The file has the usual shape `<node>: ros__parameters: {...}` (the node `thickness_collision`,
//! or `/**` for every node). Values are types ROS 2 parameters can hold: no maps, so per-item
//! settings are parallel arrays (`thin_surfaces.patterns` with `.thickness` and `.side`).
//! Unknown keys are an error naming the key.

use crate::thickness::Side;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What to do when a robot state lacks a joint of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MissingJoint {
    /// Use 0.
    #[default]
    Zero,
    /// Use the last value seen for it (0 before any).
    Last,
    /// Reject the state.
    Reject,
}

/// Per-pattern thickness and side of thin surfaces (parallel arrays).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThinSurfaces {
    /// Glob patterns over environment link names (`*`, `?`).
    pub patterns: Vec<String>,
    /// Thickness for each pattern (metres).
    pub thickness: Vec<f64>,
    /// Side for each pattern (`back`, `front`, `both`); may be empty (then `default_side`).
    pub side: Vec<String>,
}

/// Per-link padding of robot links (parallel arrays).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Padding {
    /// Glob patterns over robot link names.
    pub links: Vec<String>,
    /// Padding for each pattern (metres).
    pub values: Vec<f64>,
}

/// All parameters, with their defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// The robot's URDF file (empty: the bundled example arm).
    pub robot_description_file: String,
    /// The environment's URDF file (empty: the bundled example workcell).
    pub environment_file: String,
    /// The frame reports are expressed in.
    pub world_frame: String,
    /// Pose of the robot's root link in the world: x, y, z (metres), roll, pitch, yaw (radians).
    pub robot_base_pose: Vec<f64>,
    /// Thickness of thin surfaces no pattern matches (metres).
    pub default_thickness: f64,
    /// Side of thin surfaces no pattern matches.
    pub default_side: String,
    /// `package://` resolution: `["pkg=/path/to/pkg", ...]`, searched first.
    pub package_map: Vec<String>,
    /// Per-pattern thickness and side.
    pub thin_surfaces: ThinSurfaces,
    /// Environment links (globs) whose closed meshes are checked as their convex hull.
    pub solid_hull: Vec<String>,
    /// Per-link padding.
    pub padding: Padding,
    /// `["robot_link:environment_link", ...]` pairs never reported (globs allowed).
    pub allowed_collisions: Vec<String>,
    /// `zero`, `last` or `reject`.
    pub missing_joint: MissingJoint,
    /// Robot links (globs) that are checked; default all.
    pub checked_links: Vec<String>,
    /// Use visual geometry for links that have no collision geometry.
    pub use_visual_when_no_collision: bool,
    /// Where the node takes robot states from: `joint_states` (forward kinematics) or `tf`.
    pub pose_source: String,
    /// Prefix of the robot's frames on `/tf` (e.g. `robot1/` when several robots share it).
    pub frame_prefix: String,
    /// At most this many cells are drawn on `collision_markers/cells`.
    pub marker_max_cells: i64,
    /// At most this many contact marker messages per second (Hz).
    pub marker_rate: f64,
    /// Stamp the node's own messages (markers, diagnostics) with `/clock` time.
    pub use_sim_time: bool,
    /// Request/reply mapping of `check_states`: `cyclone` (rmw_cyclonedds), `enhanced` (Fast DDS,
    /// Connext) or `basic`.
    pub service_mapping: String,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            robot_description_file: String::new(),
            environment_file: String::new(),
            world_frame: "world".into(),
            robot_base_pose: vec![0.0; 6],
            default_thickness: 0.02,
            default_side: "back".into(),
            package_map: Vec::new(),
            thin_surfaces: ThinSurfaces::default(),
            solid_hull: Vec::new(),
            padding: Padding::default(),
            allowed_collisions: Vec::new(),
            missing_joint: MissingJoint::Zero,
            checked_links: vec!["*".into()],
            use_visual_when_no_collision: false,
            pose_source: "joint_states".into(),
            frame_prefix: String::new(),
            marker_max_cells: 20_000,
            marker_rate: 10.0,
            use_sim_time: false,
            service_mapping: "cyclone".into(),
        }
    }
}

/// A parameters file or value that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsError {
    /// The file cannot be read.
    #[error("cannot read parameters file {0}")]
    Io(PathBuf, #[source] std::io::Error),
    /// The YAML is malformed or has an unknown key or a wrong type.
    #[error("parameters file {0}: {1}")]
    Yaml(PathBuf, String),
    /// The file has no section for this node.
    #[error("parameters file {0} has no `thickness_collision:` or `/**:` section with `ros__parameters`")]
    NoSection(PathBuf),
    /// A value is out of its domain.
    #[error("parameter {name}: {message}")]
    Invalid {
        /// The parameter.
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// The bundled example workcell (the robot, environment and parameters in `config/`).
pub fn bundled_config_dir() -> PathBuf {
    match std::env::var_os("THICKNESS_COLLISION_CONFIG") {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config"),
    }
}

impl Params {
    /// Reads the node's section of a ROS 2 parameters file.
    pub fn from_file(path: &Path) -> Result<Params, ParamsError> {
        let text = std::fs::read_to_string(path).map_err(|e| ParamsError::Io(path.to_owned(), e))?;
        Self::from_yaml(&text, path)
    }

    /// Parses the node's section of a ROS 2 parameters YAML (`path` names it in errors).
    pub fn from_yaml(text: &str, path: &Path) -> Result<Params, ParamsError> {
        let doc: serde_yaml::Value = serde_yaml::from_str(text).map_err(|e| ParamsError::Yaml(path.to_owned(), e.to_string()))?;
        let section = ["thickness_collision", "/thickness_collision", "/**"]
            .iter()
            .find_map(|k| doc.get(k).and_then(|s| s.get("ros__parameters")))
            .ok_or_else(|| ParamsError::NoSection(path.to_owned()))?;
        let params: Params = serde_yaml::from_value(section.clone()).map_err(|e| ParamsError::Yaml(path.to_owned(), e.to_string()))?;
        params.validate()?;
        Ok(params)
    }

    /// Checks every value's domain and the lengths of parallel arrays.
    pub fn validate(&self) -> Result<(), ParamsError> {
        let bad = |name: &str, message: String| Err(ParamsError::Invalid { name: name.into(), message });
        if self.robot_base_pose.len() != 6 || self.robot_base_pose.iter().any(|v| !v.is_finite()) {
            return bad("robot_base_pose", format!("needs 6 finite numbers (x y z roll pitch yaw), got {:?}", self.robot_base_pose));
        }
        if !(self.default_thickness > 0.0 && self.default_thickness.is_finite()) {
            return bad("default_thickness", format!("must be a positive number of metres, got {}", self.default_thickness));
        }
        if parse_side(&self.default_side).is_none() {
            return bad("default_side", format!("must be back, front or both, got '{}'", self.default_side));
        }
        let ts = &self.thin_surfaces;
        if ts.thickness.len() != ts.patterns.len() {
            return bad("thin_surfaces.thickness", format!("has {} values for {} patterns", ts.thickness.len(), ts.patterns.len()));
        }
        if !ts.side.is_empty() && ts.side.len() != ts.patterns.len() {
            return bad("thin_surfaces.side", format!("has {} values for {} patterns", ts.side.len(), ts.patterns.len()));
        }
        if let Some(t) = ts.thickness.iter().find(|t| !(**t > 0.0 && t.is_finite())) {
            return bad("thin_surfaces.thickness", format!("must be positive, got {t}"));
        }
        if let Some(s) = ts.side.iter().find(|s| parse_side(s).is_none()) {
            return bad("thin_surfaces.side", format!("must be back, front or both, got '{s}'"));
        }
        if self.padding.values.len() != self.padding.links.len() {
            return bad("padding.values", format!("has {} values for {} link patterns", self.padding.values.len(), self.padding.links.len()));
        }
        if let Some(p) = self.padding.values.iter().find(|p| !(**p >= 0.0 && p.is_finite())) {
            return bad("padding.values", format!("must be >= 0, got {p}"));
        }
        if let Some(p) = self.allowed_collisions.iter().find(|p| p.split(':').count() != 2) {
            return bad("allowed_collisions", format!("'{p}' is not of the form robot_link:environment_link"));
        }
        if self.marker_max_cells < 0 {
            return bad("marker_max_cells", format!("must be >= 0, got {}", self.marker_max_cells));
        }
        if !(self.marker_rate > 0.0 && self.marker_rate.is_finite()) {
            return bad("marker_rate", format!("must be a positive rate in Hz, got {}", self.marker_rate));
        }
        if !matches!(self.service_mapping.as_str(), "cyclone" | "enhanced" | "basic") {
            return bad("service_mapping", format!("must be cyclone, enhanced or basic, got '{}'", self.service_mapping));
        }
        if !matches!(self.pose_source.as_str(), "joint_states" | "tf") {
            return bad("pose_source", format!("must be joint_states or tf, got '{}'", self.pose_source));
        }
        if let Some(p) = self.package_map.iter().find(|p| !p.contains('=')) {
            return bad("package_map", format!("'{p}' is not of the form package=/path"));
        }
        Ok(())
    }

    /// Thickness and side of the thin surface on environment link `link`.
    pub fn surface_settings(&self, link: &str) -> (f64, Side) {
        let default_side = parse_side(&self.default_side).unwrap_or_default();
        let ts = &self.thin_surfaces;
        match ts.patterns.iter().position(|p| glob_match(p, link)) {
            Some(i) => (ts.thickness[i], ts.side.get(i).and_then(|s| parse_side(s)).unwrap_or(default_side)),
            None => (self.default_thickness, default_side),
        }
    }

    /// Padding of robot link `link` (metres).
    pub fn padding_of(&self, link: &str) -> f64 {
        self.padding.links.iter().position(|p| glob_match(p, link)).map_or(0.0, |i| self.padding.values[i])
    }

    /// Whether a collision between robot link `link` and environment link `object` is allowed.
    pub fn is_allowed(&self, link: &str, object: &str) -> bool {
        self.allowed_collisions.iter().any(|pair| match pair.split_once(':') {
            Some((l, o)) => glob_match(l, link) && glob_match(o, object),
            None => false,
        })
    }

    /// Whether robot link `link` is checked.
    pub fn is_checked(&self, link: &str) -> bool {
        self.checked_links.iter().any(|p| glob_match(p, link))
    }

    /// Whether the closed meshes of environment link `link` are checked as convex hulls.
    pub fn is_solid_hull(&self, link: &str) -> bool {
        self.solid_hull.iter().any(|p| glob_match(p, link))
    }

    /// The parameters as a ROS 2 parameters YAML (for `--show-default-params`).
    pub fn to_yaml(&self) -> String {
        #[derive(Serialize)]
        struct Section<'a> {
            #[serde(rename = "ros__parameters")]
            params: &'a Params,
        }
        #[derive(Serialize)]
        struct File<'a> {
            thickness_collision: Section<'a>,
        }
        serde_yaml::to_string(&File { thickness_collision: Section { params: self } }).unwrap_or_default()
    }
}

/// `back`, `front` or `both`.
pub fn parse_side(s: &str) -> Option<Side> {
    match s {
        "back" => Some(Side::Back),
        "front" => Some(Side::Front),
        "both" => Some(Side::Both),
        _ => None,
    }
}

/// Glob match with `*` (any run) and `?` (one character).
pub fn glob_match(pattern: &str, text: &str) -> bool {
    let (p, t): (Vec<char>, Vec<char>) = (pattern.chars().collect(), text.chars().collect());
    let (mut pi, mut ti, mut star, mut mark) = (0, 0, None, 0);
    while ti < t.len() {
        if pi < p.len() && (p[pi] == '?' || p[pi] == t[ti]) {
            pi += 1;
            ti += 1;
        } else if pi < p.len() && p[pi] == '*' {
            star = Some(pi);
            mark = ti;
            pi += 1;
        } else if let Some(s) = star {
            pi = s + 1;
            mark += 1;
            ti = mark;
        } else {
            return false;
        }
    }
    p[pi..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs() {
        assert!(glob_match("*", "anything"));
        assert!(glob_match("guard_*", "guard_sheet"));
        assert!(!glob_match("guard_*", "shelf"));
        assert!(glob_match("link?", "link7"));
        assert!(glob_match("*_sheet", "guard_sheet"));
        assert!(!glob_match("link?", "link10"));
    }

    #[test]
    fn unknown_key_is_named() {
        let e = Params::from_yaml("thickness_collision:\n  ros__parameters:\n    default_thicknes: 0.1\n", Path::new("p.yaml")).unwrap_err();
        assert!(e.to_string().contains("default_thicknes"), "{e}");
    }

    #[test]
    fn defaults_and_roundtrip() {
        let p = Params::default();
        let q = Params::from_yaml(&p.to_yaml(), Path::new("x")).unwrap();
        assert_eq!(p, q);
        let e = Params::from_yaml("thickness_collision:\n  ros__parameters:\n    thin_surfaces:\n      patterns: [a]\n", Path::new("p.yaml")).unwrap_err();
        assert!(e.to_string().contains("thin_surfaces.thickness"), "{e}");
    }
}
