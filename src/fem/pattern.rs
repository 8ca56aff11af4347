//! The sparse pattern shared by assembly (which fills it) and the solver (which factors it):
//! it sits below both so that neither points up at the other.

/// Compressed sparse column pattern of the lower triangle of a symmetric matrix.
#[derive(Debug, Clone)]
pub struct LowerPattern {
    /// Matrix order.
    pub n: usize,
    /// Column pointers (length n + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column, all ≥ the column index.
    pub row_idx: Vec<usize>,
}

impl LowerPattern {
    /// The pattern of a 1 × 1 matrix (a stand-in for an analysis not done yet).
    pub fn stand_in() -> Self {
        Self {
            n: 1,
            col_ptr: vec![0, 1],
            row_idx: vec![0],
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry (i, j) with i ≥ j in the value array, if stored.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|p| a + p)
    }

    /// y = A x for the symmetric matrix whose lower triangle has `values`.
    pub fn sym_mul(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..self.n {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[p];
                y[i] += values[p] * x[j];
                if i != j {
                    y[j] += values[p] * x[i];
                }
            }
        }
    }
}
