//! Sparse assembly: the lower-triangle pattern is computed once from the element
//! connectivities; each element keeps the positions of its entries in the value array, so
//! refilling values is a scatter with no search and no allocation.

use super::dofs::{DofMap, CONSTRAINED};
use crate::linalg::pattern::{incidence, LowerPattern};
use rayon::prelude::*;

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
        // neighbour list sorts the rows. Counted first, then written in place chunk-parallel
        // (collecting per-chunk rows and joining them faulted in and copied the pattern
        // twice: 38 MB at 5e5 dofs).
        let n = dofs.n_eq;
        let n_chunks = n_nodes.div_ceil(NODE_CHUNK);
        let node_range = |c: usize| c * NODE_CHUNK..((c + 1) * NODE_CHUNK).min(n_nodes);
        // The rows of column (a, da) in increasing order, given j = its equation.
        let rows_of = |a: usize, j: usize| {
            node_adj[node_ptr[a]..node_ptr[a + 1]]
                .iter()
                .flat_map(|&b| [dofs.eq[2 * b as usize], dofs.eq[2 * b as usize + 1]])
                .filter(move |&i| i != CONSTRAINED && i >= j)
        };
        let counts: Vec<Vec<usize>> = (0..n_chunks)
            .into_par_iter()
            .map(|c| {
                let mut len = Vec::with_capacity(2 * NODE_CHUNK);
                for a in node_range(c) {
                    for da in 0..2 {
                        let j = dofs.eq[2 * a + da];
                        if j != CONSTRAINED {
                            len.push(rows_of(a, j).count());
                        }
                    }
                }
                len
            })
            .collect();
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0usize);
        for l in counts.iter().flatten() {
            col_ptr.push(col_ptr.last().copied().unwrap_or(0) + l);
        }
        // Each chunk's columns are consecutive equations (numbered in node order).
        let mut chunk_start = Vec::with_capacity(n_chunks + 1);
        chunk_start.push(0usize);
        for len in &counts {
            chunk_start.push(chunk_start.last().copied().unwrap_or(0) + len.len());
        }
        drop(counts);
        let mut row_idx = vec![0usize; col_ptr[n]];
        split_parts(&mut row_idx, n_chunks, |c| {
            col_ptr[chunk_start[c + 1]] - col_ptr[chunk_start[c]]
        })
        .into_par_iter()
        .enumerate()
        .for_each(|(c, part)| {
            let mut k = 0;
            for a in node_range(c) {
                for da in 0..2 {
                    let j = dofs.eq[2 * a + da];
                    if j != CONSTRAINED {
                        for i in rows_of(a, j) {
                            part[k] = i;
                            k += 1;
                        }
                    }
                }
            }
        });
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
        let (packed, packed_ptr) = pack(&pattern, elem_nodes, dofs);
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
        // The assembled entries in the matrix's row-major order: the same additions as a
        // walk over the whole matrix.
        for &(l, p) in &self.packed[self.packed_ptr[e]..self.packed_ptr[e + 1]] {
            values[p as usize] += k[l as usize];
        }
    }
}

/// Assembled entries (element matrix index, value position) and the start of each element's
/// entries in them (length: elements + 1).
type Packed = (Vec<(u32, u32)>, Vec<usize>);

/// The assembled entries of every element's matrix ([`Assembler::packed`]) and their starts:
/// counted, then written in place chunk-parallel (a full map with markers for the entries
/// left out, packed afterwards, faulted in and wrote 64 + 72 MB more at 5e5 dofs).
fn pack(pattern: &LowerPattern, elem_nodes: &[Vec<usize>], dofs: &DofMap) -> Packed {
    let n_el = elem_nodes.len();
    let el_chunks = n_el.div_ceil(ELEM_CHUNK);
    // The equations of an element's dofs, in its matrix numbering.
    let eqs_of = |nodes: &[usize], eqs: &mut Vec<usize>| {
        eqs.clear();
        eqs.extend(
            nodes
                .iter()
                .flat_map(|&a| [dofs.eq[2 * a], dofs.eq[2 * a + 1]]),
        );
    };
    let assembled = |i: usize, j: usize| i != CONSTRAINED && j != CONSTRAINED && i >= j;
    let ends: Vec<Vec<usize>> = elem_nodes
        .par_chunks(ELEM_CHUNK)
        .map(|chunk| {
            let mut eqs = Vec::new();
            let mut total = 0;
            chunk
                .iter()
                .map(|nodes| {
                    eqs_of(nodes, &mut eqs);
                    total += eqs
                        .iter()
                        .map(|&i| eqs.iter().filter(|&&j| assembled(i, j)).count())
                        .sum::<usize>();
                    total
                })
                .collect()
        })
        .collect();
    let mut packed_ptr = Vec::with_capacity(n_el + 1);
    packed_ptr.push(0usize);
    for e in &ends {
        let base = packed_ptr.last().copied().unwrap_or(0);
        packed_ptr.extend(e.iter().map(|&x| base + x));
    }
    drop(ends);
    let el_range = |c: usize| c * ELEM_CHUNK..((c + 1) * ELEM_CHUNK).min(n_el);
    let mut packed = vec![(0u32, 0u32); packed_ptr[n_el]];
    split_parts(&mut packed, el_chunks, |c| {
        let r = el_range(c);
        packed_ptr[r.end] - packed_ptr[r.start]
    })
    .into_par_iter()
    .zip(elem_nodes.par_chunks(ELEM_CHUNK))
    .for_each(|(s, chunk)| {
        let mut eqs = Vec::new();
        let mut k = 0;
        for nodes in chunk {
            eqs_of(nodes, &mut eqs);
            let nd = eqs.len();
            for (li, &i) in eqs.iter().enumerate() {
                for (lj, &j) in eqs.iter().enumerate() {
                    if assembled(i, j) {
                        let p = pattern.position(i, j).expect("pattern covers element");
                        s[k] = ((li * nd + lj) as u32, p as u32);
                        k += 1;
                    }
                }
            }
        }
    });
    (packed, packed_ptr)
}

/// `v` cut into `parts` consecutive slices, part c of `len(c)` entries.
fn split_parts<T>(v: &mut [T], parts: usize, len: impl Fn(usize) -> usize) -> Vec<&mut [T]> {
    let mut out = Vec::with_capacity(parts);
    let mut rest = v;
    for c in 0..parts {
        let (part, tail) = rest.split_at_mut(len(c));
        out.push(part);
        rest = tail;
    }
    out
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
