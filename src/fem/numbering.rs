//! Element numbers of the assembler, handed out per element family in contiguous blocks
//! (continuum elements, then joints, then external tendons). The scatter maps are indexed
//! by these numbers, so the order the element node lists are given to
//! [`super::assembly::Assembler::new`] and the numbers used when adding element matrices
//! must agree: both come from here, and a number outside its family's block is refused.

use std::ops::Range;

/// An element family with its own block of assembler numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// Continuum (plane-stress) elements, with the bars they host.
    Continuum,
    /// Joint (interface) elements.
    Joint,
    /// External tendons.
    Tendon,
}

impl Family {
    /// Every family, in numbering order.
    pub const ALL: [Family; 3] = [Family::Continuum, Family::Joint, Family::Tendon];

    fn index(self) -> usize {
        match self {
            Family::Continuum => 0,
            Family::Joint => 1,
            Family::Tendon => 2,
        }
    }
}

/// The blocks of assembler element numbers, one per family.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ElementNumbers {
    /// First number of each family's block, and the total at the end.
    starts: [usize; 4],
}

impl ElementNumbers {
    /// Blocks for `counts` elements of each family (order of [`Family::ALL`]).
    pub fn new(counts: [usize; 3]) -> Self {
        let mut starts = [0; 4];
        for f in 0..3 {
            starts[f + 1] = starts[f] + counts[f];
        }
        Self { starts }
    }

    /// The block of family `f`.
    pub fn range(&self, f: Family) -> Range<usize> {
        self.starts[f.index()]..self.starts[f.index() + 1]
    }

    /// Number of elements of all families.
    pub fn total(&self) -> usize {
        self.starts[3]
    }

    /// Assembler number of element `i` of family `f`, or None if `i` is outside the block.
    pub fn get(&self, f: Family, i: usize) -> Option<usize> {
        let r = self.range(f);
        (i < r.len()).then_some(r.start + i)
    }

    /// Assembler number of element `i` of family `f`.
    ///
    /// # Panics
    /// If `i` is outside the family's block: a programming error that would otherwise add
    /// the matrix into another element's scatter map.
    pub fn number(&self, f: Family, i: usize) -> usize {
        self.get(f, i).unwrap_or_else(|| {
            panic!(
                "internal error: {f:?} element {i} outside its block of {} elements",
                self.range(f).len()
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocks follow each other without gaps or overlap, in family order.
    #[test]
    fn contiguous_blocks() {
        let n = ElementNumbers::new([3, 0, 2]);
        assert_eq!(n.range(Family::Continuum), 0..3);
        assert_eq!(n.range(Family::Joint), 3..3);
        assert_eq!(n.range(Family::Tendon), 3..5);
        assert_eq!(n.total(), 5);
        assert_eq!(n.number(Family::Tendon, 1), 4);
    }

    /// A number beyond a family's block is caught, not handed out as the next family's.
    #[test]
    fn mismatch_is_caught() {
        let n = ElementNumbers::new([3, 1, 2]);
        assert_eq!(n.get(Family::Continuum, 3), None);
        assert_eq!(n.get(Family::Joint, 1), None);
        assert_eq!(n.get(Family::Joint, 0), Some(3));
        let r = std::panic::catch_unwind(|| n.number(Family::Joint, 1));
        assert!(r.is_err());
    }
}
