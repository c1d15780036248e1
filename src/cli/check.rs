//! `check`: robot states from the command line or a JSON-lines file, reports on standard output.

use crate::ModelArgs;
use anyhow::{anyhow, bail, Context, Result};
use serde::Deserialize;
use std::io::{BufRead, Write};
use std::path::Path;
use thickness_collision::checker::{Checker, JointMemory, StateReport};
use thickness_collision::math::{Pose, Rotation, Vector};

/// One line of a states file.
#[derive(Deserialize)]
#[serde(untagged, deny_unknown_fields)]
enum StateLine {
    Joints { name: Vec<String>, position: Vec<f64> },
    Transforms { transforms: Vec<LinkTransform> },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LinkTransform {
    link: String,
    translation: [f64; 3],
    rotation: [f64; 4],
}

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
    let checker = super::load::checker(args)?;
    let s = &checker.summary;
    eprintln!(
        "loaded {} ({} links, {} checked) and {} ({} thin surfaces, {} cells, {} solids) in {:.1} ms",
        s.robot_source, s.robot_links, s.checked_links, s.environment_source, s.thin_surfaces, s.cells, s.solids, s.build_seconds * 1e3
    );
    let mut memory = JointMemory::new(&checker.robot);
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    if let Some(spec) = joints {
        let (names, values) = parse_joints(spec)?;
        let (report, _) = checker.check_joints(&names, &values, &mut memory, true).context("--joints")?;
        emit(&mut out, 1, &report, json)?;
    } else if let Some(path) = states {
        let file = std::fs::File::open(path).with_context(|| format!("cannot read states file {}", path.display()))?;
        for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
            let n = i + 1;
            let line = line.with_context(|| format!("{}: line {n}", path.display()))?;
            if line.trim().is_empty() {
                continue;
            }
            let report = check_line(&checker, &line, &mut memory).with_context(|| format!("{}: line {n}", path.display()))?;
            emit(&mut out, n, &report, json)?;
        }
    }
    out.flush()?;
    Ok(())
}

fn check_line(checker: &Checker, line: &str, memory: &mut JointMemory) -> Result<StateReport> {
    let state: StateLine = serde_json::from_str(line).map_err(|e| anyhow!("not a state ({e}); expected {{\"name\": [...], \"position\": [...]}} or {{\"transforms\": [...]}}"))?;
    match state {
        StateLine::Joints { name, position } => {
            let (report, unknown) = checker.check_joints(&name, &position, memory, false)?;
            for u in unknown {
                if memory.first_unknown(&u) {
                    eprintln!("thickness_collision: warning: '{u}' is not a joint of the robot model; ignored (warned once)");
                }
            }
            Ok(report)
        }
        StateLine::Transforms { transforms } => {
            let poses: Vec<(String, Pose)> = transforms
                .into_iter()
                .map(|t| {
                    let [x, y, z, w] = t.rotation;
                    (t.link, Pose::from_parts(Vector::from_array(t.translation), Rotation::from_xyzw(x, y, z, w)))
                })
                .collect();
            Ok(checker.check_transforms(&poses)?)
        }
    }
}

fn emit(out: &mut impl Write, n: usize, report: &StateReport, json: bool) -> Result<()> {
    if json {
        serde_json::to_writer(&mut *out, report)?;
        writeln!(out)?;
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
        writeln!(
            out,
            "  {} x {} ({tri}): depth {:.4} m, normal [{:.3}, {:.3}, {:.3}], point [{:.4}, {:.4}, {:.4}]",
            c.link_name, c.object_name, c.depth, c.normal[0], c.normal[1], c.normal[2], c.position[0], c.position[1], c.position[2]
        )?;
    }
    Ok(())
}
