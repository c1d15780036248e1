//! `check`: robot states from the command line or a JSON-lines file, reports on standard output.
//! A states file goes through the node's pipeline line by line, as a recorded stream would.

use crate::ModelArgs;
use anyhow::{anyhow, bail, Context, Result};
use serde::Deserialize;
use std::io::{BufRead, Write};
use std::path::Path;
use thickness_collision::checker::StateReport;
use thickness_collision::msgs::{Header, JointState, Quaternion, TfMessage, Time, Transform, TransformStamped, Vector3};
use thickness_collision::pipeline::{CheckedState, Pipeline};

/// One line of a states file.
#[derive(Deserialize)]
#[serde(untagged, deny_unknown_fields)]
enum StateLine {
    Joints {
        name: Vec<String>,
        position: Vec<f64>,
        #[serde(default)]
        stamp: i64,
    },
    Transforms {
        transforms: Vec<LinkTransform>,
        #[serde(default)]
        stamp: i64,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LinkTransform {
    link: String,
    translation: [f64; 3],
    rotation: [f64; 4],
}

/// Longest states-file line read (a state of a few hundred joints is a few kB): a file without
/// newlines must not be read into memory whole.
const MAX_LINE: u64 = 1 << 20;

fn parse_joints(spec: &str) -> Result<(Vec<String>, Vec<f64>)> {
    let mut names = Vec::new();
    let mut values = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (name, value) = item.split_once('=').ok_or_else(|| anyhow!("--joints: '{item}' is not name=value"))?;
        let v: f64 = value.trim().parse().map_err(|_| anyhow!("--joints: joint '{}' has value '{}', not a number", name.trim(), value.trim()))?;
        names.push(name.trim().to_owned());
        values.push(v);
    }
    if names.is_empty() {
        bail!("--joints: no name=value pairs");
    }
    Ok((names, values))
}

pub fn check(args: &ModelArgs, joints: Option<&str>, states: Option<&Path>, json: bool, show_params: bool) -> Result<()> {
    if show_params {
        print!("{}", super::load::params(args)?.to_yaml());
        return Ok(());
    }
    let mut pipeline = super::load::pipeline(args)?;
    let s = pipeline.checker().summary();
    eprintln!(
        "loaded {} ({} links, {} checked) and {} ({} thin surfaces, {} cells, {} solids) in {:.1} ms",
        s.robot_source,
        s.robot_links,
        s.checked_links,
        s.environment_source,
        s.thin_surfaces,
        s.cells,
        s.solids,
        s.build_seconds * 1e3
    );
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    if let Some(spec) = joints {
        let (names, values) = parse_joints(spec)?;
        let report = pipeline.checker().check_joints(&names, &values).context("--joints")?;
        emit(&mut out, 1, &CheckedState { stamp: Time::default(), report }, json)?;
    } else if let Some(path) = states {
        let file = std::fs::File::open(path).with_context(|| format!("cannot read states file {}", path.display()))?;
        let mut reader = std::io::BufReader::new(file);
        let mut first_bad: Option<(usize, String)> = None;
        let mut line = String::new();
        for n in 1.. {
            line.clear();
            let read = std::io::Read::take(&mut reader, MAX_LINE + 1).read_line(&mut line).with_context(|| format!("{}: line {n}", path.display()))?;
            if read == 0 {
                break;
            }
            if read as u64 > MAX_LINE {
                bail!("{}: line {n} is longer than {MAX_LINE} bytes", path.display());
            }
            if line.trim().is_empty() {
                continue;
            }
            let state: StateLine = serde_json::from_str(&line).map_err(|e| {
                anyhow!("{}: line {n}: not a state ({e}); expected {{\"name\": [...], \"position\": [...]}} or {{\"transforms\": [...]}}", path.display())
            })?;
            let checked = check_line(&mut pipeline, state);
            for w in pipeline.take_warnings() {
                eprintln!("thickness_collision: warning: {w}");
            }
            if !checked.report.error.is_empty() && first_bad.is_none() {
                first_bad = Some((n, checked.report.error.clone()));
            }
            emit(&mut out, n, &checked, json)?;
        }
        out.flush()?;
        if let Some((n, error)) = first_bad {
            bail!("{}: line {n}: the state cannot be checked: {error} (reported in collision; later lines were checked)", path.display());
        }
    }
    out.flush()?;
    Ok(())
}

/// A line through the pipeline; a state it cannot check fails closed in its place.
fn check_line(pipeline: &mut Pipeline, state: StateLine) -> CheckedState {
    let (stamp, result) = match state {
        StateLine::Joints { name, position, stamp } => {
            let stamp = Time::from_nanos(stamp);
            let msg = JointState { header: Header { stamp, frame_id: String::new() }, name, position, ..Default::default() };
            (stamp, pipeline.joint_state(&msg))
        }
        StateLine::Transforms { transforms, stamp } => {
            let stamp = Time::from_nanos(stamp);
            let (world, prefix) = (pipeline.params().world_frame.clone(), pipeline.params().frame_prefix.clone());
            let transforms = transforms
                .into_iter()
                .map(|t| {
                    let ([x, y, z], [qx, qy, qz, qw]) = (t.translation, t.rotation);
                    TransformStamped {
                        header: Header { stamp, frame_id: world.clone() },
                        child_frame_id: format!("{prefix}{}", t.link),
                        transform: Transform { translation: Vector3 { x, y, z }, rotation: Quaternion { x: qx, y: qy, z: qz, w: qw } },
                    }
                })
                .collect();
            (stamp, pipeline.tf(&TfMessage { transforms }))
        }
    };
    match result {
        Ok(state) => pipeline.check(&state),
        Err(skip) => CheckedState { stamp, report: StateReport::failed(skip.message) },
    }
}

fn emit(out: &mut impl Write, n: usize, checked: &CheckedState, json: bool) -> Result<()> {
    if json {
        writeln!(out, "{}", checked.json())?;
        return Ok(());
    }
    let report = &checked.report;
    if !report.error.is_empty() {
        writeln!(out, "state {n}: NOT CHECKED, reported in collision: {}", report.error)?;
        return Ok(());
    }
    let limits = if report.out_of_limits.is_empty() { String::new() } else { format!(" (outside limits: {})", report.out_of_limits.join(", ")) };
    if !report.in_collision {
        writeln!(out, "state {n}: clear{limits}")?;
        return Ok(());
    }
    writeln!(out, "state {n}: IN COLLISION{limits}")?;
    for c in &report.contacts {
        let tri = if c.triangle == u32::MAX { "solid".to_string() } else { format!("triangle {}", c.triangle) };
        let point = c.position.map_or("none".into(), |p| format!("[{:.4}, {:.4}, {:.4}]", p[0], p[1], p[2]));
        writeln!(
            out,
            "  {} x {} ({tri}): depth {:.4} m, normal [{:.3}, {:.3}, {:.3}], point {point}",
            c.link_name, c.object_name, c.depth, c.normal[0], c.normal[1], c.normal[2]
        )?;
    }
    Ok(())
}
