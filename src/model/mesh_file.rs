//! Reading STL, OBJ and COLLADA meshes with `mesh-loader`.
//!
//! mesh-loader rejects a binary STL whose 80-byte header starts with `solid` (it takes it for
//! ASCII); such files are recognised by their size, `84 + 50 n` bytes for `n` triangles, and
//! parsed here.

use crate::math::{Real, Vector};
use std::path::{Path, PathBuf};

/// A mesh read from a file: vertices (metres, after scaling) and triangles in file order.
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    /// Vertices.
    pub vertices: Vec<Vector>,
    /// Triangles, in the file's order (submeshes concatenated in file order).
    pub triangles: Vec<[u32; 3]>,
}

/// A mesh file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshFileError {
    /// The file cannot be read.
    #[error("cannot read mesh file {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a mesh mesh-loader understands.
    #[error("cannot parse mesh file {path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        message: String,
    },
    /// The extension is not stl, obj or dae.
    #[error("unsupported mesh format for {path} (expected .stl, .obj or .dae)")]
    Format {
        /// The file.
        path: PathBuf,
    },
    /// The file has no triangles.
    #[error("mesh file {path} has no triangles")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A vertex is NaN or infinite.
    #[error("mesh file {path}: vertex {index} has a non-finite coordinate")]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// Index of the vertex.
        index: usize,
    },
}

/// Reads a mesh file and multiplies its coordinates by `scale` (per axis). A scale with an odd
/// number of negative factors mirrors the mesh; the winding is then reversed to keep the normals
/// pointing out of the same side.
pub fn read_mesh(path: &Path, scale: Vector) -> Result<MeshData, MeshFileError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if !matches!(ext.as_str(), "stl" | "obj" | "dae") {
        return Err(MeshFileError::Format { path: path.to_owned() });
    }
    let bytes = std::fs::read(path).map_err(|source| MeshFileError::Io { path: path.to_owned(), source })?;
    let mut data = if ext == "stl" && is_binary_stl(&bytes) {
        read_binary_stl(&bytes)
    } else {
        let loader = mesh_loader::Loader::default();
        let scene = loader.load_from_slice(&bytes, path).map_err(|e| MeshFileError::Parse { path: path.to_owned(), message: e.to_string() })?;
        let mut data = MeshData::default();
        for mesh in &scene.meshes {
            let base = data.vertices.len() as u32;
            data.vertices.extend(mesh.vertices.iter().map(|v| Vector::new(v[0] as Real, v[1] as Real, v[2] as Real)));
            data.triangles.extend(mesh.faces.iter().map(|f| f.map(|i| i + base)));
        }
        data
    };
    if data.triangles.is_empty() {
        return Err(MeshFileError::Empty { path: path.to_owned() });
    }
    if let Some(index) = data.vertices.iter().position(|v| !v.is_finite()) {
        return Err(MeshFileError::NonFinite { path: path.to_owned(), index });
    }
    for v in &mut data.vertices {
        *v *= scale;
    }
    if scale.x * scale.y * scale.z < 0.0 {
        for t in &mut data.triangles {
            t.swap(1, 2);
        }
    }
    Ok(data)
}

/// A binary STL: at least the 84-byte header and exactly 50 bytes per declared triangle.
fn is_binary_stl(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    bytes.len() == 84 + 50 * n
}

fn read_binary_stl(bytes: &[u8]) -> MeshData {
    let n = (bytes.len() - 84) / 50;
    let mut data = MeshData { vertices: Vec::with_capacity(3 * n), triangles: Vec::with_capacity(n) };
    for k in 0..n {
        let rec = &bytes[84 + 50 * k..84 + 50 * (k + 1)];
        let f = |o: usize| f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as Real;
        let base = data.vertices.len() as u32;
        for c in 0..3 {
            let o = 12 + 12 * c;
            data.vertices.push(Vector::new(f(o), f(o + 4), f(o + 8)));
        }
        data.triangles.push([base, base + 1, base + 2]);
    }
    data
}

/// Writes a mesh as Wavefront OBJ (vertices in metres, faces 1-based, counter-clockwise fronts).
pub fn write_obj(path: &Path, vertices: &[Vector], triangles: &[[u32; 3]], comment: &str) -> std::io::Result<()> {
    use std::io::Write;
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    for line in comment.lines() {
        writeln!(w, "# {line}")?;
    }
    for v in vertices {
        writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
    }
    for t in triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}
