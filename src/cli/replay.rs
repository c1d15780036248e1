//! `replay`: a recorded bag through the checker, with a progress bar on a terminal, the warnings
//! on standard error and a summary at the end.

use crate::ModelArgs;
use anyhow::{anyhow, bail, Result};
use std::io::IsTerminal;
use thickness_collision::replay::{replay as run_replay, NoInput, ReplayObserver, ReplayOptions};

pub fn replay(args: &ModelArgs, opts: &ReplayOptions) -> Result<()> {
    check_window(opts)?;
    let params = super::load::params(args)?;
    let mut printer = Printer::new();
    let summary = run_replay(params, opts, &mut printer)?;
    println!("{summary}");
    if let Some(e) = &summary.bag_error {
        // The reports before the fault are written; the bag itself is bad.
        return Err(anyhow!("{e}"));
    }
    if let Some(e) = &summary.no_input {
        // Nothing of the input was checked: not a success, whatever the reason.
        return Err(anyhow!("{}", no_input(e)));
    }
    Ok(())
}

fn check_window(opts: &ReplayOptions) -> Result<()> {
    for (flag, v) in [("--start", opts.start), ("--end", opts.end)] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
            bail!("{flag} {v}: must be a finite number of seconds >= 0 after the bag's first message");
        }
    }
    if let (Some(a), Some(b)) = (opts.start, opts.end) {
        if a > b {
            bail!("--start {a} is after --end {b}: no message could be replayed");
        }
    }
    Ok(())
}

/// Why nothing of the input topic was decoded, in the flags' terms.
fn no_input(e: &NoInput) -> String {
    // "none of the 1 messages decodes" reads badly; one message gets its own wording.
    let subject = |n: u64| if n == 1 { "the one message".to_owned() } else { format!("none of the {n} messages") };
    let verb = |n: u64, one: &'static str, many: &'static str| if n == 1 { one } else { many };
    match e {
        NoInput::NoMessages { topic, bag, have } => {
            let have: Vec<String> = have.iter().map(|(t, n)| format!("{t} ({n})")).collect();
            let have = if have.is_empty() { "no messages at all".to_owned() } else { format!("messages on {}", have.join(", ")) };
            format!("bag {} has no messages on topic {topic}, so no state to check (it has {have})", bag.display())
        }
        NoInput::OutsideWindow { topic, bag, messages, span: (a, b), start, end } => {
            let flag = |f: &str, v: Option<f64>| v.map_or(String::new(), |v| format!(" {f} {v}"));
            format!(
                "{} on {topic} in bag {} {}{}{} (logged {a:.3} to {b:.3} s after the bag's first message)",
                subject(*messages),
                bag.display(),
                verb(*messages, "is not inside", "is inside"),
                flag("--start", *start),
                flag("--end", *end)
            )
        }
        NoInput::Undecodable { topic, bag, expected, messages, zstd_frames, first_error } => {
            let hint = if zstd_frames == messages {
                verb(
                    *messages,
                    "; it is a zstd frame: a message-compressed bag read without its metadata.yaml (replay the bag's directory)",
                    "; they are zstd frames: a message-compressed bag read without its metadata.yaml (replay the bag's directory)",
                )
            } else {
                ""
            };
            format!(
                "{} on {topic} in bag {} {} as CDR {expected} (the first error: {first_error}){hint}",
                subject(*messages),
                bag.display(),
                verb(*messages, "does not decode", "decodes")
            )
        }
        _ => "no message of the input topic was decoded".to_owned(),
    }
}

/// Progress as a spinner when standard error is a terminal; warnings and notes as lines.
struct Printer {
    bar: Option<indicatif::ProgressBar>,
}

impl Printer {
    fn new() -> Printer {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = indicatif::ProgressBar::new_spinner();
            let style = indicatif::ProgressStyle::with_template("{spinner} {pos} messages {per_sec}");
            b.set_style(style.unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()));
            b
        });
        Printer { bar }
    }

    fn line(&self, text: String) {
        match &self.bar {
            Some(b) => b.suspend(|| eprintln!("{text}")),
            None => eprintln!("{text}"),
        }
    }
}

impl ReplayObserver for Printer {
    fn progress(&mut self, messages: u64) {
        if let Some(b) = &self.bar {
            b.set_position(messages);
        }
    }

    fn warning(&mut self, text: &str) {
        self.line(format!("thickness_collision: warning: {text}"));
    }

    fn note(&mut self, text: &str) {
        self.line(format!("thickness_collision: {text}"));
    }

    fn finished(&mut self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
