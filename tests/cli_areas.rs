//! The `areas` command end to end: real files in, report and JSON out, clear errors with exit 2.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn tmp(name: &str) -> PathBuf {
    common::scratch_dir("cli_areas").join(name)
}

/// A binary STL whose 80-byte header starts with `solid`, the case mesh-loader rejects.
fn write_binary_stl(path: &Path, tris: &[[[f32; 3]; 3]]) {
    let mut b = Vec::new();
    let mut header = b"solid but binary".to_vec();
    header.resize(80, b' ');
    b.extend_from_slice(&header);
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for v in t {
            for c in v {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    std::fs::write(path, b).unwrap();
}

fn run_ok(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert!(out.status.success(), "{args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

fn run_err(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?} should exit 2");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim_end().lines().count(), 1, "one-line error expected, got {err:?}");
    err
}

#[test]
fn binary_stl_with_solid_header_gives_cells_in_file_order() {
    let stl = tmp("square.stl");
    // Triangle 0 is degenerate (dropped), triangles 1 and 2 form a unit square, 3 duplicates 1.
    let tris = [
        [[0., 0., 0.], [1., 0., 0.], [2., 0., 0.]],
        [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]],
        [[0., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        [[1., 0., 0.], [1., 1., 0.], [0., 0., 0.]],
    ];
    write_binary_stl(&stl, &tris);
    let json = tmp("square.json");
    let report = run_ok(&["areas", stl.to_str().unwrap(), "--thickness", "0.01", "--scale", "2", "--json", json.to_str().unwrap()]);
    assert!(report.contains("cells 2"), "{report}");
    assert!(report.contains("degenerate 1, duplicate 1"), "{report}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let cells = v["cells"].as_array().unwrap();
    let triangles: Vec<u64> = cells.iter().map(|c| c["triangle"].as_u64().unwrap()).collect();
    assert_eq!(triangles, vec![1, 2]);
    // Flat square, scaled by 2: right prisms 1 cm deep behind z = 0, corners at 0 and 2.
    for c in cells {
        let verts = c["vertices"].as_array().unwrap();
        assert_eq!(verts.len(), 6);
        for p in verts {
            let p: Vec<f64> = p.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            assert!(p[2] == 0.0 || (p[2] + 0.01).abs() < 1e-15, "{p:?}");
            assert!(p[0] == 0.0 || p[0] == 2.0);
        }
    }
}

#[test]
fn obj_side_both_and_front() {
    let obj = tmp("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    for (side, lo, hi) in [("front", 0.0, 0.02), ("both", -0.02, 0.02), ("back", -0.02, 0.0)] {
        let json = tmp(&format!("tri_{side}.json"));
        let _ = run_ok(&["areas", obj.to_str().unwrap(), "--thickness", "0.02", "--side", side, "--json", json.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let zs: Vec<f64> = v["cells"][0]["vertices"].as_array().unwrap().iter().map(|p| p[2].as_f64().unwrap()).collect();
        let (min, max) = zs.iter().fold((f64::MAX, f64::MIN), |(a, b), z| (a.min(*z), b.max(*z)));
        assert_eq!((min, max), (lo, hi), "side {side}");
    }
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let obj = tmp("ok.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let ok = obj.to_str().unwrap();
    assert!(run_err(&["areas", "/nonexistent/mesh.stl", "--thickness", "0.01"]).contains("/nonexistent/mesh.stl"));
    assert!(run_err(&["areas", ok, "--thickness", "0"]).contains("--thickness"));
    assert!(run_err(&["areas", ok, "--thickness", "-0.5"]).contains("--thickness"));
    assert!(run_err(&["areas", ok, "--thickness", "NaN"]).contains("--thickness"));
    assert!(run_err(&["areas", ok, "--thickness", "0.01", "--scale", "1,2"]).contains("--scale"));
    let garbage = tmp("garbage.stl");
    std::fs::write(&garbage, "not a mesh at all").unwrap();
    assert!(run_err(&["areas", garbage.to_str().unwrap(), "--thickness", "0.01"]).contains("garbage.stl"));
    let nan = tmp("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let err = run_err(&["areas", nan.to_str().unwrap(), "--thickness", "0.01"]);
    assert!(err.contains("nan.obj") && err.contains("non-finite"), "{err}");
    let empty = tmp("empty.obj");
    std::fs::write(&empty, "# nothing\n").unwrap();
    assert!(run_err(&["areas", empty.to_str().unwrap(), "--thickness", "0.01"]).contains("no triangles"));
    let flat = tmp("flat.obj");
    std::fs::write(&flat, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    assert!(run_err(&["areas", flat.to_str().unwrap(), "--thickness", "0.01"]).contains("degenerate"));
    let txt = tmp("mesh.txt");
    std::fs::write(&txt, "x").unwrap();
    assert!(run_err(&["areas", txt.to_str().unwrap(), "--thickness", "0.01"]).contains("unsupported"));
}

/// `areas ... | head`: standard output closed before the report is written. The read end is
/// closed before the command starts, so every write fails, whatever the timing.
#[test]
fn closed_standard_output_ends_without_a_panic() {
    let obj = tmp("pipe.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let json = tmp("pipe.json");
    for extra in [&[][..], &["--json", json.to_str().unwrap()][..]] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = bin()
            .args(["areas", obj.to_str().unwrap(), "--thickness", "0.01"])
            .args(extra)
            .stdout(writer)
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(101), "{extra:?}: {err}");
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
        assert_eq!(out.status.code(), Some(2), "{extra:?}: a report nobody could read is not a success: {err}");
        assert!(err.contains("standard output") && err.trim_end().lines().count() == 1, "{extra:?}: {err}");
    }
}
