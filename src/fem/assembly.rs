//! Sparse assembly: the lower-triangle pattern is computed once from the element
//! connectivities; each element keeps the positions of its entries in the value array, so
//! refilling values is a scatter with no search and no allocation.

use super::dofs::{DofMap, CONSTRAINED};
use crate::linalg::pattern::{incidence, LowerPattern};
use rayon::prelude::*;

/// Position marker for an element matrix entry that is not assembled (constrained dof or
/// strictly upper triangle).
const SKIP: u32 = u32::MAX;

/// Pattern and scatter maps for a list of element dof lists.
#[derive(Debug, Clone)]
pub struct Assembler {
    /// Lower-triangle pattern over the free equations (shared with the symbolic analysis
    /// running on a thread of its own: [`crate::linalg::solver::SparseCholesky::in_background`]).
    pub pattern: std::sync::Arc<LowerPattern>,
    /// Node graph (compressed rows): the neighbours of node a, itself included, sorted, are
    /// `node_adj[node_ptr[a]..node_ptr[a + 1]]`. Kept for the fill-reducing ordering.
    pub node_ptr: Vec<usize>,
    /// See `node_ptr`.
    pub node_adj: Vec<u32>,
    /// Start of each element's entries in its dense matrix numbering, elements one after
    /// the other (length: elements + 1): the element's matrix has
    /// `scatter_ptr[e + 1] − scatter_ptr[e]` entries.
    scatter_ptr: Vec<usize>,
    /// The assembled entries of every element's dense matrix (row-major, elements one after
    /// the other), in that order: (index in the element's matrix, position in the value
    /// array). The entries not listed (constrained dofs, strictly upper triangle) are not
    /// assembled; `add_matrix` walks the list instead of testing every entry (half of a
    /// Q8's 256 entries are skipped).
    packed: Vec<(u32, u32)>,
    /// Start of each element's entries in `packed` (length: elements + 1).
    packed_ptr: Vec<usize>,
}

/// Nodes per parallel chunk of the pattern build.
const NODE_CHUNK: usize = 8192;
/// Elements per parallel chunk of the scatter-map build.
const ELEM_CHUNK: usize = 4096;

/// A zero value array of `n` entries whose pages are first touched by writes, in parallel.
/// `vec![0.0; n]` maps untouched pages: the scatter's first `+=` then reads the kernel's
/// shared zero page and its write copies it, flushing the TLB of every core running the
/// process (an interrupt per page on a virtual machine), 4 % of a 5e5-dof linear run.
/// Below 1 MiB the allocator serves touched heap memory and the plain vector is kept.
pub fn zeroed_values(n: usize) -> Vec<f64> {
    let mut v = vec![0.0; n];
    if n >= 1 << 17 {
        v.par_chunks_mut(1 << 16).for_each(|c| c.fill(0.0));
    }
    v
}

impl Assembler {
    /// Build the pattern from node connectivities (each element couples all dofs of its
    /// nodes); `elem_nodes[e]` lists the nodes of element e.
    pub fn new(n_nodes: usize, elem_nodes: &[Vec<usize>], dofs: &DofMap) -> Self {
        // Node → elements incidence, then each node's neighbours: the nodes of its elements,
        // sorted and unique. Flat arrays built chunk-parallel: no allocation per node (a Vec
        // per node cost more than the sorting at 1e6 dofs).
        let (inc_ptr, inc) = incidence(n_nodes, elem_nodes);
        let chunks: Vec<(Vec<u32>, Vec<usize>)> = (0..n_nodes.div_ceil(NODE_CHUNK))
            .into_par_iter()
            .map(|c| {
                let (a0, a1) = (c * NODE_CHUNK, ((c + 1) * NODE_CHUNK).min(n_nodes));
                let mut adj = Vec::with_capacity((a1 - a0) * 10);
                let mut len = Vec::with_capacity(a1 - a0);
                for a in a0..a1 {
                    let s = adj.len();
                    for &e in &inc[inc_ptr[a]..inc_ptr[a + 1]] {
                        adj.extend(elem_nodes[e as usize].iter().map(|&b| b as u32));
                    }
                    let list = &mut adj[s..];
                    list.sort_unstable();
                    let mut k = 0;
                    for i in 0..list.len() {
                        if i == 0 || list[i] != list[k - 1] {
                            list[k] = list[i];
                            k += 1;
                        }
                    }
                    adj.truncate(s + k);
                    len.push(k);
                }
                (adj, len)
            })
            .collect();
        drop(inc);
        let mut node_ptr = Vec::with_capacity(n_nodes + 1);
        node_ptr.push(0usize);
        let mut node_adj = Vec::with_capacity(chunks.iter().map(|c| c.0.len()).sum());
        for (adj, len) in &chunks {
            node_adj.extend_from_slice(adj);
            for l in len {
                node_ptr.push(node_ptr.last().copied().unwrap_or(0) + l);
            }
        }
        drop(chunks);
        // Lower pattern over equations: column j = eq of (node a, dir), rows = eqs ≥ j among
        // the dofs of neighbours of a. Equations are numbered in node order, so sorting the
        // neighbour list sorts the rows.
        let n = dofs.n_eq;
        let cols: Vec<(Vec<usize>, Vec<usize>)> = (0..n_nodes.div_ceil(NODE_CHUNK))
            .into_par_iter()
            .map(|c| {
                let (a0, a1) = (c * NODE_CHUNK, ((c + 1) * NODE_CHUNK).min(n_nodes));
                let mut rows = Vec::with_capacity((a1 - a0) * 20);
                let mut len = Vec::with_capacity(2 * (a1 - a0));
                for a in a0..a1 {
                    for da in 0..2 {
                        let j = dofs.eq[2 * a + da];
                        if j == CONSTRAINED {
                            continue;
                        }
                        let s = rows.len();
                        for &b in &node_adj[node_ptr[a]..node_ptr[a + 1]] {
                            for db in 0..2 {
                                let i = dofs.eq[2 * b as usize + db];
                                if i != CONSTRAINED && i >= j {
                                    rows.push(i);
                                }
                            }
                        }
                        len.push(rows.len() - s);
                    }
                }
                (rows, len)
            })
            .collect();
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0usize);
        let mut row_idx = Vec::with_capacity(cols.iter().map(|c| c.0.len()).sum());
        for (rows, len) in &cols {
            row_idx.extend_from_slice(rows);
            for l in len {
                col_ptr.push(col_ptr.last().copied().unwrap_or(0) + l);
            }
        }
        drop(cols);
        let pattern = LowerPattern {
            n,
            col_ptr,
            row_idx,
        };
        let mut scatter_ptr = Vec::with_capacity(elem_nodes.len() + 1);
        scatter_ptr.push(0usize);
        for nodes in elem_nodes {
            let nd = 2 * nodes.len();
            scatter_ptr.push(scatter_ptr.last().copied().unwrap_or(0) + nd * nd);
        }
        // Each chunk of elements fills its own part of the map in place (collecting the
        // parts and joining them copied the whole map again: 64 MB at 5e5 dofs).
        let mut scatter = vec![0u32; scatter_ptr.last().copied().unwrap_or(0)];
        let mut parts: Vec<&mut [u32]> = Vec::with_capacity(elem_nodes.len().div_ceil(ELEM_CHUNK));
        let mut rest = &mut scatter[..];
        for c in 0..elem_nodes.len().div_ceil(ELEM_CHUNK) {
            let (e0, e1) = (c * ELEM_CHUNK, ((c + 1) * ELEM_CHUNK).min(elem_nodes.len()));
            let (part, tail) = rest.split_at_mut(scatter_ptr[e1] - scatter_ptr[e0]);
            parts.push(part);
            rest = tail;
        }
        parts
            .into_par_iter()
            .zip(elem_nodes.par_chunks(ELEM_CHUNK))
            .for_each(|(s, chunk)| {
                let mut eqs = Vec::new();
                let mut k = 0;
                for nodes in chunk {
                    eqs.clear();
                    eqs.extend(
                        nodes
                            .iter()
                            .flat_map(|&a| [dofs.eq[2 * a], dofs.eq[2 * a + 1]]),
                    );
                    for &i in &eqs {
                        for &j in &eqs {
                            s[k] = if i == CONSTRAINED || j == CONSTRAINED || i < j {
                                SKIP
                            } else {
                                pattern.position(i, j).expect("pattern covers element") as u32
                            };
                            k += 1;
                        }
                    }
                }
            });
        let (packed, packed_ptr) = pack(&scatter, &scatter_ptr);
        drop(scatter);
        Self {
            pattern: std::sync::Arc::new(pattern),
            node_ptr,
            node_adj,
            scatter_ptr,
            packed,
            packed_ptr,
        }
    }

    /// The node blocks of element `e` (of `n` nodes, 2 dofs each) that `add_matrix` reads:
    /// bit 9a + b is set when any entry of block (a, b) goes into the lower triangle
    /// (see [`crate::elements::continuum::NodeBlocks`]).
    pub fn node_blocks(&self, e: usize, n: usize) -> u128 {
        let nd = 2 * n;
        assert_eq!(
            self.scatter_ptr[e + 1] - self.scatter_ptr[e],
            nd * nd,
            "element {e}: not of {n} nodes"
        );
        let mut mask = 0u128;
        for &(l, _) in &self.packed[self.packed_ptr[e]..self.packed_ptr[e + 1]] {
            let (row, col) = (l as usize / nd, l as usize % nd);
            mask |= 1u128 << (9 * (row / 2) + col / 2);
        }
        mask
    }

    /// Add the dense row-major element matrix `k` of element `e` into `values`.
    #[inline]
    pub fn add_matrix(&self, e: usize, k: &[f64], values: &mut [f64]) {
        // A matrix of another size belongs to another element: a numbering error.
        assert_eq!(
            self.scatter_ptr[e + 1] - self.scatter_ptr[e],
            k.len(),
            "element {e}: matrix size and scatter map differ"
        );
        // The entries that are not SKIP, in the same order: the same additions.
        for &(l, p) in &self.packed[self.packed_ptr[e]..self.packed_ptr[e + 1]] {
            values[p as usize] += k[l as usize];
        }
    }
}

/// Assembled entries (element matrix index, value position) and the end or start of each
/// element's entries in them.
type Packed = (Vec<(u32, u32)>, Vec<usize>);

/// The assembled entries of every element's map ([`Assembler::packed`]) and their starts,
/// built chunk-parallel (the linear runs build the map once and assemble once or twice).
fn pack(scatter: &[u32], scatter_ptr: &[usize]) -> Packed {
    let n_el = scatter_ptr.len() - 1;
    let parts: Vec<Packed> = (0..n_el.div_ceil(ELEM_CHUNK))
        .into_par_iter()
        .map(|c| {
            let (e0, e1) = (c * ELEM_CHUNK, ((c + 1) * ELEM_CHUNK).min(n_el));
            let mut out = Vec::new();
            let mut ends = Vec::with_capacity(e1 - e0);
            for e in e0..e1 {
                let s = &scatter[scatter_ptr[e]..scatter_ptr[e + 1]];
                out.extend(
                    s.iter()
                        .enumerate()
                        .filter(|(_, &p)| p != SKIP)
                        .map(|(l, &p)| (l as u32, p)),
                );
                ends.push(out.len());
            }
            (out, ends)
        })
        .collect();
    let mut packed = Vec::with_capacity(parts.iter().map(|p| p.0.len()).sum());
    let mut ptr = Vec::with_capacity(n_el + 1);
    ptr.push(0);
    for (out, ends) in parts {
        let base = packed.len();
        ptr.extend(ends.iter().map(|&x| base + x));
        packed.extend_from_slice(&out);
    }
    (packed, ptr)
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
        // Its node blocks read by the scatter: (1, 1) alone (node 0 is fixed).
        assert_eq!(asm.node_blocks(0, 2), 1 << (9 + 1));
        // Element 1: nodes 1, 2 numbered in order, so the lower blocks (0,0), (1,0), (1,1).
        assert_eq!(asm.node_blocks(1, 2), 1 | 1 << 9 | 1 << 10);
    }
}
