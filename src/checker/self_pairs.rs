//! The robot link pairs checked against each other (built in `self_collision`).

use crate::model::Srdf;

/// The pairs checked, and why the others are not.
#[derive(Clone, Debug, Default)]
pub struct SelfPairs {
    /// Target indices `(a, b)`, `a < b` (model order), checked against each other.
    pub pairs: Vec<(usize, usize)>,
    /// The SRDF the matrix comes from, if any.
    pub srdf: Option<Srdf>,
    /// Without an SRDF: the non-adjacent pairs allowed because they touch at the zero state, as
    /// link names (printed once).
    pub allowed_at_zero: Vec<(String, String)>,
}
