//! The rows of `G` whose laws couple them: the blocks of the matrix-free path's
//! preconditioner.
//!
//! Two rows are coupled when one row group's law owns both (the two tangent rows of a
//! Coulomb disk: its blocks `Q_ab`, `a != b`) or when a group reads the other's force (a
//! friction law on its contact's normal force: its blocks `X_as`). The connected sets of
//! this relation are the units: one row for a contact or a friction point under a
//! prescribed load, three for a 3-D frictional contact on its normal law. A unit's rows
//! keep their receptance between them and the law's blocks between them in the
//! preconditioner; the receptance between units is what GMRES corrects.

use super::laws::LawLayout;

/// The units of a law layout (module documentation): each unit's rows, each row's unit and
/// place in it, and each unit's offset in a flat store of `u x u` entries per unit.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct CoupledRows {
    /// The rows of each unit, ascending; units ordered by their first row.
    pub(crate) units: Vec<Vec<usize>>,
    /// `(unit, place)` of each row.
    pub(crate) place: Vec<(usize, usize)>,
    /// Offset of each unit's `u x u` entries in a flat store; the last entry is the total.
    pub(crate) offsets: Vec<usize>,
}

impl CoupledRows {
    /// The units of `layout` over its `rows` rows.
    pub(crate) fn new(layout: &LawLayout, rows: usize) -> Self {
        let mut root: Vec<usize> = (0..rows).collect();
        fn find(root: &mut [usize], mut i: usize) -> usize {
            while root[i] != i {
                root[i] = root[root[i]];
                i = root[i];
            }
            i
        }
        for &(a, b) in layout.q_pairs.iter().chain(&layout.x_pairs) {
            let (ra, rb) = (find(&mut root, a), find(&mut root, b));
            // The smaller row is the root, so units are ordered by their first row.
            let (low, high) = (ra.min(rb), ra.max(rb));
            root[high] = low;
        }
        let mut unit_of_root = vec![usize::MAX; rows];
        let mut units: Vec<Vec<usize>> = Vec::new();
        let mut place = vec![(0, 0); rows];
        for (row, at) in place.iter_mut().enumerate() {
            let r = find(&mut root, row);
            if unit_of_root[r] == usize::MAX {
                unit_of_root[r] = units.len();
                units.push(Vec::new());
            }
            let unit = unit_of_root[r];
            *at = (unit, units[unit].len());
            units[unit].push(row);
        }
        let mut offsets = Vec::with_capacity(units.len() + 1);
        let mut total = 0;
        for unit in &units {
            offsets.push(total);
            total += unit.len() * unit.len();
        }
        offsets.push(total);
        Self {
            units,
            place,
            offsets,
        }
    }

    /// Entries of the flat store: `sum u^2` over the units.
    pub(crate) fn entries(&self) -> usize {
        self.offsets.last().copied().unwrap_or(0)
    }

    /// Index in the flat store of the entry `(a, b)` (rows of one unit).
    pub(crate) fn entry(&self, a: usize, b: usize) -> usize {
        let ((unit, pa), (_, pb)) = (self.place[a], self.place[b]);
        self.offsets[unit] + pa * self.units[unit].len() + pb
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builder::sparse_matrix;
    use crate::model::{ContactPoint, ContactRow, FrictionalContact, StructuralModel};

    /// A contact alone is a unit of one row; a 3-D contact on its normal law is one unit of
    /// its three rows (the disk's two rows and the normal row it reads), a 3-D contact
    /// under a prescribed load a unit of its two tangent rows.
    #[test]
    fn a_frictional_contact_couples_its_rows_and_a_contact_stands_alone() {
        let n = 6;
        let identity: Vec<_> = (0..n).map(|i| (i, i, 1.0)).collect();
        let matrix = || sparse_matrix(n, &identity).expect("diagonal");
        let tangents = |a: usize| [ContactRow::unit(a, 1.0), ContactRow::unit(a + 1, 1.0)];
        let model = StructuralModel::new(matrix(), matrix(), vec![0.0; n])
            .with_contact(ContactPoint::new(5, 0.1))
            .with_frictional_contact(FrictionalContact::unilateral(
                ContactRow::unit(2, 1.0),
                0.0,
                tangents(0),
                0.3,
            ))
            .with_frictional_contact(FrictionalContact::prescribed(1.0, tangents(3), 0.3));
        let layout = LawLayout::new(&model, &[], n).expect("a valid layout");
        let rows = CoupledRows::new(&layout, 6);
        assert_eq!(rows.units, vec![vec![0], vec![1, 2, 3], vec![4, 5]]);
        assert_eq!(rows.place[3], (1, 2));
        assert_eq!(rows.offsets, vec![0, 1, 10, 14]);
        assert_eq!(rows.entries(), 14);
        assert_eq!(rows.entry(3, 1), 1 + 2 * 3);
    }
}
