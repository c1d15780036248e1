//! The geometry core without a robot: thickness areas from NumPy arrays, and a `Scene` of thin
//! surfaces and solids that convex shapes are checked against (trimesh `CollisionManager`'s
//! habits: `add_object`, `set_transform`, `remove_object`, `in_collision_single`).

use crate::errors::value_error;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::BTreeSet;
use std::sync::Arc;
use thickness_collision::collision::{CollideSettings, ConvexHull, Scene as Core, Target, TargetShape};
use thickness_collision::math::{pose_from_isometry, Pose, Vector};
use thickness_collision::mesh::{MeshTopology, TopologySettings};
use thickness_collision::thickness::{Side, ThicknessArea, ThicknessSettings};

/// Vertices (`N x 3`, finite) and faces (`M x 3`, indices below N) of a mesh: arrays, or an
/// object with `.vertices` and `.faces` (a `trimesh.Trimesh`).
fn mesh_arrays(vertices: &Bound<'_, PyAny>, faces: Option<&Bound<'_, PyAny>>) -> PyResult<(Vec<Vector>, Vec<[u32; 3]>)> {
    let (v, f) = match faces {
        Some(f) => (vertices.clone(), Some(f.clone())),
        None if vertices.hasattr("faces")? => (vertices.getattr("vertices")?, Some(vertices.getattr("faces")?)),
        None => (vertices.clone(), None),
    };
    let points = points(&v, "vertices")?;
    let Some(f) = f else { return Ok((points, Vec::new())) };
    let faces: Vec<Vec<i64>> = f.extract().map_err(|_| value_error("faces: an M x 3 array of vertex indices"))?;
    let mut out = Vec::with_capacity(faces.len());
    for (i, face) in faces.iter().enumerate() {
        let ok = face.len() == 3 && face.iter().all(|&k| k >= 0 && (k as usize) < points.len());
        if !ok {
            return Err(value_error(format!("faces[{i}] is {face:?}: three indices below {} (the vertex count)", points.len())));
        }
        out.push([face[0] as u32, face[1] as u32, face[2] as u32]);
    }
    Ok((points, out))
}

/// `N x 3` finite points.
fn points(v: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vector>> {
    let rows: Vec<Vec<f64>> = match v.extract::<PyReadonlyArray2<'_, f64>>() {
        Ok(a) => a.as_array().rows().into_iter().map(|r| r.to_vec()).collect(),
        Err(_) => v.extract().map_err(|_| value_error(format!("{what}: an N x 3 array of numbers")))?,
    };
    rows.iter()
        .enumerate()
        .map(|(i, r)| match r.as_slice() {
            [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vector::new(*x, *y, *z)),
            _ => Err(value_error(format!("{what}[{i}] is {r:?}: three finite numbers"))),
        })
        .collect()
}

fn side(s: &str) -> PyResult<Side> {
    s.parse().map_err(value_error)
}

/// The cells behind a mesh's triangles.
fn build_area(v: &[Vector], f: &[[u32; 3]], thickness: f64, side: Side) -> PyResult<ThicknessArea> {
    if !thickness_collision::limits::is_length(thickness) {
        let [lo, hi] = thickness_collision::limits::LENGTH_RANGE;
        return Err(value_error(format!("thickness {thickness}: must be from {lo:e} to {hi:e} m")));
    }
    let mesh = MeshTopology::build(v, f, &TopologySettings::default()).map_err(value_error)?;
    ThicknessArea::build(&mesh, &ThicknessSettings { thickness, side, ..Default::default() }).map_err(value_error)
}

/// A pose from a 4 x 4 homogeneous matrix (`None`: the identity); the rotation must be
/// orthonormal.
fn pose(transform: Option<&Bound<'_, PyAny>>) -> PyResult<Pose> {
    let Some(t) = transform else { return Ok(Pose::IDENTITY) };
    let m: Vec<Vec<f64>> = t.extract().map_err(|_| value_error("transform: a 4 x 4 matrix"))?;
    if m.len() != 4 || m.iter().any(|r| r.len() != 4 || r.iter().any(|x| !x.is_finite())) {
        return Err(value_error("transform: a 4 x 4 matrix of finite numbers"));
    }
    let r = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    if (r.transpose() * r - nalgebra::Matrix3::identity()).abs().max() > 1e-6 || r.determinant() < 0.0 {
        return Err(value_error("transform: its upper 3 x 3 block is not a rotation"));
    }
    let rotation = nalgebra::UnitQuaternion::from_matrix(&r);
    let iso = nalgebra::Isometry3::from_parts(nalgebra::Translation3::new(m[0][3], m[1][3], m[2][3]), rotation);
    Ok(pose_from_isometry(&iso))
}

/// A pose as a 4 x 4 homogeneous matrix.
pub fn matrix(p: &Pose) -> Array2<f64> {
    let q = p.rotation;
    let (x, y, z, w) = (q.x, q.y, q.z, q.w);
    #[rustfmt::skip]
    let r = [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
    ];
    let t = [p.translation.x, p.translation.y, p.translation.z];
    Array2::from_shape_fn((4, 4), |(i, j)| match (i, j) {
        (3, 3) => 1.0,
        (3, _) => 0.0,
        (i, 3) => t[i],
        (i, j) => r[i][j],
    })
}

/// The cells behind every triangle of a mesh: a dict of arrays, `back_cap` and `front_cap`
/// (`N x 3 x 3`, each cap's three corners), `normal` (`N x 3`), `triangle` (`N`, the input
/// triangle each cell stands behind).
#[pyfunction]
#[pyo3(signature = (vertices, faces, thickness=0.02, side="back"))]
pub fn areas<'py>(py: Python<'py>, vertices: &Bound<'py, PyAny>, faces: &Bound<'py, PyAny>, thickness: f64, side: &str) -> PyResult<Bound<'py, PyDict>> {
    let (v, f) = mesh_arrays(vertices, Some(faces))?;
    let area = build_area(&v, &f, thickness, self::side(side)?)?;
    let n = area.cells.len();
    let caps =
        |pick: fn(&thickness_collision::thickness::ThicknessCell) -> [Vector; 3]| Array3::from_shape_fn((n, 3, 3), |(i, k, d)| pick(&area.cells[i])[k][d]);
    let out = PyDict::new(py);
    out.set_item("back_cap", caps(|c| c.back_cap).into_pyarray(py))?;
    out.set_item("front_cap", caps(|c| c.front_cap).into_pyarray(py))?;
    out.set_item("normal", Array2::from_shape_fn((n, 3), |(i, d)| area.cells[i].normal[d]).into_pyarray(py))?;
    out.set_item("triangle", Array1::from_iter(area.cells.iter().map(|c| c.triangle)).into_pyarray(py))?;
    Ok(out)
}

/// Thin surfaces (cells behind their triangles) and convex solids, by name.
#[pyclass(module = "thickness_collision")]
pub struct Scene {
    core: Core,
}

impl Scene {
    fn index(&self, name: &str) -> Option<usize> {
        self.core.objects().iter().position(|o| o.name == name)
    }
}

#[pymethods]
impl Scene {
    #[new]
    fn new() -> Scene {
        Scene { core: Core::new() }
    }

    /// Adds `mesh` (a `trimesh.Trimesh`, or vertices with `faces`) as `name` at `transform`: a thin
    /// surface with cells of `thickness` on `side`, or with `thin=False` a solid, the convex hull
    /// of its vertices. A name already in the scene is replaced.
    #[pyo3(signature = (name, mesh, faces=None, transform=None, thin=true, thickness=0.02, side="back"))]
    #[allow(clippy::too_many_arguments)]
    fn add_object(
        &mut self,
        name: &str,
        mesh: &Bound<'_, PyAny>,
        faces: Option<&Bound<'_, PyAny>>,
        transform: Option<&Bound<'_, PyAny>>,
        thin: bool,
        thickness: f64,
        side: &str,
    ) -> PyResult<()> {
        let (v, f) = mesh_arrays(mesh, faces)?;
        let at = pose(transform)?;
        let side = self::side(side)?;
        if let Some(i) = self.index(name) {
            let _ = self.core.remove(i);
        }
        if thin {
            let area = build_area(&v, &f, thickness, side)?;
            let _ = self.core.add_surface(name, at, area);
        } else {
            let hull = ConvexHull::from_points(&v).ok_or_else(|| value_error(format!("{name}: its vertices span no volume (a solid needs a convex hull)")))?;
            let _ = self.core.add_solid(name, at, TargetShape::Polytope(Arc::new(hull)));
        }
        Ok(())
    }

    /// Moves object `name` (its cells are kept, not rebuilt).
    fn set_transform(&mut self, name: &str, transform: &Bound<'_, PyAny>) -> PyResult<()> {
        let at = pose(Some(transform))?;
        let i = self.index(name).ok_or_else(|| value_error(format!("no object named '{name}'")))?;
        let _ = self.core.set_pose(i, at);
        Ok(())
    }

    /// Removes object `name`.
    fn remove_object(&mut self, name: &str) -> PyResult<()> {
        let i = self.index(name).ok_or_else(|| value_error(format!("no object named '{name}'")))?;
        let _ = self.core.remove(i);
        Ok(())
    }

    /// The objects' names, in the order they were added.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.core.objects().iter().map(|o| o.name.clone()).collect()
    }

    /// Whether the convex hull of `shape` (points `N x 3`, or a `trimesh.Trimesh`) at
    /// `transform` meets any object (its cells, for a thin surface); with `return_names`, also
    /// the names of the objects it meets.
    #[pyo3(signature = (shape, transform=None, return_names=false))]
    fn in_collision_single<'py>(
        &self,
        py: Python<'py>,
        shape: &Bound<'py, PyAny>,
        transform: Option<&Bound<'py, PyAny>>,
        return_names: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let v = if shape.hasattr("vertices")? { points(&shape.getattr("vertices")?, "shape.vertices")? } else { points(shape, "shape")? };
        let hull = ConvexHull::from_points(&v).ok_or_else(|| value_error("shape: its points span no volume (a convex shape is needed)"))?;
        let target = Target::new(TargetShape::Polytope(Arc::new(hull)), pose(transform)?);
        let settings = CollideSettings { all_contacts: return_names, flag_only: !return_names, least_overlap: false };
        let report = py.detach(|| self.core.collide(&target, &settings));
        let hit = report.in_collision();
        if !return_names {
            return Ok(pyo3::types::PyBool::new(py, hit).to_owned().into_any());
        }
        let names: BTreeSet<String> = report.contacts.iter().map(|c| self.core.objects()[c.object].name.clone()).collect();
        Ok((hit, names).into_pyobject(py)?.into_any())
    }

    fn __len__(&self) -> usize {
        self.core.objects().len()
    }
}
