//! The robot's SRDF, as MoveIt users already have it: the allowed collision matrix
//! (`disable_collisions`, `disable_default_collisions`, `enable_collisions`) and the groups
//! (`joint`, `link`, `chain` and nested `group`). Everything else in the file (group states, end
//! effectors, virtual and passive joints, vendor extensions) is read past.
//!
//! Names are checked against the robot: an SRDF naming a link or joint the robot lacks is refused
//! whole, with the element, the name and the file in one line.

use super::robot::RobotModel;
use super::xml_guard::check_xml;
use std::collections::{BTreeSet, HashMap};

/// Groups one SRDF may define, and members one group may list: far past any real robot, and what
/// keeps resolution (nested groups, chains) bounded.
const MAX_GROUPS: usize = 4096;
const MAX_MEMBERS: usize = 65_536;

/// An SRDF that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SrdfError {
    /// The text is not well-formed XML, or too deep, or has a DTD.
    #[error("{origin}: {message}")]
    Xml {
        /// File or topic.
        origin: String,
        /// What the parser said.
        message: String,
    },
    /// The text is unexpanded xacro (read as SRDF it would give no pairs and no groups).
    #[error(
        "{origin}: unexpanded xacro ({evidence}); expand it first (`xacro {origin} > robot.srdf`) or publish the expanded SRDF on robot_description_semantic"
    )]
    Xacro {
        /// File or topic.
        origin: String,
        /// What marks it as xacro, with its line.
        evidence: String,
    },
    /// An element names something the robot lacks, or is missing an attribute.
    #[error("{origin}: <{element}> {message}")]
    Element {
        /// File or topic.
        origin: String,
        /// The element.
        element: String,
        /// What is wrong, with the value.
        message: String,
    },
}

/// One group's members as written (resolved against the robot by [`Srdf::group_joints`]).
#[derive(Clone, Debug, Default, PartialEq)]
struct GroupSpec {
    joints: Vec<usize>,
    links: Vec<usize>,
    /// (base link, tip link).
    chains: Vec<(usize, usize)>,
    subgroups: Vec<String>,
}

/// A parsed SRDF, its names resolved to the robot's link and joint indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Srdf {
    /// Where it came from (a file, or the topic), for messages.
    pub source: String,
    /// Link pairs (lower index first) whose collisions are never checked.
    disabled: BTreeSet<(usize, usize)>,
    /// Links whose collisions are off by default (`disable_default_collisions`).
    disabled_default: BTreeSet<usize>,
    /// Pairs turned back on (`enable_collisions`), over the defaults above.
    enabled: BTreeSet<(usize, usize)>,
    groups: HashMap<String, GroupSpec>,
}

fn ordered(a: usize, b: usize) -> (usize, usize) {
    if a <= b {
        (a, b)
    } else {
        (b, a)
    }
}

impl Srdf {
    /// Parses `text` (named `source` in errors) against `robot`.
    pub fn parse(text: &str, source: &str, robot: &RobotModel) -> Result<Srdf, SrdfError> {
        let xml = |message: String| SrdfError::Xml { origin: source.to_owned(), message };
        check_xml(text.as_bytes()).map_err(|e| xml(e.to_string()))?;
        if let Some(evidence) = super::xacro::xacro_evidence(text, source) {
            return Err(SrdfError::Xacro { origin: source.to_owned(), evidence });
        }
        let doc = roxmltree::Document::parse(text).map_err(|e| xml(e.to_string()))?;
        let root = doc.root_element();
        if root.tag_name().name() != "robot" {
            return Err(xml(format!("the root element is <{}>, not <robot>", root.tag_name().name())));
        }
        let bad = |element: &str, message: String| SrdfError::Element { origin: source.to_owned(), element: element.to_owned(), message };
        let attr = |n: roxmltree::Node, name: &str| -> Result<String, SrdfError> {
            n.attribute(name)
                .map(str::to_owned)
                .ok_or_else(|| bad(n.tag_name().name(), format!("has no '{name}' attribute (line {})", doc.text_pos_at(n.range().start).row)))
        };
        let link = |n: roxmltree::Node, name: &str| -> Result<usize, SrdfError> {
            let value = attr(n, name)?;
            robot.link(&value).ok_or_else(|| bad(n.tag_name().name(), format!("{name}=\"{value}\": the robot '{}' has no such link", robot.name)))
        };
        let mut srdf =
            Srdf { source: source.to_owned(), disabled: BTreeSet::new(), disabled_default: BTreeSet::new(), enabled: BTreeSet::new(), groups: HashMap::new() };
        for n in root.children().filter(roxmltree::Node::is_element) {
            match n.tag_name().name() {
                "disable_collisions" => {
                    let _ = srdf.disabled.insert(ordered(link(n, "link1")?, link(n, "link2")?));
                }
                "enable_collisions" => {
                    let _ = srdf.enabled.insert(ordered(link(n, "link1")?, link(n, "link2")?));
                }
                "disable_default_collisions" => {
                    let _ = srdf.disabled_default.insert(link(n, "link")?);
                }
                "group" => {
                    let name = attr(n, "name")?;
                    if srdf.groups.len() >= MAX_GROUPS {
                        return Err(bad("group", format!("name=\"{name}\": more than {MAX_GROUPS} groups")));
                    }
                    let mut spec = GroupSpec::default();
                    for m in n.children().filter(roxmltree::Node::is_element) {
                        if spec.joints.len() + spec.links.len() + spec.chains.len() + spec.subgroups.len() >= MAX_MEMBERS {
                            return Err(bad("group", format!("name=\"{name}\": more than {MAX_MEMBERS} members")));
                        }
                        match m.tag_name().name() {
                            "joint" => {
                                let j = attr(m, "name")?;
                                // A virtual joint (the floating base MoveIt adds) is not in the URDF.
                                match robot.joint(&j) {
                                    Some(ji) => spec.joints.push(ji),
                                    None if is_virtual_joint(root, &j) => {}
                                    None => return Err(bad("joint", format!("name=\"{j}\" in group '{name}': the robot '{}' has no such joint", robot.name))),
                                }
                            }
                            "link" => spec.links.push(link(m, "name")?),
                            "chain" => spec.chains.push((link(m, "base_link")?, link(m, "tip_link")?)),
                            "group" => spec.subgroups.push(attr(m, "name")?),
                            _ => {}
                        }
                    }
                    let _ = srdf.groups.insert(name, spec);
                }
                _ => {}
            }
        }
        // Every nested group must exist.
        for (name, spec) in &srdf.groups {
            if let Some(missing) = spec.subgroups.iter().find(|s| !srdf.groups.contains_key(*s)) {
                return Err(bad("group", format!("name=\"{missing}\" in group '{name}': no such group in the file")));
            }
        }
        Ok(srdf)
    }

    /// Whether collisions between links `a` and `b` are never checked.
    pub fn is_disabled(&self, a: usize, b: usize) -> bool {
        let pair = ordered(a, b);
        if self.enabled.contains(&pair) {
            return false;
        }
        self.disabled.contains(&pair) || self.disabled_default.contains(&a) || self.disabled_default.contains(&b)
    }

    /// Group names, sorted.
    pub fn group_names(&self) -> Vec<&str> {
        let mut names: Vec<&str> = self.groups.keys().map(String::as_str).collect();
        names.sort_unstable();
        names
    }

    /// The joints of group `name` (its own, its links' parent joints, its chains' joints and its
    /// subgroups'), sorted; `None` for an unknown group. Nested groups are resolved with a work
    /// list, each once, so a cycle in the file ends.
    pub fn group_joints(&self, name: &str, robot: &RobotModel) -> Option<Vec<usize>> {
        let _ = self.groups.get(name)?;
        let mut joints = BTreeSet::new();
        let mut seen = BTreeSet::new();
        let mut work = vec![name.to_owned()];
        while let Some(g) = work.pop() {
            if !seen.insert(g.clone()) {
                continue;
            }
            let Some(spec) = self.groups.get(&g) else { continue };
            joints.extend(spec.joints.iter().copied());
            joints.extend(spec.links.iter().filter_map(|&l| robot.parent_joint(l)));
            for &(base, tip) in &spec.chains {
                // Up from the tip to the base; a tip not below the base adds nothing.
                let mut chain = Vec::new();
                let mut link = tip;
                let mut found = false;
                for _ in 0..=robot.joints.len() {
                    if link == base {
                        found = true;
                        break;
                    }
                    let Some(j) = robot.parent_joint(link) else { break };
                    chain.push(j);
                    link = robot.joints[j].parent;
                }
                if found {
                    joints.extend(chain);
                }
            }
            work.extend(spec.subgroups.iter().cloned());
        }
        Some(joints.into_iter().collect())
    }

    /// The links group `name` moves: the child links of its joints and everything below them
    /// (the hand for an arm), plus its own links' subtrees; `None` for an unknown group.
    pub fn group_links(&self, name: &str, robot: &RobotModel) -> Option<Vec<usize>> {
        let joints = self.group_joints(name, robot)?;
        let mut roots: Vec<usize> = joints.iter().map(|&j| robot.joints[j].child).collect();
        let mut seen = BTreeSet::new();
        let mut work = Vec::new();
        work.append(&mut roots);
        while let Some(l) = work.pop() {
            if !seen.insert(l) {
                continue;
            }
            work.extend(robot.joints.iter().filter(|j| j.parent == l).map(|j| j.child));
        }
        Some(seen.into_iter().collect())
    }
}

/// Whether `name` is declared as a `<virtual_joint>` of the file.
fn is_virtual_joint(root: roxmltree::Node, name: &str) -> bool {
    root.children().any(|n| n.is_element() && n.tag_name().name() == "virtual_joint" && n.attribute("name") == Some(name))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::PackageResolver;
    use std::path::Path;

    const ARM: &str = r#"<robot name="two"><link name="base"/><link name="upper"><collision><geometry><box size="0.1 0.1 0.5"/></geometry></collision></link>
<link name="lower"/><link name="hand"/>
<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="wrist" type="fixed"><parent link="lower"/><child link="hand"/></joint></robot>"#;

    fn robot() -> RobotModel {
        RobotModel::from_str(ARM, "two.urdf", Path::new("."), &PackageResolver::default(), false).unwrap()
    }

    #[test]
    fn pairs_and_groups_resolve_and_unknown_names_are_refused() {
        let r = robot();
        let text = r#"<robot name="two"><virtual_joint name="world_joint" type="fixed" parent_frame="world" child_link="base"/>
<group name="arm"><chain base_link="base" tip_link="lower"/></group><group name="hand"><link name="hand"/></group>
<group name="all"><group name="arm"/><group name="hand"/><joint name="world_joint"/></group>
<disable_collisions link1="upper" link2="base" reason="Adjacent"/><disable_default_collisions link="hand"/><enable_collisions link1="hand" link2="base"/>
<group_state name="home" group="arm"><joint name="shoulder" value="0"/></group_state><vendor_extension x="1"/></robot>"#;
        let s = Srdf::parse(text, "two.srdf", &r).unwrap();
        let (base, upper, lower, hand) = (r.link("base").unwrap(), r.link("upper").unwrap(), r.link("lower").unwrap(), r.link("hand").unwrap());
        assert!(s.is_disabled(base, upper) && s.is_disabled(upper, base));
        assert!(!s.is_disabled(upper, lower));
        assert!(s.is_disabled(hand, lower), "disable_default_collisions");
        assert!(!s.is_disabled(hand, base), "enable_collisions re-enables a pair");
        assert_eq!(s.group_names(), vec!["all", "arm", "hand"]);
        let names = |v: Vec<usize>, f: &dyn Fn(usize) -> String| v.into_iter().map(f).collect::<Vec<_>>();
        let jn = |j: usize| r.joints[j].name.clone();
        let ln = |l: usize| r.links[l].name.clone();
        assert_eq!(names(s.group_joints("arm", &r).unwrap(), &jn), vec!["shoulder", "elbow"]);
        assert_eq!(names(s.group_links("arm", &r).unwrap(), &ln), vec!["upper", "lower", "hand"], "the hand moves with the arm");
        assert_eq!(names(s.group_joints("all", &r).unwrap(), &jn), vec!["shoulder", "elbow", "wrist"]);
        assert_eq!(s.group_joints("legs", &r), None);

        for (bad, want) in [
            (
                r#"<robot><disable_collisions link1="upper" link2="tail"/></robot>"#,
                "two.srdf: <disable_collisions> link2=\"tail\": the robot 'two' has no such link",
            ),
            (
                r#"<robot><group name="g"><joint name="knee"/></group></robot>"#,
                "two.srdf: <joint> name=\"knee\" in group 'g': the robot 'two' has no such joint",
            ),
            (r#"<robot><group name="g"><group name="h"/></group></robot>"#, "two.srdf: <group> name=\"h\" in group 'g': no such group in the file"),
            (r#"<robot><disable_collisions link1="upper"/></robot>"#, "two.srdf: <disable_collisions> has no 'link2' attribute (line 1)"),
            (r#"<srdf/>"#, "two.srdf: the root element is <srdf>, not <robot>"),
        ] {
            assert_eq!(Srdf::parse(bad, "two.srdf", &r).unwrap_err().to_string(), want);
        }
        let deep = "<robot>".to_owned() + &"<a>".repeat(20_000) + &"</a>".repeat(20_000) + "</robot>";
        assert!(Srdf::parse(&deep, "deep.srdf", &r).unwrap_err().to_string().starts_with("deep.srdf: "));
    }

    #[test]
    fn a_cycle_of_nested_groups_ends() {
        let r = robot();
        let text =
            r#"<robot><group name="a"><group name="b"/><joint name="shoulder"/></group><group name="b"><group name="a"/><joint name="elbow"/></group></robot>"#;
        let s = Srdf::parse(text, "cycle.srdf", &r).unwrap();
        assert_eq!(s.group_joints("a", &r).unwrap().len(), 2);
    }
}
