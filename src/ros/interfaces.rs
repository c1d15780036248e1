//! The node's DDS wiring: the names of its topics and services (remapped, resolved against its
//! namespace), their QoS, their creation at start, and every input as a stream of [`Event`]s for
//! the loop. A new topic or service is a name in [`Names`], a field in [`Interfaces`], one line
//! in [`Interfaces::build`] and, for an input, one in [`Interfaces::events`].

use super::description_msg::DescriptionMsg;
use super::param_services::{ros_mapping, ParamRequest};
use super::ros_args::RosArgs;
use crate::model::{Params, PoseSource};
use crate::msgs::moveit::{GetStateValidityRequest, GetStateValidityResponse};
use crate::msgs::planning_scene::{
    ApplyPlanningSceneRequest, ApplyPlanningSceneResponse, AttachedCollisionObject, CollisionObject, GetPlanningSceneRequest, GetPlanningSceneResponse,
    PlanningScene, PlanningSceneWorld,
};
use crate::msgs::{CheckStatesRequest, CheckStatesResponse, ClockMsg};
use crate::msgs::{CheckTrajectoryRequest, CheckTrajectoryResponse, CollisionReport, DiagnosticArray, JointState, MarkerArray, TfMessage, Time};
use anyhow::{anyhow, Result};
use futures::stream::Stream;
use futures::StreamExt;
use ros2_client::dds::rustdds::Topic;
use ros2_client::qos::{History, WhenFull};
use ros2_client::service::RmwRequestId;
use ros2_client::{MessageTypeName, Name, Node, Publisher, QosProfile, ReadError, Server, ServiceMapping, ServiceTypeName, Subscription};
use std::pin::Pin;

/// Joint states the reader keeps while the node is busy: states that arrive while one is checked
/// are covered by the next report's motion (`check_motion`), not lost.
const STATES_KEPT: usize = 100;

/// A message or service type: (package, name).
type TypeName = (&'static str, &'static str);

/// What one turn of the loop got.
pub(super) enum Event {
    /// Joint states are waiting that the receiving thread left to the loop.
    States,
    Tf(TfMessage),
    TfStatic(TfMessage),
    Description(DescriptionMsg),
    Semantic(DescriptionMsg),
    Clock(Time),
    Request(RmwRequestId, CheckStatesRequest),
    TrajectoryRequest(RmwRequestId, CheckTrajectoryRequest),
    /// The worker checked a trajectory: the answer to send.
    TrajectoryDone(RmwRequestId, CheckTrajectoryResponse),
    /// Boxed: a request holds some 450 bytes inline, the other events a fraction of that.
    ValidityRequest(RmwRequestId, Box<GetStateValidityRequest>),
    /// The worker checked a state: the answer to send, and why the request was not honoured.
    ValidityDone(RmwRequestId, GetStateValidityResponse, Option<String>),
    /// Planning-scene inputs (boxed: a scene message is large, and rare).
    CollisionObject(Box<CollisionObject>),
    AttachedObject(Box<AttachedCollisionObject>),
    Scene(Box<PlanningScene>),
    SceneWorld(Box<PlanningSceneWorld>),
    ApplyScene(RmwRequestId, Box<ApplyPlanningSceneRequest>),
    GetScene(RmwRequestId, GetPlanningSceneRequest),
    /// A parameter service request (served here with the basic and cyclone mappings).
    Parameter(ParamRequest),
    /// A sample that could not be read (on the topic or service named).
    ReadFailed(&'static str, ReadError),
    Tick,
}

impl Event {
    /// A planning-scene input (topic message or `apply_planning_scene` request): the loop builds
    /// its cells without holding the node's state (`node_run.rs`).
    pub(super) fn is_scene(&self) -> bool {
        matches!(self, Event::CollisionObject(_) | Event::AttachedObject(_) | Event::Scene(_) | Event::SceneWorld(_) | Event::ApplyScene(..))
    }
}

/// One source of events for the loop's `select_all`.
pub(super) type Events<'a> = Pin<Box<dyn Stream<Item = Event> + 'a>>;

/// The node's topics, publishers, subscriptions and services, made once at start.
pub(super) struct Interfaces {
    pub(super) states: Subscription<JointState>,
    pub(super) tf: Option<(Subscription<TfMessage>, Subscription<TfMessage>)>,
    /// With `robot_description_topic` (and `robot_description_semantic_topic`) not empty.
    descriptions: Option<Subscription<DescriptionMsg>>,
    semantics: Option<Subscription<DescriptionMsg>>,
    clock: Option<Subscription<ClockMsg>>,
    pub(super) collisions: Publisher<CollisionReport>,
    pub(super) cells: Publisher<MarkerArray>,
    pub(super) contacts: Publisher<MarkerArray>,
    pub(super) diagnostics: Publisher<DiagnosticArray>,
    pub(super) check_states: Server<CheckStatesRequest, CheckStatesResponse>,
    pub(super) check_trajectory: Server<CheckTrajectoryRequest, CheckTrajectoryResponse>,
    pub(super) check_state_validity: Server<GetStateValidityRequest, GetStateValidityResponse>,
    /// MoveIt's planning-scene doors, with the parameter `planning_scene`.
    pub(super) scene: Option<SceneDoors>,
    pub(super) names: Names,
}

/// The subscriptions and services of MoveIt's planning scene (`planning_scene_monitor`'s and
/// `move_group`'s names, relative to the node).
pub(super) struct SceneDoors {
    objects: Subscription<CollisionObject>,
    attached: Subscription<AttachedCollisionObject>,
    scenes: Subscription<PlanningScene>,
    worlds: Subscription<PlanningSceneWorld>,
    pub(super) apply: Server<ApplyPlanningSceneRequest, ApplyPlanningSceneResponse>,
    pub(super) get: Server<GetPlanningSceneRequest, GetPlanningSceneResponse>,
}

impl SceneDoors {
    /// Reliable, volatile, keep last 10 (MoveIt's `ServicesQoS`, which its scene topics use).
    fn build(node: &mut Node, names: &Names, ns: &str, mapping: ServiceMapping) -> Result<SceneDoors> {
        let qos = reliable(10);
        let mut sub = |name: &str, ty: &'static str| topic(node, name, ns, ("moveit_msgs", ty), &qos);
        let (o, a, s, w) = (
            sub(&names.collision_object, "CollisionObject")?,
            sub(&names.attached_collision_object, "AttachedCollisionObject")?,
            sub(&names.planning_scene, "PlanningScene")?,
            sub(&names.planning_scene_world, "PlanningSceneWorld")?,
        );
        Ok(SceneDoors {
            objects: subscription(node, &o, Some(qos.clone()), &names.collision_object)?,
            attached: subscription(node, &a, Some(qos.clone()), &names.attached_collision_object)?,
            scenes: subscription(node, &s, Some(qos.clone()), &names.planning_scene)?,
            worlds: subscription(node, &w, Some(qos.clone()), &names.planning_scene_world)?,
            apply: server(node, mapping, &names.apply_planning_scene, ns, ("moveit_msgs", "ApplyPlanningScene"))?,
            get: server(node, mapping, &names.get_planning_scene, ns, ("moveit_msgs", "GetPlanningScene"))?,
        })
    }

    fn events(&self) -> Vec<Events<'_>> {
        vec![
            read(&self.objects, "collision_object", |m| Event::CollisionObject(Box::new(m))),
            read(&self.attached, "attached_collision_object", |m| Event::AttachedObject(Box::new(m))),
            read(&self.scenes, "planning_scene", |m| Event::Scene(Box::new(m))),
            read(&self.worlds, "planning_scene_world", |m| Event::SceneWorld(Box::new(m))),
            requests(&self.apply, "apply_planning_scene", |id, q| Event::ApplyScene(id, Box::new(q))),
            requests(&self.get, "get_planning_scene", Event::GetScene),
        ]
    }
}

/// Resolved names, for the banner and the warnings.
pub(super) struct Names {
    pub(super) joint_states: String,
    pub(super) collisions: String,
    pub(super) check_states: String,
    pub(super) check_trajectory: String,
    pub(super) check_state_validity: String,
    pub(super) description: String,
    pub(super) semantic: String,
    pub(super) cells: String,
    pub(super) contacts: String,
    pub(super) collision_object: String,
    pub(super) attached_collision_object: String,
    pub(super) planning_scene: String,
    pub(super) planning_scene_world: String,
    pub(super) apply_planning_scene: String,
    pub(super) get_planning_scene: String,
}

impl Names {
    /// The names, remapped; an empty topic parameter gives an empty name (not subscribed).
    fn new(remaps: &[(String, String)], params: &Params) -> Names {
        let optional = |topic: &str| if topic.is_empty() { String::new() } else { resolve(remaps, topic) };
        Names {
            joint_states: resolve(remaps, "joint_states"),
            collisions: resolve(remaps, "collisions"),
            check_states: resolve(remaps, "check_states"),
            check_trajectory: resolve(remaps, "check_trajectory"),
            check_state_validity: resolve(remaps, "check_state_validity"),
            description: optional(&params.robot_description_topic),
            semantic: optional(&params.robot_description_semantic_topic),
            cells: resolve(remaps, "collision_markers/cells"),
            contacts: resolve(remaps, "collision_markers/contacts"),
            collision_object: resolve(remaps, "collision_object"),
            attached_collision_object: resolve(remaps, "attached_collision_object"),
            planning_scene: resolve(remaps, "planning_scene"),
            planning_scene_world: resolve(remaps, "planning_scene_world"),
            apply_planning_scene: resolve(remaps, "apply_planning_scene"),
            get_planning_scene: resolve(remaps, "get_planning_scene"),
        }
    }
}

fn resolve(remaps: &[(String, String)], name: &str) -> String {
    remaps.iter().find(|(from, _)| from == name || from.trim_start_matches('/') == name).map_or(name.to_owned(), |(_, to)| to.clone())
}

/// A topic or service name resolved against the node's namespace, as an absolute name
/// (`joint_states` under `/robot1` is `/robot1/joint_states`; `/tf` stays `/tf`).
fn ros_name(name: &str, namespace: &str) -> Result<Name> {
    let full = if name.starts_with('/') { name.to_owned() } else { format!("{}/{}", namespace.trim_end_matches('/'), name) };
    let full = full.trim_end_matches('/');
    let (ns, base) = full.rsplit_once('/').ok_or_else(|| anyhow!("invalid ROS name '{full}'"))?;
    Name::new(if ns.is_empty() { "/" } else { ns }, base).map_err(|e| anyhow!("invalid ROS name '{full}': {e:?}"))
}

/// Reliable, transient local ("latched"), keep last `depth`: how `robot_description`,
/// `/tf_static` and the cell markers are offered.
fn latched(base: QosProfile, depth: usize) -> QosProfile {
    base.reliability_reliable(WhenFull::DEFAULT).durability(ros2_client::qos::Durability::TransientLocal).history(History::KeepLast { depth })
}

/// Reliable, keep last `depth`.
fn reliable(depth: usize) -> QosProfile {
    QosProfile::publisher_default().reliability_reliable(WhenFull::DEFAULT).history(History::KeepLast { depth })
}

/// Best effort, keep last `depth`: sensor streams.
fn best_effort(depth: usize) -> QosProfile {
    QosProfile::subscription_default().reliability_best_effort().history(History::KeepLast { depth })
}

fn topic(node: &mut Node, name: &str, ns: &str, (pkg, ty): TypeName, qos: &QosProfile) -> Result<Topic> {
    node.create_topic(&ros_name(name, ns)?, MessageTypeName::new(pkg, ty), qos).map_err(|e| anyhow!("topic {name}: {e:?}"))
}

/// A subscription; `label` names it in the error.
fn subscription<M: 'static>(node: &mut Node, topic: &Topic, qos: Option<QosProfile>, label: &str) -> Result<Subscription<M>> {
    node.create_subscription::<M>(topic, qos).map_err(|e| anyhow!("subscription {label}: {e:?}"))
}

/// A publisher; `label` names it in the error.
fn publisher<M: serde::Serialize>(node: &mut Node, topic: &Topic, qos: Option<QosProfile>, label: &str) -> Result<Publisher<M>> {
    node.create_publisher::<M>(topic, qos).map_err(|e| anyhow!("publisher {label}: {e:?}"))
}

/// A service the node serves: requests and responses reliable, keep last 100.
fn server<Q: ros2_client::Message + Clone + 'static, A: ros2_client::Message + 'static>(
    node: &mut Node,
    mapping: ServiceMapping,
    name: &str,
    ns: &str,
    (pkg, ty): TypeName,
) -> Result<Server<Q, A>> {
    node.create_server::<Q, A>(mapping, &ros_name(name, ns)?, &ServiceTypeName::new(pkg, ty), reliable(100), reliable(100))
        .map_err(|e| anyhow!("service {name}: {e:?}"))
}

/// A subscription's samples as events (`what` names it when one cannot be read).
fn read<'a, M: 'static + serde::de::DeserializeOwned>(s: &'a Subscription<M>, what: &'static str, event: fn(M) -> Event) -> Events<'a> {
    Box::pin(s.async_stream().map(move |m| m.map_or_else(|e| Event::ReadFailed(what, e), |(m, _)| event(m))))
}

/// A server's requests as events (`what` names it when one cannot be read).
fn requests<'a, Q: ros2_client::Message + 'static, A: ros2_client::Message + 'static>(
    s: &'a Server<Q, A>,
    what: &'static str,
    event: fn(RmwRequestId, Q) -> Event,
) -> Events<'a> {
    Box::pin(s.receive_request_stream().map(move |r| r.map_or_else(|e| Event::ReadFailed(what, e), |(id, q)| event(id, q))))
}

impl Interfaces {
    /// Every topic and service the node uses. `joint_states` and `/tf` are best effort (sensor
    /// streams, keep last); reports and the services reliable; `robot_description`, `/tf_static`
    /// and the cell markers latched (reliable, transient local), as their publishers offer them.
    pub(super) fn build(node: &mut Node, params: &Params, ros_args: &RosArgs) -> Result<Interfaces> {
        let ns = ros_args.namespace.clone().unwrap_or_else(|| "/".into());
        let (ns, remaps) = (ns.as_str(), &ros_args.remaps);
        let names = Names::new(remaps, params);
        let js = topic(node, &names.joint_states, ns, ("sensor_msgs", "JointState"), &best_effort(STATES_KEPT))?;
        let states = subscription(node, &js, Some(best_effort(STATES_KEPT)), &names.joint_states)?;
        let desc_qos = latched(QosProfile::subscription_default(), 1);
        // The URDF and the SRDF, latched as robot_state_publisher and move_group offer them;
        // doors a deployment may close (an empty topic parameter).
        let mut text_door = |name: &str| -> Result<Option<Subscription<DescriptionMsg>>> {
            if name.is_empty() {
                return Ok(None);
            }
            let t = topic(node, name, ns, ("std_msgs", "String"), &desc_qos)?;
            Ok(Some(subscription(node, &t, Some(desc_qos.clone()), name)?))
        };
        let descriptions = text_door(&names.description)?;
        let semantics = text_door(&names.semantic)?;
        let clock = if params.use_sim_time {
            let t = topic(node, "/clock", "/", ("rosgraph_msgs", "Clock"), &best_effort(1))?;
            Some(subscription(node, &t, None, "/clock")?)
        } else {
            None
        };
        // /tf and /tf_static are absolute: the same for every robot, frames told apart by frame_prefix.
        let tf = if params.pose_source == PoseSource::Tf {
            let static_qos = latched(QosProfile::subscription_default(), 100);
            let tf_topic = topic(node, &resolve(remaps, "/tf"), "/", ("tf2_msgs", "TFMessage"), &best_effort(100))?;
            let st_topic = topic(node, &resolve(remaps, "/tf_static"), "/", ("tf2_msgs", "TFMessage"), &static_qos)?;
            Some((subscription(node, &tf_topic, Some(best_effort(100)), "/tf")?, subscription(node, &st_topic, Some(static_qos), "/tf_static")?))
        } else {
            None
        };
        let out = topic(node, &names.collisions, ns, ("thickness_collision_msgs", "CollisionReport"), &reliable(100))?;
        let collisions = publisher(node, &out, None, &names.collisions)?;
        let latched_pub = latched(QosProfile::publisher_default(), 1);
        let cells_topic = topic(node, &names.cells, ns, ("visualization_msgs", "MarkerArray"), &latched_pub)?;
        let contacts_topic = topic(node, &names.contacts, ns, ("visualization_msgs", "MarkerArray"), &reliable(100))?;
        let diag_topic = topic(node, &resolve(remaps, "/diagnostics"), "/", ("diagnostic_msgs", "DiagnosticArray"), &reliable(100))?;
        let mapping = ros_mapping(params.service_mapping);
        Ok(Interfaces {
            states,
            tf,
            descriptions,
            semantics,
            clock,
            collisions,
            cells: publisher(node, &cells_topic, Some(latched_pub.clone()), &names.cells)?,
            contacts: publisher(node, &contacts_topic, None, &names.contacts)?,
            diagnostics: publisher(node, &diag_topic, None, "/diagnostics")?,
            check_states: server(node, mapping, &names.check_states, ns, ("thickness_collision_msgs", "CheckStates"))?,
            check_trajectory: server(node, mapping, &names.check_trajectory, ns, ("thickness_collision_msgs", "CheckTrajectory"))?,
            // MoveIt's service type, so a planner calls it unchanged (remap to /check_state_validity
            // to take move_group's name; never with move_group serving it too).
            check_state_validity: server(node, mapping, &names.check_state_validity, ns, ("moveit_msgs", "GetStateValidity"))?,
            // move_group's names in the root namespace: never run both on one name (`-r` remaps).
            scene: if params.planning_scene { Some(SceneDoors::build(node, &names, ns, mapping)?) } else { None },
            names,
        })
    }

    /// Every input but the joint states (whoever holds the node's state reads those:
    /// `states_on_receive.rs`), one stream each.
    pub(super) fn events(&self) -> Vec<Events<'_>> {
        let mut sources = Vec::new();
        if let Some((tf, tf_static)) = &self.tf {
            sources.push(read(tf, "/tf", Event::Tf));
            sources.push(read(tf_static, "/tf_static", Event::TfStatic));
        }
        if let Some(d) = &self.descriptions {
            sources.push(read(d, "robot_description", Event::Description));
        }
        if let Some(s) = &self.semantics {
            sources.push(read(s, "robot_description_semantic", Event::Semantic));
        }
        if let Some(clock) = &self.clock {
            sources.push(read(clock, "/clock", |m: ClockMsg| Event::Clock(m.clock)));
        }
        sources.push(requests(&self.check_states, "check_states", Event::Request));
        sources.push(requests(&self.check_trajectory, "check_trajectory", Event::TrajectoryRequest));
        sources.push(requests(&self.check_state_validity, "check_state_validity", |id, q| Event::ValidityRequest(id, Box::new(q))));
        if let Some(scene) = &self.scene {
            sources.extend(scene.events());
        }
        sources
    }
}
