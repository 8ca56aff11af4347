//! The sparse pattern shared by assembly (which fills it, `fem::assembly`) and the solver
//! (which factors it), and the node → element incidence both the assembler and the
//! element dissection build their graphs from: linear-algebra types, below both users.

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

/// Node → element incidence in compressed rows: the elements holding node a are
/// `inc[inc_ptr[a]..inc_ptr[a + 1]]`, in increasing order; `elem_nodes[e]` lists the nodes of
/// element e.
pub fn incidence(n_nodes: usize, elem_nodes: &[Vec<usize>]) -> (Vec<usize>, Vec<u32>) {
    let mut inc_ptr = vec![0usize; n_nodes + 1];
    for nodes in elem_nodes {
        for &a in nodes {
            inc_ptr[a + 1] += 1;
        }
    }
    for a in 0..n_nodes {
        inc_ptr[a + 1] += inc_ptr[a];
    }
    let mut fill = inc_ptr.clone();
    let mut inc = vec![0u32; inc_ptr[n_nodes]];
    for (e, nodes) in elem_nodes.iter().enumerate() {
        for &a in nodes {
            inc[fill[a]] = e as u32;
            fill[a] += 1;
        }
    }
    (inc_ptr, inc)
}
