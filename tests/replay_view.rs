//! Issue 16: a recording you can look at. A joint-state bag written by rosbags, replayed with
//! `--out` and `--plot`: the output bag decodes with mcap-ros2-support from its own schemas (the
//! markers stamped and framed like the reports, drawing the reports' contact points; `/tf` the
//! link poses `check` uses; `/robot_description`), and the SVG's bars are the runs of colliding
//! reports of `--jsonl`, link by link.

mod common;

use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;
use thickness_collision::checker::Checker;
use thickness_collision::model::{bundled_config_dir, Params};

const T0: i64 = 1_700_000_000_000_000_000;
const STATES: usize = 300;
/// Every actuated joint of the bundled arm (missing_joint: last checks nothing before each came).
const JOINTS: [&str; 7] = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn dir(name: &str) -> PathBuf {
    common::emptied(common::scratch_subdir("replay_view", name))
}

fn ok(c: &mut Command) -> String {
    let out = c.output().unwrap();
    assert!(out.status.success(), "failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// A fast sweep of the bundled arm at 100 Hz: every link meets the workcell in several runs,
/// and some runs are motion-only (the link crossed something between two states).
fn path() -> Vec<Vec<f64>> {
    (0..STATES)
        .map(|k| {
            let s = k as f64 / 100.0 * 6.0;
            vec![1.2 * (0.9 * s).sin(), 0.7 + 0.6 * (2.1 * s).sin(), 0.3 + 0.6 * (1.3 * s + 0.5).sin(), 0.8 * (1.7 * s).sin(), 0.5 * (1.1 * s).cos(), 0.0, 0.0]
        })
        .collect()
}

/// Log time of state k; its stamp is 1234 ns earlier (the two must not be confused).
fn log_time(k: usize) -> i64 {
    T0 + k as i64 * 10_000_000
}

fn stamp(k: usize) -> i64 {
    log_time(k) - 1234
}

fn lines(v: &str) -> Vec<Value> {
    v.lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

fn links_of(report: &Value) -> Vec<String> {
    report["contacts"].as_array().unwrap().iter().map(|c| c["link_name"].as_str().unwrap().to_owned()).collect()
}

/// One bar of the SVG: link, report numbers (from 1), seconds, motion-only, and its pixel box.
#[derive(Debug)]
struct Bar {
    link: String,
    states: (usize, usize),
    seconds: (f64, f64),
    motion_only: bool,
    x: (f64, f64),
}

fn svg_bars(svg: &str) -> Vec<Bar> {
    let doc = roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("the SVG is not XML: {e}"));
    let mut bars = Vec::new();
    for rect in doc.descendants().filter(|n| n.has_tag_name("rect")) {
        let Some(title) = rect.children().find(|n| n.has_tag_name("title")).and_then(|t| t.text()) else { continue };
        // "forearm_link: 0.000 s to 0.100 s, states 1 to 11; in collision, 11 states colliding\n..."
        let first = title.lines().next().unwrap();
        let (link, rest) = first.split_once(": ").unwrap();
        let words: Vec<&str> = rest.split([' ', ',', ';']).filter(|w| !w.is_empty()).collect();
        assert!(!first.contains("merged"), "no run may be merged in a 3 s bag: {first}");
        let attr = |a: &str| rect.attribute(a).unwrap().parse::<f64>().unwrap();
        bars.push(Bar {
            link: link.to_owned(),
            seconds: (words[0].parse().unwrap(), words[3].parse().unwrap()),
            states: (words[6].parse().unwrap(), words[8].parse().unwrap()),
            motion_only: first.contains("motion-only"),
            x: (attr("x"), attr("x") + attr("width")),
        });
    }
    bars
}

#[test]
fn replay_writes_markers_tf_description_and_a_timeline() {
    let d = dir("main");
    let q = path();
    let messages: Vec<Value> = q.iter().enumerate().map(|(k, p)| json!({"t": log_time(k), "stamp": stamp(k), "name": JOINTS, "position": p})).collect();
    let bag = d.join("in");
    let _ = common::run_peer("bag_tool.py", &json!({"op": "write", "path": bag, "storage": "mcap", "messages": messages}));
    let (out_bag, jsonl, svg) = (d.join("out"), d.join("out.jsonl"), d.join("timeline.svg"));
    // Motions on (the default): the timeline has motion-only runs to mark.
    let summary = ok(bin().arg("replay").arg(&bag).arg("--motion").arg("--out").arg(&out_bag).arg("--jsonl").arg(&jsonl).arg("--plot").arg(&svg));
    let reports = lines(&std::fs::read_to_string(&jsonl).unwrap());
    assert_eq!(reports.len(), STATES, "{summary}");

    // The states one by one, through `check` (the discrete reference: which links collide at
    // each state itself).
    let state_lines: Vec<String> = q.iter().enumerate().map(|(k, p)| json!({"name": JOINTS, "position": p, "stamp": stamp(k)}).to_string()).collect();
    let states_file = d.join("states.jsonl");
    std::fs::write(&states_file, state_lines.join("\n") + "\n").unwrap();
    let discrete = lines(&ok(bin().arg("check").arg("--states").arg(&states_file).arg("--json")));

    let view = common::run_peer("bag_tool.py", &json!({"op": "view", "path": out_bag}));
    let schemas = &view["schemas"];
    for (topic, ty) in [
        ("/collisions", "thickness_collision_msgs/msg/CollisionReport"),
        ("/collision_markers/contacts", "visualization_msgs/msg/MarkerArray"),
        ("/collision_markers/cells", "visualization_msgs/msg/MarkerArray"),
        ("/tf", "tf2_msgs/msg/TFMessage"),
        ("/robot_description", "std_msgs/msg/String"),
    ] {
        assert_eq!(schemas[topic], ty, "{topic}: {schemas}");
        assert_eq!(view["rosbags_topics"][topic][0], ty, "rosbags reads {topic} from metadata.yaml");
    }
    assert_eq!(view["rosbags_topics"]["/collision_markers/contacts"][1], STATES);

    // Reports and contact markers: one each per state, at its log time, stamped with its stamp.
    let collisions = view["collisions"].as_array().unwrap();
    let contacts = view["contacts"].as_array().unwrap();
    assert_eq!((collisions.len(), contacts.len()), (STATES, STATES));
    let mut drawn = 0;
    for k in 0..STATES {
        let (report, array) = (&collisions[k], &contacts[k]);
        assert_eq!((report["log_time"].as_i64(), array["log_time"].as_i64()), (Some(log_time(k)), Some(log_time(k))));
        assert_eq!((report["stamp"].as_i64(), report["frame_id"].as_str()), (Some(stamp(k)), Some("world")));
        assert_eq!(reports[k]["stamp"].as_i64(), Some(stamp(k)), "the JSON line of state {k}");
        let markers = array["markers"].as_array().unwrap();
        assert_eq!(markers[0]["action"], 3, "state {k}: a DELETEALL first");
        for m in markers {
            assert_eq!((m["frame_id"].as_str(), m["stamp"].as_i64()), (Some("world"), Some(stamp(k))), "state {k}: {m}");
        }
        let by_ns = |ns: &str| markers.iter().filter(|m| m["ns"] == ns).collect::<Vec<_>>();
        let positions = report["positions"].as_array().unwrap();
        if positions.is_empty() {
            assert_eq!(markers.len(), 1, "state {k}: no contacts, only the DELETEALL");
            continue;
        }
        drawn += 1;
        let spheres = by_ns("contacts");
        assert_eq!((spheres.len(), spheres[0]["type"].as_i64(), spheres[0]["colors"].as_u64()), (1, Some(7), Some(positions.len() as u64)));
        assert_eq!(&spheres[0]["points"], &report["positions"], "state {k}: the sphere list is the contact points");
        let arrows = by_ns("normals");
        assert_eq!(arrows.len(), positions.len());
        for (i, a) in arrows.iter().enumerate() {
            assert_eq!(a["type"], 0);
            assert_eq!(a["points"][0], positions[i], "state {k}: arrow {i} starts at its contact");
            let depth = report["depths"][i].as_f64().unwrap().max(0.005);
            for c in 0..3 {
                let along = a["points"][1][c].as_f64().unwrap() - a["points"][0][c].as_f64().unwrap();
                assert!(
                    (along - report["normals"][i][c].as_f64().unwrap() * depth).abs() < 1e-12,
                    "state {k}: arrow {i} along its normal, as long as its depth"
                );
            }
        }
        let labels = by_ns("labels");
        for (i, l) in labels.iter().enumerate() {
            let text = l["text"].as_str().unwrap();
            assert!(text.starts_with(&format!("{} x {}", report["links"][i].as_str().unwrap(), report["objects"][i].as_str().unwrap())), "{text}");
        }
    }
    assert!(drawn > 50, "{drawn} states with contacts: the sweep should hit more");

    // The cells: once, at the bag's first message, every cell of the workcell as triangles.
    let cells = view["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 1);
    assert_eq!(cells[0]["log_time"].as_i64(), Some(log_time(0)));
    let all = cells[0]["markers"].as_array().unwrap();
    assert_eq!(all[0]["action"], 3, "a DELETEALL first: {:?}", all[0]);
    assert!(all.iter().any(|m| m["ns"] == "solids/table"), "the table (a solid) is drawn");
    let markers: Vec<&Value> = all.iter().filter(|m| m["ns"].as_str().unwrap_or_default().starts_with("cells/")).collect();
    assert_eq!(markers.len(), 3, "one triangle list per thin surface");
    assert!(markers.iter().all(|m| m["type"] == 11 && m["frame_id"] == "world"));
    assert_eq!(markers.iter().map(|m| m["points"].as_u64().unwrap() / 3).sum::<u64>(), 8 * 4112);

    // /robot_description: the bag has none, so the URDF replay checked (the bundled arm).
    let urdf = std::fs::read_to_string(bundled_config_dir().join("example_workcell/robot.urdf")).unwrap();
    assert_eq!(view["robot_description"], json!([urdf]));

    // /tf: per state, world to every link, at the poses check's forward kinematics gives.
    let checker = Checker::from_params(Params::default()).unwrap();
    let robot = checker.robot();
    let joint_index: Vec<usize> = JOINTS.iter().map(|j| robot.joint(j).unwrap()).collect();
    let tf = view["tf"].as_array().unwrap();
    assert_eq!(tf.len(), STATES);
    let mut tf_lines = Vec::new();
    for (k, m) in tf.iter().enumerate() {
        assert_eq!(m["log_time"].as_i64(), Some(log_time(k)));
        let mut positions = vec![0.0; robot.joints.len()];
        for (i, j) in joint_index.iter().enumerate() {
            positions[*j] = q[k][i];
        }
        let poses = robot.forward_kinematics(&positions, checker.base_pose()).unwrap();
        let transforms = m["transforms"].as_array().unwrap();
        let world_root = usize::from(robot.links.iter().any(|l| l.name == "world"));
        assert_eq!(transforms.len(), robot.links.len() - world_root, "state {k}: every link");
        let mut line = Vec::new();
        for t in transforms {
            assert_eq!((t["parent"].as_str(), t["stamp"].as_i64()), (Some("world"), Some(stamp(k))));
            let child = t["child"].as_str().unwrap();
            let pose = &poses[robot.link(child).unwrap_or_else(|| panic!("/tf names {child}, not a link"))];
            let (tr, ro) = (pose.translation.vector, pose.rotation.coords);
            let want = [tr.x, tr.y, tr.z, ro.x, ro.y, ro.z, ro.w];
            let got: Vec<f64> = t["translation"].as_array().unwrap().iter().chain(t["rotation"].as_array().unwrap()).map(|v| v.as_f64().unwrap()).collect();
            assert_eq!(got, want, "state {k}, link {child}");
            line.push(json!({"link": child, "translation": t["translation"], "rotation": t["rotation"]}));
        }
        tf_lines.push(json!({"transforms": line, "stamp": stamp(k)}).to_string());
    }
    // The same poses through `check` as link poses give the reports of the joint states (to
    // rounding: the transform tree composes the poses in another order).
    let tf_file = d.join("tf_states.jsonl");
    std::fs::write(&tf_file, tf_lines.join("\n") + "\n").unwrap();
    let from_tf = lines(&ok(bin().arg("check").arg("--states").arg(&tf_file).arg("--json")));
    let mut ties = 0;
    for k in 0..STATES {
        let (got, want) = (&from_tf[k], &discrete[k]);
        assert_eq!((&got["in_collision"], &got["error"]), (&want["in_collision"], &want["error"]), "state {k}");
        let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
        assert_eq!(g.len(), w.len(), "state {k}: colliding links");
        for (a, b) in g.iter().zip(w) {
            for key in ["link_name", "object_name"] {
                assert_eq!(a[key], b[key], "state {k}: {key}");
            }
            let near = |x: &Value, y: &Value| (x.as_f64().unwrap() - y.as_f64().unwrap()).abs() <= 1e-9;
            assert!(near(&a["depth"], &b["depth"]), "state {k}: depth");
            // Cells of a flat stretch tie for the deepest: rounding may pick another of them.
            if a["triangle"] != b["triangle"] {
                ties += 1;
                continue;
            }
            for i in 0..3 {
                assert!(near(&a["position"][i], &b["position"][i]) && near(&a["normal"][i], &b["normal"][i]), "state {k}: point, normal");
            }
        }
    }

    eprintln!("{ties} deepest contacts found on another triangle of the same depth through /tf");

    // The timeline: bars = runs of consecutive colliding JSON lines, link by link.
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    let bars = svg_bars(&svg_text);
    let mut want: BTreeMap<String, Vec<(usize, usize)>> = BTreeMap::new();
    for (k, r) in reports.iter().enumerate() {
        for link in links_of(r) {
            let runs = want.entry(link).or_default();
            match runs.last_mut() {
                Some(run) if run.1 == k => run.1 = k + 1,
                Some(run) if run.1 == k + 1 => {} // a second contact of the link
                _ => runs.push((k + 1, k + 1)),
            }
        }
    }
    let mut got: BTreeMap<String, Vec<(usize, usize)>> = BTreeMap::new();
    for b in &bars {
        got.entry(b.link.clone()).or_default().push(b.states);
        let seconds = |n: usize| (log_time(n - 1) - log_time(0)) as f64 * 1e-9;
        assert!((b.seconds.0 - seconds(b.states.0)).abs() < 6e-4 && (b.seconds.1 - seconds(b.states.1)).abs() < 6e-4, "{b:?}");
        // A motion-only bar: the link collides at none of its states on its own.
        if b.motion_only {
            for n in b.states.0..=b.states.1 {
                assert!(!links_of(&discrete[n - 1]).contains(&b.link), "{b:?}: state {n} collides on its own");
            }
        } else {
            assert!((b.states.0..=b.states.1).any(|n| links_of(&discrete[n - 1]).contains(&b.link)), "{b:?}: no state collides on its own");
        }
    }
    assert_eq!(got, want, "the SVG's bars vs the JSON lines' colliding runs");
    assert!(bars.iter().any(|b| b.motion_only) && bars.iter().any(|b| !b.motion_only), "the sweep has both kinds of run");
    // x grows with time along the axis: one linear map (fitted on the extremes) places every bar
    // within a pixel.
    let (first, last) =
        bars.iter().fold((&bars[0], &bars[0]), |(a, z), b| (if b.seconds.0 < a.seconds.0 { b } else { a }, if b.seconds.0 > z.seconds.0 { b } else { z }));
    let per_second = (last.x.0 - first.x.0) / (last.seconds.0 - first.seconds.0);
    for b in &bars {
        let x = first.x.0 + (b.seconds.0 - first.seconds.0) * per_second;
        assert!((x - b.x.0).abs() <= 1.0, "{b:?}: x {x:.1} expected");
        assert!(b.x.1 > b.x.0);
    }
    assert!(svg_text.contains("states, ") && svg_text.contains("deepest contact: "), "the header");
    assert!(svg_text.contains(&*bag.display().to_string()), "the header names the bag");
    let _ = std::fs::remove_dir_all(&d);
}

/// A plot file that cannot be created fails before the bag is read, with exit 2 and the path.
#[test]
fn an_unwritable_plot_path_is_refused() {
    let d = dir("unwritable");
    let bag = d.join("in");
    let _ = common::run_peer(
        "bag_tool.py",
        &json!({"op": "write", "path": bag, "storage": "mcap", "messages": [{"t": T0, "stamp": T0, "name": JOINTS, "position": vec![0.0; 7]}]}),
    );
    let target = d.join("no_such_dir").join("t.svg");
    let out = bin().arg("replay").arg(&bag).arg("--plot").arg(&target).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&*target.display().to_string()), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
