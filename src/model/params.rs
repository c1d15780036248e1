//! The parameters: one ROS 2 parameters YAML read by the CLI and the node alike.
//!
//! The file has the usual shape `<node>: ros__parameters: {...}`. Values are types ROS 2
//! parameters can hold: no maps, so per-item settings are parallel arrays
//! (`thin_surfaces.patterns` with `.thickness` and `.side`).
//!
//!
//! Reading the files (which sections apply to the node) is in `params_file`.

use super::bundled::{bundled_environment, bundled_robot};
use super::glob::glob_match;
use crate::thickness::Side;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The command line's file, else the parameter's, else the bundled one.
fn input_path(over: Option<&Path>, param: &str, bundled: fn() -> PathBuf) -> PathBuf {
    match over {
        Some(p) => p.to_owned(),
        None if param.is_empty() => bundled(),
        None => PathBuf::from(param),
    }
}

/// What to do when a robot state lacks a joint of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MissingJoint {
    /// Each message alone: a joint it does not name is at 0.
    Zero,
    /// Partial messages are merged, as robot_state_publisher merges several publishers: a joint a
    /// message does not name keeps its last received value (0 before any).
    #[default]
    Last,
    /// Merged as `last`, but a state is refused while some actuated joint has never been received
    /// (a service request's state must name every actuated joint).
    Reject,
}

/// Where the node and replay take robot states from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum PoseSource {
    /// `sensor_msgs/JointState` through forward kinematics.
    #[default]
    #[serde(rename = "joint_states")]
    JointStates,
    /// `tf2_msgs/TFMessage` on `/tf` and `/tf_static`: link poses composed up to `world_frame`.
    #[serde(rename = "tf")]
    Tf,
}

impl std::str::FromStr for PoseSource {
    type Err = String;

    fn from_str(s: &str) -> Result<PoseSource, String> {
        match s {
            "joint_states" => Ok(PoseSource::JointStates),
            "tf" => Ok(PoseSource::Tf),
            _ => Err(format!("'{s}' is not a pose source (joint_states or tf)")),
        }
    }
}

/// How requests and replies of the node's services are matched on DDS.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ServiceMapping {
    /// rmw_cyclonedds's mapping.
    #[default]
    Cyclone,
    /// rmw_fastrtps's and rmw_connextdds's mapping (sample identity beside each request).
    Enhanced,
    /// The DDS-RPC basic mapping.
    Basic,
}

/// Per-pattern thickness and side of thin surfaces (parallel arrays).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThinSurfaces {
    /// Glob patterns over environment link names (`*`, `?`).
    pub patterns: Vec<String>,
    /// Thickness for each pattern (metres).
    pub thickness: Vec<f64>,
    /// Side for each pattern; may be empty (then `default_side`).
    pub side: Vec<Side>,
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
    pub default_side: Side,
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
    /// What a state that lacks a joint means.
    pub missing_joint: MissingJoint,
    /// Robot links (globs) that are checked; default all.
    pub checked_links: Vec<String>,
    /// Use visual geometry for links that have no collision geometry.
    pub use_visual_when_no_collision: bool,
    /// Where the node and replay take robot states from.
    pub pose_source: PoseSource,
    /// Prefix of the robot's frames on `/tf` (e.g. `robot1/` when several robots share it).
    pub frame_prefix: String,
    /// At most this many cells are drawn on `collision_markers/cells`.
    pub marker_max_cells: i64,
    /// At most this many contact marker messages per second (Hz).
    pub marker_rate: f64,
    /// Stamp the node's own messages (markers, diagnostics) with `/clock` time.
    pub use_sim_time: bool,
    /// Request/reply mapping of the node's services.
    pub service_mapping: ServiceMapping,
    /// A motion is reported colliding when a pose along it comes within this distance of a cell
    /// or solid, and free only when no pose does (metres).
    pub motion_tolerance: f64,
    /// The node and replay check the motion between consecutive states (`replay --motion` /
    /// `--no-motion` override it).
    pub check_motion: bool,
    /// Stamps further apart than this (seconds) are checked as separate states, not as a motion.
    pub motion_max_gap: f64,
    /// Every report lists each checked link within this distance (metres) of the environment,
    /// with its distance and nearest points; 0 turns clearance off.
    pub clearance_threshold: f64,
    /// The robot's SRDF (its `disable_collisions` form the allowed collision matrix; its groups
    /// serve `check_state_validity`); empty: none, or what `robot_description_semantic` brings.
    pub robot_semantic_file: String,
    /// Check the robot's links against each other.
    pub self_collision: bool,
    /// The node serves MoveIt's planning-scene doors (`collision_object`, `planning_scene`, ...,
    /// `apply_planning_scene`, `get_planning_scene`); read at start.
    pub planning_scene: bool,
    /// The topic the robot's URDF comes on (`std_msgs/String`, latched), relative to the node;
    /// empty: not subscribed (a deployment that loads its robot from a file closes this door);
    /// read at start.
    pub robot_description_topic: String,
    /// The topic the robot's SRDF comes on; empty: not subscribed; read at start.
    pub robot_description_semantic_topic: String,
    /// Parameters (names or globs, `*` for all) a remote `set_parameters` may not change, on top
    /// of those that shape the node's topics; itself always read only; read at start.
    pub read_only_parameters: Vec<String>,
    /// Files named on the command line in place of the two above.
    #[serde(skip)]
    pub input_files: InputFiles,
}

/// Input files named on the command line (`--robot`, `--environment`). They override
/// `robot_description_file` and `environment_file` but are not parameters: a node neither
/// declares nor serves them, and a parameter change keeps them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputFiles {
    /// The robot's URDF (`--robot`).
    pub robot: Option<PathBuf>,
    /// The environment's URDF (`--environment`).
    pub environment: Option<PathBuf>,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            robot_description_file: String::new(),
            environment_file: String::new(),
            world_frame: "world".into(),
            robot_base_pose: vec![0.0; 6],
            default_thickness: 0.02,
            default_side: Side::Back,
            package_map: Vec::new(),
            thin_surfaces: ThinSurfaces::default(),
            solid_hull: Vec::new(),
            padding: Padding::default(),
            allowed_collisions: Vec::new(),
            missing_joint: MissingJoint::Last,
            checked_links: vec!["*".into()],
            use_visual_when_no_collision: false,
            pose_source: PoseSource::JointStates,
            frame_prefix: String::new(),
            marker_max_cells: 5_000,
            marker_rate: 10.0,
            use_sim_time: false,
            service_mapping: ServiceMapping::Cyclone,
            motion_tolerance: 0.001,
            check_motion: true,
            motion_max_gap: 0.5,
            clearance_threshold: 0.0,
            robot_semantic_file: String::new(),
            self_collision: true,
            planning_scene: true,
            robot_description_topic: "robot_description".into(),
            robot_description_semantic_topic: "robot_description_semantic".into(),
            read_only_parameters: Vec::new(),
            input_files: InputFiles::default(),
        }
    }
}

/// Longest `motion_max_gap` (s): an hour between two states is no motion anyone recorded.
const MAX_MOTION_GAP: f64 = 3600.0;

/// Largest `clearance_threshold` (m): clearance is a local question (a planner's margin), and a
/// threshold of metres would make every report measure most of the environment.
const MAX_CLEARANCE: f64 = 10.0;

/// Marker rates outside this range (Hz) are refused: below it a period overflows a `Duration`
/// long before anyone would wait for it, above it the markers would cost more than the checks.
const MARKER_RATE_RANGE: (f64, f64) = (1e-3, 1e4);

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
    /// No section of the file (or files) applies to the node.
    #[error(
        "parameters file {files} has no section for node {node} (sections: {}); a key applies when it is the node's full name, a key without a leading / is in the root namespace, /** stands for any namespaces and * for one name",
        show_keys(.keys)
    )]
    NoSection {
        /// The file or files, as given.
        files: String,
        /// The node's fully qualified name.
        node: String,
        /// The section keys the files have.
        keys: Vec<String>,
    },
    /// A value is out of its domain.
    #[error("parameter {name}: {message}")]
    Invalid {
        /// The parameter.
        name: String,
        /// What is wrong.
        message: String,
    },
}

impl Params {
    /// The robot URDF to load: `--robot`, else `robot_description_file`, else the bundled arm.
    pub fn robot_path(&self) -> PathBuf {
        input_path(self.input_files.robot.as_deref(), &self.robot_description_file, bundled_robot)
    }

    /// The environment URDF to load: `--environment`, else `environment_file`, else the bundled
    /// workcell.
    pub fn environment_path(&self) -> PathBuf {
        input_path(self.input_files.environment.as_deref(), &self.environment_file, bundled_environment)
    }

    /// Whether no robot file is named, so that the bundled arm stands in.
    pub(crate) fn robot_is_bundled(&self) -> bool {
        self.input_files.robot.is_none() && self.robot_description_file.is_empty()
    }

    /// Checks every value's domain and the lengths of parallel arrays.
    pub fn validate(&self) -> Result<(), ParamsError> {
        let bad = |name: &str, message: String| Err(ParamsError::Invalid { name: name.into(), message });
        if self.robot_base_pose.len() != 6 || self.robot_base_pose.iter().any(|v| !v.is_finite()) {
            return bad("robot_base_pose", format!("needs 6 finite numbers (x y z roll pitch yaw), got {:?}", self.robot_base_pose));
        }
        let [lo, hi] = crate::limits::LENGTH_RANGE;
        if !crate::limits::is_length(self.default_thickness) {
            return bad("default_thickness", format!("must be from {lo:e} to {hi:e} m, got {}", crate::limits::show_number(self.default_thickness)));
        }
        if let Some(v) = self.robot_base_pose.iter().take(3).find(|v| !crate::limits::is_coordinate(**v)) {
            return bad("robot_base_pose", format!("x, y and z must be within {:e} m, got {v:?}", crate::limits::MAX_COORDINATE));
        }
        let ts = &self.thin_surfaces;
        if ts.thickness.len() != ts.patterns.len() {
            return bad("thin_surfaces.thickness", format!("has {} values for {} patterns", ts.thickness.len(), ts.patterns.len()));
        }
        if !ts.side.is_empty() && ts.side.len() != ts.patterns.len() {
            return bad("thin_surfaces.side", format!("has {} values for {} patterns", ts.side.len(), ts.patterns.len()));
        }
        if let Some(t) = ts.thickness.iter().find(|t| !crate::limits::is_length(**t)) {
            return bad("thin_surfaces.thickness", format!("must be from {lo:e} to {hi:e} m, got {}", crate::limits::show_number(*t)));
        }
        if self.padding.values.len() != self.padding.links.len() {
            return bad("padding.values", format!("has {} values for {} link patterns", self.padding.values.len(), self.padding.links.len()));
        }
        if !(1e-6..=0.1).contains(&self.motion_tolerance) {
            return bad("motion_tolerance", format!("must be from 1e-6 to 0.1 m, got {}", crate::limits::show_number(self.motion_tolerance)));
        }
        if !(0.0..=MAX_MOTION_GAP).contains(&self.motion_max_gap) {
            return bad("motion_max_gap", format!("must be from 0 to {MAX_MOTION_GAP} s, got {}", crate::limits::show_number(self.motion_max_gap)));
        }
        if !(0.0..=MAX_CLEARANCE).contains(&self.clearance_threshold) {
            return bad(
                "clearance_threshold",
                format!("must be from 0 (off) to {MAX_CLEARANCE} m, got {}", crate::limits::show_number(self.clearance_threshold)),
            );
        }
        if let Some(p) = self.padding.values.iter().find(|p| !(**p >= 0.0 && **p <= hi)) {
            return bad("padding.values", format!("must be from 0 to {hi:e} m, got {p:?}"));
        }
        if let Some(p) = self.allowed_collisions.iter().find(|p| p.split(':').count() != 2 || p.split(':').any(str::is_empty)) {
            return bad("allowed_collisions", format!("'{p}' is not of the form robot_link:environment_link"));
        }
        if self.marker_max_cells < 0 {
            return bad("marker_max_cells", format!("must be >= 0, got {}", self.marker_max_cells));
        }
        let (lo, hi) = MARKER_RATE_RANGE;
        if !(self.marker_rate >= lo && self.marker_rate <= hi) {
            return bad("marker_rate", format!("must be a rate from {lo} to {hi} Hz, got {:?}", self.marker_rate));
        }
        for (name, topic) in
            [("robot_description_topic", &self.robot_description_topic), ("robot_description_semantic_topic", &self.robot_description_semantic_topic)]
        {
            if topic.chars().any(|c| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '/' | '~'))) {
                return bad(name, format!("must be a ROS topic name (letters, digits, '_', '/', '~') or empty (not subscribed), got '{topic}'"));
            }
        }
        if self.world_frame.trim_start_matches('/').is_empty() {
            return bad("world_frame", format!("must name a frame, got '{}'", self.world_frame));
        }
        if let Some(p) = self.package_map.iter().find(|p| !p.contains('=')) {
            return bad("package_map", format!("'{p}' is not of the form package=/path"));
        }
        Ok(())
    }

    /// Thickness and side of the thin surface on environment link `link`.
    pub(crate) fn surface_settings(&self, link: &str) -> (f64, Side) {
        let ts = &self.thin_surfaces;
        // validate() keeps the arrays parallel; a pattern without its thickness falls back.
        match ts.patterns.iter().position(|p| glob_match(p, link)) {
            Some(i) => (ts.thickness.get(i).copied().unwrap_or(self.default_thickness), ts.side.get(i).copied().unwrap_or(self.default_side)),
            None => (self.default_thickness, self.default_side),
        }
    }

    /// Padding of robot link `link` (metres).
    pub(crate) fn padding_of(&self, link: &str) -> f64 {
        self.padding.links.iter().position(|p| glob_match(p, link)).and_then(|i| self.padding.values.get(i).copied()).unwrap_or(0.0)
    }

    /// Whether a collision between robot link `link` and environment link `object` is allowed.
    pub(crate) fn is_allowed(&self, link: &str, object: &str) -> bool {
        self.allowed_collisions.iter().any(|pair| match pair.split_once(':') {
            Some((l, o)) => glob_match(l, link) && glob_match(o, object),
            None => false,
        })
    }

    /// Whether robot link `link` is checked.
    pub(crate) fn is_checked(&self, link: &str) -> bool {
        self.checked_links.iter().any(|p| glob_match(p, link))
    }

    /// Whether the closed meshes of environment link `link` are checked as convex hulls.
    pub(crate) fn is_solid_hull(&self, link: &str) -> bool {
        self.solid_hull.iter().any(|p| glob_match(p, link))
    }

    /// Every parameter as a dotted name and its value (`thin_surfaces.patterns`, ...): what a ROS 2
    /// node declares. Enumerations are strings, as in the parameters file.
    pub fn flat(&self) -> Vec<(String, serde_json::Value)> {
        fn walk(prefix: &str, v: serde_json::Value, out: &mut Vec<(String, serde_json::Value)>) {
            match v {
                serde_json::Value::Object(map) => {
                    for (k, v) in map {
                        let name = if prefix.is_empty() { k } else { format!("{prefix}.{k}") };
                        walk(&name, v, out);
                    }
                }
                v => out.push((prefix.to_owned(), v)),
            }
        }
        let mut out = Vec::new();
        // Params holds only strings, numbers, booleans, arrays and nested structs: it always
        // serialises; an empty list is what a failure could give, never a panic.
        if let Ok(v) = serde_json::to_value(self) {
            walk("", v, &mut out);
        }
        out
    }

    /// The element of every list parameter, by dotted name: what an empty list would hold (the
    /// node declares its parameters with them).
    #[cfg(feature = "ros")]
    pub(crate) fn array_kinds() -> Vec<(String, serde_json::Value)> {
        let sample = Params {
            robot_base_pose: vec![0.0],
            package_map: vec![String::new()],
            thin_surfaces: ThinSurfaces { patterns: vec![String::new()], thickness: vec![0.0], side: vec![Side::Back] },
            solid_hull: vec![String::new()],
            padding: Padding { links: vec![String::new()], values: vec![0.0] },
            allowed_collisions: vec![String::new()],
            checked_links: vec![String::new()],
            read_only_parameters: vec![String::new()],
            ..Params::default()
        };
        sample
            .flat()
            .into_iter()
            .filter_map(|(n, v)| match v {
                serde_json::Value::Array(mut a) => a.pop().map(|e| (n, e)),
                _ => None,
            })
            .collect()
    }

    /// These parameters with `name` (dotted, as in [`Params::flat`]) set to `value`, validated.
    pub fn with_value(&self, name: &str, value: serde_json::Value) -> Result<Params, ParamsError> {
        let params = self.with_unchecked(name, value)?;
        params.validate()?;
        Ok(params)
    }

    fn with_unchecked(&self, name: &str, value: serde_json::Value) -> Result<Params, ParamsError> {
        let invalid = |message: String| ParamsError::Invalid { name: name.to_owned(), message };
        let mut doc = serde_json::to_value(self).map_err(|e| invalid(e.to_string()))?;
        let mut at = &mut doc;
        for part in name.split('.') {
            at = at.as_object_mut().and_then(|m| m.get_mut(part)).ok_or_else(|| invalid("no such parameter".into()))?;
        }
        if at.is_object() {
            return Err(invalid("is a group; set its members".into()));
        }
        *at = value;
        let params: Params = serde_json::from_value(doc).map_err(|e| invalid(e.to_string()))?;
        // Not parameters, so not in `doc`: setting a parameter keeps them.
        Ok(Params { input_files: self.input_files.clone(), ..params })
    }

    /// These parameters with `-p name:=value` overrides applied (values are YAML, as `ros2 run`
    /// reads them), then validated together: parallel arrays may change one by one.
    pub fn with_overrides(&self, overrides: &[(String, String)]) -> Result<Params, ParamsError> {
        let mut params = self.clone();
        for (name, text) in overrides {
            let value: serde_json::Value = serde_yaml_ng::from_str(text)
                .map_err(|e| ParamsError::Invalid { name: name.clone(), message: format!("'{text}' is not a YAML value: {e}") })?;
            params = params.with_unchecked(name, value)?;
        }
        params.validate()?;
        Ok(params)
    }

    /// The parameters as a ROS 2 parameters YAML (for `check --show-params`).
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
        serde_yaml_ng::to_string(&File { thickness_collision: Section { params: self } }).unwrap_or_default()
    }
}

/// Keys quoted for an error (`none` when there are none).
pub(super) fn show_keys(keys: &[String]) -> String {
    if keys.is_empty() {
        return "none".into();
    }
    keys.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::super::params_file::*;
    use super::*;
    use std::path::Path;

    #[test]
    fn unknown_key_is_named() {
        let e = Params::from_yaml("thickness_collision:\n  ros__parameters:\n    default_thicknes: 0.1\n", Path::new("p.yaml")).unwrap_err();
        assert!(e.to_string().contains("default_thicknes"), "{e}");
    }

    #[test]
    fn overrides_are_typed_and_validated() {
        let p = Params::default();
        let q = p
            .with_overrides(&[
                ("default_thickness".into(), "0.05".into()),
                ("thin_surfaces.patterns".into(), "[a]".into()),
                ("thin_surfaces.thickness".into(), "[1]".into()),
            ])
            .unwrap();
        assert_eq!(q.default_thickness, 0.05);
        assert_eq!(q.thin_surfaces.thickness, vec![1.0]);
        assert_eq!(q.surface_settings("a"), (1.0, Side::Back));
        let q = p.with_overrides(&[("robot_description_topic".into(), "''".into()), ("read_only_parameters".into(), "['*']".into())]).unwrap();
        assert_eq!((q.robot_description_topic.as_str(), q.read_only_parameters.as_slice()), ("", &["*".to_string()][..]), "an empty topic closes the door");
        let q = p.with_overrides(&[("pose_source".into(), "tf".into()), ("missing_joint".into(), "reject".into())]).unwrap();
        assert_eq!((q.pose_source, q.missing_joint), (PoseSource::Tf, MissingJoint::Reject));
        for (k, v, says) in [
            ("pose_source", "tcp", "pose_source"),
            ("default_side", "left", "default_side"),
            ("marker_rate", "1e-300", "marker_rate"),
            ("nonexistent", "1", "nonexistent"),
            ("thin_surfaces", "1", "group"),
            ("default_thickness", "-1", "default_thickness"),
            ("robot_description_topic", "'a b'", "robot_description_topic"),
            ("robot_description_semantic_topic", "'srdf!'", "robot_description_semantic_topic"),
        ] {
            let e = p.with_overrides(&[(k.into(), v.into())]).unwrap_err().to_string();
            assert!(e.contains(says), "{k}:={v}: {e}");
        }
    }

    #[test]
    fn flat_names_every_parameter_once() {
        let flat = Params::default().flat();
        let names: Vec<&str> = flat.iter().map(|(n, _)| n.as_str()).collect();
        for n in ["default_thickness", "thin_surfaces.patterns", "padding.values", "pose_source", "service_mapping"] {
            assert_eq!(names.iter().filter(|x| **x == n).count(), 1, "{n} in {names:?}");
        }
        for (n, v) in &flat {
            assert_eq!(Params::default().with_value(n, v.clone()).unwrap(), Params::default(), "{n}");
        }
    }

    #[test]
    fn clearance_threshold_is_off_by_default_and_validated() {
        let p = Params::default();
        assert_eq!(p.clearance_threshold, 0.0, "off unless asked for");
        let q = p.with_overrides(&[("clearance_threshold".into(), "0.05".into())]).unwrap();
        assert_eq!(q.clearance_threshold, 0.05);
        let says = |e: String, what: &str| {
            assert!(e.contains("clearance_threshold") && e.contains("must be from 0 (off) to 10 m") && !e.contains('\n'), "{what}: {e}")
        };
        for v in ["-0.01", "11", "-1e-9"] {
            says(p.with_overrides(&[("clearance_threshold".into(), v.into())]).unwrap_err().to_string(), v);
        }
        for v in [f64::NAN, f64::INFINITY] {
            says(Params { clearance_threshold: v, ..Params::default() }.validate().unwrap_err().to_string(), &format!("{v}"));
        }
    }

    fn for_node(text: &str, node: &str) -> Result<LoadedParams, ParamsError> {
        Params::from_yaml_for_node(text, Path::new("p.yaml"), node)
    }

    fn thickness_for(text: &str, node: &str) -> Option<f64> {
        for_node(text, node).ok().map(|l| l.params.default_thickness)
    }

    #[test]
    fn node_names_from_ros_args() {
        assert_eq!(node_fqn(None, None), DEFAULT_NODE_FQN);
        assert_eq!(node_fqn(Some("/robot1"), None), "/robot1/thickness_collision");
        assert_eq!(node_fqn(Some("/robot1/"), Some("arm_checker")), "/robot1/arm_checker");
        assert_eq!(node_fqn(Some("robot1"), Some("tc")), "/robot1/tc");
        assert_eq!(node_fqn(Some("/"), Some("tc")), "/tc");
    }

    #[test]
    fn each_key_form_matches_as_rclcpp_does() {
        let file = |key: &str| format!("{key}:\n  ros__parameters:\n    default_thickness: 0.05\n");
        let root = "/thickness_collision";
        let ns = "/robot1/thickness_collision";
        let deep = "/a/b/thickness_collision";
        let renamed = "/robot1/arm_checker";
        // (key, nodes it applies to, nodes it does not)
        let cases: &[(&str, &[&str], &[&str])] = &[
            ("/**", &[root, ns, deep, renamed], &[]),
            ("/**/thickness_collision", &[root, ns, deep], &[renamed]),
            ("/robot1/thickness_collision", &[ns], &[root, deep, renamed]),
            // A relative key gets a leading slash: the root namespace only.
            ("thickness_collision", &[root], &[ns, deep, renamed]),
            ("/thickness_collision", &[root], &[ns, deep, renamed]),
            ("/robot1/*", &[ns, renamed], &[root, deep]),
            ("/*", &[root], &[ns, deep, renamed]),
            ("/**/*", &[root, ns, deep, renamed], &[]),
            ("arm_checker", &[], &[root, ns, deep, renamed]),
            ("robot1/arm_checker", &[renamed], &[root, ns, deep]),
        ];
        for (key, yes, no) in cases {
            for node in *yes {
                assert_eq!(thickness_for(&file(key), node), Some(0.05), "{key} should apply to {node}");
            }
            for node in *no {
                let e = for_node(&file(key), node).unwrap_err().to_string();
                assert!(e.contains("no section for node") && e.contains(node) && e.contains(&format!("`{key}`")) && !e.contains('\n'), "{key} for {node}: {e}");
            }
        }
        // Nested keys are a namespace: robot1: {thickness_collision: ...}.
        let nested = "robot1:\n  thickness_collision:\n    ros__parameters:\n      default_thickness: 0.07\n";
        assert_eq!(thickness_for(nested, ns), Some(0.07));
        assert!(for_node(nested, root).is_err());
        // Keys rcl refuses are refused, naming the section.
        for key in ["/*/thickness_collision", "/robot-1/thickness_collision", "/ro bot/x", "1node"] {
            let e = for_node(&file(key), root).unwrap_err().to_string();
            assert!(e.contains(&format!("section `{key}`")) && e.contains("p.yaml"), "{key}: {e}");
        }
    }

    #[test]
    fn sections_apply_in_order_of_first_appearance_later_wins() {
        let two = |a: &str, b: &str| {
            format!("{a}:\n  ros__parameters:\n    default_thickness: 0.01\n    marker_rate: 5.0\n{b}:\n  ros__parameters:\n    default_thickness: 0.03\n")
        };
        let p = for_node(&two("/**", "thickness_collision"), DEFAULT_NODE_FQN).unwrap().params;
        assert_eq!((p.default_thickness, p.marker_rate), (0.03, 5.0), "the named section after /** wins; /** keeps what it alone sets");
        // The other order: rclcpp has no preference for the exact name, the later section wins.
        let p = for_node(&two("thickness_collision", "/**"), DEFAULT_NODE_FQN).unwrap().params;
        assert_eq!((p.default_thickness, p.marker_rate), (0.03, 5.0));
        let p = for_node(&two("/robot1/thickness_collision", "/**/thickness_collision"), "/robot1/thickness_collision").unwrap().params;
        assert_eq!(p.default_thickness, 0.03);
        // A section that does not match takes no part.
        let p = for_node(&two("/**", "/robot2/thickness_collision"), "/robot1/thickness_collision").unwrap().params;
        assert_eq!((p.default_thickness, p.marker_rate), (0.01, 5.0));
        // Nested groups merge member by member.
        let groups = "/**:\n  ros__parameters:\n    thin_surfaces:\n      patterns: [a]\n      thickness: [0.1]\nthickness_collision:\n  ros__parameters:\n    thin_surfaces.thickness: [0.2]\n";
        let p = for_node(groups, DEFAULT_NODE_FQN).unwrap().params;
        assert_eq!((p.thin_surfaces.patterns, p.thin_surfaces.thickness), (vec!["a".to_owned()], vec![0.2]));
    }

    #[test]
    fn files_merge_with_keys_in_first_seen_order() {
        let dir = std::env::temp_dir().join(format!("tc_params_files_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = dir.join("a.yaml");
        let b = dir.join("b.yaml");
        std::fs::write(&a, "/**:\n  ros__parameters:\n    default_thickness: 0.01\nthickness_collision:\n  ros__parameters:\n    marker_rate: 2.0\n").unwrap();
        std::fs::write(&b, "/**:\n  ros__parameters:\n    default_thickness: 0.04\n    marker_rate: 3.0\n").unwrap();
        let p = Params::from_files_for_node(&[a.clone(), b.clone()], DEFAULT_NODE_FQN).unwrap().params;
        // b's /** joins a's /** entry, which comes before thickness_collision: marker_rate stays 2.
        assert_eq!((p.default_thickness, p.marker_rate), (0.04, 2.0));
        let p = Params::from_files_for_node(&[b, a], DEFAULT_NODE_FQN).unwrap().params;
        assert_eq!((p.default_thickness, p.marker_rate), (0.01, 2.0));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unknown_keys_are_refused_by_name_and_ignored_from_wildcards() {
        let e = for_node("thickness_collision:\n  ros__parameters:\n    thin_surfaces:\n      patern: [a]\n", DEFAULT_NODE_FQN).unwrap_err().to_string();
        assert!(e.contains("p.yaml") && e.contains("`thin_surfaces.patern`") && e.contains("section `thickness_collision`"), "{e}");
        let e = for_node("/**/thickness_collision:\n  ros__parameters:\n    foo: 1\n", "/r/thickness_collision").unwrap_err().to_string();
        assert!(e.contains("`foo`"), "{e}");
        let shared =
            "/**:\n  ros__parameters:\n    foo: 1\n    bar.baz: x\n    default_thickness: 0.05\n/robot1/*:\n  ros__parameters:\n    qos_overrides: 1\n";
        let l = for_node(shared, "/robot1/thickness_collision").unwrap();
        assert_eq!(l.params.default_thickness, 0.05);
        assert_eq!(l.warnings.len(), 1, "{:?}", l.warnings);
        assert!(l.warnings[0].contains("`foo`") && l.warnings[0].contains("`bar.baz`") && l.warnings[0].contains("`qos_overrides`"), "{:?}", l.warnings);
        // A known key of ours with a wrong type in a wildcard section is still an error.
        assert!(for_node("/**:\n  ros__parameters:\n    default_thickness: thick\n", DEFAULT_NODE_FQN).is_err());
        // A file with sections for other nodes only keeps its clear error.
        let e = for_node("other_node:\n  ros__parameters:\n    x: 1\n", DEFAULT_NODE_FQN).unwrap_err().to_string();
        assert!(e.contains("no section for node /thickness_collision") && e.contains("`other_node`"), "{e}");
        let e = for_node("", DEFAULT_NODE_FQN).unwrap_err().to_string();
        assert!(e.contains("(sections: none)"), "{e}");
        let e = for_node("thickness_collision: 3\n", DEFAULT_NODE_FQN).unwrap_err().to_string();
        assert!(e.contains("`thickness_collision` has a value"), "{e}");
    }

    #[test]
    fn launch_generated_file_honours_use_sim_time() {
        // What `ros2 launch` writes for SetParameter(use_sim_time) beside a node's own section.
        let text = "/**:\n  ros__parameters:\n    use_sim_time: true\nthickness_collision:\n  ros__parameters:\n    default_thickness: 0.03\n    thin_surfaces:\n      patterns: [\"guard_*\"]\n      thickness: [0.005]\n";
        let l = for_node(text, DEFAULT_NODE_FQN).unwrap();
        assert!(l.params.use_sim_time, "the /** value must not be dropped");
        assert_eq!(l.params.default_thickness, 0.03);
        assert_eq!(l.params.surface_settings("guard_sheet"), (0.005, Side::Back));
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        // The same file for a node in a namespace: the relative key is the root node's only.
        let l = for_node(text, "/robot1/thickness_collision").unwrap();
        assert!(l.params.use_sim_time);
        assert_eq!(l.params.default_thickness, Params::default().default_thickness);
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
