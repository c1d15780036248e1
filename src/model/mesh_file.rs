//! Reading STL, OBJ and COLLADA meshes with `mesh-loader`.
//!
//! mesh-loader rejects a binary STL whose 80-byte header starts with `solid` (it takes it for
//! ASCII); such files are recognised by their size, `84 + 50 n` bytes for `n` triangles, and
//! parsed here.

use super::collada_guard::check_collada;
use super::xml_guard::check_xml;
use crate::limits::{contain_panic, is_coordinate, read_regular, InputFileError, LENGTH_RANGE, MAX_COORDINATE, MAX_MESH_BYTES, MAX_MESH_TRIANGLES};
use crate::math::{Real, Vector};
use std::path::{Path, PathBuf};

/// A mesh read from a file: vertices (metres, after scaling) and triangles in file order.
#[derive(Clone, Debug, Default, PartialEq)]
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
    /// The file cannot be read (missing, not a regular file, too large).
    #[error("{0}")]
    Input(Box<InputFileError>),
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
///
/// Only a regular file of at most 1 GiB (`limits::MAX_MESH_BYTES`) is read.
pub fn read_mesh(path: &Path, scale: Vector) -> Result<MeshData, MeshFileError> {
    let _ = format_of(path)?;
    let bytes = read_regular(path, "mesh file", MAX_MESH_BYTES).map_err(|e| MeshFileError::Input(Box::new(e)))?;
    parse_mesh(&bytes, path, scale)
}

fn format_of(path: &Path) -> Result<&'static str, MeshFileError> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("stl") => Ok("stl"),
        Some("obj") => Ok("obj"),
        Some("dae") => Ok("dae"),
        _ => Err(MeshFileError::Format { path: path.to_owned() }),
    }
}

/// [`read_mesh`] on bytes already read; the extension of `path` picks the format and `path`
/// names the mesh in errors.
///
/// mesh-loader panics or aborts on some malformed COLLADA and OBJ; the guards before it refuse
/// what is known to do that (`xml_guard::check_xml`, `collada_guard::check_collada`), and a panic that still happens is
/// contained and reported as a parse error, so no mesh can take the process down.
pub fn parse_mesh(bytes: &[u8], path: &Path, scale: Vector) -> Result<MeshData, MeshFileError> {
    let parse = |message: String| MeshFileError::Parse { path: path.to_owned(), message };
    let format = format_of(path)?;
    let data = match format {
        "stl" if is_binary_stl(bytes) => read_binary_stl(bytes).map_err(parse)?,
        _ => {
            if format == "dae" {
                check_xml(bytes).map_err(|e| parse(e.to_string()))?;
                check_collada(bytes).map_err(parse)?;
            }
            let normalised;
            let bytes = if format == "obj" {
                // Counted before mesh-loader allocates them.
                let triangles: usize = bytes
                    .split(|&b| b == b'\n')
                    .filter(|l| l.starts_with(b"f ") || l.starts_with(b"f\t"))
                    .map(|l| l.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty()).count().saturating_sub(3))
                    .sum();
                if triangles > MAX_MESH_TRIANGLES {
                    return Err(parse(format!("{triangles} triangles, more than the {MAX_MESH_TRIANGLES} allowed")));
                }
                normalised = obj_positions_only(bytes).map_err(parse)?;
                normalised.as_deref().unwrap_or(bytes)
            } else {
                bytes
            };
            // Materials do not matter to collision: an OBJ's `mtllib` is never opened (it could
            // name a FIFO or a device).
            let no_materials = |_: &Path| -> std::io::Result<Vec<u8>> { Err(std::io::Error::other("material files are not read")) };
            let loader = mesh_loader::Loader::default();
            let scene = contain_panic(|| loader.load_from_slice_with_reader(bytes, path, no_materials))
                .map_err(|panic| parse(format!("the mesh-loader crate failed on this file ({panic})")))?
                .map_err(|e| parse(crate::limits::first_line(&e.to_string())))?;
            let mut data = MeshData::default();
            for mesh in &scene.meshes {
                let base = data.vertices.len();
                if let Some(f) = mesh.faces.iter().find(|f| f.iter().any(|&i| i as usize >= mesh.vertices.len())) {
                    return Err(parse(format!("a face {f:?} indexes past the {} vertices of its mesh", mesh.vertices.len())));
                }
                if base + mesh.vertices.len() > u32::MAX as usize || data.triangles.len() + mesh.faces.len() > MAX_MESH_TRIANGLES {
                    return Err(parse(format!("more than {MAX_MESH_TRIANGLES} triangles")));
                }
                data.vertices.extend(mesh.vertices.iter().map(|v| Vector::new(v[0] as Real, v[1] as Real, v[2] as Real)));
                data.triangles.extend(mesh.faces.iter().map(|f| f.map(|i| i + base as u32)));
            }
            data
        }
    };
    if data.triangles.is_empty() {
        return Err(MeshFileError::Empty { path: path.to_owned() });
    }
    if let Some(index) = data.vertices.iter().position(|v| !v.is_finite()) {
        return Err(MeshFileError::NonFinite { path: path.to_owned(), index });
    }
    if scale == Vector::ONE {
        return scale_checked(data, path);
    }
    scale_mesh(&data, scale, path)
}

/// An OBJ whose faces reference positions only, or `None` when it already does; every face index
/// checked first, naming its line.
///
/// Collision needs positions only, and mesh-loader refuses a file whose faces mix `v/vt/vn` with
/// plain `v` (pybullet's `table_square/table.obj`): it reads texture coordinates for some corners
/// and not others and reports "a position past the end of the file". It also turns an index 0 or
/// one counting back past the first vertex into 4294967295 and the like. So each `f` line keeps
/// the position of each corner (`7/3/2` -> `7`), and an index that is 0 or out of range is
/// refused here with the index as written.
fn obj_positions_only(bytes: &[u8]) -> Result<Option<Vec<u8>>, String> {
    let is_space = |b: &u8| *b == b' ' || *b == b'\t';
    let keyword = |line: &[u8], k: &[u8]| line.starts_with(k) && line.get(k.len()).is_some_and(is_space);
    let lines = || bytes.split(|&b| b == b'\n').map(|l| l.strip_suffix(b"\r").unwrap_or(l));
    // Positive indices may name a vertex defined further down (mesh-loader resolves them at the
    // end of the group); negative ones count back from the vertices defined so far (OBJ spec).
    let total = lines().filter(|l| keyword(l.trim_ascii_start(), b"v")).count();
    let mut defined = 0usize;
    let mut rewrite = false;
    for (n, line) in lines().enumerate() {
        let line = line.trim_ascii_start();
        if keyword(line, b"v") {
            defined += 1;
        } else if keyword(line, b"f") {
            for corner in line[1..].split(is_space).filter(|w| !w.is_empty()) {
                let position = corner.split(|&b| b == b'/').next().unwrap_or_default();
                rewrite |= position.len() != corner.len();
                let text = String::from_utf8_lossy(position);
                let at = |what: String| format!("line {}: face index {text}: {what}", n + 1);
                let index: i64 =
                    text.parse().map_err(|_| format!("line {}: face corner '{}' has no integer vertex index", n + 1, String::from_utf8_lossy(corner)))?;
                if index == 0 {
                    return Err(at("OBJ indices start at 1 (negative ones count back from the last vertex defined)".into()));
                }
                if index > 0 && index as u64 > total as u64 {
                    return Err(at(format!("past the {total} vertices of the file (OBJ indices start at 1)")));
                }
                if index < 0 && index.unsigned_abs() > defined as u64 {
                    return Err(at(format!("counts back past the first vertex: {defined} are defined before this line (-1 is the last)")));
                }
            }
        }
    }
    if !rewrite {
        return Ok(None);
    }
    let mut out = Vec::with_capacity(bytes.len());
    for line in bytes.split_inclusive(|&b| b == b'\n') {
        let start = line.len() - line.trim_ascii_start().len();
        if !keyword(&line[start..], b"f") {
            out.extend_from_slice(line);
            continue;
        }
        out.extend_from_slice(b"f");
        let body = line[start + 1..].trim_ascii_end();
        for corner in body.split(is_space).filter(|w| !w.is_empty()) {
            out.push(b' ');
            out.extend_from_slice(corner.split(|&b| b == b'/').next().unwrap_or_default());
        }
        out.push(b'\n');
    }
    Ok(Some(out))
}

/// `data` scaled per axis (the winding reversed for a mirroring scale), with every vertex within
/// [`MAX_COORDINATE`] and the mesh at least [`LENGTH_RANGE`]`[0]` across.
pub(crate) fn scale_mesh(data: &MeshData, scale: Vector, path: &Path) -> Result<MeshData, MeshFileError> {
    if let Some(s) = scale.to_array().into_iter().find(|s| !(s.is_finite() && *s != 0.0)) {
        return Err(MeshFileError::Parse { path: path.to_owned(), message: format!("scale {s} is not a finite, non-zero number") });
    }
    let mut out = MeshData { vertices: data.vertices.iter().map(|v| *v * scale).collect(), triangles: data.triangles.clone() };
    if scale.x * scale.y * scale.z < 0.0 {
        for t in &mut out.triangles {
            t.swap(1, 2);
        }
    }
    scale_checked(out, path)
}

fn scale_checked(data: MeshData, path: &Path) -> Result<MeshData, MeshFileError> {
    let parse = |message: String| MeshFileError::Parse { path: path.to_owned(), message };
    if let Some(index) = data.vertices.iter().position(|v| !v.to_array().into_iter().all(is_coordinate)) {
        let v = data.vertices[index];
        return Err(parse(format!(
            "vertex {index} is at [{:e}, {:e}, {:e}] m after scaling; coordinates are allowed up to {MAX_COORDINATE:e} m",
            v.x, v.y, v.z
        )));
    }
    let (lo, hi) = data.vertices.iter().fold((Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY)), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    let across = (hi - lo).max_element();
    if !(across >= LENGTH_RANGE[0]) {
        return Err(parse(format!("the mesh is {across:e} m across after scaling; the smallest size allowed is {:e} m", LENGTH_RANGE[0])));
    }
    Ok(data)
}

/// A binary STL: at least the 84-byte header, and either a header that does not start with
/// `solid` or exactly 50 bytes per declared triangle (binary files from some exporters start
/// with `solid` too).
fn is_binary_stl(bytes: &[u8]) -> bool {
    let Some(count) = bytes.get(80..84) else {
        return false;
    };
    let n = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as u64;
    !bytes.trim_ascii_start().starts_with(b"solid") || bytes.len() as u64 == 84 + 50 * n
}

fn read_binary_stl(bytes: &[u8]) -> Result<MeshData, String> {
    let (header, records) = bytes.split_at(84);
    let declared = u32::from_le_bytes([header[80], header[81], header[82], header[83]]) as u64;
    if records.len() as u64 != 50 * declared {
        return Err(format!("binary STL declares {declared} triangles ({} bytes) but has {} bytes after its header", 50 * declared, records.len()));
    }
    if declared as usize > MAX_MESH_TRIANGLES {
        return Err(format!("{declared} triangles, more than the {MAX_MESH_TRIANGLES} allowed"));
    }
    let n = declared as usize;
    let mut data = MeshData { vertices: Vec::with_capacity(3 * n), triangles: Vec::with_capacity(n) };
    for rec in records.chunks_exact(50) {
        let f = |o: usize| f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as Real;
        let base = data.vertices.len() as u32;
        for c in 0..3 {
            let o = 12 + 12 * c;
            data.vertices.push(Vector::new(f(o), f(o + 4), f(o + 8)));
        }
        data.triangles.push([base, base + 1, base + 2]);
    }
    Ok(data)
}

/// Writes a mesh as Wavefront OBJ (vertices in metres, faces 1-based, counter-clockwise fronts):
/// how the tests write the generated example meshes and their fixtures (feature `testing`).
#[cfg(feature = "testing")]
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tc_mesh_file_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn corners(data: &MeshData) -> Vec<[[Real; 3]; 3]> {
        data.triangles.iter().map(|t| t.map(|i| data.vertices[i as usize].to_array())).collect()
    }

    #[test]
    fn obj_with_mixed_faces_loads_every_corner() {
        // Faces with and without texture coordinates and normals, as pybullet's
        // table_square/table.obj has, a negative index and a quad.
        let path = scratch("mixed.obj");
        let text = "# mixed faces\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n\
                    f 1/1/1 2/2/1 3/3/1\nf 1 3 4\nf -1 1//1 2/2\r\nf 2/1 3/2 5/3 4";
        std::fs::write(&path, text).unwrap();
        let data = read_mesh(&path, Vector::ONE).unwrap();
        let (a, b, c, d, e) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        // What the file says, corner by corner: f 1 2 3; f 1 3 4; f 5 1 2 (-1 is the fifth);
        // the quad 2 3 5 4 as the fan (2 3 5), (2 5 4).
        assert_eq!(corners(&data), vec![[a, b, c], [a, c, d], [e, a, b], [b, c, e], [b, e, d]]);
    }

    #[test]
    fn obj_face_index_errors_name_the_index_and_line() {
        let refused = |name: &str, faces: &str| -> String {
            let path = scratch(name);
            std::fs::write(&path, format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{faces}")).unwrap();
            let e = read_mesh(&path, Vector::ONE).unwrap_err().to_string();
            assert!(e.contains(name) && !e.contains("4294967") && !e.contains('\n'), "{e}");
            e
        };
        let e = refused("zero.obj", "f 1 2 3\nf 0 1 2\n");
        assert!(e.contains("line 5: face index 0: OBJ indices start at 1 (negative ones count back"), "{e}");
        let e = refused("minus100.obj", "f -100/1 1 2\n");
        assert!(e.contains("line 4: face index -100: counts back past the first vertex: 3 are defined before this line"), "{e}");
        let e = refused("past.obj", "f 1 2 4\n");
        assert!(e.contains("line 4: face index 4: past the 3 vertices of the file"), "{e}");
        let e = refused("word.obj", "f 1 x/1 2\n");
        assert!(e.contains("line 4: face corner 'x/1' has no integer vertex index"), "{e}");
    }
}
