//! `check`: robot states from the command line or a JSON-lines file, reports on standard output.
//! A states file goes through the node's pipeline line by line, as a recorded stream would.

use crate::ModelArgs;
use anyhow::{anyhow, bail, Context, Result};
use std::io::{BufRead, Write};
use std::path::Path;
use thickness_collision::checker::ObjectType;
use thickness_collision::limits::{open_regular, MAX_STATE_LINE_BYTES};
use thickness_collision::msgs::Time;
use thickness_collision::pipeline::{parse_state_line, CheckedState, Pipeline, RobotState, StateLine};

pub(super) fn parse_joints(spec: &str) -> Result<(Vec<String>, Vec<f64>)> {
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

/// What `check` was asked: one state, or a states file; the output form.
pub struct CheckRequest<'a> {
    /// `--joints name=value,...`.
    pub joints: Option<&'a str>,
    /// `--states FILE` (`-`: standard input).
    pub states: Option<&'a Path>,
    /// `--json`: one JSON object per state.
    pub json: bool,
    /// `--motion`: each line after the first is the motion to it.
    pub motion: bool,
    /// `--show-params`: print the parameters in force and stop.
    pub show_params: bool,
}

pub fn check(args: &ModelArgs, req: &CheckRequest) -> Result<()> {
    if req.show_params {
        print!("{}", super::load::params(args)?.to_yaml());
        return Ok(());
    }
    if req.motion && req.states.is_none() {
        bail!("--motion needs --states FILE.jsonl (the waypoints of a path)");
    }
    let mut pipeline = super::load::pipeline(args)?;
    print_loaded(&pipeline);
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    if let Some(spec) = req.joints {
        let (names, values) = parse_joints(spec)?;
        let report = pipeline.checker().check_joints(&names, &values).context("--joints")?;
        emit(&mut out, 1, &CheckedState { stamp: Time::default(), report }, req.json)?;
    } else if let Some(path) = req.states {
        check_states_file(&mut pipeline, path, req, &mut out)?;
    }
    out.flush()?;
    Ok(())
}

pub(super) fn print_loaded(pipeline: &Pipeline) {
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
    eprintln!("{}", pipeline.checker().self_pairs().summary(pipeline.checker()));
}

/// Every line of a states file through the pipeline, each report emitted in turn; a line that
/// cannot be checked fails closed in its place and the first one makes the command fail.
fn check_states_file(pipeline: &mut Pipeline, path: &Path, req: &CheckRequest, out: &mut impl Write) -> Result<()> {
    // `-` is standard input; anything else must be a regular file (a FIFO or a device would
    // block or never end).
    let (source, name): (Box<dyn std::io::Read>, String) = if path == Path::new("-") {
        (Box::new(std::io::stdin().lock()), "standard input".into())
    } else {
        let (file, _) = open_regular(path, "states file", u64::MAX)?;
        (Box::new(file), path.display().to_string())
    };
    let mut reader = std::io::BufReader::new(source);
    let mut first_bad: Option<(usize, String)> = None;
    let mut previous = None;
    let mut line = Vec::new();
    for n in 1.. {
        line.clear();
        let read = std::io::Read::take(&mut reader, MAX_STATE_LINE_BYTES + 1).read_until(b'\n', &mut line).with_context(|| format!("{name}: line {n}"))?;
        if read == 0 {
            break;
        }
        if read as u64 > MAX_STATE_LINE_BYTES {
            bail!("{name}: line {n} is longer than {MAX_STATE_LINE_BYTES} bytes, the longest state line read");
        }
        let Ok(text) = std::str::from_utf8(&line) else {
            bail!("{name}: line {n}: not UTF-8 text");
        };
        if text.trim().is_empty() {
            continue;
        }
        let state = parse_state_line(text).map_err(|e| anyhow!("{name}: line {n}: {e}"))?;
        let checked = if req.motion { waypoint(pipeline, state, &mut previous) } else { pipeline.check_line(state) };
        for w in pipeline.take_warnings() {
            eprintln!("thickness_collision: warning: {w}");
        }
        if !checked.report.error.is_empty() && first_bad.is_none() {
            first_bad = Some((n, checked.report.error.clone()));
        }
        emit(out, n, &checked, req.json)?;
    }
    out.flush()?;
    if let Some((n, error)) = first_bad {
        bail!("{name}: line {n}: the state cannot be checked: {error} (reported in collision; later lines were checked)");
    }
    Ok(())
}

/// A waypoint of a path: the motion to it from the last good one. A waypoint that cannot be
/// checked fails closed, and the next motion starts from the last good waypoint.
fn waypoint(pipeline: &mut Pipeline, state: StateLine, previous: &mut Option<RobotState>) -> CheckedState {
    let (stamp, result) = pipeline.line_state(state);
    match result {
        Ok(state) => {
            let checked = match previous.as_ref() {
                Some(from) => pipeline.check_motion(from, &state),
                None => pipeline.check(&state),
            };
            *previous = Some(state);
            checked
        }
        Err(skip) => CheckedState { stamp, report: thickness_collision::checker::StateReport::failed(skip.message) },
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
    if report.motion {
        match report.fraction {
            None => writeln!(out, "motion to state {n}: clear")?,
            Some(f) => writeln!(out, "motion to state {n}: IN COLLISION from {f:.4} of the way")?,
        }
        if !report.in_collision {
            return Ok(());
        }
    } else if !report.in_collision {
        writeln!(out, "state {n}: clear{limits}")?;
        return Ok(());
    }
    if !report.motion {
        writeln!(out, "state {n}: IN COLLISION{limits}")?;
    }
    print_contacts(out, report)
}

/// One line per contact of `report`.
pub(super) fn print_contacts(out: &mut impl Write, report: &thickness_collision::checker::StateReport) -> Result<()> {
    for c in &report.contacts {
        let tri = match c.object_type {
            ObjectType::RobotLink => "robot link".to_string(),
            ObjectType::AttachedObject => "attached object".to_string(),
            ObjectType::Environment if c.triangle == u32::MAX => "solid".to_string(),
            ObjectType::Environment => format!("triangle {}", c.triangle),
        };
        let point = c.position.map_or("none".into(), |p| format!("[{:.4}, {:.4}, {:.4}]", p[0], p[1], p[2]));
        writeln!(
            out,
            "  {} x {} ({tri}): depth {:.4} m, normal [{:.3}, {:.3}, {:.3}], point {point}",
            c.link_name, c.object_name, c.depth, c.normal[0], c.normal[1], c.normal[2]
        )?;
    }
    Ok(())
}
