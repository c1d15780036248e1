//! MoveIt's allowed collision matrix as a planning scene carries it: an entry for each pair of
//! names (links and objects) and a default entry per name, read as
//! `collision_detection::AllowedCollisionMatrix::getAllowedCollision` reads them.

use std::collections::{BTreeMap, HashMap};

/// Which pairs of names may collide without being reported.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct CollisionMatrix {
    names: Vec<String>,
    index: HashMap<String, usize>,
    /// `allowed[i][j]`: names `i` and `j` may collide.
    allowed: Vec<Vec<bool>>,
    defaults: BTreeMap<String, bool>,
}

impl CollisionMatrix {
    /// A matrix of `names` with `allowed` rows (square, as many as names) and default entries;
    /// the error says which lengths differ. A name given twice keeps its last row, as MoveIt's
    /// constructor (entries set in order) does.
    pub(crate) fn new(names: Vec<String>, allowed: Vec<Vec<bool>>, defaults: BTreeMap<String, bool>) -> Result<CollisionMatrix, String> {
        if allowed.len() != names.len() {
            return Err(format!("{} entry_names but {} entry_values", names.len(), allowed.len()));
        }
        if let Some((i, row)) = allowed.iter().enumerate().find(|(_, r)| r.len() != names.len()) {
            return Err(format!("entry_values[{i}] has {} values for {} entry_names", row.len(), names.len()));
        }
        let index = names.iter().enumerate().map(|(i, n)| (n.clone(), i)).collect();
        Ok(CollisionMatrix { names, index, allowed, defaults })
    }

    /// Whether `a` and `b` may collide: their entry (of a matrix that is not symmetric, the later
    /// row's, as MoveIt reads it), else their default entries (either's when
    /// one has one, both when both have one), else not.
    pub(crate) fn allows(&self, a: &str, b: &str) -> bool {
        if let (Some(&i), Some(&j)) = (self.index.get(a), self.index.get(b)) {
            // MoveIt's constructor sets both (i, j) and (j, i) row by row: the later row wins.
            return self.allowed[i.max(j)][i.min(j)];
        }
        match (self.defaults.get(a), self.defaults.get(b)) {
            (None, None) => false,
            (Some(x), None) | (None, Some(x)) => *x,
            (Some(x), Some(y)) => *x && *y,
        }
    }

    /// Names, rows and default entries, as the message holds them.
    pub(crate) fn parts(&self) -> (&[String], &[Vec<bool>], &BTreeMap<String, bool>) {
        (&self.names, &self.allowed, &self.defaults)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_then_defaults_as_moveit_reads_them() {
        let m = CollisionMatrix::new(
            vec!["hand".into(), "tray".into()],
            vec![vec![false, true], vec![true, false]],
            [("floor".to_owned(), true), ("wall".to_owned(), false)].into_iter().collect(),
        )
        .unwrap();
        assert!(m.allows("hand", "tray") && m.allows("tray", "hand") && !m.allows("hand", "hand"));
        assert!(m.allows("arm", "floor"), "a default entry alone decides");
        assert!(!m.allows("floor", "wall"), "both defaults: allowed only when both allow");
        assert!(!m.allows("arm", "shelf"), "no entry, no default: checked");
        assert_eq!(CollisionMatrix::new(vec!["a".into()], vec![], BTreeMap::new()).unwrap_err(), "1 entry_names but 0 entry_values");
        assert_eq!(CollisionMatrix::new(vec!["a".into()], vec![vec![]], BTreeMap::new()).unwrap_err(), "entry_values[0] has 0 values for 1 entry_names");
    }
}
