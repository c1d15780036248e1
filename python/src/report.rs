//! A state's or a motion's report as Python objects: the fields of `check --json`, and
//! `to_dict()` giving exactly that object.

use pyo3::prelude::*;
use thickness_collision::checker::{ReportClearance, ReportContact, StateReport};
use thickness_collision::msgs::Time;
use thickness_collision::pipeline::CheckedState;

/// One contact, as `check --json` gives it.
#[pyclass(frozen, get_all, module = "thickness_collision")]
#[derive(Clone)]
pub struct Contact {
    /// The robot link (or attached object) in contact.
    link_name: String,
    /// What it touches: an environment object, or another link.
    object_name: String,
    /// `"environment"`, `"robot_link"` or `"attached_object"`.
    object_type: String,
    /// The triangle whose cell is met (4294967295 for a solid or a link).
    triangle: u32,
    /// Penetration depth (metres; 0 for a motion's near miss).
    depth: f64,
    /// Unit normal (world), pointing out of the object.
    normal: (f64, f64, f64),
    /// The contact point (world), or `None` when not computed.
    position: Option<(f64, f64, f64)>,
}

#[pymethods]
impl Contact {
    /// `link_name`, by its short name.
    #[getter]
    fn link(&self) -> &str {
        &self.link_name
    }

    /// `object_name`, by its short name.
    #[getter]
    fn object(&self) -> &str {
        &self.object_name
    }

    /// `position`: the contact point (world), or `None` when not computed.
    #[getter]
    fn point(&self) -> Option<(f64, f64, f64)> {
        self.position
    }

    fn __repr__(&self) -> String {
        format!("Contact({} x {} ({}), depth {:.6})", self.link_name, self.object_name, self.object_type, self.depth)
    }
}

/// The smallest distance from one link to the environment, within `clearance_threshold`.
#[pyclass(frozen, get_all, module = "thickness_collision")]
#[derive(Clone)]
pub struct Clearance {
    link_name: String,
    object_name: String,
    triangle: u32,
    distance: f64,
    point_on_link: (f64, f64, f64),
    point_on_object: (f64, f64, f64),
}

#[pymethods]
impl Clearance {
    fn __repr__(&self) -> String {
        format!("Clearance({} to {}: {:.6} m)", self.link_name, self.object_name, self.distance)
    }
}

/// A state's (or a motion's) report. Its Python objects are made when they are read: a check
/// that only asks `in_collision` pays for nothing else.
#[pyclass(frozen, module = "thickness_collision")]
pub struct Report {
    inner: StateReport,
}

fn triple(a: [f64; 3]) -> (f64, f64, f64) {
    (a[0], a[1], a[2])
}

fn contact(c: &ReportContact) -> Contact {
    let object_type = serde_json::to_value(c.object_type).ok().and_then(|v| v.as_str().map(str::to_owned)).unwrap_or_default();
    Contact {
        link_name: c.link_name.clone(),
        object_name: c.object_name.clone(),
        object_type,
        triangle: c.triangle,
        depth: c.depth,
        normal: triple(c.normal),
        position: c.position.map(triple),
    }
}

fn clearance(c: &ReportClearance) -> Clearance {
    Clearance {
        link_name: c.link_name.clone(),
        object_name: c.object_name.clone(),
        triangle: c.triangle,
        distance: c.distance,
        point_on_link: triple(c.point_on_link),
        point_on_object: triple(c.point_on_object),
    }
}

impl Report {
    pub fn new(inner: StateReport) -> Report {
        Report { inner }
    }

    pub fn clearances(&self) -> Vec<Clearance> {
        self.inner.clearances.iter().map(clearance).collect()
    }
}

#[pymethods]
impl Report {
    /// True when in collision, and when the state could not be checked (see `error`).
    #[getter]
    fn in_collision(&self) -> bool {
        self.inner.in_collision
    }

    /// The contacts: one per link (its deepest) and per colliding self pair.
    #[getter]
    fn contacts(&self) -> Vec<Contact> {
        self.inner.contacts.iter().map(contact).collect()
    }

    /// Each link within `clearance_threshold` of the environment (signed: minus the depth in
    /// contact).
    #[getter(clearances)]
    fn clearances_py(&self) -> Vec<Clearance> {
        self.clearances()
    }

    /// Joints outside their limits.
    #[getter]
    fn out_of_limits(&self) -> Vec<String> {
        self.inner.out_of_limits.clone()
    }

    /// Why the state could not be checked ("" when it was).
    #[getter]
    fn error(&self) -> &str {
        &self.inner.error
    }

    /// A motion's report.
    #[getter]
    fn motion(&self) -> bool {
        self.inner.motion
    }

    /// For a motion in collision: the start of the first stretch that could not be cleared.
    #[getter]
    fn fraction(&self) -> Option<f64> {
        self.inner.fraction
    }

    /// Seconds the check took.
    #[getter]
    fn check_seconds(&self) -> f64 {
        self.inner.check_seconds
    }

    /// Exactly the object `check --json` prints for this state (`stamp` 0).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let json = CheckedState { stamp: Time::default(), report: self.inner.clone() }.json();
        py.import("json")?.call_method1("loads", (json,))
    }

    fn __bool__(&self) -> bool {
        self.inner.in_collision
    }

    fn __repr__(&self) -> String {
        let r = &self.inner;
        if !r.error.is_empty() {
            return format!("Report(not checked, in collision: {})", r.error);
        }
        match (r.motion, r.fraction) {
            (true, Some(f)) => format!("Report(motion in collision from {f:.4}, {} contacts)", r.contacts.len()),
            (true, None) => "Report(motion free)".into(),
            _ => format!("Report(in_collision={}, {} contacts)", if r.in_collision { "True" } else { "False" }, r.contacts.len()),
        }
    }
}
