//! Sparse assembly: the lower-triangle pattern is computed once from the element
//! connectivities; each element keeps the positions of its entries in the value array, so
//! refilling values is a scatter with no search and no allocation.

use super::dofs::{DofMap, CONSTRAINED};
use crate::analysis::solver::LowerPattern;
use rayon::prelude::*;

/// Position marker for an element matrix entry that is not assembled (constrained dof or
/// strictly upper triangle).
const SKIP: u32 = u32::MAX;

/// Pattern and scatter maps for a list of element dof lists.
#[derive(Debug, Clone)]
pub struct Assembler {
    /// Lower-triangle pattern over the free equations.
    pub pattern: LowerPattern,
    /// Per element, for each (a, b) of its dense matrix (row-major), the position in the value
    /// array or SKIP.
    scatter: Vec<Vec<u32>>,
}

impl Assembler {
    /// Build the pattern from node connectivities (each element couples all dofs of its
    /// nodes); `elem_nodes[e]` lists the nodes of element e.
    pub fn new(n_nodes: usize, elem_nodes: &[Vec<usize>], dofs: &DofMap) -> Self {
        // Node adjacency (each node's neighbours incl. itself), sorted and unique.
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n_nodes];
        for nodes in elem_nodes {
            for &a in nodes {
                for &b in nodes {
                    adj[a].push(b as u32);
                }
            }
        }
        adj.iter_mut().for_each(|v| {
            v.sort_unstable();
            v.dedup();
        });
        // Lower pattern over equations: column j = eq of (node a, dir), rows = eqs ≥ j among
        // the dofs of neighbours of a. Equations are numbered in node order, so sorting the
        // neighbour list sorts the rows.
        let n = dofs.n_eq;
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0usize);
        let mut row_idx = Vec::new();
        let mut col_of_dof = vec![usize::MAX; 2 * n_nodes];
        for a in 0..n_nodes {
            for da in 0..2 {
                let j = dofs.eq[2 * a + da];
                if j == CONSTRAINED {
                    continue;
                }
                col_of_dof[2 * a + da] = j;
                for &b in &adj[a] {
                    for db in 0..2 {
                        let i = dofs.eq[2 * b as usize + db];
                        if i != CONSTRAINED && i >= j {
                            row_idx.push(i);
                        }
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        let pattern = LowerPattern {
            n,
            col_ptr,
            row_idx,
        };
        let scatter = elem_nodes
            .par_iter()
            .map(|nodes| {
                let eqs: Vec<usize> = nodes
                    .iter()
                    .flat_map(|&a| [dofs.eq[2 * a], dofs.eq[2 * a + 1]])
                    .collect();
                let mut s = Vec::with_capacity(eqs.len() * eqs.len());
                for &i in &eqs {
                    for &j in &eqs {
                        let p = if i == CONSTRAINED || j == CONSTRAINED || i < j {
                            SKIP
                        } else {
                            pattern.position(i, j).expect("pattern covers element") as u32
                        };
                        s.push(p);
                    }
                }
                s
            })
            .collect();
        Self { pattern, scatter }
    }

    /// Add the dense row-major element matrix `k` of element `e` into `values`.
    #[inline]
    pub fn add_matrix(&self, e: usize, k: &[f64], values: &mut [f64]) {
        for (p, v) in self.scatter[e].iter().zip(k) {
            if *p != SKIP {
                values[*p as usize] += v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two 2-node "elements" sharing node 1: the pattern holds exactly the coupled entries.
    #[test]
    fn pattern_of_a_chain() {
        let dofs = DofMap::new(3, &[(0, 0.0), (1, 0.0)]);
        let asm = Assembler::new(3, &[vec![0, 1], vec![1, 2]], &dofs);
        // Free eqs: node1 (0,1), node2 (2,3); all four couple → lower triangle of 4×4 = 10.
        assert_eq!(asm.pattern.n, 4);
        assert_eq!(asm.pattern.nnz(), 10);
        let mut vals = vec![0.0; 10];
        let k = vec![1.0; 16];
        asm.add_matrix(0, &k, &mut vals);
        // Element 0 touches only node 1's two eqs: entries (0,0), (1,0), (1,1).
        assert_eq!(vals.iter().sum::<f64>(), 3.0);
    }
}
