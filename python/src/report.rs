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

/// A state's (or a motion's) report.
#[pyclass(frozen, module = "thickness_collision")]
pub struct Report {
    /// True when in collision, and when the state could not be checked (see `error`).
    #[pyo3(get)]
    in_collision: bool,
    #[pyo3(get)]
    contacts: Vec<Contact>,
    #[pyo3(get)]
    clearances: Vec<Clearance>,
    /// Joints outside their limits.
    #[pyo3(get)]
    out_of_limits: Vec<String>,
    /// Why the state could not be checked ("" when it was).
    #[pyo3(get)]
    error: String,
    /// A motion's report.
    #[pyo3(get)]
    motion: bool,
    /// For a motion in collision: the start of the first stretch that could not be cleared.
    #[pyo3(get)]
    fraction: Option<f64>,
    /// Seconds the check took.
    #[pyo3(get)]
    check_seconds: f64,
    json: String,
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
    pub fn new(report: StateReport) -> Report {
        let r = &report;
        let fields = Report {
            in_collision: r.in_collision,
            contacts: r.contacts.iter().map(contact).collect(),
            clearances: r.clearances.iter().map(clearance).collect(),
            out_of_limits: r.out_of_limits.clone(),
            error: r.error.clone(),
            motion: r.motion,
            fraction: r.fraction,
            check_seconds: r.check_seconds,
            json: String::new(),
        };
        Report { json: CheckedState { stamp: Time::default(), report }.json(), ..fields }
    }
}

impl Report {
    pub fn clearances(&self) -> Vec<Clearance> {
        self.clearances.clone()
    }
}

#[pymethods]
impl Report {
    /// Exactly the object `check --json` prints for this state (`stamp` 0).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (&self.json,))
    }

    fn __bool__(&self) -> bool {
        self.in_collision
    }

    fn __repr__(&self) -> String {
        if !self.error.is_empty() {
            return format!("Report(not checked, in collision: {})", self.error);
        }
        match (self.motion, self.fraction) {
            (true, Some(f)) => format!("Report(motion in collision from {f:.4}, {} contacts)", self.contacts.len()),
            (true, None) => "Report(motion free)".into(),
            _ => format!("Report(in_collision={}, {} contacts)", if self.in_collision { "True" } else { "False" }, self.contacts.len()),
        }
    }
}
