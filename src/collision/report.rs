//! What a scene query returns.

use crate::math::{Real, Vector};

/// What a query computes.
#[derive(Clone, Copy, Debug)]
pub struct CollideSettings {
    /// Report every colliding cell (else only the deepest contact per target).
    pub all_contacts: bool,
    /// Only ask whether the target collides: stop at the first colliding cell, no contact point.
    pub flag_only: bool,
    /// Fill [`Contact::least`] (the least overlap, from the full SAT of the reported pair).
    /// Without it a pair that cheaper tests already proved colliding skips that SAT (~10 µs on a
    /// 300-face link hull), and it is `None`.
    pub least_overlap: bool,
}

impl Default for CollideSettings {
    fn default() -> Self {
        CollideSettings { all_contacts: false, flag_only: false, least_overlap: true }
    }
}

/// One contact between a target and an environment object, in the world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Index of the object in the scene.
    pub object: usize,
    /// Input index of the triangle whose cell was hit (`u32::MAX` for solids).
    pub triangle: u32,
    /// How far the target reaches past the surface along `normal` (metres).
    pub depth: Real,
    /// Push-out direction (unit).
    pub normal: Vector,
    /// A point within 1e-6 m of both shapes (`None` when `flag_only`, or where the clipped
    /// contact region is degenerate).
    pub position: Option<Vector>,
    /// The least overlap of the pair: the minimal translation. Without
    /// [`CollideSettings::least_overlap`] it is `None` where cheaper tests decided the pair.
    pub least: Option<LeastOverlap>,
}

/// The minimal translation that separates a colliding pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeastOverlap {
    /// How far (metres).
    pub overlap: Real,
    /// Unit direction in which the target moves by `overlap` to separate.
    pub axis: Vector,
}

/// The result for one target.
#[derive(Clone, Debug, Default)]
pub struct TargetReport {
    /// Colliding objects (indices into the scene), ascending.
    pub objects: Vec<usize>,
    /// The contacts: every colliding cell with `all_contacts`, else the deepest one only.
    pub contacts: Vec<Contact>,
    /// Cells in the tree leaves the query reached (each then faces its box and normal-axis tests,
    /// and the SAT if those do not decide it).
    pub candidates: usize,
}

impl TargetReport {
    /// Whether the target collides with anything.
    pub fn in_collision(&self) -> bool {
        !self.objects.is_empty()
    }

    /// The contact with the greatest depth.
    pub fn deepest(&self) -> Option<&Contact> {
        self.contacts.iter().max_by(|a, b| a.depth.total_cmp(&b.depth))
    }
}
