//! The floor of the node's middleware, for the latency instrument (benches/run_latency.sh):
//! ros2-client on RustDDS, loopback only, the node's QoS and the node's kind of loop (smol, the
//! subscription's async stream, `async_publish`), and nothing else.
//!
//! ```text
//! ros_relay relay                      answers each joint_states sample with an empty CollisionReport
//! ros_relay latched TOPIC BYTES SECS   publishes one std_msgs/String of BYTES latched, then waits
//! ```
//! `ROS_DOMAIN_ID` picks the domain. Built with `cargo build --release --example ros_relay`
//! (the `ros` feature, on by default).

use futures::StreamExt;
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{Context, MessageTypeName, Name, NodeName, NodeOptions, QosProfile};
use std::time::{Duration, Instant};
use thickness_collision::msgs::{CollisionReport, Header, JointState, StringMsg};

fn main() {
    if let Err(e) = run() {
        eprintln!("ros_relay: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let domain: u16 = std::env::var("ROS_DOMAIN_ID").ok().and_then(|v| v.parse().ok()).unwrap_or(0);
    // Loopback only, as the node with ROS_LOCALHOST_ONLY=1 (the network rule of this project).
    let dp = DomainParticipantBuilder::new(domain).with_only_networks([std::net::IpAddr::from([127, 0, 0, 1])]).build().map_err(|e| format!("{e:?}"))?;
    let context = Context::from_domain_participant(dp).map_err(|e| format!("{e:?}"))?;
    let mut node = context
        .new_node(NodeName::new("/", "ros_relay").map_err(|e| format!("{e:?}"))?, NodeOptions::new().enable_rosout(false))
        .map_err(|e| format!("{e:?}"))?;
    let name = |n: &str| Name::new("/", n).map_err(|e| format!("{e:?}"));
    match args.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        ["relay"] => {
            // The node's QoS: joint_states best effort keep last 100, collisions reliable keep last 100.
            let best_effort = QosProfile::subscription_default().reliability_best_effort().history(History::KeepLast { depth: 100 });
            let reliable = QosProfile::publisher_default().reliability_reliable(WhenFull::DEFAULT).history(History::KeepLast { depth: 100 });
            let js =
                node.create_topic(&name("joint_states")?, MessageTypeName::new("sensor_msgs", "JointState"), &best_effort).map_err(|e| format!("{e:?}"))?;
            let out = node
                .create_topic(&name("collisions")?, MessageTypeName::new("thickness_collision_msgs", "CollisionReport"), &reliable)
                .map_err(|e| format!("{e:?}"))?;
            let states = node.create_subscription::<JointState>(&js, Some(best_effort)).map_err(|e| format!("{e:?}"))?;
            let reports = node.create_publisher::<CollisionReport>(&out, None).map_err(|e| format!("{e:?}"))?;
            let spinner = node.spinner().map_err(|e| format!("{e:?}"))?;
            println!("relay ready");
            smol::block_on(async {
                let _spin = smol::spawn(spinner.spin());
                let mut stream = Box::pin(states.async_stream());
                while let Some(sample) = stream.next().await {
                    let Ok((state, _)) = sample else { continue };
                    let report = CollisionReport { header: Header { stamp: state.header.stamp, frame_id: "world".into() }, ..Default::default() };
                    if reports.async_publish(report).await.is_err() {
                        eprintln!("ros_relay: publish failed");
                    }
                }
            });
            Ok(())
        }
        ["latched", topic, bytes, secs] => {
            let bytes: usize = bytes.parse().map_err(|_| "BYTES is a number")?;
            let secs: f64 = secs.parse().map_err(|_| "SECS is a number")?;
            let qos = QosProfile::publisher_default()
                .reliability_reliable(WhenFull::DEFAULT)
                .durability(Durability::TransientLocal)
                .history(History::KeepLast { depth: 1 });
            let t = node.create_topic(&name(topic)?, MessageTypeName::new("std_msgs", "String"), &qos).map_err(|e| format!("{e:?}"))?;
            let publisher = node.create_publisher::<StringMsg>(&t, Some(qos)).map_err(|e| format!("{e:?}"))?;
            let spinner = node.spinner().map_err(|e| format!("{e:?}"))?;
            let mut data = String::from("<?xml version=\"1.0\"?>\n<!-- padding -->\n");
            data.extend(std::iter::repeat_n(' ', bytes.saturating_sub(data.len())));
            smol::block_on(async {
                let _spin = smol::spawn(spinner.spin());
                let started = Instant::now();
                publisher.publish(StringMsg { data }).map_err(|e| format!("{e:?}"))?;
                println!("published {bytes} bytes in {:.1} ms", started.elapsed().as_secs_f64() * 1e3);
                smol::Timer::after(Duration::from_secs_f64(secs)).await;
                Ok(())
            })
        }
        _ => Err("usage: ros_relay relay | ros_relay latched TOPIC BYTES SECS".into()),
    }
}
