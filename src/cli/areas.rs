//! `areas`: the cells of one mesh file.

use anyhow::{bail, Context, Result};
use std::io::Write;
use std::path::PathBuf;
use thickness_collision::math::Vector;
use thickness_collision::mesh::{MeshTopology, TopologySettings};
use thickness_collision::model::read_mesh;
use thickness_collision::thickness::{Side, ThicknessArea, ThicknessReport, ThicknessSettings};

fn parse_scale(s: &str) -> Result<Vector> {
    let parts: Vec<f64> = s.split(',').map(|p| p.trim().parse::<f64>().with_context(|| format!("--scale: '{p}' is not a number"))).collect::<Result<_>>()?;
    let v = match parts[..] {
        [k] => Vector::splat(k),
        [x, y, z] => Vector::new(x, y, z),
        _ => bail!("--scale takes one factor or three (sx,sy,sz), got '{s}'"),
    };
    if !v.is_finite() || v.to_array().contains(&0.0) {
        bail!("--scale must be finite and non-zero, got '{s}'");
    }
    Ok(v)
}

pub fn areas(path: PathBuf, thickness: f64, side: Side, scale: &str, json: Option<PathBuf>) -> Result<()> {
    if !thickness_collision::limits::is_length(thickness) {
        let [lo, hi] = thickness_collision::limits::LENGTH_RANGE;
        bail!("--thickness {}: must be from {lo:e} to {hi:e} m", thickness_collision::limits::show_number(thickness));
    }
    let scale = parse_scale(scale)?;
    let data = read_mesh(&path, scale)?;
    let started = std::time::Instant::now();
    let mesh = MeshTopology::build(&data.vertices, &data.triangles, &TopologySettings::default()).with_context(|| format!("mesh file {}", path.display()))?;
    let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness, side, ..Default::default() })?;
    let elapsed = started.elapsed();
    // Written, not printed: println! panics when standard output is closed (`areas ... | head`);
    // a write error ends the command with its message, as check's does.
    let mut stdout = std::io::stdout().lock();
    write_report(&mut stdout, &path, &area.report, thickness, side, elapsed).context("standard output")?;
    if let Some(out) = json {
        write_cells_json(&out, &area).with_context(|| format!("cannot write {}", out.display()))?;
        writeln!(stdout, "cells written to {}", out.display()).context("standard output")?;
    }
    stdout.flush().context("standard output")?;
    Ok(())
}

fn write_report(w: &mut impl Write, path: &std::path::Path, r: &ThicknessReport, t: f64, side: Side, elapsed: std::time::Duration) -> std::io::Result<()> {
    let topo = &r.topology;
    writeln!(w, "{}: {} triangles, {} vertices ({} after welding)", path.display(), topo.input_triangles, topo.input_vertices, topo.vertices)?;
    writeln!(w, "  thickness {t} m, side {}, built in {:.3} ms", side.as_str(), elapsed.as_secs_f64() * 1e3)?;
    writeln!(w, "  cells {}: tetrahedra {}, ratioed {}, prisms {}, diverging {}", r.cells, r.tetrahedra, r.ratioed, r.prisms, r.diverging)?;
    writeln!(w, "  skipped: degenerate {}, duplicate {}", r.degenerate_skipped, topo.duplicate_triangles)?;
    writeln!(
        w,
        "  edges: shared {}, boundary {}, non-manifold {}, inconsistent {}, folded {}",
        topo.shared_edges, r.boundary_edges, r.non_manifold_edges, r.inconsistent_edges, r.folded_edges
    )?;
    writeln!(w, "  orientation: {} faces flipped; components closed {}, open {}", r.flipped_faces, topo.closed_components, topo.open_components)
}

fn write_cells_json(out: &std::path::Path, area: &ThicknessArea) -> Result<()> {
    let file = std::fs::File::create(out)?;
    let mut w = std::io::BufWriter::new(file);
    w.write_all(b"{\"cells\": [")?;
    for (i, cell) in area.cells.iter().enumerate() {
        if i > 0 {
            w.write_all(b",")?;
        }
        let vertices: Vec<[f64; 3]> = cell.distinct_vertices().iter().map(|v| v.to_array()).collect();
        let entry = serde_json::json!({ "triangle": cell.triangle, "kind": cell.kind, "vertices": vertices });
        serde_json::to_writer(&mut w, &entry)?;
    }
    w.write_all(b"]}\n")?;
    w.flush()?;
    Ok(())
}
