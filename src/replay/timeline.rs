//! The collision timeline of a replay: per link, the runs of consecutive reports in which it
//! collides, gathered as the bag streams by (`replay --plot`; drawn by `timeline_svg`).

use crate::checker::StateReport;
use std::collections::{BTreeSet, HashMap, HashSet};

/// Bars kept per link before neighbours are merged. A flickering contact at 100 Hz for an hour
/// makes 180,000 runs; the picture cannot show more than one per few pixels anyway, and memory
/// must stay bounded by the model, not the bag.
const MAX_BARS_KEPT: usize = 8192;

/// One link's run of consecutive colliding reports (or several merged).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TimelineBar {
    /// Seconds from the bag's first message to the first colliding report of the run.
    pub start: f64,
    /// Seconds from the bag's first message to its last colliding report.
    pub end: f64,
    /// Number of the first and the last report in the run (from 1, as in the summary).
    pub states: (usize, usize),
    /// Reports in which the link collides.
    pub colliding: u64,
    /// Some report of the run collides at its own state. Without one the run is motion-only: the
    /// link met something between states, never at a state reported.
    pub state_hit: bool,
    /// Deepest contact of the link in the run (metres).
    pub depth: f64,
    /// Objects (or links, for self-collision) the link touched, as numbers into
    /// [`Timeline::objects`].
    pub objects: BarObjects,
    /// Runs merged into this bar (1: none).
    pub runs: u64,
}

impl TimelineBar {
    /// No state in it collides: only the motions into them do.
    pub(crate) fn motion_only(&self) -> bool {
        !self.state_hit
    }

    /// Takes `next` (later) into this bar.
    pub(crate) fn absorb(&mut self, next: &TimelineBar) {
        self.end = next.end;
        self.states.1 = next.states.1;
        self.colliding += next.colliding;
        self.state_hit |= next.state_hit;
        self.depth = self.depth.max(next.depth);
        self.objects.extend(&next.objects);
        self.runs += next.runs;
    }
}

/// The objects of a bar. Almost every bar touches one object, kept without an allocation: a
/// flickering contact makes a bar every few reports, and a heap node per bar (a `BTreeSet` of
/// names, as it was) slowed every allocation of the replay loop by a fifth (docs/benchmarks.md).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum BarObjects {
    One(u32),
    Many(BTreeSet<u32>),
}

impl BarObjects {
    fn insert(&mut self, id: u32) {
        match self {
            BarObjects::One(o) if *o == id => {}
            BarObjects::One(o) => *self = BarObjects::Many(BTreeSet::from([*o, id])),
            BarObjects::Many(set) => {
                let _ = set.insert(id);
            }
        }
    }

    fn extend(&mut self, other: &BarObjects) {
        match other {
            BarObjects::One(id) => self.insert(*id),
            BarObjects::Many(set) => set.iter().for_each(|id| self.insert(*id)),
        }
    }

    /// The numbers, ascending.
    pub(crate) fn ids(&self) -> Vec<u32> {
        match self {
            BarObjects::One(o) => vec![*o],
            BarObjects::Many(set) => set.iter().copied().collect(),
        }
    }
}

/// One row of the picture.
#[derive(Clone, Debug)]
pub(crate) struct TimelineRow {
    /// The link.
    pub link: String,
    /// Its bars, in time order.
    pub bars: Vec<TimelineBar>,
    /// Bars closer than this (seconds) were merged to bound memory (0: none were).
    merged_within: f64,
}

/// The deepest contact of the replay: (seconds, report number, link, object, depth).
pub(crate) type TimelineDeepest = (f64, usize, String, String, f64);

/// Everything the picture shows, gathered report by report.
#[derive(Clone, Debug, Default)]
pub(crate) struct Timeline {
    /// Rows in the order their links first collided.
    pub rows: Vec<TimelineRow>,
    /// Reports recorded.
    pub reports: usize,
    /// Reports in collision.
    pub in_collision: usize,
    /// Seconds from the bag's first message to the last report.
    pub last_seconds: f64,
    /// The deepest contact.
    pub deepest: Option<TimelineDeepest>,
    /// The names of the objects the bars touched, numbered in the order first met.
    pub objects: Vec<String>,
    object_ids: HashMap<String, u32>,
}

impl Timeline {
    /// Whether the next report's state must be checked on its own to tell motion-only hits: a
    /// motion in collision where some colliding link has no state hit in its run yet. A run
    /// known to hit at a state stays so, so a long contact costs one second check, not one per
    /// report.
    pub(crate) fn needs_state_check(&self, report: &StateReport) -> bool {
        let n = self.reports + 1;
        report.motion
            && report.in_collision
            && report.contacts.iter().any(|c| {
                let bar = self.rows.iter().find(|r| r.link == c.link_name).and_then(|r| r.bars.last());
                !bar.is_some_and(|b| b.state_hit && b.states.1 + 1 >= n)
            })
    }

    /// The names of a bar's objects, sorted.
    pub(crate) fn object_names(&self, bar: &TimelineBar) -> Vec<&str> {
        let mut names: Vec<&str> = bar.objects.ids().into_iter().filter_map(|id| self.objects.get(id as usize).map(String::as_str)).collect();
        names.sort_unstable();
        names
    }

    fn object_id(&mut self, name: &str) -> u32 {
        if let Some(id) = self.object_ids.get(name) {
            return *id;
        }
        let id = self.objects.len() as u32;
        self.objects.push(name.to_owned());
        let _ = self.object_ids.insert(name.to_owned(), id);
        id
    }

    /// Motion-only runs (bars) in the picture's rows.
    pub(crate) fn motion_only_runs(&self) -> usize {
        self.rows.iter().flat_map(|r| &r.bars).filter(|b| b.motion_only()).count()
    }

    /// Records the next report, made `seconds` after the bag's first message. `state_links`: the
    /// links that collide at the reported state itself, when [`Timeline::needs_state_check`] asked
    /// for them (`None`: every colliding link counts as a state hit).
    pub(crate) fn record(&mut self, seconds: f64, report: &StateReport, state_links: Option<&HashSet<String>>) {
        self.reports += 1;
        self.last_seconds = seconds;
        let n = self.reports;
        if !report.in_collision {
            return;
        }
        self.in_collision += 1;
        // A failed check has no contacts: it counts, but draws no bar.
        for c in &report.contacts {
            let state_hit = state_links.is_none_or(|s| s.contains(&c.link_name));
            if self.deepest.as_ref().is_none_or(|d| c.depth > d.4) {
                self.deepest = Some((seconds, n, c.link_name.clone(), c.object_name.clone(), c.depth));
            }
            let object = self.object_id(&c.object_name);
            let row = match self.rows.iter().position(|r| r.link == c.link_name) {
                Some(i) => &mut self.rows[i],
                None => {
                    // Grown as bars come (most links collide in a few runs); `MAX_BARS_KEPT` caps it.
                    self.rows.push(TimelineRow { link: c.link_name.clone(), bars: Vec::new(), merged_within: 0.0 });
                    let last = self.rows.len() - 1;
                    &mut self.rows[last]
                }
            };
            match row.bars.last_mut() {
                // A second contact of the same link in the same report.
                Some(b) if b.states.1 == n => {
                    b.depth = b.depth.max(c.depth);
                    b.objects.insert(object);
                }
                // The run goes on; or, once bars are merged to bound memory, a close one joins.
                Some(b) if b.states.1 + 1 == n || seconds - b.end < row.merged_within => {
                    b.runs += (b.states.1 + 1 != n) as u64;
                    b.end = seconds;
                    b.states.1 = n;
                    b.colliding += 1;
                    b.state_hit |= state_hit;
                    b.depth = b.depth.max(c.depth);
                    b.objects.insert(object);
                }
                _ => row.bars.push(TimelineBar {
                    start: seconds,
                    end: seconds,
                    states: (n, n),
                    colliding: 1,
                    state_hit,
                    depth: c.depth,
                    objects: BarObjects::One(object),
                    runs: 1,
                }),
            }
            if row.bars.len() > MAX_BARS_KEPT {
                row.coarsen();
            }
        }
    }
}

impl TimelineRow {
    /// Merges bars closer than a gap that doubles until at most half of [`MAX_BARS_KEPT`] are left.
    fn coarsen(&mut self) {
        let span = self.bars.last().map_or(0.0, |b| b.end) - self.bars.first().map_or(0.0, |b| b.start);
        let mut gap = (span / MAX_BARS_KEPT as f64).max(self.merged_within * 2.0).max(1e-9);
        loop {
            merge_bars(&mut self.bars, |a, b| b.start - a.end < gap);
            if self.bars.len() <= MAX_BARS_KEPT / 2 {
                break;
            }
            gap *= 2.0;
        }
        self.merged_within = gap;
    }
}

/// Merges each bar into the one before it while `close(before, bar)`, within the vector (which
/// keeps its block: a row's bars are merged again and again while a bag streams).
pub(crate) fn merge_bars(bars: &mut Vec<TimelineBar>, close: impl Fn(&TimelineBar, &TimelineBar) -> bool) {
    let mut kept = 0;
    for i in 0..bars.len() {
        if kept > 0 && close(&bars[kept - 1], &bars[i]) {
            let (before, after) = bars.split_at_mut(i);
            before[kept - 1].absorb(&after[0]);
        } else {
            bars.swap(kept, i);
            kept += 1;
        }
    }
    bars.truncate(kept);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checker::ReportContact;

    fn hit(links: &[(&str, f64)]) -> StateReport {
        let contacts = links
            .iter()
            .map(|(l, d)| ReportContact {
                link_name: (*l).into(),
                object_name: "guard".into(),
                triangle: 0,
                depth: *d,
                position: Some([0.0; 3]),
                normal: [0.0, 0.0, 1.0],
                object_type: Default::default(),
                link_type: crate::checker::ObjectType::RobotLink,
            })
            .collect::<Vec<_>>();
        StateReport { in_collision: !contacts.is_empty(), contacts, ..Default::default() }
    }

    #[test]
    fn runs_of_consecutive_reports_make_one_bar_per_link() {
        let mut t = Timeline::default();
        let plan: [&[(&str, f64)]; 6] = [&[], &[("a", 0.01)], &[("a", 0.03), ("b", 0.0)], &[], &[("a", 0.02)], &[("a", 0.01)]];
        for (k, links) in plan.iter().enumerate() {
            let report = hit(links);
            // Report 3 is a motion whose own state has only `a` colliding.
            let state = HashSet::from(["a".to_owned()]);
            t.record(k as f64 * 0.01, &report, (k == 2).then_some(&state));
        }
        let a: Vec<_> = t.rows[0].bars.iter().map(|b| (b.states, b.colliding, b.depth)).collect();
        assert_eq!(a, [((2, 3), 2, 0.03), ((5, 6), 2, 0.02)]);
        assert_eq!(t.rows[1].link, "b");
        assert!(t.rows[1].bars[0].motion_only(), "b collided only along the motion into report 3");
        assert_eq!((t.reports, t.in_collision, t.motion_only_runs()), (6, 4, 1));
        assert_eq!(t.deepest.as_ref().map(|d| (d.1, d.4)), Some((3, 0.03)));
    }

    #[test]
    fn a_state_is_checked_again_only_while_its_run_has_no_state_hit() {
        let mut t = Timeline::default();
        let motion = |links: &[(&str, f64)]| StateReport { motion: true, ..hit(links) };
        t.record(0.0, &hit(&[("a", 0.01)]), None);
        assert!(!t.needs_state_check(&motion(&[("a", 0.01)])), "a's run already hit at a state");
        assert!(t.needs_state_check(&motion(&[("a", 0.01), ("b", 0.0)])), "b starts a run");
        assert!(!t.needs_state_check(&hit(&[("b", 0.01)])), "a state's own check needs no other");
        t.record(0.01, &hit(&[]), None);
        assert!(t.needs_state_check(&motion(&[("a", 0.01)])), "a's next run starts after a free report");
    }

    #[test]
    fn a_bar_names_every_object_its_link_touched_also_after_merging() {
        let mut t = Timeline::default();
        let on = |object: &str| StateReport {
            in_collision: true,
            contacts: vec![ReportContact { object_name: object.into(), ..hit(&[("a", 0.01)]).contacts[0].clone() }],
            ..Default::default()
        };
        // Runs: [shelf, guard] at reports 1-2, then guard alone at 4, then many short runs of guard.
        t.record(0.0, &on("shelf"), None);
        t.record(0.01, &on("guard"), None);
        t.record(0.02, &hit(&[]), None);
        t.record(0.03, &on("guard"), None);
        assert_eq!(t.object_names(&t.rows[0].bars[0]), ["guard", "shelf"]);
        assert_eq!(t.object_names(&t.rows[0].bars[1]), ["guard"]);
        for k in 0..2 * MAX_BARS_KEPT {
            t.record(0.04 + k as f64 * 0.01, &if k % 2 == 0 { hit(&[]) } else { on("guard") }, None);
        }
        let bars = &t.rows[0].bars;
        assert!(bars.len() <= MAX_BARS_KEPT / 2 + 1, "{} bars", bars.len());
        assert_eq!(t.object_names(&bars[0]), ["guard", "shelf"], "the first bar absorbed its neighbours and kept both objects");
        assert_eq!(bars.iter().map(|b| b.colliding).sum::<u64>(), 3 + MAX_BARS_KEPT as u64);
    }

    #[test]
    fn a_flickering_link_is_merged_to_bounded_bars() {
        let mut t = Timeline::default();
        for k in 0..200_000 {
            let links: &[(&str, f64)] = if k % 2 == 0 { &[("a", 0.01)] } else { &[] };
            t.record(k as f64 * 0.01, &hit(links), None);
        }
        let bars = &t.rows[0].bars;
        assert!(bars.len() <= MAX_BARS_KEPT, "{} bars kept", bars.len());
        assert_eq!(bars.iter().map(|b| b.colliding).sum::<u64>(), 100_000, "every colliding report is in some bar");
        assert_eq!(bars.iter().map(|b| b.runs).sum::<u64>(), 100_000);
    }
}
