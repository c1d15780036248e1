//! Scaffolding every kind of test uses: a scratch folder per test file (and one per test inside
//! it), raw little-endian arrays for the Python peers, a thickness area straight from a
//! triangle soup, and the Python package built into the peers' venv. The benches include this
//! file too (`#[path]`).

use std::path::{Path, PathBuf};
use thickness_collision::math::{Real, Vector};
use thickness_collision::mesh::{MeshTopology, TopologySettings};
use thickness_collision::thickness::{ThicknessArea, ThicknessSettings};

/// `<temp>/tc_<name>_<pid>`, created: the scratch folder of one test binary (the process id keeps
/// two runs at a time apart; `name` keeps the test files apart).
pub fn scratch_dir(name: &str) -> PathBuf {
    created(std::env::temp_dir().join(format!("tc_{name}_{}", std::process::id())))
}

/// `<scratch_dir(file)>/<name>`, created: one test's own folder, so that the tests of one file,
/// which run in parallel threads, do not share files.
pub fn scratch_subdir(file: &str, name: &str) -> PathBuf {
    created(scratch_dir(file).join(name))
}

/// `dir` removed with everything in it and created again, empty: for a test that reads back what
/// it wrote there (a bag, a report file) and must not find files a test run with the same process
/// id left.
pub fn emptied(dir: PathBuf) -> PathBuf {
    if let Err(e) = std::fs::remove_dir_all(&dir) {
        assert!(e.kind() == std::io::ErrorKind::NotFound, "cannot empty {}: {e}", dir.display());
    }
    created(dir)
}

fn created(dir: PathBuf) -> PathBuf {
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    dir
}

/// A value written as its little-endian bytes, as the peers' `numpy.fromfile` reads them.
pub trait LeBytes {
    /// Appends the bytes of `self`.
    fn put_le(&self, out: &mut Vec<u8>);
}

impl LeBytes for f64 {
    fn put_le(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl LeBytes for f32 {
    fn put_le(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl LeBytes for u32 {
    fn put_le(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl<T: LeBytes, const N: usize> LeBytes for [T; N] {
    fn put_le(&self, out: &mut Vec<u8>) {
        for v in self {
            v.put_le(out);
        }
    }
}

/// Writes `data` as a plain little-endian array (no header, no padding).
pub fn write_le<T: LeBytes>(path: &Path, data: &[T]) {
    let mut bytes = Vec::with_capacity(std::mem::size_of_val(data));
    for v in data {
        v.put_le(&mut bytes);
    }
    std::fs::write(path, bytes).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
}

/// The topology of a triangle soup with the default settings; panics if it does not build.
pub fn topology(vertices: &[Vector], triangles: &[[u32; 3]]) -> MeshTopology {
    MeshTopology::build(vertices, triangles, &TopologySettings::default()).expect("the mesh builds")
}

/// The thickness area of a topology; panics if it does not build. For a test that also reads the
/// topology, or builds several areas on one.
pub fn topology_area(topology: &MeshTopology, settings: &ThicknessSettings) -> ThicknessArea {
    ThicknessArea::build(topology, settings).expect("the cells build")
}

/// The thickness area of a triangle soup (default topology settings); panics if it does not build.
pub fn mesh_area(vertices: &[Vector], triangles: &[[u32; 3]], settings: &ThicknessSettings) -> ThicknessArea {
    topology_area(&topology(vertices, triangles), settings)
}

/// [`mesh_area`] with only the thickness set (metres).
pub fn thin_area(vertices: &[Vector], triangles: &[[u32; 3]], thickness: Real) -> ThicknessArea {
    mesh_area(vertices, triangles, &ThicknessSettings { thickness, ..Default::default() })
}

/// Builds the Python package (`python/`) into the venv of `python` (`<venv>/bin/python`) with
/// `maturin develop --release`, as an installed wheel would be, in a target directory of its own:
/// a test runs while `cargo test` holds `target/`'s lock.
pub fn develop_python_package(python: &Path) {
    let venv = python.parent().and_then(|bin| bin.parent()).expect("TC_PYTHON is <venv>/bin/python");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let status = std::process::Command::new(python)
        .args(["-m", "maturin", "develop", "--release", "--manifest-path"])
        .arg(root.join("python/Cargo.toml"))
        .env("VIRTUAL_ENV", venv)
        .env("CARGO_TARGET_DIR", root.join("target").join("python"))
        .status()
        .expect("maturin (scripts/setup_venv.sh installs it)");
    assert!(status.success(), "maturin develop failed");
}
