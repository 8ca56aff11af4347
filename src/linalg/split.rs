//! Subtree parallelism of the sparse Cholesky factorisation on two cores: the two halves of
//! the top-level nested dissection factorised at once, then the separator.
//!
//! With the elimination order of [`super::ordering`], the permuted matrix is
//!
//! ```text
//! P A Pᵀ = [A11  0   A13]          L = [L11  0    0 ]
//!          [ 0  A22  A23]              [ 0  L22   0 ]
//!          [A31 A32  A33]              [L31 L32  L33]
//! ```
//!
//! (half 1, half 2, the top separator last). Each half's border matrix
//! Bᵢ = [Aᵢᵢ Aᵢ₃; A₃ᵢ A33] is a principal submatrix of A, positive definite when A is; its
//! sparse LLᵀ (faer's supernodal factorisation, one core each, both at once) gives Lᵢᵢ, L₃ᵢ
//! and a trailing block Mᵢ with Mᵢ Mᵢᵀ = A33 − L₃ᵢ L₃ᵢᵀ. The separator's Schur complement is
//! then S = M₁M₁ᵀ + M₂M₂ᵀ − A33 = A33 − L31 L31ᵀ − L32 L32ᵀ, and L33 its dense Cholesky
//! factor. The solves run forward through both halves at once (each adding −L₃ᵢ yᵢ to the
//! separator's right-hand side), through L33 and L33ᵀ, and back through both halves at once.
//!
//! An indefinite matrix (a nonlinear tangent past a limit point) goes by halves too
//! ([`SplitCholesky::factorize_indefinite`]): a half whose LLᵀ fails is factorised by faer's
//! LDLᵀ without pivoting, which gives Lᵢᵢ, Dᵢ, L₃ᵢ and a trailing block with
//! Mᵢ D̃ᵢ Mᵢᵀ = A33 − L₃ᵢ Dᵢ L₃ᵢᵀ; S = M₁D̃₁M₁ᵀ + M₂D̃₂M₂ᵀ − A33 gets a dense LDLᵀ. By
//! Sylvester's law of inertia on P A Pᵀ = L D Lᵀ, D = diag(D1, D2, D3), the negative pivots
//! of A are those of D1, D2 (the halves' own columns) and D3 (docs/theory.md, "LDLᵀ by
//! halves").
//!
//! The price is the separator's dense work three times on the critical path (in Bᵢ, in
//! MᵢMᵢᵀ, in S) instead of once: small for the plane meshes' separators (a cross-section of
//! the mesh), against half of everything below them.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::matmul::triangular::BlockStructure;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Accum, MatMut, MatRef, Par, Side};

use super::solver::{
    fault_in, supernodal_in_order, LowerPattern, SINGULAR_PIVOT, TOUCH_AHEAD_VALUES,
};

/// One supernode of a half's factor: its first column `b`, its `ncols` columns, the rows
/// below them (`pat`) and its values `blk`, column-major with `ncols + pat.len()` rows.
struct Supernode<'a> {
    b: usize,
    ncols: usize,
    pat: &'a [usize],
    blk: &'a [f64],
}

/// The supernodes of a half's factor, in elimination order.
fn supernodes<'a>(
    symbolic: &'a SymbolicCholesky<usize>,
    l_values: &'a [f64],
) -> impl DoubleEndedIterator<Item = Supernode<'a>> + 'a {
    let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else {
        unreachable!("the halves are analysed supernodal");
    };
    let (begin, end, cpv) = (
        sn.supernode_begin(),
        sn.supernode_end(),
        sn.col_ptr_for_val(),
    );
    (0..sn.n_supernodes()).map(move |k| Supernode {
        b: begin[k],
        ncols: end[k] - begin[k],
        pat: sn.supernode(k).pattern(),
        blk: &l_values[cpv[k]..cpv[k + 1]],
    })
}

const NONE: usize = usize::MAX;

/// The top-level split of an elimination order: half 1 is `[0, n1)`, half 2 `[n1, n1 + n2)`,
/// the separator `[n1 + n2, n)` (positions in the order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopSplit {
    pub n1: usize,
    pub n2: usize,
    pub s: usize,
}

/// The top-level split of the lower-triangle matrix whose upper-triangle pattern (the
/// transpose: column i holds the rows k ≤ i) is `up_ptr`/`up_idx`, eliminated as it stands,
/// from its elimination tree: the chain of single-child nodes from the root down is the
/// separator, and the subtrees below it are shared out between the two halves (the
/// prefix of them, in postorder, that balances the halves' columns best). None when the
/// tree does not split (a chain, a forest, an order that is not postordered).
pub fn top_split(n: usize, up_ptr: &[usize], up_idx: &[u32]) -> Option<TopSplit> {
    if n < 3 {
        return None;
    }
    // Liu's elimination tree with path compression.
    let mut parent = vec![NONE; n];
    let mut ancestor = vec![NONE; n];
    for i in 0..n {
        for &k in &up_idx[up_ptr[i]..up_ptr[i + 1]] {
            let k = k as usize;
            if k >= i {
                continue;
            }
            let mut r = k;
            while ancestor[r] != NONE && ancestor[r] != i {
                let t = ancestor[r];
                ancestor[r] = i;
                r = t;
            }
            if ancestor[r] == NONE {
                ancestor[r] = i;
                parent[r] = i;
            }
        }
    }
    let mut size = vec![1usize; n];
    let mut n_children = vec![0usize; n];
    for v in 0..n {
        if parent[v] != NONE {
            if parent[v] <= v {
                return None;
            }
            size[parent[v]] += size[v];
            n_children[parent[v]] += 1;
        }
    }
    // A single root (a connected matrix): walk down its chain of single children.
    if parent[n - 1] != NONE || (0..n - 1).any(|v| parent[v] == NONE) {
        return None;
    }
    let mut sep0 = n - 1;
    while n_children[sep0] == 1 {
        // Postorder: the only child of v is v − 1.
        if sep0 == 0 || parent[sep0 - 1] != sep0 {
            return None;
        }
        sep0 -= 1;
    }
    if n_children[sep0] == 0 {
        return None;
    }
    // The children of the separator's lowest node, with the ranges of their subtrees: in
    // postorder these tile [0, sep0).
    let mut children: Vec<usize> = (0..sep0).filter(|&v| parent[v] == sep0).collect();
    children.sort_unstable();
    let mut start = 0;
    for &c in &children {
        if c + 1 < size[c] || c + 1 - size[c] != start {
            return None;
        }
        start = c + 1;
    }
    if start != sep0 {
        return None;
    }
    // The prefix of subtrees whose columns come nearest half of [0, sep0).
    let mut best = (sep0, 0);
    for &c in &children[..children.len() - 1] {
        let n1 = c + 1;
        let d = n1.abs_diff(sep0 - n1);
        if d < best.0 {
            best = (d, n1);
        }
    }
    let n1 = best.1;
    if n1 == 0 || n1 >= sep0 {
        return None;
    }
    Some(TopSplit {
        n1,
        n2: sep0 - n1,
        s: n - sep0,
    })
}

/// One half's border matrix Bᵢ, its analysis and factor.
struct Half {
    /// Columns of the half itself (Bᵢ has `m + s`).
    m: usize,
    /// Lower-triangle pattern of Bᵢ.
    pattern: SymbolicSparseColMat<usize>,
    /// For each stored entry of `pattern`, its position in the caller's value array (32 bits:
    /// the analysis is made only below `u32::MAX` entries).
    source: Vec<u32>,
    values: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// The numeric factorisation's scratch (LLᵀ or LDLᵀ), given back by
    /// [`SplitCholesky::release`] and allocated anew by the next factorisation.
    mem: MemBuffer,
    mem_req: StackReq,
    /// Mᵢ (dense s × s, column-major, lower; unit diagonal after an LDLᵀ) and then
    /// Mᵢ Mᵢᵀ or Mᵢ Dᵢ Mᵢᵀ (lower).
    m33: Vec<f64>,
    schur: Vec<f64>,
    /// Whether the factor in `l_values` is an LDLᵀ (D on the supernodes' diagonals, L
    /// unit) rather than an LLᵀ.
    ldlt: bool,
    /// Whether the last factorisation was an LDLᵀ of an indefinite Bᵢ (a negative pivot of
    /// its own or trailing block): the next indefinite factorisation goes to LDLᵀ at once.
    indefinite: bool,
    /// After an LDLᵀ: the trailing block's pivots Dᵢ (s) and Mᵢ Dᵢ (s × s, allocated at the
    /// first LDLᵀ).
    d33: Vec<f64>,
    md: Vec<f64>,
    /// Solve scratch: the half's right-hand side (its `m` unknowns and the separator's `s`)
    /// and the gathered rows of one supernode.
    x: Vec<f64>,
    work: Vec<f64>,
}

/// How a numeric factorisation of the split ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitOutcome {
    /// Positive definite, no pivot at round-off of its diagonal entry.
    Ok,
    /// A pivot not positive, or tiny (position in the elimination order).
    NotPositiveDefinite(usize),
}

/// How an indefinite factorisation by halves ([`SplitCholesky::factorize_indefinite`]) ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IndefiniteOutcome {
    /// Positive definite: LLᵀ in both halves and the separator, the factor
    /// [`SplitCholesky::factorize`] gives.
    Llt,
    /// LDLᵀ in at least one block (the others LLᵀ); the number of negative pivots of the
    /// whole matrix (Sylvester: the halves' own ones and the separator's).
    Ldlt(usize),
    /// A pivot of D zero, not finite, or at most [`SINGULAR_PIVOT`] of the largest.
    Singular,
    /// A half's trailing block could not be used (its LDLᵀ met a zero pivot there, or grew
    /// past [`TRAILING_GROWTH`]): the caller factorises the whole matrix.
    Whole,
}

/// Largest growth of a half's trailing LDLᵀ, max_j Σ_k M_jk² |D_k| against the larger of
/// the largest diagonal entries of A33 and of Mᵢ Dᵢ Mᵢᵀ (1 or less when Bᵢ is positive
/// definite), for its product Mᵢ Dᵢ Mᵢᵀ to stand in for A33 − L₃ᵢ Dᵢ L₃ᵢᵀ: the product's
/// round-off is ~1e-16 of that growth, so at most ~1e-10 of the separator's entries.
pub const TRAILING_GROWTH: f64 = 1e6;

/// Why a half's factorisation failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum HalfFail {
    /// An LLᵀ pivot (position in Bᵢ) not positive, or round-off of its diagonal entry.
    NotPositive(usize),
    /// An LDLᵀ pivot of the half's own columns zero or not finite.
    Singular,
    /// The LDLᵀ's trailing block unusable (a zero pivot there, or growth).
    Trailing,
}

/// Pivots of the half's own columns (l_jj² of an LLᵀ, D_j of an LDLᵀ): the largest and
/// smallest magnitudes, the negative ones, and whether all are finite.
#[derive(Debug, Clone, Copy)]
struct Pivots {
    max: f64,
    min: f64,
    negative: usize,
    finite: bool,
}

impl Pivots {
    fn new() -> Self {
        Self {
            max: 0.0,
            min: f64::INFINITY,
            negative: 0,
            finite: true,
        }
    }

    fn add(&mut self, d: f64) {
        self.max = self.max.max(d.abs());
        self.min = self.min.min(d.abs());
        self.negative += usize::from(d < 0.0);
        self.finite &= d.is_finite();
    }

    fn join(self, o: Self) -> Self {
        Self {
            max: self.max.max(o.max),
            min: self.min.min(o.min),
            negative: self.negative + o.negative,
            finite: self.finite && o.finite,
        }
    }
}

/// The split factorisation: both halves and the separator's dense factor.
pub struct SplitCholesky {
    pub split: TopSplit,
    halves: [Half; 2],
    /// The separator block A33: (dense position in the s × s column-major lower block,
    /// position in the caller's value array).
    a33: Vec<(usize, usize)>,
    /// S and then its Cholesky factor L33, or its LDLᵀ factor (unit L33 below the
    /// diagonal, D33 on it) when `s_ldlt` (dense s × s column-major, lower).
    l33: Vec<f64>,
    s_ldlt: bool,
    mem33: MemBuffer,
    /// `order[k]`: the original equation eliminated k-th.
    order: Vec<usize>,
}

impl SplitCholesky {
    /// The split analysis of `pattern` eliminated in the order `order` (`inverse`: its
    /// inverse), or None when the order has no top-level split.
    // long: one pass over the pattern building both halves' border matrices and the separator block from the same transpose
    pub fn new(
        pattern: &LowerPattern,
        order: &[usize],
        inverse: &[usize],
    ) -> Result<Option<Self>, String> {
        let n = pattern.n;
        if n.max(pattern.nnz()) >= u32::MAX as usize {
            return Ok(None);
        }
        // Each stored entry's (row, column) in P A Pᵀ, lower triangle.
        let at = |j: usize, p: usize| {
            let (a, b) = (inverse[pattern.row_idx[p]], inverse[j]);
            (a.max(b), a.min(b))
        };
        // The upper triangle of P A Pᵀ (column r holds the rows c ≤ r, unsorted): its
        // elimination tree.
        let mut up_ptr = vec![0usize; n + 1];
        for j in 0..n {
            for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                up_ptr[at(j, p).0 + 1] += 1;
            }
        }
        for r in 0..n {
            up_ptr[r + 1] += up_ptr[r];
        }
        // Each entry's row and its position in the caller's values (32 bits: the pattern
        // is read once here, the halves are built from this transpose).
        let mut next = up_ptr[..n].to_vec();
        let mut up_idx = vec![0u32; pattern.nnz()];
        let mut up_src = vec![0u32; pattern.nnz()];
        for j in 0..n {
            for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let (r, c) = at(j, p);
                up_idx[next[r]] = c as u32;
                up_src[next[r]] = p as u32;
                next[r] += 1;
            }
        }
        drop(next);
        let Some(split) = top_split(n, &up_ptr, &up_idx) else {
            return Ok(None);
        };
        let TopSplit { n1, n2, s } = split;
        let sep0 = n1 + n2;
        // Half i's border matrix in its own numbering: the half's columns first, the
        // separator's after (None: an entry of the other half).
        let local = |half: usize, g: usize| -> Option<usize> {
            match half {
                0 if g < n1 => Some(g),
                0 if g >= sep0 => Some(g - n2),
                1 if g >= n1 => Some(g - n1),
                _ => None,
            }
        };
        let (up_ptr, up_idx, up_src) = (&up_ptr, &up_idx, &up_src);
        let half = |h: usize, m: usize| -> Result<Half, String> {
            let nb = m + s;
            // The half's columns of the upper triangle, in increasing order (the local
            // numbering keeps the order).
            let columns = || {
                let own = if h == 0 { 0..n1 } else { n1..sep0 };
                own.chain(sep0..n).map(|r| (r, up_ptr[r]..up_ptr[r + 1]))
            };
            // The lower triangle of Bᵢ: column c holds its rows r in increasing order,
            // as the upper columns r come.
            let mut col_ptr = vec![0usize; nb + 1];
            for (r, range) in columns() {
                for &c in &up_idx[range] {
                    match local(h, c as usize) {
                        Some(c) => col_ptr[c + 1] += 1,
                        // A column of half 2 with a row of half 1 (the elimination tree
                        // rules it out).
                        None if r < sep0 => return Err("top split: the halves are coupled".into()),
                        None => {}
                    }
                }
            }
            for c in 0..nb {
                col_ptr[c + 1] += col_ptr[c];
            }
            let mut next = col_ptr[..nb].to_vec();
            let nnz = col_ptr[nb];
            let mut row_idx = vec![0usize; nnz];
            let mut source = vec![0u32; nnz];
            for (r, range) in columns() {
                let rl = local(h, r).expect("the half's own column");
                for q in range {
                    if let Some(c) = local(h, up_idx[q] as usize) {
                        row_idx[next[c]] = rl;
                        source[next[c]] = up_src[q];
                        next[c] += 1;
                    }
                }
            }
            drop(next);
            // faer analyses the upper triangle when given no ordering: the transpose (its
            // columns' rows come sorted, in column order).
            let mut up_ptr = vec![0usize; nb + 1];
            for &r in &row_idx {
                up_ptr[r + 1] += 1;
            }
            for r in 0..nb {
                up_ptr[r + 1] += up_ptr[r];
            }
            let mut next = up_ptr[..nb].to_vec();
            let mut up_idx = vec![0usize; nnz];
            for c in 0..nb {
                for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                    up_idx[next[r]] = c;
                    next[r] += 1;
                }
            }
            drop(next);
            let pattern = SymbolicSparseColMat::new_checked(nb, nb, col_ptr, None, row_idx);
            let upper = SymbolicSparseColMatRef::new_checked(nb, nb, &up_ptr, None, &up_idx);
            let symbolic = supernodal_in_order(upper)?;
            let req = symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
                .or(symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()));
            let l_values = vec![0.0; symbolic.len_val()];
            let mem = MemBuffer::try_new(req).map_err(|e| format!("{e:?}"))?;
            Ok(Half {
                m,
                pattern,
                source,
                values: vec![0.0; nnz],
                l_values,
                mem,
                mem_req: req,
                symbolic,
                m33: vec![0.0; s * s],
                schur: vec![0.0; s * s],
                ldlt: false,
                indefinite: false,
                d33: vec![0.0; s],
                md: Vec::new(),
                x: vec![0.0; nb],
                work: Vec::new(),
            })
        };
        let (h1, h2) = rayon::join(|| half(0, n1), || half(1, n2));
        let (mut h1, mut h2) = (h1?, h2?);
        // The factors' pages faulted in now (an analysis of a large system runs beside the
        // assembly), not in the first factorisation; both halves at once, after both are
        // allocated: a half's allocation (mmap) waits for the mmap lock that the other's
        // population holds, which serialised the two at 5e5 equations (0.1 s of one core
        // idle).
        if h1.l_values.len() + h2.l_values.len() >= TOUCH_AHEAD_VALUES {
            rayon::join(|| h1.fault_in(), || h2.fault_in());
        }
        // The separator block A33 (dense positions).
        let mut a33 = Vec::new();
        for &i in &order[sep0..] {
            for p in pattern.col_ptr[i]..pattern.col_ptr[i + 1] {
                let (r, c) = at(i, p);
                if c >= sep0 {
                    a33.push(((r - sep0) + (c - sep0) * s, p));
                }
            }
        }
        let req = faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
            s,
            Par::Seq,
            Default::default(),
        )
        .or(
            faer::linalg::cholesky::ldlt::factor::cholesky_in_place_scratch::<f64>(
                s,
                Par::Seq,
                Default::default(),
            ),
        );
        Ok(Some(Self {
            split,
            halves: [h1, h2],
            a33,
            l33: vec![0.0; s * s],
            s_ldlt: false,
            mem33: MemBuffer::try_new(req).map_err(|e| format!("{e:?}"))?,
            order: order.to_vec(),
        }))
    }

    /// Stored factor values (both halves and the dense separator block).
    pub fn factor_len(&self) -> usize {
        self.halves
            .iter()
            .map(|h| h.symbolic.len_val())
            .sum::<usize>()
            + self.split.s * self.split.s
    }

    /// Give the factor values and the halves' scratch back (the analysis stays; the next
    /// factorisation allocates both anew).
    pub fn release(&mut self) -> (Vec<Vec<f64>>, Vec<MemBuffer>) {
        self.halves
            .iter_mut()
            .map(|h| {
                (
                    std::mem::take(&mut h.l_values),
                    std::mem::replace(&mut h.mem, MemBuffer::new(StackReq::EMPTY)),
                )
            })
            .unzip()
    }

    /// `order[k]`: the original equation eliminated k-th.
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// Numeric LLᵀ of the matrix with these values (the caller's pattern). `tiny`: the
    /// relative pivot size l_jj² ≤ tiny a_jj counted as zero.
    pub fn factorize(&mut self, values: &[f64], tiny: f64) -> SplitOutcome {
        let TopSplit { n1, n2, .. } = self.split;
        let [h1, h2] = &mut self.halves;
        let (r1, r2) = rayon::join(
            || h1.factorize(values, tiny, false),
            || h2.factorize(values, tiny, false),
        );
        // Positions in the elimination order of a failed pivot (local to the half).
        let global = |r: Result<Pivots, HalfFail>, m: usize, off: usize| match r {
            Err(HalfFail::NotPositive(k)) if k < m => Some(off + k),
            Err(HalfFail::NotPositive(k)) => Some(n1 + n2 + (k - m)),
            Err(_) => unreachable!("an LLᵀ fails by a pivot"),
            Ok(_) => None,
        };
        let bad = [global(r1, n1, 0), global(r2, n2, n1)];
        if let Some(k) = bad.into_iter().flatten().min() {
            return SplitOutcome::NotPositiveDefinite(k);
        }
        match self.separator_llt(values, tiny) {
            Ok(()) => SplitOutcome::Ok,
            Err(j) => SplitOutcome::NotPositiveDefinite(n1 + n2 + j),
        }
    }

    /// Numeric factorisation of a symmetric matrix that may be indefinite, by halves: each
    /// half's border matrix by LLᵀ, or by LDLᵀ (no pivoting) where its LLᵀ fails or where
    /// the border matrix was indefinite at the last factorisation; the
    /// separator's S by dense LLᵀ when both halves went by LLᵀ and it is positive definite,
    /// else by dense LDLᵀ (no pivoting). `tiny`: as in [`SplitCholesky::factorize`].
    pub fn factorize_indefinite(&mut self, values: &[f64], tiny: f64) -> IndefiniteOutcome {
        let [h1, h2] = &mut self.halves;
        // A half whose border matrix was indefinite at the last factorisation goes to LDLᵀ at
        // once (its LLᵀ attempt would most likely fail again, after part of the work).
        let run = |h: &mut Half| {
            if h.indefinite {
                return h.factorize(values, tiny, true);
            }
            match h.factorize(values, tiny, false) {
                Err(HalfFail::NotPositive(_)) => h.factorize(values, tiny, true),
                r => r,
            }
        };
        let (r1, r2) = rayon::join(|| run(h1), || run(h2));
        let pivots = match (r1, r2) {
            (Ok(a), Ok(b)) => a.join(b),
            (Err(HalfFail::Singular), _) | (_, Err(HalfFail::Singular)) => {
                return IndefiniteOutcome::Singular
            }
            _ => return IndefiniteOutcome::Whole,
        };
        if !h1.ldlt && !h2.ldlt && self.separator_llt(values, tiny).is_ok() {
            return IndefiniteOutcome::Llt;
        }
        // S = A33 − L31 D1 L31ᵀ − L32 D2 L32ᵀ, its LDLᵀ without pivoting.
        self.s_ldlt = true;
        self.schur(values);
        let s = self.split.s;
        let a = MatMut::from_column_major_slice_mut(&mut self.l33, s, s);
        if faer::linalg::cholesky::ldlt::factor::cholesky_in_place(
            a,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem33),
            Default::default(),
        )
        .is_err()
        {
            return IndefiniteOutcome::Singular;
        }
        let mut sep = Pivots::new();
        for j in 0..s {
            sep.add(self.l33[j + j * s]);
        }
        let all = pivots.join(sep);
        if !all.finite || all.min <= SINGULAR_PIVOT * all.max {
            return IndefiniteOutcome::Singular;
        }
        IndefiniteOutcome::Ldlt(all.negative)
    }

    /// S = (A33 − L31 D1 L31ᵀ) + (A33 − L32 D2 L32ᵀ) − A33 into `l33` (lower), D = I after
    /// an LLᵀ.
    fn schur(&mut self, values: &[f64]) {
        let s = self.split.s;
        let [h1, h2] = &self.halves;
        let l = &mut self.l33;
        for j in 0..s {
            for i in j..s {
                let q = i + j * s;
                l[q] = h1.schur[q] + h2.schur[q];
            }
        }
        for &(q, p) in &self.a33 {
            l[q] -= values[p];
        }
    }

    /// S and its dense Cholesky factor L33. Err: the separator's position of a pivot not
    /// positive or round-off of its diagonal entry.
    fn separator_llt(&mut self, values: &[f64], tiny: f64) -> Result<(), usize> {
        let s = self.split.s;
        self.s_ldlt = false;
        self.schur(values);
        let a = MatMut::from_column_major_slice_mut(&mut self.l33, s, s);
        let res = faer::linalg::cholesky::llt::factor::cholesky_in_place(
            a,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem33),
            Default::default(),
        );
        if let Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) = res
        {
            return Err(index.min(s - 1));
        }
        // A separator pivot at round-off of its diagonal entry a_jj of A33 (the diagonal
        // entries come in `a33` in the order of j; a pivot without one is not zero here).
        for &(q, p) in &self.a33 {
            let j = q % s;
            if q / s == j && self.l33[q] * self.l33[q] <= tiny * values[p].abs() {
                return Err(j);
            }
        }
        Ok(())
    }

    /// Which blocks of the last factorisation went by LDLᵀ: half 1, half 2, the separator.
    #[cfg(test)]
    pub fn ldlt_blocks(&self) -> [bool; 3] {
        [self.halves[0].ldlt, self.halves[1].ldlt, self.s_ldlt]
    }

    /// Solve A x = b in place with the last successful factorisation.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let TopSplit { n1, n2, s } = self.split;
        let sep0 = n1 + n2;
        let order = &self.order;
        let [h1, h2] = &mut self.halves;
        // Forward through both halves: yᵢ, and −L₃ᵢ yᵢ in the separator's slots.
        let gather = |h: &mut Half, off: usize| {
            for (x, &i) in h.x[..h.m].iter_mut().zip(&order[off..off + h.m]) {
                *x = b[i];
            }
            h.x[h.m..].fill(0.0);
            h.forward();
        };
        rayon::join(|| gather(h1, 0), || gather(h2, n1));
        let mut y3: Vec<f64> = (0..s)
            .map(|j| b[order[sep0 + j]] + h1.x[n1 + j] + h2.x[n2 + j])
            .collect();
        {
            use faer::linalg::triangular_solve as ts;
            let l = MatRef::from_column_major_slice(&self.l33, s, s);
            fn y(y3: &mut [f64]) -> MatMut<'_, f64> {
                let s = y3.len();
                MatMut::from_column_major_slice_mut(y3, s, 1)
            }
            if self.s_ldlt {
                ts::solve_unit_lower_triangular_in_place(l, y(&mut y3), Par::Seq);
                for (j, v) in y3.iter_mut().enumerate() {
                    *v /= self.l33[j + j * s];
                }
                ts::solve_unit_upper_triangular_in_place(l.transpose(), y(&mut y3), Par::Seq);
            } else {
                ts::solve_lower_triangular_in_place(l, y(&mut y3), Par::Seq);
                ts::solve_upper_triangular_in_place(l.transpose(), y(&mut y3), Par::Seq);
            }
        }
        let back = |h: &mut Half| {
            h.x[h.m..].copy_from_slice(&y3);
            h.backward();
        };
        rayon::join(|| back(h1), || back(h2));
        for (k, &i) in order.iter().enumerate() {
            b[i] = if k < n1 {
                h1.x[k]
            } else if k < sep0 {
                h2.x[k - n1]
            } else {
                y3[k - sep0]
            };
        }
    }
}

impl Half {
    /// Fault in the pages of the factor values and the scratch ([`fault_in`]).
    fn fault_in(&mut self) {
        fault_in(self.l_values.as_mut_ptr().cast(), self.l_values.len() * 8);
        fault_in(self.mem.as_mut_ptr().cast(), self.mem.len());
    }

    /// Fill Bᵢ, factorise it (LLᵀ, or LDLᵀ without pivoting if `ldlt`), check the half's
    /// own pivots, and form Mᵢ Mᵢᵀ (Mᵢ Dᵢ Mᵢᵀ). Ok: the own pivots (l_jj² or D_j).
    fn factorize(&mut self, values: &[f64], tiny: f64, ldlt: bool) -> Result<Pivots, HalfFail> {
        for (v, &p) in self.values.iter_mut().zip(&self.source) {
            *v = values[p as usize];
        }
        if self.l_values.len() != self.symbolic.len_val() {
            self.l_values = vec![0.0; self.symbolic.len_val()];
        }
        let (m, nb) = (self.m, self.pattern.nrows());
        let s = nb - m;
        self.ldlt = ldlt;
        self.indefinite = false;
        let a = SparseColMatRef::new(self.pattern.as_ref(), &self.values);
        if self.mem.len() < self.mem_req.size_bytes() {
            self.mem = MemBuffer::new(self.mem_req);
        }
        let stack = MemStack::new(&mut self.mem);
        if ldlt {
            let res = self.symbolic.factorize_numeric_ldlt(
                &mut self.l_values,
                a,
                Side::Lower,
                LdltRegularization::default(),
                Par::Seq,
                stack,
                Default::default(),
            );
            if let Err(faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index }) = res {
                return Err(if index < m {
                    HalfFail::Singular
                } else {
                    HalfFail::Trailing
                });
            }
        } else if let Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot {
            index,
        }) = self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            a,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        ) {
            return Err(HalfFail::NotPositive(index));
        }
        let (cp, ri) = (self.pattern.col_ptr(), self.pattern.row_idx());
        // The diagonal entry of Bᵢ in column j (0 if not stored).
        let diag = |j: usize| {
            if cp[j] < cp[j + 1] && ri[cp[j]] == j {
                self.values[cp[j]]
            } else {
                0.0
            }
        };
        let mut own = Pivots::new();
        self.m33.fill(0.0);
        for Supernode { b, ncols, pat, blk } in supernodes(&self.symbolic, &self.l_values) {
            let nrows = ncols + pat.len();
            for c in 0..ncols {
                let j = b + c;
                let d = blk[c + c * nrows];
                if j < m {
                    if ldlt {
                        own.add(d);
                    } else {
                        // The half's own pivot against its diagonal entry.
                        if d * d <= tiny * diag(j).abs() {
                            return Err(HalfFail::NotPositive(j));
                        }
                        own.add(d * d);
                    }
                    continue;
                }
                // A column of Mᵢ: its rows in the block (all ≥ m).
                let col = &mut self.m33[(j - m) * s..(j - m + 1) * s];
                for r in c..ncols {
                    col[b + r - m] = blk[r + c * nrows];
                }
                for (t, &r) in pat.iter().enumerate() {
                    col[r - m] = blk[ncols + t + c * nrows];
                }
                if ldlt {
                    self.d33[j - m] = d;
                    col[j - m] = 1.0;
                }
            }
        }
        let mm = MatRef::from_column_major_slice(&self.m33, s, s);
        let lhs = if ldlt {
            // Mᵢ Dᵢ, and the growth of the trailing LDLᵀ: max_j Σ_k M_jk² |D_k|.
            self.md.resize(s * s, 0.0);
            let mut g = vec![0.0_f64; s];
            for k in 0..s {
                let dk = self.d33[k];
                for j in k..s {
                    let q = j + k * s;
                    self.md[q] = self.m33[q] * dk;
                    g[j] += (self.m33[q] * self.md[q]).abs();
                }
            }
            let growth = g.iter().fold(0.0_f64, |a, &v| a.max(v));
            let a33 = (m..nb).fold(0.0_f64, |a, j| a.max(diag(j).abs()));
            let t33 = (0..s).fold(0.0_f64, |a, j| {
                let t: f64 = (0..=j)
                    .map(|k| self.md[j + k * s] * self.m33[j + k * s])
                    .sum();
                a.max(t.abs())
            });
            // (A NaN growth fails too.)
            let bound = TRAILING_GROWTH * a33.max(t33);
            if growth.is_nan() || growth > bound {
                return Err(HalfFail::Trailing);
            }
            self.indefinite = own.negative > 0 || self.d33.iter().any(|&d| d < 0.0);
            MatRef::from_column_major_slice(&self.md, s, s)
        } else {
            mm
        };
        faer::linalg::matmul::triangular::matmul(
            MatMut::from_column_major_slice_mut(&mut self.schur, s, s),
            BlockStructure::TriangularLower,
            Accum::Replace,
            lhs,
            BlockStructure::TriangularLower,
            mm.transpose(),
            BlockStructure::TriangularUpper,
            1.0,
            Par::Seq,
        );
        Ok(own)
    }

    /// Forward substitution through the half's own columns: y = L_ii⁻¹ x[..m],
    /// x[m..] −= L₃ᵢ y, and x[..m] ← y, or D_ii⁻¹ y after an LDLᵀ (the supernodes
    /// straddling the boundary processed up to it).
    fn forward(&mut self) {
        let (m, ldlt) = (self.m, self.ldlt);
        let (x, w) = (&mut self.x, &mut self.work);
        for Supernode { b, ncols, pat, blk } in supernodes(&self.symbolic, &self.l_values) {
            if b >= m {
                break;
            }
            let kc = ncols.min(m - b);
            let nrows = ncols + pat.len();
            w.clear();
            w.resize(pat.len(), 0.0);
            for c in 0..kc {
                let col = &blk[c * nrows..(c + 1) * nrows];
                // LDLᵀ: the unit L's forward step, then D⁻¹ on the half's own unknown.
                let v = if ldlt { x[b + c] } else { x[b + c] / col[c] };
                x[b + c] = if ldlt { v / col[c] } else { v };
                for (xr, l) in x[b + c + 1..b + ncols].iter_mut().zip(&col[c + 1..ncols]) {
                    *xr -= l * v;
                }
                for (wr, l) in w.iter_mut().zip(&col[ncols..]) {
                    *wr -= l * v;
                }
            }
            for (&r, wr) in pat.iter().zip(w.iter()) {
                x[r] += wr;
            }
        }
    }

    /// Back substitution through the half's own columns, the separator's unknowns in
    /// x[m..]: x[..m] ← L_ii⁻ᵀ (x[..m] − L₃ᵢᵀ x[m..]) (L_ii unit after an LDLᵀ).
    fn backward(&mut self) {
        let (m, ldlt) = (self.m, self.ldlt);
        let (x, w) = (&mut self.x, &mut self.work);
        for Supernode { b, ncols, pat, blk } in supernodes(&self.symbolic, &self.l_values).rev() {
            if b >= m {
                continue;
            }
            let kc = ncols.min(m - b);
            let nrows = ncols + pat.len();
            w.clear();
            w.extend(pat.iter().map(|&r| x[r]));
            for c in (0..kc).rev() {
                let col = &blk[c * nrows..(c + 1) * nrows];
                let mut v = x[b + c];
                for (xr, l) in x[b + c + 1..b + ncols].iter().zip(&col[c + 1..ncols]) {
                    v -= l * xr;
                }
                for (wr, l) in w.iter().zip(&col[ncols..]) {
                    v -= l * wr;
                }
                x[b + c] = if ldlt { v } else { v / col[c] };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::analysis::system::System;
    use crate::linalg::solver::SparseCholesky;

    /// The LLᵀ by halves against the whole matrix's on a model's stiffness: K x = K·1 and a
    /// second right-hand side, solutions equal to 1e-10 relative (measured 1e-13–1e-12: the
    /// round-off of another summation order in the separator, times the condition number).
    fn split_matches_whole(text: &str, min_equations: usize) {
        let model = crate::input::parse(text, "test.toml").unwrap().model;
        let mut sys = System::new(&model);
        let u = vec![0.0; model.n_dofs()];
        let k = sys.assemble(&u, true).ok().unwrap().k_values.unwrap();
        let p = &sys.asm.pattern;
        assert!(p.n >= min_equations, "{} equations", p.n);
        let order = sys.ordering.as_deref();
        let mut split = SparseCholesky::with_ordering(p, order).unwrap();
        assert!(split.is_split());
        let mut whole = SparseCholesky::with_ordering(p, order)
            .unwrap()
            .without_split(p)
            .unwrap();
        split.factorize(p, &k).unwrap();
        whole.factorize(p, &k).unwrap();
        let mut b = vec![0.0; p.n];
        p.sym_mul(&k, &vec![1.0; p.n], &mut b);
        let b2: Vec<f64> = (0..p.n).map(|i| (i as f64 * 0.37).sin()).collect();
        for b in [b, b2] {
            let (mut x, mut y) = (b.clone(), b.clone());
            split.solve_in_place(&mut x);
            whole.solve_in_place(&mut y);
            let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let diff = x
                .iter()
                .zip(&y)
                .fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
            assert!(diff <= 1e-10 * scale, "difference {diff} of {scale}");
        }
        // Factor and scratch given back, then factorised again (both allocated anew): the
        // same solution to the bit.
        let b: Vec<f64> = (0..p.n).map(|i| (i as f64 * 0.11).cos()).collect();
        let (mut x, mut y) = (b.clone(), b);
        split.solve_in_place(&mut x);
        split.release();
        split.factorize(p, &k).unwrap();
        split.solve_in_place(&mut y);
        assert_eq!(x, y);
    }

    /// The RC beam refined 4× (Q8, 32,084 equations, element dissection).
    #[test]
    fn rc_beam_by_halves() {
        let r = 4;
        let text = include_str!("../../examples/rc-beam.toml")
            .replace("nx = 32\n", &format!("nx = {}\n", 32 * r))
            .replace("rows = 10 }", &format!("rows = {} }}", 10 * r));
        split_matches_whole(&text, 30_000);
    }

    /// A clamped Q4 square of 110 × 110 elements (24,420 equations, node dissection).
    #[test]
    fn q4_square_by_halves() {
        let text = r#"
[[materials]]
name = "m"
kind = "elastic"
E = 30e9
nu = 0.2
[[regions]]
name = "r"
material = "m"
thickness = 0.2
[mesh]
type = "banded"
length = 1.0
nx = 110
element = "Q4"
bands = [{ region = "r", depth = 1.0, rows = 110 }]
[[supports]]
name = "wall"
line = [[0.0, 0.0], [0.0, 1.0]]
ux = 0.0
uy = 0.0
[[load_cases]]
name = "shear"
line_loads = [{ line = [[1.0, 0.0], [1.0, 1.0]], q = [0.0, 100000.0] }]
[[steps]]
name = "load"
kind = "linear"
loads = { shear = 1.0 }
"#;
        split_matches_whole(text, 20_000);
    }
}
