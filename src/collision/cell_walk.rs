//! The one traversal of a surface's cell tree. What a query wants (a first hit, every hit, the
//! deepest, the nearest) is its visitor's business: the visitor keys each subtree, says which keys
//! can still change its answer, and reads the leaves; the walk only orders and prunes (Jolt's
//! collectors, parry's traversal closures).

use super::cell_tree::CellTree;
use super::target_view::TargetView;
use crate::math::Real;
use std::ops::ControlFlow;

/// A query's side of [`walk`].
pub(crate) trait CellVisitor {
    /// The root's key, or `None` when nothing under it can matter.
    fn root(&mut self, tree: &CellTree, view: &TargetView) -> Option<Real>;

    /// The keys of an inner node's two children (`None`: that child cannot matter).
    fn children(&mut self, tree: &CellTree, children: [u32; 2], view: &TargetView) -> [Option<Real>; 2];

    /// Whether a subtree with this key can still change the answer. Asked when a child is found
    /// and again when it is taken from the stack: the answer may have improved in between.
    fn worth(&self, key: Real) -> bool;

    /// Reads a leaf's cells; `Break` ends the walk.
    fn leaf(&mut self, tree: &CellTree, node: u32, view: &TargetView) -> ControlFlow<()>;
}

/// Depth first from the root, the child with the larger key first.
#[inline(always)]
pub(crate) fn walk(tree: &CellTree, view: &TargetView, visitor: &mut impl CellVisitor) -> ControlFlow<()> {
    if tree.is_empty() {
        return ControlFlow::Continue(());
    }
    let mut stack: Vec<(Real, u32)> = Vec::with_capacity(64);
    if let Some(key) = visitor.root(tree, view) {
        stack.push((key, 0));
    }
    while let Some((key, node)) = stack.pop() {
        if !visitor.worth(key) {
            continue;
        }
        let Some(children) = tree.children(node) else {
            visitor.leaf(tree, node, view)?;
            continue;
        };
        let keys = visitor.children(tree, children, view);
        let mut next = [(Real::NEG_INFINITY, 0u32); 2];
        let mut n = 0;
        for (child, key) in children.into_iter().zip(keys) {
            if let Some(key) = key.filter(|k| visitor.worth(*k)) {
                // Its box or slabs are read when it is popped: ask for them now.
                tree.prefetch(child);
                next[n] = (key, child);
                n += 1;
            }
        }
        // The larger key on top of the stack.
        if n == 2 && next[0].0 > next[1].0 {
            next.swap(0, 1);
        }
        stack.extend(next.into_iter().take(n));
    }
    ControlFlow::Continue(())
}
