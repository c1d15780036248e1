//! The node's life: participant, node, topics and service, and the loop that checks states.

use super::msg_impls::{CheckStatesRequest, CheckStatesResponse, ClockMsg};
use super::ros_args::RosArgs;
use crate::checker::{Checker, JointMemory, StateReport};
use crate::model::Params;
use crate::msgs::{CollisionReport, DiagnosticArray, Header, JointState, MarkerArray, StringMsg, TfMessage, Time};
use super::markers::{cell_markers, contact_markers, diagnostics, NodeStats};
use crate::checker::TfTree;
use ros2_client::MessageInfo;
use std::pin::Pin;
use futures::stream::FusedStream;
use anyhow::{anyhow, Context as _, Result};
use futures::{FutureExt, StreamExt};
use ros2_client::dds::rustdds::{DomainParticipant, DomainParticipantBuilder};
use ros2_client::qos::{History, WhenFull};
use ros2_client::QosProfile;
use ros2_client::{Context, MessageTypeName, Name, NodeName, NodeOptions, ParameterValue, ServiceMapping, ServiceTypeName};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, RwLock};
use std::time::{Duration, Instant};

/// How the node was started.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// `--ros-args`.
    pub ros_args: RosArgs,
    /// Robot URDF override (`--robot`).
    pub robot: Option<PathBuf>,
    /// Environment URDF override (`--environment`).
    pub environment: Option<PathBuf>,
}

/// Warnings at most once a second per cause, so a flood of bad messages cannot flood the log.
#[derive(Default)]
struct RateLimitedLog {
    last: HashMap<String, Instant>,
    suppressed: HashMap<String, u64>,
    /// Messages written but not yet sent to `/rosout` (the node is borrowed elsewhere then).
    pending: Vec<String>,
}

impl RateLimitedLog {
    fn warn(&mut self, cause: &str, message: impl FnOnce() -> String) {
        let now = Instant::now();
        match self.last.get(cause) {
            Some(t) if now.duration_since(*t) < Duration::from_secs(1) => {
                *self.suppressed.entry(cause.to_owned()).or_insert(0) += 1;
            }
            _ => {
                let n = self.suppressed.remove(cause).unwrap_or(0);
                let more = if n > 0 { format!(" ({n} more like it in the last second)") } else { String::new() };
                let text = format!("{}{more}", message());
                eprintln!("[WARN] thickness_collision: {text}");
                if self.pending.len() < 64 {
                    self.pending.push(text);
                }
                // Causes are a handful of fixed strings: the maps stay small.
                let _ = self.last.insert(cause.to_owned(), now);
            }
        }
    }
}

fn env_flag(name: &str, value: &str) -> bool {
    std::env::var(name).map(|v| v.eq_ignore_ascii_case(value)).unwrap_or(false)
}

/// The DDS participant: `ROS_DOMAIN_ID`, and loopback only when the environment asks for it.
fn participant() -> Result<(DomainParticipant, u16, bool)> {
    let domain: u16 = match std::env::var("ROS_DOMAIN_ID") {
        Ok(v) if !v.trim().is_empty() => v.trim().parse().map_err(|_| anyhow!("ROS_DOMAIN_ID='{v}' is not a domain id (0-232)"))?,
        _ => 0,
    };
    let localhost = env_flag("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST") || env_flag("ROS_LOCALHOST_ONLY", "1");
    let mut builder = DomainParticipantBuilder::new(domain);
    if localhost {
        builder = builder.with_only_networks([std::net::IpAddr::from([127, 0, 0, 1])]);
    }
    Ok((builder.build().context("cannot create the DDS participant")?, domain, localhost))
}

/// Applies `-p key:=value` to the parameters (values parsed as YAML, keys with dots nest).
fn apply_param_overrides(params: Params, overrides: &[(String, String)]) -> Result<Params> {
    if overrides.is_empty() {
        return Ok(params);
    }
    let mut doc = serde_yaml::to_value(&params)?;
    for (key, value) in overrides {
        let v: serde_yaml::Value = serde_yaml::from_str(value).with_context(|| format!("-p {key}:={value}: not a value"))?;
        let mut at = &mut doc;
        let parts: Vec<&str> = key.split('.').collect();
        for (i, part) in parts.iter().enumerate() {
            let map = at.as_mapping_mut().ok_or_else(|| anyhow!("-p {key}: '{part}' is not a parameter group"))?;
            let k = serde_yaml::Value::String((*part).to_owned());
            if !map.contains_key(&k) {
                return Err(anyhow!("-p {key}:={value}: unknown parameter '{key}'"));
            }
            if i + 1 == parts.len() {
                let _ = map.insert(k, v.clone());
                break;
            }
            at = map.get_mut(&k).ok_or_else(|| anyhow!("-p {key}: unknown parameter"))?;
        }
    }
    let params: Params = serde_yaml::from_value(doc).context("-p")?;
    params.validate()?;
    Ok(params)
}

/// Reliable, transient local ("latched"), keep last `depth`: how `robot_description`,
/// `/tf_static` and the cell markers are offered.
fn latched(base: QosProfile, depth: usize) -> QosProfile {
    base.reliability_reliable(WhenFull::DEFAULT).durability(ros2_client::qos::Durability::TransientLocal).history(History::KeepLast { depth })
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

fn report_message(report: &StateReport, stamp: Time, frame: &str) -> CollisionReport {
    CollisionReport::from_state(report, Header { stamp, frame_id: frame.to_owned() })
}

/// Runs the node until Ctrl-C or SIGTERM.
pub fn run(params: Params, opts: &RunOptions) -> Result<()> {
    let params = apply_param_overrides(params, &opts.ros_args.params)?;
    let checker = Checker::from_params(params.clone(), opts.robot.as_deref(), opts.environment.as_deref())?;
    let shared: Arc<RwLock<Arc<Checker>>> = Arc::new(RwLock::new(Arc::new(checker)));
    let (dp, domain, localhost) = participant()?;
    let context = Context::from_domain_participant(dp).map_err(|e| anyhow!("ROS context: {e:?}"))?;

    let namespace = opts.ros_args.namespace.clone().unwrap_or_else(|| "/".into());
    let node_name = opts.ros_args.node_name.clone().unwrap_or_else(|| "thickness_collision".into());
    // Parameters served by the standard services; thickness and side rebuild the cells.
    let rebuild = {
        let shared = shared.clone();
        let params = Arc::new(RwLock::new(params.clone()));
        let (robot, environment) = (opts.robot.clone(), opts.environment.clone());
        let initial = Arc::new(RwLock::new(HashMap::<String, String>::new()));
        move |name: &str, value: &ParameterValue| -> Result<(), String> {
            let mut p = params.read().map_err(|_| "poisoned".to_string())?.clone();
            let before = p.clone();
            match (name, value) {
                ("default_thickness", ParameterValue::Double(t)) => p.default_thickness = *t,
                ("default_side", ParameterValue::String(s)) => p.default_side = s.clone(),
                ("world_frame", ParameterValue::String(s)) => p.world_frame = s.clone(),
                _ => {
                    // Read-only after start: the declaration sets it once, nothing changes it.
                    let mut seen = initial.write().map_err(|_| "poisoned".to_string())?;
                    let v = format!("{value:?}");
                    return match seen.get(name) {
                        None => {
                            let _ = seen.insert(name.to_owned(), v);
                            Ok(())
                        }
                        Some(old) if *old == v => Ok(()),
                        Some(_) => Err(format!("parameter '{name}' is read-only while the node runs")),
                    };
                }
            }
            if p == before {
                return Ok(());
            }
            p.validate().map_err(|e| e.to_string())?;
            let fresh = Checker::from_params(p.clone(), robot.as_deref(), environment.as_deref()).map_err(|e| e.to_string())?;
            // Swapped whole: a check in flight keeps the old cells.
            *shared.write().map_err(|_| "poisoned".to_string())? = Arc::new(fresh);
            *params.write().map_err(|_| "poisoned".to_string())? = p;
            Ok(())
        }
    };
    let options = NodeOptions::new()
        .enable_rosout(true)
        .start_parameter_services(true)
        .declare_parameter("default_thickness", ParameterValue::Double(params.default_thickness))
        .declare_parameter("default_side", ParameterValue::String(params.default_side.clone()))
        .declare_parameter("world_frame", ParameterValue::String(params.world_frame.clone()))
        .declare_parameter("robot_description_file", ParameterValue::String(params.robot_description_file.clone()))
        .declare_parameter("environment_file", ParameterValue::String(params.environment_file.clone()))
        .declare_parameter("missing_joint", ParameterValue::String(format!("{:?}", params.missing_joint).to_lowercase()))
        .declare_parameter("allowed_collisions", ParameterValue::StringArray(params.allowed_collisions.clone()))
        .declare_parameter("checked_links", ParameterValue::StringArray(params.checked_links.clone()))
        .declare_parameter("use_sim_time", ParameterValue::Boolean(params.use_sim_time))
        .declare_parameter("robot_base_pose", ParameterValue::DoubleArray(params.robot_base_pose.clone()))
        .declare_parameter("package_map", ParameterValue::StringArray(params.package_map.clone()))
        .declare_parameter("thin_surfaces.patterns", ParameterValue::StringArray(params.thin_surfaces.patterns.clone()))
        .declare_parameter("thin_surfaces.thickness", ParameterValue::DoubleArray(params.thin_surfaces.thickness.clone()))
        .declare_parameter("thin_surfaces.side", ParameterValue::StringArray(params.thin_surfaces.side.clone()))
        .declare_parameter("solid_hull", ParameterValue::StringArray(params.solid_hull.clone()))
        .declare_parameter("padding.links", ParameterValue::StringArray(params.padding.links.clone()))
        .declare_parameter("padding.values", ParameterValue::DoubleArray(params.padding.values.clone()))
        .declare_parameter("use_visual_when_no_collision", ParameterValue::Boolean(params.use_visual_when_no_collision))
        .declare_parameter("pose_source", ParameterValue::String(params.pose_source.clone()))
        .declare_parameter("frame_prefix", ParameterValue::String(params.frame_prefix.clone()))
        .declare_parameter("marker_max_cells", ParameterValue::Integer(params.marker_max_cells))
        .declare_parameter("marker_rate", ParameterValue::Double(params.marker_rate))
        .declare_parameter("service_mapping", ParameterValue::String(params.service_mapping.clone()))
        .parameter_set_action(Box::new(rebuild));
    let mut node = context
        .new_node(NodeName::new(&namespace, &node_name).map_err(|e| anyhow!("node name {namespace}/{node_name}: {e:?}"))?, options)
        .map_err(|e| anyhow!("cannot create the node: {e:?}"))?;

    let remaps = &opts.ros_args.remaps;
    let js_name = resolve(remaps, "joint_states");
    let out_name = resolve(remaps, "collisions");
    let srv_name = resolve(remaps, "check_states");
    // joint_states: best effort, keep last (a sensor stream); collisions and the service: reliable.
    let best_effort = QosProfile::subscription_default().reliability_best_effort().history(History::KeepLast { depth: 1 });
    let reliable = QosProfile::publisher_default().reliability_reliable(WhenFull::DEFAULT).history(History::KeepLast { depth: 100 });
    let js_topic = node.create_topic(&ros_name(&js_name, &namespace)?, MessageTypeName::new("sensor_msgs", "JointState"), &best_effort).map_err(|e| anyhow!("topic {js_name}: {e:?}"))?;
    let out_topic = node
        .create_topic(&ros_name(&out_name, &namespace)?, MessageTypeName::new("thickness_collision_msgs", "CollisionReport"), &reliable)
        .map_err(|e| anyhow!("topic {out_name}: {e:?}"))?;
    let subscription = node.create_subscription::<JointState>(&js_topic, None).map_err(|e| anyhow!("subscription: {e:?}"))?;
    // robot_description: reliable, transient local (latched), as robot_state_publisher offers it.
    let latched_qos = latched(QosProfile::subscription_default(), 1);
    let desc_name = resolve(remaps, "robot_description");
    let desc_topic = node.create_topic(&ros_name(&desc_name, &namespace)?, MessageTypeName::new("std_msgs", "String"), &latched_qos).map_err(|e| anyhow!("topic {desc_name}: {e:?}"))?;
    let desc_sub = node.create_subscription::<StringMsg>(&desc_topic, Some(latched_qos.clone())).map_err(|e| anyhow!("subscription {desc_name}: {e:?}"))?;
    // /clock (rosgraph_msgs/Clock) when use_sim_time: the node's own stamps follow it.
    let clock_sub = if params.use_sim_time {
        let clock_topic = node.create_topic(&ros_name("/clock", "/")?, MessageTypeName::new("rosgraph_msgs", "Clock"), &best_effort).map_err(|e| anyhow!("topic /clock: {e:?}"))?;
        Some(node.create_subscription::<ClockMsg>(&clock_topic, None).map_err(|e| anyhow!("subscription /clock: {e:?}"))?)
    } else {
        None
    };
    // /tf and /tf_static are absolute: the same for every robot, frames told apart by frame_prefix.
    let use_tf = params.pose_source == "tf";
    let (tf_sub, tf_static_sub) = if use_tf {
        let tf_static_qos = latched(QosProfile::subscription_default(), 100);
        let tf_topic = node.create_topic(&ros_name(&resolve(remaps, "/tf"), "/")?, MessageTypeName::new("tf2_msgs", "TFMessage"), &best_effort).map_err(|e| anyhow!("topic /tf: {e:?}"))?;
        let st_topic = node.create_topic(&ros_name(&resolve(remaps, "/tf_static"), "/")?, MessageTypeName::new("tf2_msgs", "TFMessage"), &tf_static_qos).map_err(|e| anyhow!("topic /tf_static: {e:?}"))?;
        let tf_qos = QosProfile::subscription_default().reliability_best_effort().history(History::KeepLast { depth: 100 });
        (
            Some(node.create_subscription::<TfMessage>(&tf_topic, Some(tf_qos)).map_err(|e| anyhow!("subscription /tf: {e:?}"))?),
            Some(node.create_subscription::<TfMessage>(&st_topic, Some(tf_static_qos)).map_err(|e| anyhow!("subscription /tf_static: {e:?}"))?),
        )
    } else {
        (None, None)
    };
    let publisher = node.create_publisher::<CollisionReport>(&out_topic, None).map_err(|e| anyhow!("publisher: {e:?}"))?;
    // Markers: the cells once, latched (capped by marker_max_cells); contacts at most marker_rate.
    let latched_pub = latched(QosProfile::publisher_default(), 1);
    let cells_name = resolve(remaps, "collision_markers/cells");
    let contacts_name = resolve(remaps, "collision_markers/contacts");
    let cells_topic = node.create_topic(&ros_name(&cells_name, &namespace)?, MessageTypeName::new("visualization_msgs", "MarkerArray"), &latched_pub).map_err(|e| anyhow!("topic {cells_name}: {e:?}"))?;
    let contacts_topic = node.create_topic(&ros_name(&contacts_name, &namespace)?, MessageTypeName::new("visualization_msgs", "MarkerArray"), &reliable).map_err(|e| anyhow!("topic {contacts_name}: {e:?}"))?;
    let diag_topic = node.create_topic(&ros_name(&resolve(remaps, "/diagnostics"), "/")?, MessageTypeName::new("diagnostic_msgs", "DiagnosticArray"), &reliable).map_err(|e| anyhow!("topic /diagnostics: {e:?}"))?;
    let cells_pub = node.create_publisher::<MarkerArray>(&cells_topic, Some(latched_pub.clone())).map_err(|e| anyhow!("publisher {cells_name}: {e:?}"))?;
    let contacts_pub = node.create_publisher::<MarkerArray>(&contacts_topic, None).map_err(|e| anyhow!("publisher {contacts_name}: {e:?}"))?;
    let diag_pub = node.create_publisher::<DiagnosticArray>(&diag_topic, None).map_err(|e| anyhow!("publisher /diagnostics: {e:?}"))?;
    let max_cells = params.marker_max_cells.max(0) as usize;
    let marker_period = Duration::from_secs_f64(1.0 / params.marker_rate);
    let server = node
        .create_server::<CheckStatesRequest, CheckStatesResponse>(
            match params.service_mapping.as_str() {
                "enhanced" => ServiceMapping::Enhanced,
                "basic" => ServiceMapping::Basic,
                _ => ServiceMapping::Cyclone,
            },
            &ros_name(&srv_name, &namespace)?,
            &ServiceTypeName::new("thickness_collision_msgs", "CheckStates"),
            reliable.clone(),
            reliable.clone(),
        )
        .map_err(|e| anyhow!("service {srv_name}: {e:?}"))?;

    {
        let c = shared.read().map_err(|_| anyhow!("poisoned"))?;
        let s = &c.summary;
        println!(
            "thickness_collision: node {} on DDS domain {domain}{}",
            node.fully_qualified_name(),
            if localhost { " (loopback only)" } else { "" }
        );
        println!("  robot {} ({} links, {} checked)", s.robot_source, s.robot_links, s.checked_links);
        println!("  environment {} ({} thin surfaces, {} cells, {} solids), built in {:.1} ms", s.environment_source, s.thin_surfaces, s.cells, s.solids, s.build_seconds * 1e3);
        let input = if use_tf { format!("/tf and /tf_static (tf2_msgs/msg/TFMessage, frame prefix '{}')", params.frame_prefix) } else { format!("{js_name} (sensor_msgs/msg/JointState)") };
        println!("  subscribes {input}, publishes {out_name} (thickness_collision_msgs/msg/CollisionReport), serves {srv_name}");
    }

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst)).context("cannot install the Ctrl-C/SIGTERM handler")?;
    }
    let spinner = node.spinner().map_err(|e| anyhow!("spinner: {e:?}"))?;
    let world_frame = params.world_frame.clone();
    let mut log = RateLimitedLog::default();

    smol::block_on(async {
        let spin = smol::spawn(spinner.spin());
        let mut merged: HashMap<String, f64> = HashMap::new();
        let mut memory: Option<JointMemory> = None;
        let mut stats = NodeStats::default();
        let mut last_markers = Instant::now() - marker_period;
        let mut last_diag = Instant::now();
        let sim_time: std::cell::Cell<Option<Time>> = std::cell::Cell::new(None);
        let now_stamp = || match sim_time.get() {
            Some(t) => t,
            None => Time::from_nanos(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as i64)),
        };
        let mut clocks: Stream<ClockMsg> = match &clock_sub { Some(s) => Box::pin(s.async_stream()), None => Box::pin(futures::stream::pending()) };
        if let Ok(c) = shared.read() {
            if cells_pub.publish(cell_markers(&c, max_cells, &world_frame, now_stamp())).is_err() {
                log.warn("markers", || format!("publishing {cells_name} failed"));
            }
        }
        let fqn = node.fully_qualified_name();
        let mut requests = server.receive_request_stream();
        type Stream<'a, M> = Pin<Box<dyn FusedStream<Item = ros2_client::ReadResult<(M, MessageInfo)>> + 'a>>;
        let mut states: Stream<JointState> = if use_tf { Box::pin(futures::stream::pending()) } else { Box::pin(subscription.async_stream()) };
        let mut tfs: Stream<TfMessage> = match &tf_sub { Some(s) => Box::pin(s.async_stream()), None => Box::pin(futures::stream::pending()) };
        let mut tf_statics: Stream<TfMessage> = match &tf_static_sub { Some(s) => Box::pin(s.async_stream()), None => Box::pin(futures::stream::pending()) };
        let mut descriptions: Stream<StringMsg> = Box::pin(desc_sub.async_stream());
        let mut tree = TfTree::default();
        let prefix = params.frame_prefix.clone();
        loop {
            if stop.load(Ordering::SeqCst) {
                break;
            }
            // Warnings go to /rosout too (the console already has them).
            for text in log.pending.drain(..) {
                ros2_client::rosout!(node, ros2_client::ros2::LogLevel::Warn, "{}", text);
            }
            // Checked on every turn, not on the timer only: a busy input would starve it.
            let elapsed = last_diag.elapsed();
            if elapsed >= Duration::from_secs(1) {
                last_diag = Instant::now();
                if diag_pub.publish(diagnostics(&fqn, &mut stats, elapsed.as_secs_f64(), now_stamp())).is_err() {
                    log.warn("diagnostics", || "publishing /diagnostics failed".into());
                }
            }
            let tick = FutureExt::fuse(smol::Timer::after(Duration::from_millis(100)));
            futures::pin_mut!(tick);
            futures::select! {
                msg = states.select_next_some() => {
                    let Ok((first, _)) = msg else { log.warn("read", || format!("reading {js_name} failed")); continue };
                    // Skip to the newest: merge everything already waiting, check once.
                    let mut latest = first;
                    let mut batch = vec![];
                    while let Ok(Some((m, _))) = subscription.take() {
                        batch.push(std::mem::replace(&mut latest, m));
                    }
                    stats.received += 1 + batch.len() as u64;
                    stats.skipped += batch.len() as u64;
                    let checker = match shared.read() { Ok(c) => c.clone(), Err(_) => break };
                    let memory = memory.get_or_insert_with(|| JointMemory::new(&checker.robot));
                    for m in batch.iter().chain(std::iter::once(&latest)) {
                        if m.name.len() != m.position.len() {
                            log.warn("lengths", || format!("JointState with {} names and {} positions skipped", m.name.len(), m.position.len()));
                            continue;
                        }
                        if let Some((n, v)) = m.name.iter().zip(&m.position).find(|(_, v)| !v.is_finite()) {
                            log.warn("nan", || format!("JointState skipped: joint '{n}' has position {v}"));
                            continue;
                        }
                        for (n, v) in m.name.iter().zip(&m.position) {
                            // Only the model's joints are kept: memory stays bounded by the model.
                            if checker.robot.joint(n).is_some() {
                                let _ = merged.insert(n.clone(), *v);
                            } else {
                                log.warn("unknown", || format!("'{n}' is not a joint of the robot model; ignored"));
                            }
                        }
                    }
                    let (names, positions): (Vec<String>, Vec<f64>) = merged.iter().map(|(k, v)| (k.clone(), *v)).unzip();
                    match checker.check_joints(&names, &positions, memory, false) {
                        Ok((report, _)) => {
                            stats.record_check(report.check_seconds);
                            if publisher.async_publish(report_message(&report, latest.header.stamp, &world_frame)).await.is_err() {
                                log.warn("publish", || format!("publishing on {out_name} failed"));
                            }
                            if last_markers.elapsed() >= marker_period {
                                last_markers = Instant::now();
                                if contacts_pub.publish(contact_markers(&report, &world_frame, latest.header.stamp)).is_err() {
                                    log.warn("markers", || format!("publishing {contacts_name} failed"));
                                }
                            }
                        }
                        Err(e) => log.warn("state", || format!("state rejected: {e}")),
                    }
                }
                msg = clocks.select_next_some() => {
                    if let Ok((c, _)) = msg {
                        sim_time.set(Some(c.clock));
                    }
                }
                msg = descriptions.select_next_some() => {
                    let Ok((d, _)) = msg else { log.warn("read-desc", || format!("reading {desc_name} failed")); continue };
                    // A new robot: rebuilt off to the side and swapped in whole; a bad one is
                    // reported and the running model stays.
                    let current = match shared.read() { Ok(c) => c.params.clone(), Err(_) => break };
                    match Checker::from_description(current, &d.data, &format!("{desc_name} topic"), opts.environment.as_deref()) {
                        Ok(fresh) => {
                            println!("thickness_collision: robot from {desc_name}: {} links, {} checked", fresh.summary.robot_links, fresh.summary.checked_links);
                            memory = None;
                            merged.clear();
                            if cells_pub.publish(cell_markers(&fresh, max_cells, &world_frame, now_stamp())).is_err() {
                                log.warn("markers", || format!("publishing {cells_name} failed"));
                            }
                            match shared.write() { Ok(mut c) => *c = Arc::new(fresh), Err(_) => break }
                        }
                        Err(e) => log.warn("description", || format!("{desc_name} rejected, keeping the current robot: {e}")),
                    }
                }
                msg = tf_statics.select_next_some() => {
                    if let Ok((m, _)) = msg {
                        for bad in tree.update(&m) {
                            log.warn("tf", || format!("transform for frame '{bad}' skipped (not finite, or past {} frames)", TfTree::MAX_FRAMES));
                        }
                    }
                }
                msg = tfs.select_next_some() => {
                    let Ok((m, _)) = msg else { log.warn("read-tf", || "reading /tf failed".into()); continue };
                    stats.received += 1;
                    for bad in tree.update(&m) {
                        log.warn("tf", || format!("transform for frame '{bad}' skipped (not finite, or past {} frames)", TfTree::MAX_FRAMES));
                    }
                    let checker = match shared.read() { Ok(c) => c.clone(), Err(_) => break };
                    // A message that names no frame of this robot (another robot's, a sensor's)
                    // updates the tree but is not a robot state: warned about and skipped.
                    let ours = m.transforms.iter().any(|t| {
                        let child = t.child_frame_id.trim_start_matches('/');
                        child.strip_prefix(prefix.as_str()).is_some_and(|link| checker.robot.link(link).is_some())
                    });
                    if !ours {
                        let first = m.transforms.first().map(|t| t.child_frame_id.clone()).unwrap_or_default();
                        log.warn("tf-unknown", || format!("/tf message for frames unknown to the robot (e.g. '{first}', prefix '{prefix}') skipped"));
                        continue;
                    }
                    let poses: Vec<(String, crate::math::Pose)> = checker.targets.iter().filter_map(|t| tree.world_pose(&format!("{prefix}{}", t.name), &world_frame).map(|p| (t.name.clone(), p))).collect();
                    if poses.is_empty() {
                        continue; // none of the robot's frames reach world_frame yet
                    }
                    let stamp = m.transforms.iter().map(|t| t.header.stamp).max().unwrap_or_default();
                    match checker.check_transforms(&poses) {
                        Ok(report) => {
                            stats.record_check(report.check_seconds);
                            if publisher.async_publish(report_message(&report, stamp, &world_frame)).await.is_err() {
                                log.warn("publish", || format!("publishing on {out_name} failed"));
                            }
                        }
                        Err(e) => log.warn("state", || format!("state rejected: {e}")),
                    }
                }
                req = requests.select_next_some() => {
                    let (id, req) = match req {
                        Ok(r) => r,
                        Err(e) => {
                            log.warn("service", || format!("reading a check_states request failed: {e:?}"));
                            continue;
                        }
                    };
                    if std::env::var_os("TC_DEBUG").is_some() {
                        eprintln!("check_states request {id:?}: {} states", req.states.len());
                    }
                    let checker = match shared.read() { Ok(c) => c.clone(), Err(_) => break };
                    let reports = req.states.iter().map(|s| {
                        let mut m = JointMemory::new(&checker.robot);
                        match checker.check_joints(&s.name, &s.position, &mut m, false) {
                            Ok((r, _)) => report_message(&r, s.header.stamp, &world_frame),
                            Err(e) => {
                                log.warn("service-state", || format!("check_states: state rejected: {e}"));
                                // A rejected state is answered, marked by a negative check time.
                                CollisionReport { header: Header { stamp: s.header.stamp, frame_id: world_frame.clone() }, check_seconds: -1.0, ..Default::default() }
                            }
                        }
                    }).collect();
                    if server.async_send_response(id, CheckStatesResponse { reports }).await.is_err() {
                        log.warn("service-send", || "sending a check_states response failed".into());
                    }
                }
                _ = tick => {}
            }
        }
        println!("thickness_collision: shutting down ({} states received, {} checked, {} skipped as stale)", stats.received, stats.checked, stats.skipped);
        drop(spin);
    });
    Ok(())
}
