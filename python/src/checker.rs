//! `Checker`: a robot and its environment, checked from Python. One `Checker` serves many
//! threads at once (the library's checker is immutable after loading; the class is frozen).

use crate::errors::{error, value_error};
use crate::positions::{rows, state, State};
use crate::report::Report;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, MutexGuard};
use thickness_collision::checker::{Checker as Core, StateError};
use thickness_collision::model::{InputFiles, JointKind, Params, DEFAULT_NODE_FQN};
use thickness_collision::pipeline::Pipeline;

/// Per-row flags and fractions of a batch of motions.
type MotionArrays<'py> = (Bound<'py, PyArray1<bool>>, Bound<'py, PyArray1<f64>>);

/// A robot among its environment's thin surfaces and solids, as the node checks it.
#[pyclass(frozen, module = "thickness_collision")]
pub struct Checker {
    /// The scene in force and the joint state it was last given (for objects placed on robot
    /// links); a check takes the checker in force and runs without the lock.
    pipeline: Mutex<Pipeline>,
    /// The actuated joints (not mimic, not fixed), in model order: the order of every array.
    names: Vec<String>,
    /// Their indices in the model's joints.
    index: Vec<usize>,
}

fn state_error(e: StateError) -> PyErr {
    value_error(e)
}

impl Checker {
    fn build(params: Params) -> PyResult<Checker> {
        params.validate().map_err(value_error)?;
        let pipeline = Pipeline::new(params).map_err(error)?;
        let robot = pipeline.checker().robot();
        let (names, index) = robot.joints.iter().enumerate().filter(|(_, j)| j.is_actuated()).map(|(i, j)| (j.name.clone(), i)).unzip();
        Ok(Checker { pipeline: Mutex::new(pipeline), names, index })
    }

    pub(crate) fn pipeline(&self) -> MutexGuard<'_, Pipeline> {
        // A panic while the lock was held leaves a pipeline whose scene changes are whole or
        // not made: it is still consistent.
        self.pipeline.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// The checker in force (the planning scene's objects included).
    pub(crate) fn core(&self) -> Arc<Core> {
        self.pipeline().checker().clone()
    }

    pub(crate) fn names(&self) -> &[String] {
        &self.names
    }

    /// Every joint's position from one state.
    fn full(&self, core: &Core, s: &State) -> PyResult<Vec<f64>> {
        core.positions(s.names(&self.names), &s.values).map_err(state_error)
    }

    /// Every joint's position from each row (in `joint_names` order).
    fn full_rows(&self, core: &Core, rows: &[Vec<f64>]) -> PyResult<Vec<Vec<f64>>> {
        rows.iter().map(|row| core.positions(&self.names, row).map_err(state_error)).collect()
    }
}

#[pymethods]
impl Checker {
    /// A checker from files: `robot` and `environment` URDFs (`None`: the parameters' or the
    /// bundled workcell's), an SRDF, a thickness (metres) and side (`"back"`, `"front"`,
    /// `"both"`) for every thin surface, and a parameters file as the node reads it.
    #[new]
    #[pyo3(signature = (robot=None, environment=None, srdf=None, thickness=None, side=None, params=None, clearance_threshold=None))]
    fn new(
        robot: Option<PathBuf>,
        environment: Option<PathBuf>,
        srdf: Option<PathBuf>,
        thickness: Option<f64>,
        side: Option<&str>,
        params: Option<PathBuf>,
        clearance_threshold: Option<f64>,
    ) -> PyResult<Checker> {
        let mut p = match params {
            Some(path) => Params::from_files_for_node(&[path], DEFAULT_NODE_FQN).map_err(error)?.params,
            None => Params::default(),
        };
        if let Some(t) = thickness {
            if !thickness_collision::limits::is_length(t) {
                let [lo, hi] = thickness_collision::limits::LENGTH_RANGE;
                return Err(value_error(format!("thickness {t}: must be from {lo:e} to {hi:e} m")));
            }
            p.default_thickness = t;
            p.thin_surfaces.thickness.iter_mut().for_each(|x| *x = t);
        }
        if let Some(side) = side {
            let side: thickness_collision::thickness::Side = side.parse().map_err(value_error)?;
            p.default_side = side;
            p.thin_surfaces.side.iter_mut().for_each(|x| *x = side);
        }
        if let Some(srdf) = srdf {
            p.robot_semantic_file = srdf.display().to_string();
        }
        if let Some(c) = clearance_threshold {
            p.clearance_threshold = c;
        }
        if robot.is_some() || environment.is_some() {
            p.input_files = InputFiles { robot, environment };
        }
        Checker::build(p)
    }

    /// A checker from a parameters file, as the node reads it for `/thickness_collision`.
    #[staticmethod]
    fn from_params(path: PathBuf) -> PyResult<Checker> {
        let loaded = Params::from_files_for_node(&[path], DEFAULT_NODE_FQN).map_err(error)?;
        Checker::build(loaded.params)
    }

    /// The actuated joints (not mimic, not fixed), in model order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// (lower, upper) limits in `joint_names` order; a continuous joint's are -π and π (one
    /// turn: a planner's bounds).
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let core = self.core();
        let joints = &core.robot().joints;
        let turn = |i: usize| -> [f64; 2] {
            match joints[i].kind {
                JointKind::Continuous => [-std::f64::consts::PI, std::f64::consts::PI],
                _ => joints[i].limits,
            }
        };
        let (lo, hi): (Vec<f64>, Vec<f64>) = self.index.iter().map(|&i| turn(i).into()).unzip();
        (lo.into_pyarray(py), hi.into_pyarray(py))
    }

    /// The report of one state: `q` in `joint_names` order (a sequence or array), or a dict
    /// of `{name: value}` (a joint it lacks at 0).
    fn check(&self, py: Python<'_>, q: &Bound<'_, PyAny>) -> PyResult<Report> {
        let s = state(q, &self.names, "q")?;
        let core = self.core();
        let report = py.detach(|| core.check_joints(s.names(&self.names), &s.values)).map_err(state_error)?;
        Ok(Report::new(report))
    }

    /// Whether each row of `Q` (`N x dof`, `joint_names` order) collides, on every core with the
    /// GIL released; with `depths=True` also each state's deepest contact depth (0 when free).
    #[pyo3(signature = (q, depths=false))]
    fn check_batch<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, depths: bool) -> PyResult<Bound<'py, PyAny>> {
        let rows = rows(q, &self.names, "Q")?;
        let core = self.core();
        let results: Vec<Result<(bool, f64), StateError>> = py.detach(|| {
            rows.par_iter()
                .map(|row| {
                    if depths {
                        let r = core.check_joints(&self.names, row)?;
                        Ok((r.in_collision, r.contacts.iter().map(|c| c.depth).fold(0.0, f64::max)))
                    } else {
                        Ok((core.check_joints_flags(&self.names, row)?.in_collision, 0.0))
                    }
                })
                .collect()
        });
        let results: Vec<(bool, f64)> = results.into_iter().collect::<Result<_, _>>().map_err(state_error)?;
        let (flags, deep): (Vec<bool>, Vec<f64>) = results.into_iter().unzip();
        let flags = flags.into_pyarray(py).into_any();
        if depths {
            Ok((flags, deep.into_pyarray(py)).into_pyobject(py)?.into_any())
        } else {
            Ok(flags)
        }
    }

    /// The guaranteed check of the straight line in joint space from `q0` to `q1`: "free" is
    /// certain; in collision, `fraction` is no later than the first contact.
    fn check_motion(&self, py: Python<'_>, q0: &Bound<'_, PyAny>, q1: &Bound<'_, PyAny>) -> PyResult<Report> {
        let (a, b) = (state(q0, &self.names, "q0")?, state(q1, &self.names, "q1")?);
        let core = self.core();
        let (from, to) = (self.full(&core, &a)?, self.full(&core, &b)?);
        Ok(Report::new(py.detach(|| core.check_motion(&from, &to).report)))
    }

    /// The motions along a path (rows of `Q`), one report per edge, in order; the first edge in
    /// collision ends it (the reports stop there).
    fn check_path(&self, py: Python<'_>, q: &Bound<'_, PyAny>) -> PyResult<Vec<Report>> {
        let rows = rows(q, &self.names, "Q")?;
        let core = self.core();
        let full = self.full_rows(&core, &rows)?;
        let reports = py.detach(|| {
            let mut out = Vec::with_capacity(full.len().saturating_sub(1));
            for edge in full.windows(2) {
                let r = core.check_motion(&edge[0], &edge[1]).report;
                let stop = r.in_collision;
                out.push(r);
                if stop {
                    break;
                }
            }
            out
        });
        Ok(reports.into_iter().map(Report::new).collect())
    }

    /// Many motions at once (row `i` of `Q0` to row `i` of `Q1`), on every core with the GIL
    /// released: `(in_collision, fraction)` arrays, `fraction` NaN where free.
    fn check_motions<'py>(&self, py: Python<'py>, q0: &Bound<'py, PyAny>, q1: &Bound<'py, PyAny>) -> PyResult<MotionArrays<'py>> {
        let (a, b) = (rows(q0, &self.names, "Q0")?, rows(q1, &self.names, "Q1")?);
        if a.len() != b.len() {
            return Err(value_error(format!("Q0 has {} rows and Q1 {}: one motion per row", a.len(), b.len())));
        }
        let core = self.core();
        let (a, b) = (self.full_rows(&core, &a)?, self.full_rows(&core, &b)?);
        let out: Vec<(bool, f64)> = py.detach(|| {
            a.par_iter()
                .zip(&b)
                .map(|(x, y)| {
                    let r = core.check_motion(x, y).report;
                    (r.in_collision, r.fraction.unwrap_or(f64::NAN))
                })
                .collect()
        });
        let (flags, fractions): (Vec<bool>, Vec<f64>) = out.into_iter().unzip();
        Ok((flags.into_pyarray(py), fractions.into_pyarray(py)))
    }

    /// Each link's smallest distance to the environment within `clearance_threshold` (a
    /// `Checker` made with one), at `q`.
    fn clearance(&self, py: Python<'_>, q: &Bound<'_, PyAny>) -> PyResult<Vec<crate::report::Clearance>> {
        if self.core().params().clearance_threshold <= 0.0 {
            return Err(error("clearance_threshold is 0: make the Checker with clearance_threshold=<metres>"));
        }
        Ok(self.check(py, q)?.clearances())
    }

    /// The benchmark's instrument (benches/python_layer.py): the Rust API's `check_joints` on
    /// each row of `Q` in turn, in this process, timed in Rust; returns (seconds per row, rows
    /// in collision). Beside a Python loop of `check` on the same rows it measures what the
    /// Python layer adds per call.
    fn _time_rust_checks(&self, py: Python<'_>, q: &Bound<'_, PyAny>) -> PyResult<(f64, usize)> {
        let rows = rows(q, &self.names, "Q")?;
        let core = self.core();
        py.detach(|| {
            let started = std::time::Instant::now();
            let mut colliding = 0;
            for row in &rows {
                colliding += core.check_joints(&self.names, row).map_err(state_error)?.in_collision as usize;
            }
            Ok((started.elapsed().as_secs_f64() / rows.len().max(1) as f64, colliding))
        })
    }

    /// Each link's world pose at `q` (forward kinematics, the robot's base pose applied): a dict
    /// of link name to a 4 x 4 matrix.
    fn link_poses<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let s = state(q, &self.names, "q")?;
        let core = self.core();
        let full = self.full(&core, &s)?;
        let poses = core.robot().forward_kinematics(&full, core.base_pose()).map_err(value_error)?;
        let out = pyo3::types::PyDict::new(py);
        for (link, iso) in core.robot().links.iter().zip(&poses) {
            out.set_item(&link.name, crate::geometry::matrix(&thickness_collision::math::pose_from_isometry(iso)).into_pyarray(py))?;
        }
        Ok(out)
    }

    /// The collision geometry each checked link is checked with, in its link's frame: a dict of
    /// link name to a list of `(kind, data, offset)`: `("hull", N x 3 points, 4 x 4)`,
    /// `("sphere", radius, ...)`, `("capsule" | "cylinder", (half_height, radius), ...)` (along z).
    fn collision_geometry<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        use thickness_collision::collision::TargetShape;
        let core = self.core();
        let out = pyo3::types::PyDict::new(py);
        for t in core.targets() {
            let parts = pyo3::types::PyList::empty(py);
            for (shape, offset) in &t.parts {
                let offset = crate::geometry::matrix(offset).into_pyarray(py);
                let item = match shape {
                    TargetShape::Polytope(h) => {
                        let pts = numpy::ndarray::Array2::from_shape_fn((h.points().len(), 3), |(i, d)| h.points()[i][d]);
                        ("hull", pts.into_pyarray(py).into_any(), offset).into_pyobject(py)?
                    }
                    TargetShape::Sphere { radius } => ("sphere", radius.into_pyobject(py)?.into_any(), offset).into_pyobject(py)?,
                    TargetShape::Capsule { half_height, radius } => {
                        ("capsule", (*half_height, *radius).into_pyobject(py)?.into_any(), offset).into_pyobject(py)?
                    }
                    TargetShape::Cylinder { half_height, radius } => {
                        ("cylinder", (*half_height, *radius).into_pyobject(py)?.into_any(), offset).into_pyobject(py)?
                    }
                    // Only the motion check makes swept hulls, for one question; a link is never one.
                    TargetShape::Swept { .. } => return Err(error(format!("link '{}': a swept hull is not a link's shape", t.name))),
                };
                parts.append(item)?;
            }
            out.set_item(&t.name, parts)?;
        }
        Ok(out)
    }

    /// Applies a `moveit_msgs/CollisionObject` (a dict with the message's field names, lists
    /// for sequences; `thickness_collision.collision_object` makes one) as the node applies the
    /// `collision_object` topic: in force when this returns. With `q`, that joint state is made
    /// the current one first (an object placed on a robot link is placed at it).
    #[pyo3(signature = (msg, q=None))]
    fn apply_collision_object(&self, msg: &Bound<'_, PyAny>, q: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        crate::scene_msgs::apply_collision_object(self, msg, q)
    }

    /// Applies a `moveit_msgs/AttachedCollisionObject` dict (attach, or detach with
    /// `object.operation` REMOVE) as the node applies the `attached_collision_object` topic;
    /// with `q`, that joint state is made the current one first (an attachment keeps the
    /// object's pose at it).
    #[pyo3(signature = (msg, q=None))]
    fn apply_attached_collision_object(&self, msg: &Bound<'_, PyAny>, q: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        crate::scene_msgs::apply_attached_collision_object(self, msg, q)
    }

    /// (world objects, attached objects) of the planning scene in force.
    #[getter]
    fn scene_object_count(&self) -> (usize, usize) {
        self.pipeline().scene_object_count()
    }

    fn __repr__(&self) -> String {
        let core = self.core();
        let s = core.summary();
        format!(
            "Checker({}, {} joints; {}: {} thin surfaces, {} cells, {} solids)",
            s.robot_source,
            self.names.len(),
            s.environment_source,
            s.thin_surfaces,
            s.cells,
            s.solids
        )
    }
}
