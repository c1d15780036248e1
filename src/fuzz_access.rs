//! Entry points for the fuzz harness (`fuzz/harness`) into steps that are not part of the API:
//! a fuzzer must reach them on their own, without the checks around them that would hide their
//! failures. Not for any other caller; their signatures may change with the harness.

use crate::checker::{Checker, SelfPairs};
use crate::model::Srdf;

/// Builds the self-collision pairs of `checker`'s robot from a parsed SRDF, as
/// `Checker::apply_semantic` does after parsing, and drops them.
pub fn build_self_pairs(checker: &Checker, srdf: Srdf) {
    let _ = SelfPairs::build(checker, Some(srdf));
}
