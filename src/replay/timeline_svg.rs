//! The timeline as an SVG picture, drawn with plotters: time along x, one row per link that ever
//! collided, a shaded bar per run in collision (motion-only runs in another colour), the deepest
//! contact of each bar drawn over it on one scale, and each bar's objects in its tooltip.

use super::timeline::{merge_bars, Timeline, TimelineBar};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::collections::HashMap;

const WIDTH: u32 = 1200;
const HEADER: u32 = 78;
const ROW: u32 = 30;
/// Axis labels and margins below and above the rows.
const FOOTER: u32 = 60;

/// Bars closer than this many pixels are drawn as one: an hour at 100 Hz stays a few hundred
/// bars per row, whatever the contacts do.
const MERGE_PIXELS: i32 = 3;
/// The narrowest bar: a single report must still show.
const MIN_BAR_PIXELS: i32 = 2;

const STATE_HIT: RGBColor = RGBColor(228, 87, 46);
const MOTION_ONLY: RGBColor = RGBColor(123, 44, 191);

/// A bar as drawn: its pixel box (the SVG rectangle's x, y, width, height) and tooltip.
struct DrawnBar {
    rect: (i32, i32, i32, i32),
    title: String,
}

/// The picture of `timeline` for the bag named `bag`.
pub(crate) fn timeline_svg(timeline: &Timeline, bag: &str) -> Result<String, super::output_error::OutputError> {
    let rows = timeline.rows.len().max(1) as u32;
    let height = HEADER + rows * ROW + FOOTER;
    let mut svg = String::new();
    let drawn = {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        let drawn = draw(&root, timeline, bag).map_err(|e| super::output_error::OutputError::Timeline(e.to_string()))?;
        root.present().map_err(|e| super::output_error::OutputError::Timeline(e.to_string()))?;
        drawn
    };
    Ok(with_titles(&svg, &drawn))
}

fn draw(root: &DrawingArea<SVGBackend, Shift>, t: &Timeline, bag: &str) -> Result<Vec<DrawnBar>, Box<dyn std::error::Error>> {
    root.fill(&WHITE)?;
    let (header, body) = root.split_vertically(HEADER);
    let text = |size: u32| ("sans-serif", size).into_font().color(&BLACK);
    header.draw(&Text::new(format!("Collision timeline of {bag}"), (10, 8), text(22)))?;
    let deepest = match &t.deepest {
        Some((s, n, link, object, d)) => format!("deepest contact: {link} x {object}, {:.1} mm at {s:.3} s (state {n})", d * 1e3),
        None => "deepest contact: none".into(),
    };
    let counts = format!(
        "{} states, {} in collision, {} motion-only runs, {} links in collision; {deepest}",
        t.reports,
        t.in_collision,
        t.motion_only_runs(),
        t.rows.len()
    );
    header.draw(&Text::new(counts, (10, 34), text(17)))?;
    // The legend: swatches drawn like the bars they stand for.
    let mut x = 10;
    for (color, label) in [(STATE_HIT, "in collision at a state"), (MOTION_ONLY, "motion-only (between states)")] {
        header.draw(&Rectangle::new([(x, 56), (x + 14, 68)], color.mix(0.35).filled()))?;
        header.draw(&Text::new(label, (x + 18, 56), text(16)))?;
        x += 250;
    }
    let max_depth = t.rows.iter().flat_map(|r| &r.bars).map(|b| b.depth).fold(0.0, f64::max);
    header.draw(&Rectangle::new([(x, 62), (x + 14, 68)], STATE_HIT.mix(0.85).filled()))?;
    header.draw(&Text::new(format!("deepest contact in the bar, row height = {:.1} mm", max_depth * 1e3), (x + 18, 56), text(16)))?;

    let span = t.last_seconds.max(1e-3);
    let n = t.rows.len().max(1) as i32;
    let label_width = t.rows.iter().map(|r| r.link.len() as u32 * 9 + 14).max().unwrap_or(40).min(360);
    let mut chart = ChartBuilder::on(&body)
        .margin_left(10)
        .margin_right(20)
        .margin_top(6)
        .x_label_area_size(40)
        .y_label_area_size(label_width)
        .build_cartesian_2d(0.0..span, (0..n).into_segmented())?;
    // The first link to collide on top.
    let names: Vec<&str> = t.rows.iter().rev().map(|r| r.link.as_str()).collect();
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(names.len().max(1))
        .y_label_formatter(&|v| match v {
            SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => names.get(*i as usize).map(|s| s.to_string()).unwrap_or_default(),
            SegmentValue::Last => String::new(),
        })
        .x_desc("seconds from the bag's first message")
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 16))
        .draw()?;

    let mut drawn = Vec::new();
    for (i, row) in t.rows.iter().enumerate() {
        let i = n - 1 - i as i32;
        // Row i spans Exact(i)..Exact(i + 1); backend y grows downwards.
        let top = chart.backend_coord(&(0.0, SegmentValue::Exact(i + 1))).1 + 3;
        let bottom = chart.backend_coord(&(0.0, SegmentValue::Exact(i))).1 - 3;
        let px = |s: f64| chart.backend_coord(&(s, SegmentValue::Exact(i))).0;
        // Bars closer than MERGE_PIXELS on screen are one bar.
        let mut bars = row.bars.clone();
        merge_bars(&mut bars, |a, b| px(b.start) - px(a.end).max(px(a.start) + MIN_BAR_PIXELS) < MERGE_PIXELS);
        for b in &bars {
            let x0 = px(b.start);
            let x1 = px(b.end).max(x0 + MIN_BAR_PIXELS);
            let color = if b.motion_only() { MOTION_ONLY } else { STATE_HIT };
            root.draw(&Rectangle::new([(x0, top), (x1, bottom)], color.mix(0.35).filled()))?;
            // The depth from the row's bottom on the shared scale, below the bar's top so the two
            // rectangles never coincide.
            if max_depth > 0.0 && b.depth > 0.0 {
                let h = ((bottom - top - 2) as f64 * b.depth / max_depth).round().max(1.0) as i32;
                root.draw(&Rectangle::new([(x0, bottom - h), (x1, bottom)], color.mix(0.85).filled()))?;
            }
            drawn.push(DrawnBar { rect: (x0, top, x1 - x0, bottom - top), title: tooltip(&row.link, b, &t.object_names(b)) });
        }
    }
    Ok(drawn)
}

/// The bar's tooltip: link, time span, report numbers, what it stands for and its objects. The
/// first line is the same for every bar, so a reader (or a test) can parse it.
fn tooltip(link: &str, b: &TimelineBar, objects: &[&str]) -> String {
    let kind = if b.motion_only() { "motion-only" } else { "in collision" };
    let merged = if b.runs > 1 { format!(", {} runs merged", b.runs) } else { String::new() };
    format!(
        "{link}: {:.3} s to {:.3} s, states {} to {}; {kind}, {} states colliding{merged}\ndeepest {:.1} mm; objects: {}",
        b.start,
        b.end,
        b.states.0,
        b.states.1,
        b.colliding,
        b.depth * 1e3,
        objects.join(", ")
    )
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Gives each bar's `<rect>` its tooltip. plotters' SVG backend has no way to emit `<title>`, so
/// the rectangles it wrote are found by their pixel box (unique per bar: bars of one row do not
/// overlap, rows do not either, and the depth rectangles are lower).
fn with_titles(svg: &str, bars: &[DrawnBar]) -> String {
    let titles: HashMap<(i32, i32, i32, i32), &str> = bars.iter().map(|b| (b.rect, b.title.as_str())).collect();
    let attr = |tag: &str, name: &str| -> Option<i32> {
        let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
        let end = start + tag[start..].find('"')?;
        tag[start..end].parse().ok()
    };
    let mut out = String::with_capacity(svg.len() + bars.len() * 120);
    let mut rest = svg;
    while let Some(at) = rest.find("<rect ") {
        let Some(len) = rest[at..].find("/>") else { break };
        let tag = &rest[at..at + len];
        out.push_str(&rest[..at]);
        match (attr(tag, "x"), attr(tag, "y"), attr(tag, "width"), attr(tag, "height")) {
            (Some(x), Some(y), Some(w), Some(h)) if titles.contains_key(&(x, y, w, h)) => {
                out.push_str(tag);
                out.push_str(&format!("><title>{}</title></rect>", xml_escape(titles[&(x, y, w, h)])));
            }
            _ => {
                out.push_str(tag);
                out.push_str("/>");
            }
        }
        rest = &rest[at + len + 2..];
    }
    out.push_str(rest);
    out
}
