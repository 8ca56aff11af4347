//! Fill-reducing ordering of large systems by geometric nested dissection.
//!
//! George's nested dissection with a geometric split in place of a graph partitioner: a
//! subdomain is cut in two along the longer side of its bounding box, the vertex separator
//! between the halves is numbered after both, and each half is dissected in turn. Both
//! dofs of a node stay together. Two variants:
//!
//! - [`nested_dissection`] (meshes of Q4 elements): the nodes are split at their median
//!   coordinate; the nodes of the lower half that touch the upper half form the separator.
//!   Subdomains of up to 48 nodes are numbered as they come.
//! - [`element_dissection`] (meshes with Q8/Q9 elements, or mixed): the continuum elements
//!   are split at their median centroid, so that the cut runs along element edges; the
//!   separator is the nodes both halves share (corner and mid-side nodes of the common
//!   edges), with any lower node coupled to an upper one outside the elements (joints,
//!   tendons); nodes in no element go by their coordinate. Split down to single elements.
//!   A median line through the nodes, as in the Q4 variant, cuts through quadratic
//!   elements: the separators double and the factor was 1.5× AMD's on a Q8 square.
//!
//! Against faer's approximate minimum degree (AMD), on segfem's plane meshes the factor is
//! about as sparse or sparser and the ordering cheaper (docs/performance.md): with Q4 at 1e6
//! dofs, 21 % fewer factor values and a 1.8× faster numeric factorisation on a clamped
//! square, 4 % more values and the same time on a 4:1 banded beam; with Q8, 3 % fewer
//! values on the RC beam refined 5× (49,704 equations), 4–31 % fewer on squares and
//! 4–25 % fewer on 4:1 banded beams from 2e4 to 5e5 dofs, numeric factorisation
//! 0.46–0.85× AMD's. Both are used from 20,000 equations ([`ND_MIN_EQUATIONS`],
//! [`ND_MIN_EQUATIONS_QUADRATIC`]). The element variant wins on every Q8/Q9 mesh measured
//! from there (and on a 40 × 40 Q8 square of 9,760 equations, by 5 %, see the tests); the
//! threshold is kept where it is so that smaller systems, all the bundled examples among
//! them, keep AMD and their results to the bit.

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Systems of Q4 elements with at least this many equations are ordered by nested
/// dissection ([`nested_dissection`]).
pub const ND_MIN_EQUATIONS: usize = 20_000;

/// Systems with Q8/Q9 elements with at least this many equations are ordered by nested
/// dissection along element edges ([`element_dissection`]).
pub const ND_MIN_EQUATIONS_QUADRATIC: usize = 20_000;

/// Subdomains of at most this many nodes are not split further (numbered as they come).
/// 4-node leaves give a smaller factor (clamped Q4 square of 499,000 equations: 56.7
/// instead of 61.6 million values, numeric factorisation 9 % faster; docs/performance.md,
/// session 15) but were not adopted: their round-off path stops a Q4 RC beam of 23,870
/// equations in its cracked phase (20.6 mm, no convergence) where 48- and 32-node leaves
/// complete it, and a run that stops is outside the tolerance for ordering changes.
const LEAF_NODES: usize = 48;

/// As [`LEAF_NODES`] for the element dissection: split down to single elements. Larger
/// leaves, numbered as they come, filled more: the factor of the RC beam refined 5× (49,704
/// equations) grew from 0.97× AMD's at 4 nodes to 0.99× at 8, 1.15× at 48 and 1.58× at 200.
const ELEMENT_LEAF_NODES: usize = 4;

/// Separator marker in the part labels.
const SEPARATOR: u32 = u32::MAX;

/// Reorder `items` so that those below the median of their points' coordinate along the
/// longer side of the points' bounding box come first; items tied with the median go to
/// the upper part. Returns the size of the lower part (half, if every item is tied), the
/// axis split (0: x, 1: y) and the median coordinate on it [m].
fn median_split(items: &mut [u32], point: impl Fn(u32) -> [f64; 2]) -> (usize, usize, f64) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &v in items.iter() {
        let p = point(v);
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let axis = usize::from(hi[1] - lo[1] > hi[0] - lo[0]);
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| point(*a)[axis].total_cmp(&point(*b)[axis]));
    let v = point(items[mid])[axis];
    let mut split = 0;
    for i in 0..mid {
        if point(items[i])[axis] < v {
            items.swap(i, split);
            split += 1;
        }
    }
    (if split == 0 { mid } else { split }, axis, v)
}

/// Subdomains from this many nodes have their two halves dissected in parallel (rayon).
/// The halves read and write the labels of their own nodes only (a node of one half has
/// no neighbour in the other: those are in the separator), and labels only need to be
/// distinct, so the order is the same as a sequential dissection's.
const PARALLEL_MIN_NODES: usize = 4096;

struct Dissection<'a> {
    node_ptr: &'a [usize],
    node_adj: &'a [u32],
    coords: &'a [[f64; 2]],
    /// Part label of each node: the subdomain currently holding it, or SEPARATOR (atomic
    /// with relaxed order, plain loads and stores on x86, for the parallel halves).
    part: Vec<AtomicU32>,
    next_label: AtomicU32,
    /// Subdomains from this many nodes are split in parallel ([`PARALLEL_MIN_NODES`];
    /// `usize::MAX` in the test that compares with the sequential order).
    parallel_min: usize,
}

impl<'a> Dissection<'a> {
    /// The dissection of the free nodes `nodes`, all labelled 1 (the others 0: fully
    /// constrained nodes carry no equation, a label no subdomain has).
    fn new(
        node_ptr: &'a [usize],
        node_adj: &'a [u32],
        coords: &'a [[f64; 2]],
        nodes: &[u32],
    ) -> Self {
        let part: Vec<AtomicU32> = (0..coords.len()).map(|_| AtomicU32::new(0)).collect();
        for &v in nodes {
            part[v as usize].store(1, Relaxed);
        }
        Self {
            node_ptr,
            node_adj,
            coords,
            part,
            next_label: AtomicU32::new(1),
            parallel_min: PARALLEL_MIN_NODES,
        }
    }

    /// A label no subdomain had.
    fn label(&self) -> u32 {
        self.next_label.fetch_add(1, Relaxed) + 1
    }

    /// Part label of node `v`.
    fn part(&self, v: usize) -> u32 {
        self.part[v].load(Relaxed)
    }

    fn set_part(&self, v: usize, label: u32) {
        self.part[v].store(label, Relaxed);
    }

    /// Append the elimination order of `nodes` (all labelled alike) to `out`.
    fn dissect_into(&self, nodes: &mut [u32], out: &mut Vec<u32>) {
        let start = out.len();
        out.resize(start + nodes.len(), 0);
        self.dissect(nodes, &mut out[start..]);
    }

    /// Write the elimination order of `nodes` (all labelled alike) into `out` (as long).
    fn dissect(&self, nodes: &mut [u32], out: &mut [u32]) {
        if nodes.len() <= LEAF_NODES {
            out.copy_from_slice(nodes);
            return;
        }
        // Nodes tied with the median go to the upper half, so that a grid line is never
        // split between the halves (the separator would be up to twice as large).
        let coords = self.coords;
        let (split, _, _) = median_split(nodes, |v| coords[v as usize]);
        let (lower, upper) = nodes.split_at_mut(split);
        let up = self.label();
        for &v in upper.iter() {
            self.set_part(v as usize, up);
        }
        // Separator: nodes of the lower half with a neighbour in the upper half. Moved to
        // the end of `lower`; the rest keep their relative order.
        let mut kept = 0;
        for i in 0..lower.len() {
            let v = lower[i] as usize;
            let touches = self.node_adj[self.node_ptr[v]..self.node_ptr[v + 1]]
                .iter()
                .any(|&w| self.part(w as usize) == up);
            if !touches {
                lower.swap(i, kept);
                kept += 1;
            }
        }
        let low = self.label();
        let (inner, sep) = lower.split_at_mut(kept);
        for &v in inner.iter() {
            self.set_part(v as usize, low);
        }
        for &v in sep.iter() {
            self.set_part(v as usize, SEPARATOR);
        }
        // The order: the lower half's, the upper half's, the separator.
        let (out_inner, rest) = out.split_at_mut(inner.len());
        let (out_upper, out_sep) = rest.split_at_mut(upper.len());
        out_sep.copy_from_slice(sep);
        if inner.len() + upper.len() >= self.parallel_min {
            rayon::join(
                || self.dissect(inner, out_inner),
                || self.dissect(upper, out_upper),
            );
        } else {
            self.dissect(inner, out_inner);
            self.dissect(upper, out_upper);
        }
    }
}

/// The continuum elements of a mesh for [`element_dissection`]: for each node the elements
/// holding it (compressed rows), and the elements' centroids [m].
struct Elements {
    inc_ptr: Vec<usize>,
    inc: Vec<u32>,
    centroid: Vec<[f64; 2]>,
    /// Part label of each element (the subdomain holding it).
    part: Vec<u32>,
}

impl Elements {
    /// The elements `elements` (node lists) of a mesh with nodes at `coords` [m], all in
    /// part 1.
    fn new(elements: &[Vec<usize>], coords: &[[f64; 2]]) -> Self {
        let (inc_ptr, inc) = super::pattern::incidence(coords.len(), elements);
        let centroid = elements
            .iter()
            .map(|el| {
                let s = el
                    .iter()
                    .fold([0.0; 2], |s, &a| [s[0] + coords[a][0], s[1] + coords[a][1]]);
                [s[0] / el.len() as f64, s[1] / el.len() as f64]
            })
            .collect();
        Elements {
            inc_ptr,
            inc,
            centroid,
            part: vec![1; elements.len()],
        }
    }
}

impl Dissection<'_> {
    /// Append the elimination order of `nodes` (all labelled `id`), the free nodes of the
    /// elements `elems` (all labelled `id` in `el.part`) and nodes in no element, to `out`.
    /// Every continuum element of a node in `nodes` is in `elems`.
    fn dissect_elements(
        &mut self,
        el: &mut Elements,
        elems: &mut [u32],
        nodes: &mut [u32],
        out: &mut Vec<u32>,
    ) {
        if nodes.len() <= ELEMENT_LEAF_NODES {
            out.extend_from_slice(nodes);
            return;
        }
        if elems.len() < 2 {
            // Nodes in no element (or one element's) left: split on their coordinates.
            return self.dissect_into(nodes, out);
        }
        let (split_e, n_low, n_up) = self.split_elements(el, elems, nodes);
        let (low_e, up_e) = elems.split_at_mut(split_e);
        let (low_n, rest) = nodes.split_at_mut(n_low);
        let (up_n, sep) = rest.split_at_mut(n_up);
        self.dissect_elements(el, low_e, low_n, out);
        self.dissect_elements(el, up_e, up_n, out);
        out.extend_from_slice(sep);
    }

    /// One level of the element dissection: the elements split at the median centroid
    /// along the longer side of their centroids' box (reordered lower half first, then the
    /// upper; labelled so), the nodes reordered into those of the lower half, of the upper
    /// half and the separator (labelled so). Returns the number of lower elements and of
    /// lower and upper nodes. The separator is every node shared by elements of both
    /// halves, then every lower node coupled (node graph: joints, tendons) to an upper one;
    /// a node in no element goes with the side of its coordinate.
    fn split_elements(
        &mut self,
        el: &mut Elements,
        elems: &mut [u32],
        nodes: &mut [u32],
    ) -> (usize, usize, usize) {
        // Elements tied with the median go to the upper half: a column (row) of elements
        // is never split, the separator is one line of element edges.
        let centroid = &el.centroid;
        let (split, axis, v) = median_split(elems, |e| centroid[e as usize]);
        let (low, up) = (self.label(), self.label());
        for (i, &e) in elems.iter().enumerate() {
            el.part[e as usize] = if i < split { low } else { up };
        }
        // Sides of the nodes from their elements: 1 lower, 2 upper, 3 both.
        let side = |a: u32| -> u8 {
            let a = a as usize;
            let mut s = 0;
            for &e in &el.inc[el.inc_ptr[a]..el.inc_ptr[a + 1]] {
                let p = el.part[e as usize];
                s |= u8::from(p == low) | (u8::from(p == up) << 1);
            }
            if el.inc_ptr[a] == el.inc_ptr[a + 1] {
                s = if self.coords[a][axis] < v { 1 } else { 2 };
            }
            s
        };
        let sides: Vec<u8> = nodes.iter().map(|&a| side(a)).collect();
        for (&a, &s) in nodes.iter().zip(&sides) {
            self.set_part(
                a as usize,
                match s {
                    1 => low,
                    2 => up,
                    _ => SEPARATOR,
                },
            );
        }
        // Lower nodes coupled to upper ones outside the elements join the separator.
        for &a in nodes.iter() {
            let a = a as usize;
            if self.part(a) == low
                && self.node_adj[self.node_ptr[a]..self.node_ptr[a + 1]]
                    .iter()
                    .any(|&w| self.part(w as usize) == up)
            {
                self.set_part(a, SEPARATOR);
            }
        }
        // Nodes reordered: lower, upper, separator (each in its previous order).
        let key = |a: &u32| match self.part(*a as usize) {
            p if p == low => 0u8,
            p if p == up => 1,
            _ => 2,
        };
        let mut sorted = Vec::with_capacity(nodes.len());
        for k in 0..3 {
            sorted.extend(nodes.iter().filter(|a| key(a) == k));
        }
        let n_low = sorted.iter().filter(|a| key(a) == 0).count();
        let n_up = sorted.iter().filter(|a| key(a) == 1).count();
        nodes.copy_from_slice(&sorted);
        (split, n_low, n_up)
    }
}

/// The free nodes of a system in node order, and the elimination order of the node list
/// turned into one of the free equations (both dofs of a node together).
fn free_nodes(eq: &[usize], n_eq: usize, n_nodes: usize) -> Vec<u32> {
    (0..n_nodes)
        .filter(|&a| eq[2 * a] < n_eq || eq[2 * a + 1] < n_eq)
        .map(|a| a as u32)
        .collect()
}

/// The equations of the nodes of `order`, node by node.
fn node_order_to_equations(order: &[u32], eq: &[usize], n_eq: usize) -> Vec<usize> {
    let mut perm = Vec::with_capacity(n_eq);
    for &v in order {
        for c in 0..2 {
            let q = eq[2 * v as usize + c];
            if q < n_eq {
                perm.push(q);
            }
        }
    }
    debug_assert_eq!(perm.len(), n_eq);
    perm
}

/// Elimination order of the free equations: `perm[k]` is the equation eliminated k-th.
/// `node_ptr`/`node_adj`: the node graph (compressed rows); `coords`: node coordinates [m];
/// `eq`: the equation of each dof (2 per node) or `CONSTRAINED`; `n_eq`: free equations.
pub fn nested_dissection(
    node_ptr: &[usize],
    node_adj: &[u32],
    coords: &[[f64; 2]],
    eq: &[usize],
    n_eq: usize,
) -> Vec<usize> {
    let n_nodes = coords.len();
    let mut nodes = free_nodes(eq, n_eq, n_nodes);
    let d = Dissection::new(node_ptr, node_adj, coords, &nodes);
    let mut order = vec![0; nodes.len()];
    d.dissect(&mut nodes, &mut order);
    node_order_to_equations(&order, eq, n_eq)
}

/// As [`nested_dissection`], splitting the continuum elements `elements` (node lists) rather
/// than the nodes: at their median centroid along the longer side, the separator being the
/// nodes the two halves share (whole element edges, mid-side nodes included) and the nodes
/// coupled across outside the elements (joints, tendons: `node_ptr`/`node_adj` hold every
/// coupling). For meshes with Q8/Q9 elements, whose mid-side nodes a median line through the
/// nodes would cut off. Nodes in no element are split on their coordinates.
pub fn element_dissection(
    node_ptr: &[usize],
    node_adj: &[u32],
    coords: &[[f64; 2]],
    elements: &[Vec<usize>],
    eq: &[usize],
    n_eq: usize,
) -> Vec<usize> {
    let n_nodes = coords.len();
    let mut nodes = free_nodes(eq, n_eq, n_nodes);
    let mut el = Elements::new(elements, coords);
    let mut elems: Vec<u32> = (0..elements.len() as u32).collect();
    let mut d = Dissection::new(node_ptr, node_adj, coords, &nodes);
    let mut order = Vec::with_capacity(nodes.len());
    d.dissect_elements(&mut el, &mut elems, &mut nodes, &mut order);
    node_order_to_equations(&order, eq, n_eq)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::dofs::DofMap;

    /// Grid graph of an m × m node lattice with 9-point (Q4) connectivity.
    fn grid(m: usize) -> (Vec<usize>, Vec<u32>, Vec<[f64; 2]>) {
        let mut ptr = vec![0];
        let mut adj = vec![];
        let mut xy = vec![];
        for j in 0..m {
            for i in 0..m {
                xy.push([i as f64, j as f64]);
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (a, b) = (i as i64 + di, j as i64 + dj);
                        if a >= 0 && b >= 0 && a < m as i64 && b < m as i64 {
                            adj.push((b as usize * m + a as usize) as u32);
                        }
                    }
                }
                ptr.push(adj.len());
            }
        }
        (ptr, adj, xy)
    }

    /// The halves dissected in parallel give the sequential order exactly (a grid of
    /// 40,000 nodes: subdomains down to 4,096 nodes split in parallel, some 16 of them).
    #[test]
    fn parallel_dissection_is_the_sequential_one() {
        let m = 200;
        let (ptr, adj, xy) = grid(m);
        let cons: Vec<(usize, f64)> = (0..m)
            .flat_map(|j| [(2 * j * m, 0.0), (2 * j * m + 1, 0.0)])
            .collect();
        let dofs = DofMap::new(m * m, &cons);
        let order = |parallel_min| {
            let mut nodes = free_nodes(&dofs.eq, dofs.n_eq, m * m);
            let mut d = Dissection::new(&ptr, &adj, &xy, &nodes);
            d.parallel_min = parallel_min;
            let mut out = vec![0; nodes.len()];
            d.dissect(&mut nodes, &mut out);
            out
        };
        let sequential = order(usize::MAX);
        for _ in 0..3 {
            assert_eq!(order(PARALLEL_MIN_NODES), sequential);
        }
        assert_eq!(
            nested_dissection(&ptr, &adj, &xy, &dofs.eq, dofs.n_eq),
            node_order_to_equations(&sequential, &dofs.eq, dofs.n_eq)
        );
    }

    /// Every free equation appears exactly once, constrained ones never.
    #[test]
    fn is_a_permutation_of_the_free_equations() {
        let m = 30;
        let (ptr, adj, xy) = grid(m);
        // Clamp the first column of nodes.
        let cons: Vec<(usize, f64)> = (0..m)
            .flat_map(|j| [(2 * j * m, 0.0), (2 * j * m + 1, 0.0)])
            .collect();
        let dofs = DofMap::new(m * m, &cons);
        let p = nested_dissection(&ptr, &adj, &xy, &dofs.eq, dofs.n_eq);
        let mut seen = vec![false; dofs.n_eq];
        for &q in &p {
            assert!(!seen[q]);
            seen[q] = true;
        }
        assert!(seen.iter().all(|s| *s));
    }

    /// The last nodes eliminated form the top-level separator: a full grid line through the
    /// middle (m nodes), which splits the rest into two parts with no edge between them.
    #[test]
    fn top_separator_splits_the_grid() {
        let m = 30;
        let (ptr, adj, xy) = grid(m);
        let dofs = DofMap::new(m * m, &[]);
        let p = nested_dissection(&ptr, &adj, &xy, &dofs.eq, dofs.n_eq);
        let order: Vec<usize> = p.iter().step_by(2).map(|q| q / 2).collect();
        let sep: Vec<usize> = order[order.len() - m..].to_vec();
        // All on one grid line (constant x: the box is square, the split is along x first).
        let x0 = xy[sep[0]][0];
        assert!(sep.iter().all(|&v| xy[v][0] == x0), "separator {sep:?}");
        // The nodes before it: none on one side of the line is adjacent to the other side.
        for &v in &order[..order.len() - m] {
            for &w in &adj[ptr[v]..ptr[v + 1]] {
                let w = w as usize;
                let side = |a: usize| xy[a][0].total_cmp(&x0);
                if !sep.contains(&w) {
                    assert_eq!(side(v), side(w));
                }
            }
        }
    }

    /// The ordering solves a 9-point grid system correctly and fills no more than AMD does
    /// (within 25 %): the reason to use it.
    #[test]
    fn factor_is_correct_and_as_sparse_as_amd() {
        use crate::linalg::solver::{LowerPattern, SparseCholesky};
        let m = 60;
        let (ptr, adj, xy) = grid(m);
        // One equation per node here (take the x dofs): the 9-point Laplacian shifted to be
        // positive definite, lower triangle.
        let n = m * m;
        let mut col_ptr = vec![0];
        let mut row_idx = vec![];
        let mut vals = vec![];
        for a in 0..n {
            for &b in &adj[ptr[a]..ptr[a + 1]] {
                let b = b as usize;
                if b >= a {
                    row_idx.push(b);
                    vals.push(if b == a { 8.5 } else { -1.0 });
                }
            }
            col_ptr.push(row_idx.len());
        }
        let p = LowerPattern {
            n,
            col_ptr,
            row_idx,
        };
        let eq: Vec<usize> = (0..n)
            .flat_map(|a| [a, crate::fem::dofs::CONSTRAINED])
            .collect();
        let order = nested_dissection(&ptr, &adj, &xy, &eq, n);
        assert_eq!(order.len(), n);
        let mut nd = SparseCholesky::with_ordering(&p, Some(&order)).unwrap();
        let amd = SparseCholesky::with_ordering(&p, None).unwrap();
        assert!(
            (nd.stats.factor_nnz as f64) < 1.25 * amd.stats.factor_nnz as f64,
            "nested dissection {} vs AMD {}",
            nd.stats.factor_nnz,
            amd.stats.factor_nnz
        );
        nd.factorize(&p, &vals).unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mut x = b.clone();
        nd.solve_in_place(&mut x);
        let mut ax = vec![0.0; n];
        p.sym_mul(&vals, &x, &mut ax);
        // Diagonally dominant (8.5 against 8 × 1): well conditioned, round-off only.
        let err = ax
            .iter()
            .zip(&b)
            .map(|(a, c)| (a - c).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "residual {err}");
    }
    /// A Q8/Q9 mesh for the element dissection: two blocks of `nx` × `ny` elements (each
    /// 1 m × 1 m) side by side with their own nodes on the joint line x = 1 m, coupled node
    /// to node there (a joint), and `extra` nodes in no element on y = 0.5 m, each coupled to
    /// the next and to the nearest corner of the mesh (a tendon). Returns the node graph,
    /// coordinates, continuum element node lists and all couplings.
    #[allow(clippy::type_complexity)]
    fn jointed_mesh(
        kind: crate::model::ElementKind,
        nx: usize,
        ny: usize,
        extra: usize,
    ) -> (Vec<[f64; 2]>, Vec<Vec<usize>>, Vec<Vec<usize>>) {
        use crate::mesh::banded::{generate, Band};
        let band = [Band {
            depth: 1.0,
            rows: ny,
            region: 0,
        }];
        let a = generate([0.0, 0.0], 1.0, nx, &band, kind);
        let b = generate([1.0, 0.0], 1.0, nx, &band, kind);
        let mut xy = a.nodes.clone();
        let off = xy.len();
        xy.extend_from_slice(&b.nodes);
        let mut elements: Vec<Vec<usize>> = a.elements.iter().map(|e| e.0.clone()).collect();
        elements.extend(
            b.elements
                .iter()
                .map(|e| e.0.iter().map(|&n| n + off).collect::<Vec<_>>()),
        );
        let mut couplings = elements.clone();
        for (i, p) in a.nodes.iter().enumerate() {
            if p[0] == 1.0 {
                let j = b.nodes.iter().position(|q| q == p).expect("joint partner");
                couplings.push(vec![i, j + off]);
            }
        }
        for k in 0..extra {
            let x = 2.0 * (k as f64 + 0.5) / extra as f64;
            let v = xy.len();
            xy.push([x, 0.5]);
            let near = (0..v)
                .min_by(|&p, &q| {
                    let d = |n: usize| (xy[n][0] - x).abs() + (xy[n][1] - 0.5).abs();
                    d(p).total_cmp(&d(q))
                })
                .expect("mesh nodes");
            couplings.push(vec![v, near]);
            if k > 0 {
                couplings.push(vec![v - 1, v]);
            }
        }
        (xy, elements, couplings)
    }

    /// The element dissection of a jointed Q8 mesh and a Q9 mesh with a clamped edge orders
    /// every free equation exactly once, constrained ones never.
    #[test]
    fn element_dissection_is_a_permutation() {
        use crate::fem::assembly::Assembler;
        use crate::model::ElementKind;
        for kind in [ElementKind::Q8, ElementKind::Q9] {
            let (xy, elements, couplings) = jointed_mesh(kind, 12, 9, 7);
            let cons: Vec<(usize, f64)> = (0..xy.len())
                .filter(|&a| xy[a][0] == 0.0)
                .flat_map(|a| [(2 * a, 0.0), (2 * a + 1, 0.0)])
                .chain([(2 * (xy.len() - 1), 0.0)])
                .collect();
            let dofs = DofMap::new(xy.len(), &cons);
            let asm = Assembler::new(xy.len(), &couplings, &dofs);
            let p = element_dissection(
                &asm.node_ptr,
                &asm.node_adj,
                &xy,
                &elements,
                &dofs.eq,
                dofs.n_eq,
            );
            assert_eq!(p.len(), dofs.n_eq, "{kind:?}");
            let mut seen = vec![false; dofs.n_eq];
            for &q in &p {
                assert!(!seen[q], "{kind:?}: equation {q} twice");
                seen[q] = true;
            }
            // Both equations of a node one after the other.
            for pair in p.chunks(2).take(20) {
                assert_eq!(pair[0] + 1, pair[1]);
            }
        }
    }

    /// Every separator of the element dissection separates: at each level of the recursion
    /// (followed here as `dissect_elements` does), no coupling of the node graph (element,
    /// joint or tendon) joins a node of the lower half to one of the upper half, and the
    /// three parts hold every node of the subdomain once. On the plain Q8 grid the top
    /// separator is one vertical line of element edges: 2 ny + 1 nodes, mid-side included.
    #[test]
    fn element_separators_separate() {
        use crate::fem::assembly::Assembler;
        use crate::model::ElementKind;
        fn check(
            d: &mut Dissection,
            el: &mut Elements,
            elems: &mut [u32],
            nodes: &mut [u32],
            levels: &mut usize,
        ) {
            if nodes.len() <= ELEMENT_LEAF_NODES || elems.len() < 2 {
                return;
            }
            let before: std::collections::BTreeSet<u32> = nodes.iter().copied().collect();
            let (split_e, n_low, n_up) = d.split_elements(el, elems, nodes);
            let after: std::collections::BTreeSet<u32> = nodes.iter().copied().collect();
            assert_eq!(before, after);
            assert!(n_low + n_up > 0);
            let (low_n, rest) = nodes.split_at_mut(n_low);
            let (up_n, _sep) = rest.split_at_mut(n_up);
            let up: std::collections::BTreeSet<u32> = up_n.iter().copied().collect();
            for &a in low_n.iter() {
                for &w in &d.node_adj[d.node_ptr[a as usize]..d.node_ptr[a as usize + 1]] {
                    assert!(!up.contains(&w), "nodes {a} and {w} across the separator");
                }
            }
            *levels += 1;
            let (low_e, up_e) = elems.split_at_mut(split_e);
            check(d, el, low_e, low_n, levels);
            check(d, el, up_e, up_n, levels);
        }
        for (extra, nx) in [(0, 10), (9, 10), (5, 3)] {
            let (xy, elements, couplings) = jointed_mesh(ElementKind::Q8, nx, 6, extra);
            let dofs = DofMap::new(xy.len(), &[]);
            let asm = Assembler::new(xy.len(), &couplings, &dofs);
            let mut nodes: Vec<u32> = (0..xy.len() as u32).collect();
            let mut d = Dissection::new(&asm.node_ptr, &asm.node_adj, &xy, &nodes);
            let mut el = Elements::new(&elements, &xy);
            let mut elems: Vec<u32> = (0..elements.len() as u32).collect();
            if extra == 0 && nx == 10 {
                // 20 × 6 elements: the top split is between columns 10 and 11, at the
                // joint (x = 1 m): the separator is the left block's 13 joint nodes.
                let (_, n_low, n_up) = d.split_elements(&mut el, &mut elems, &mut nodes);
                let sep = &nodes[n_low + n_up..];
                assert_eq!(sep.len(), 2 * 6 + 1, "{sep:?}");
                assert!(sep.iter().all(|&a| xy[a as usize][0] == 1.0));
                d = Dissection::new(&asm.node_ptr, &asm.node_adj, &xy, &nodes);
                el.part.iter_mut().for_each(|p| *p = 1);
            }
            let mut levels = 0;
            check(&mut d, &mut el, &mut elems, &mut nodes, &mut levels);
            assert!(levels >= 3, "{levels} levels");
        }
        // One block alone (10 × 6 elements): the top separator is the element edge line
        // x = 0.5 m, 13 nodes eliminated last.
        let (xy, elements, _) = jointed_mesh(ElementKind::Q8, 10, 6, 0);
        let elements = &elements[..60];
        let dofs = DofMap::new(xy.len(), &[]);
        let asm = Assembler::new(xy.len(), elements, &dofs);
        let p = element_dissection(
            &asm.node_ptr,
            &asm.node_adj,
            &xy,
            elements,
            &dofs.eq,
            dofs.n_eq,
        );
        let order: Vec<usize> = p.iter().step_by(2).map(|q| q / 2).collect();
        let sep = &order[order.len() - 13..];
        assert!(sep.iter().all(|&a| xy[a][0] == 0.5), "{sep:?}");
    }

    /// On a regular Q8 square of 40 × 40 elements (9,760 equations, clamped on one side as
    /// the bench's squares) the element dissection's factor is smaller than AMD's (800,432
    /// against 840,176 values when written), and much smaller than that of the dissection
    /// along node coordinates, whose median lines cut through the elements (1,250,416).
    #[test]
    fn element_dissection_factor_vs_amd() {
        use crate::fem::assembly::Assembler;
        use crate::linalg::solver::SparseCholesky;
        use crate::mesh::banded::{generate, Band};
        use crate::model::ElementKind;
        let n = 40;
        let band = [Band {
            depth: 1.0,
            rows: n,
            region: 0,
        }];
        let g = generate([0.0, 0.0], 1.0, n, &band, ElementKind::Q8);
        let elements: Vec<Vec<usize>> = g.elements.iter().map(|e| e.0.clone()).collect();
        let cons: Vec<(usize, f64)> = (0..g.nodes.len())
            .filter(|&a| g.nodes[a][0] == 0.0)
            .flat_map(|a| [(2 * a, 0.0), (2 * a + 1, 0.0)])
            .collect();
        let dofs = DofMap::new(g.nodes.len(), &cons);
        let asm = Assembler::new(g.nodes.len(), &elements, &dofs);
        let order = element_dissection(
            &asm.node_ptr,
            &asm.node_adj,
            &g.nodes,
            &elements,
            &dofs.eq,
            dofs.n_eq,
        );
        let nd = SparseCholesky::with_ordering(&asm.pattern, Some(&order)).unwrap();
        let amd = SparseCholesky::with_ordering(&asm.pattern, None).unwrap();
        let node = SparseCholesky::with_ordering(
            &asm.pattern,
            Some(&nested_dissection(
                &asm.node_ptr,
                &asm.node_adj,
                &g.nodes,
                &dofs.eq,
                dofs.n_eq,
            )),
        )
        .unwrap();
        let (e, n, a) = (
            nd.stats.factor_nnz as f64,
            node.stats.factor_nnz as f64,
            amd.stats.factor_nnz as f64,
        );
        assert!(e < a, "element dissection {e} vs AMD {a}");
        assert!(n > 1.3 * e, "node dissection {n} vs element dissection {e}");
    }
}
