//! The one linear-solver interface of segfem: a symmetric sparse matrix in compressed-column
//! form (lower triangle), symbolic analysis (AMD ordering) once per pattern, numeric
//! factorisation per iteration, solve. faer's supernodal/simplicial Cholesky does the work;
//! the LLᵀ of a large system ordered by nested dissection, and the LDLᵀ of an indefinite
//! one, go by halves on two cores ([`super::split`]).
// long: one solver keeps its private factor storage, analyses and statistics across the whole-matrix LLᵀ/LDLᵀ, the pair at once and the split by halves; the split's own factorisation is in split.rs

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::split::{IndefiniteOutcome, SplitCholesky, SplitOutcome};

pub use super::pattern::LowerPattern;

/// faer's view of a lower-triangle pattern.
fn symbolic(p: &LowerPattern) -> SymbolicSparseColMatRef<'_, usize> {
    SymbolicSparseColMatRef::new_checked(p.n, p.n, &p.col_ptr, None, &p.row_idx)
}

/// The matrix a numeric factorisation reads: the kept-permuted one (already holding the
/// values) or the caller's pattern with `values`.
fn matrix<'a>(
    pre: &'a Option<Prepermuted>,
    pattern: &'a LowerPattern,
    values: &'a [f64],
) -> SparseColMatRef<'a, usize, f64> {
    match pre {
        Some(p) => SparseColMatRef::new(p.pattern.as_ref(), &p.values),
        None => SparseColMatRef::new(symbolic(pattern), values),
    }
}

/// Why a factorisation or solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The matrix is not positive definite: a mechanism, or a limit point of the response.
    #[error("stiffness matrix is not positive definite (pivot at equation {equation})")]
    NotPositiveDefinite {
        /// Equation (free dof) index in the original numbering.
        equation: usize,
    },
    /// Out of memory or another failure inside the sparse library.
    #[error("sparse factorisation failed: {0}")]
    Internal(String),
    /// LDLᵀ met a zero (or non-finite) pivot: the tangent is singular (exactly at a limit
    /// point, or a mechanism).
    #[error("stiffness matrix is singular (zero pivot in LDLᵀ)")]
    Singular,
}

/// Work for an idle core, run beside the next numeric factorisation (handed over by the
/// step driver's observer, `analysis::driver::Observer::idle_work`).
pub type IdleWork = Box<dyn FnOnce() + Send + Sync + 'static>;

/// Timing and size figures of the solver, for summaries and benchmarks.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SolverStats {
    /// Seconds spent in ordering and symbolic factorisation.
    pub symbolic_s: f64,
    /// Seconds spent in numeric factorisations (all of them).
    pub numeric_s: f64,
    /// Seconds spent in forward/back substitution.
    pub solve_s: f64,
    /// Number of numeric factorisations.
    pub factorisations: usize,
    /// Stored values of the factor.
    pub factor_nnz: usize,
    /// Numeric factorisations that fell back to LDLᵀ (indefinite tangent).
    pub ldlt_factorisations: usize,
    /// LDLᵀ factorisations computed on the second core beside an LLᵀ attempt after an
    /// indefinite tangent ([`SparseCholesky::factorize_indefinite`]); those the LLᵀ made
    /// unnecessary are in neither count above.
    #[serde(skip_serializing_if = "is_zero")]
    pub concurrent_ldlt: usize,
    /// Seconds of the numeric factorisations that ended in an LDLᵀ (their failed LLᵀ
    /// attempt included; part of `numeric_s`).
    pub indefinite_s: f64,
    /// Indefinite factorisations by halves that went to the whole matrix's LDLᵀ (a half's
    /// trailing block unusable, [`super::split::IndefiniteOutcome::Whole`]).
    #[serde(skip_serializing_if = "is_zero")]
    pub split_ldlt_to_whole: usize,
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

/// Smallest factor [values] whose LDLᵀ is computed beside the LLᵀ attempt after an
/// indefinite tangent: below it a factorisation takes about a millisecond or less, and the
/// second buffer and the hand-over are not worth it.
const CONCURRENT_LDLT_VALUES: usize = 1 << 20;

/// Supernodal factorisation at every size. faer's automatic rule (supernodal above 40 flops
/// per factor entry) chose the simplicial up-looking factorisation for the seed beam's
/// 1,859 equations (66,538 factor values), which took 4.6 ms per factorisation; the
/// supernodal one, with dense blocks of the two dofs of each node and relaxed supernodes
/// (87,435 values, explicit zeros included), takes 1.8 ms on the same matrices
/// (docs/performance.md).
const FACTOR_KIND: SupernodalThreshold = SupernodalThreshold::FORCE_SUPERNODAL;

/// Relative size of an LLᵀ pivot below which it counts as zero: l_jj² ≤ TINY_PIVOT a_jj.
/// Round-off leaves ~1e-16 of a_jj on a mechanism (1.3e-16 on the hinge of tests/cli.rs,
/// where simplicial LLᵀ happened to meet a pivot ≤ 0 and supernodal LLᵀ does not); the
/// smallest ratios of the bundled examples are 1e-5–2e-2, 8e-9 for the seed beam next to
/// its limit point (where LDLᵀ takes over anyway).
const TINY_PIVOT: f64 = 1e-11;

/// Relative size of an LDLᵀ pivot at or below which the tangent counts as singular:
/// |D_j| ≤ SINGULAR_PIVOT max_k |D_k| ([`SolverError::Singular`]), by halves as whole.
pub(crate) const SINGULAR_PIVOT: f64 = 1e-14;

/// Systems from this many equations on have the pivots of an LLᵀ factor checked in parallel
/// ([`SparseCholesky::tiny_pivot`]).
const PARALLEL_PIVOT_CHECK: usize = 1 << 16;

/// Which factor the solver holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Factor {
    None,
    Llt,
    Ldlt,
    /// LLᵀ of the two halves and the separator ([`SplitCholesky`]).
    Split,
}

/// Systems from this many equations on, ordered by segfem's nested dissection, have their
/// LLᵀ factorised as two halves at once and then the separator ([`SplitCholesky`]).
pub const SPLIT_MIN_EQUATIONS: usize = 20_000;

/// The matrix permuted once into the elimination order, so that faer factorises it as it
/// stands (identity ordering) instead of permuting it at every numeric factorisation.
struct Prepermuted {
    /// Lower-triangle pattern of P A Pᵀ (checked once).
    pattern: SymbolicSparseColMat<usize>,
    /// For each stored entry of `pattern`, its position in the caller's value array.
    source: Vec<usize>,
    /// Values of P A Pᵀ (refilled at each factorisation).
    values: Vec<f64>,
    /// `order[k]`: the original equation eliminated k-th.
    order: Vec<usize>,
    /// Right-hand side in the elimination order (solve scratch).
    rhs: Vec<f64>,
}

/// Largest matrix (stored lower-triangle entries) that is permuted once and kept permuted:
/// three more arrays of this length (pattern, source map, values), ≤ 48 MB. Above it faer
/// permutes per factorisation, which then costs little against the factorisation itself.
const PREPERMUTE_MAX_NNZ: usize = 2_000_000;

/// faer's supernodal analysis of a matrix already in its elimination order, given by its
/// upper triangle (the identity ordering: no permutation at each numeric factorisation).
pub(crate) fn supernodal_in_order(
    upper: SymbolicSparseColMatRef<'_, usize>,
) -> Result<SymbolicCholesky<usize>, String> {
    factorize_symbolic_cholesky(
        upper,
        Side::Upper,
        SymmetricOrdering::Identity,
        CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
    )
    .map_err(|e| format!("{e:?}"))
}

/// Compressed columns of an n × n pattern from (column, row, source) triples: column
/// pointers, row indices sorted within each column, and the source of each entry.
fn compress(n: usize, triples: &[(usize, usize, usize)]) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let mut col_ptr = vec![0usize; n + 1];
    for &(c, _, _) in triples {
        col_ptr[c + 1] += 1;
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut next = col_ptr[..n].to_vec();
    let mut entries = vec![(0usize, 0usize); triples.len()];
    for &(c, r, p) in triples {
        entries[next[c]] = (r, p);
        next[c] += 1;
    }
    for j in 0..n {
        entries[col_ptr[j]..col_ptr[j + 1]].sort_unstable();
    }
    let (row_idx, source) = entries.into_iter().unzip();
    (col_ptr, row_idx, source)
}

impl Prepermuted {
    /// P A Pᵀ of the lower-triangle `pattern` for the elimination order `order` (`inverse`:
    /// its inverse, the position of each equation in the order), and the symbolic
    /// factorisation of it as it stands (faer analyses the upper triangle when given no
    /// ordering: it gets the transposed pattern for that).
    fn new(
        pattern: &LowerPattern,
        order: &[usize],
        inverse: &[usize],
    ) -> Result<(Self, SymbolicCholesky<usize>), SolverError> {
        let n = pattern.n;
        let mut triples = Vec::with_capacity(pattern.nnz());
        for j in 0..n {
            for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let (a, b) = (inverse[pattern.row_idx[p]], inverse[j]);
                triples.push((a.max(b), a.min(b), p));
            }
        }
        let (up_ptr, up_idx, _) = compress(n, &triples);
        let upper = SymbolicSparseColMatRef::new_checked(n, n, &up_ptr, None, &up_idx);
        let symbolic = supernodal_in_order(upper).map_err(SolverError::Internal)?;
        for t in triples.iter_mut() {
            *t = (t.1, t.0, t.2);
        }
        let (col_ptr, row_idx, source) = compress(n, &triples);
        let nnz = row_idx.len();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok((
            Self {
                pattern,
                source,
                values: vec![0.0; nnz],
                order: order.to_vec(),
                rhs: vec![0.0; n],
            },
            symbolic,
        ))
    }

    /// Gather the caller's values into the permuted matrix.
    fn fill(&mut self, values: &[f64]) {
        for (v, &p) in self.values.iter_mut().zip(&self.source) {
            *v = values[p];
        }
    }
}

/// Systems from this many equations on are analysed on a thread of their own
/// ([`SparseCholesky::in_background`]): below, the analysis takes a few milliseconds and
/// the thread and the pattern's copy would cost as much.
pub const BACKGROUND_MIN_EQUATIONS: usize = 50_000;

/// Factor values from this many on (≈ 1e5 equations of a plane mesh) are allocated and their
/// pages touched on a thread of their own while the caller assembles the matrix.
pub(crate) const TOUCH_AHEAD_VALUES: usize = 4_000_000;

/// Fault in every page of the `len` bytes at `ptr` for writing, their contents unchanged
/// (Linux ≥ 5.14: `madvise(MADV_POPULATE_WRITE)`, the pages faulted in by the kernel in one
/// call: 0.27–0.30 s for 454 MB on this project's VM against 0.37–0.40 s writing a byte of
/// each page, docs/performance.md, session 16). False if the kernel cannot (the caller then
/// touches the pages itself).
#[cfg(target_os = "linux")]
pub(crate) fn populate(ptr: *mut u8, len: usize) -> bool {
    const MADV_POPULATE_WRITE: i32 = 23;
    extern "C" {
        fn madvise(addr: *mut u8, len: usize, advice: i32) -> i32;
    }
    let page = Storage::PAGE;
    // madvise wants a page-aligned start: the pages wholly inside the range are populated,
    // the partial ones at its ends written here (one byte each, its own value: unchanged).
    let start = (ptr as usize).next_multiple_of(page);
    let end = (ptr as usize + len) & !(page - 1);
    if end <= start {
        return false;
    }
    // SAFETY: [start, end) lies inside memory the caller owns exclusively; the advice
    // changes no contents and no permissions.
    if unsafe { madvise(start as *mut u8, end - start, MADV_POPULATE_WRITE) } != 0 {
        return false;
    }
    // SAFETY: the first and last bytes of the range are the caller's, initialised or not:
    // read and written back as raw bytes (MaybeUninit), no value is assumed.
    unsafe {
        for p in [ptr, ptr.add(len - 1)] {
            let p = p.cast::<std::mem::MaybeUninit<u8>>();
            std::ptr::write_volatile(p, std::ptr::read_volatile(p));
        }
    }
    true
}

#[cfg(not(target_os = "linux"))]
pub(crate) fn populate(_ptr: *mut u8, _len: usize) -> bool {
    false
}

/// Seconds to fault in `bytes` of fresh memory on two threads (each half by [`fault_in`],
/// as a factor's storage is) and then to give them back: what memory of a factor's size
/// costs a run on this machine before any value is computed (a benchmark figure,
/// docs/performance.md).
pub fn fresh_pages_s(bytes: usize) -> (f64, f64) {
    let t = std::time::Instant::now();
    // Zeroed: fresh pages from the kernel, not yet faulted in.
    let mut buf = vec![0u8; bytes];
    let (first, second) = buf.split_at_mut(bytes / 2);
    std::thread::scope(|s| {
        s.spawn(|| fault_in(second.as_mut_ptr(), second.len()));
        fault_in(first.as_mut_ptr(), first.len());
    });
    let fault = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    drop(buf);
    (fault, t.elapsed().as_secs_f64())
}

/// Fault in every page of the `len` bytes at `ptr` for writing, their contents unchanged:
/// by [`populate`] where the kernel can, else by reading and writing back one byte of each
/// page.
pub(crate) fn fault_in(ptr: *mut u8, len: usize) {
    if len == 0 || populate(ptr, len) {
        return;
    }
    for off in (0..len).step_by(Storage::PAGE) {
        // SAFETY: `ptr + off` lies inside the caller's exclusive buffer; the byte is read
        // and written back unchanged (as raw, possibly uninitialised memory).
        unsafe {
            let p = ptr.add(off).cast::<std::mem::MaybeUninit<u8>>();
            std::ptr::write_volatile(p, std::ptr::read_volatile(p));
        }
    }
}

/// Factor values and the scratch of the numeric factorisation and solves.
struct Storage {
    l_values: Vec<f64>,
    mem: MemBuffer,
}

impl Storage {
    /// Page size the touching steps by [bytes] (the smallest the kernel maps).
    const PAGE: usize = 4096;

    fn new(symbolic: &SymbolicCholesky<usize>) -> Result<Self, SolverError> {
        Ok(Self {
            l_values: vec![0.0; symbolic.len_val()],
            mem: SparseCholesky::scratch(symbolic)?,
        })
    }

    /// Write one byte of every page of both buffers. A fresh buffer is only reserved: the
    /// kernel maps and zeroes each page at its first write, which for a large factor
    /// (0.5 GB at 5e5 equations) took 0.6 s of the first factorisation on one core.
    ///
    /// The pages are faulted in by two threads (this one and one more, each half of the
    /// values): the analysis that started this ends about when the assembly does, so the
    /// first factorisation waits for the touching with the other core idle.
    fn touch(mut self) -> Self {
        // The split on a page boundary of the values (any boundary is correct: the halves
        // are disjoint).
        let n = self.l_values.len();
        let half = (n / 2).next_multiple_of(Self::PAGE / 8).min(n);
        let (first, second) = self.l_values.split_at_mut(half);
        let mem = &mut self.mem;
        std::thread::scope(|s| {
            s.spawn(|| fault_in(second.as_mut_ptr().cast(), std::mem::size_of_val(second)));
            fault_in(first.as_mut_ptr().cast(), std::mem::size_of_val(first));
            fault_in(mem.as_mut_ptr().cast(), mem.len());
        });
        self
    }

    /// Storage for `symbolic`: ready at once for a small factor; for a large one, empty
    /// buffers now and a thread preparing the real ones, which overlaps the page faults
    /// with the assembly of the matrix.
    #[allow(clippy::type_complexity)]
    fn start(
        symbolic: &SymbolicCholesky<usize>,
    ) -> Result<
        (
            Vec<f64>,
            MemBuffer,
            Option<std::thread::JoinHandle<Result<Storage, SolverError>>>,
        ),
        SolverError,
    > {
        if symbolic.len_val() < TOUCH_AHEAD_VALUES {
            let s = Self::new(symbolic)?;
            return Ok((s.l_values, s.mem, None));
        }
        let len_val = symbolic.len_val();
        let req = SparseCholesky::scratch_req(symbolic);
        let handle = std::thread::spawn(move || {
            let mem =
                MemBuffer::try_new(req).map_err(|e| SolverError::Internal(format!("{e:?}")))?;
            Ok(Storage {
                l_values: vec![0.0; len_val],
                mem,
            }
            .touch())
        });
        Ok((
            Vec::new(),
            MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
            Some(handle),
        ))
    }
}

/// Sparse symmetric positive-definite solver with a reusable symbolic factorisation.
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    /// `symbolic` is a stand-in: the whole matrix's analysis is left for when it is needed
    /// ([`SparseCholesky::whole`]; a solver by halves).
    whole_due: bool,
    /// Set when the matrix is kept in the elimination order (then `symbolic` has none).
    pre: Option<Prepermuted>,
    /// The matrix is to be kept permuted from the next factorisation on.
    prepermute_due: bool,
    l_values: Vec<f64>,
    mem: MemBuffer,
    /// Factor values and scratch being allocated and touched on another thread (large
    /// factors, see [`Storage`]); taken into `l_values` and `mem` before they are used.
    pending: Option<std::thread::JoinHandle<Result<Storage, SolverError>>>,
    /// The whole analysis running on another thread ([`SparseCholesky::in_background`]):
    /// until it is joined, `symbolic` is a stand-in of order 1 and `stats` are empty.
    analysis: Option<std::thread::JoinHandle<Result<SparseCholesky, SolverError>>>,
    /// Work to start on a thread of its own when the next numeric factorisation starts
    /// ([`SparseCholesky::beside_next_factorisation`]).
    beside: Option<IdleWork>,
    factor: Factor,
    /// Whether the last [`SparseCholesky::factorize_indefinite`] ended in LDLᵀ: the next
    /// one then computes LDLᵀ beside its LLᵀ attempt ([`SparseCholesky::factorize_both`]).
    last_ldlt: bool,
    /// Factor values and scratch of the LDLᵀ computed beside an LLᵀ (allocated at the first
    /// such pair).
    spare: Option<(Vec<f64>, MemBuffer)>,
    /// Smallest factor [values] for that ([`CONCURRENT_LDLT_VALUES`]; lowered by tests).
    concurrent_min: usize,
    /// The LLᵀ factorised as two halves at once and the separator (large systems ordered by
    /// nested dissection), and the LDLᵀ of an indefinite tangent; a failed split LLᵀ of
    /// [`SparseCholesky::factorize`] and an LDLᵀ whose trailing block is unusable go the
    /// whole-matrix way.
    split: Option<SplitCholesky>,
    /// Negative pivots of the last successful factorisation (0 after LLᵀ).
    pub negative_pivots: usize,
    /// Accumulated timings.
    pub stats: SolverStats,
}

impl Drop for SparseCholesky {
    /// A large factor is released on a thread of its own: returning 0.5 GB of pages to the
    /// kernel took ~0.1–0.2 s at 5e5 equations, which the caller (writing results) need not
    /// wait for.
    fn drop(&mut self) {
        self.release();
    }
}

impl SparseCholesky {
    /// Start `work` on a thread of its own when the next numeric factorisation starts (its
    /// storage ready): faer's sequential factorisation leaves the other cores idle. Work
    /// handed earlier and not started yet is dropped (never run).
    pub fn beside_next_factorisation(&mut self, work: IdleWork) {
        self.beside = Some(work);
    }

    /// Give the factor's memory (values and scratch) back now, when no solve will follow
    /// (the last increment of a run has converged): the field files and the checkpoint are
    /// then written into the pages just freed. On a virtual machine whose balloon reports
    /// free memory to its host (docs/running.md, "Huge pages"), pages freed long ago cost a
    /// host fault at their first touch, recently freed ones do not: at 5e5 equations the
    /// .vtu's 70 MB of page cache took 0.2–0.3 s to fill from cold pages. A large factor is
    /// released on a thread of its own (0.1–0.2 s of the kernel's work at 5e5 equations).
    /// The analysis stays; the next factorisation allocates the storage anew.
    pub fn release(&mut self) {
        self.factor = Factor::None;
        let pending = self.pending.take();
        // The spare LDLᵀ storage beside an LLᵀ attempt goes too (factor-sized).
        let spare = self.spare.take();
        let halves = self.split.as_mut().map(SplitCholesky::release);
        let l_values = std::mem::take(&mut self.l_values);
        let mem = std::mem::replace(
            &mut self.mem,
            MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
        );
        let split_len: usize = halves.iter().flat_map(|h| &h.0).map(Vec::len).sum();
        if l_values.len().max(split_len) >= TOUCH_AHEAD_VALUES
            || pending.is_some()
            || spare.is_some()
        {
            std::thread::spawn(move || {
                drop((l_values, mem, spare, halves));
                drop(pending.map(|h| h.join()));
            });
        }
    }

    /// Floating-point operations of one numeric LLᵀ with this analysis: Σ c² over the
    /// factor's columns, c the stored values of the column (diagonal included), as the
    /// supernodes store them. 0 for a simplicial analysis or before a background one is joined.
    pub fn factor_flops(&self) -> f64 {
        let SymbolicCholeskyRaw::Supernodal(s) = self.symbolic.raw() else {
            return 0.0;
        };
        let (begin, end) = (s.supernode_begin(), s.supernode_end());
        (0..s.n_supernodes())
            .map(|k| {
                let w = end[k] - begin[k];
                let r = (w + s.supernode(k).pattern().len()) as f64;
                (0..w).map(|j| (r - j as f64).powi(2)).sum::<f64>()
            })
            .sum()
    }

    /// Ordering (AMD) and symbolic analysis of `pattern`; done once per pattern.
    pub fn new(pattern: &LowerPattern) -> Result<Self, SolverError> {
        Self::with_threshold(pattern, FACTOR_KIND)
    }

    /// Symbolic analysis of `pattern` with the elimination order `order` (`order[k]`: the
    /// equation eliminated k-th, e.g. from [`super::ordering::nested_dissection`]), or AMD
    /// when `None`.
    pub fn with_ordering(
        pattern: &LowerPattern,
        order: Option<&[usize]>,
    ) -> Result<Self, SolverError> {
        Self::build(pattern, FACTOR_KIND, order, SPLIT_MIN_EQUATIONS)
    }

    /// Drop the factorisation by halves ([`SplitCholesky`]): every LLᵀ goes the whole-matrix
    /// way on one core (benchmarks compare both on the same matrix).
    pub fn without_split(mut self, pattern: &LowerPattern) -> Result<Self, SolverError> {
        self.take_analysis()?;
        self.whole(pattern)?;
        self.split = None;
        self.stats.factor_nnz = self.symbolic.len_val();
        Ok(self)
    }

    /// Whether LLᵀ factorisations go by halves ([`SplitCholesky`]).
    pub fn is_split(&self) -> bool {
        self.split.is_some()
    }

    /// As [`SparseCholesky::with_ordering`], the analysis of a large system (from
    /// [`BACKGROUND_MIN_EQUATIONS`]) done on a thread of its own, while the caller goes on
    /// (sets up the states, assembles the matrix); the first factorisation waits for it. At
    /// 5e5 equations faer's symbolic analysis takes 0.3–0.4 s on one core. Errors of the
    /// analysis come with that factorisation. Smaller systems are analysed at once.
    pub fn in_background(
        pattern: &std::sync::Arc<LowerPattern>,
        order: Option<&[usize]>,
    ) -> Result<Self, SolverError> {
        if pattern.n < BACKGROUND_MIN_EQUATIONS {
            return Self::with_ordering(pattern, order);
        }
        // The pattern shared, not copied (a copy was 36 MB of fresh pages at 5e5 equations,
        // on the caller's thread before the assembly).
        let (pattern, order) = (pattern.clone(), order.map(<[usize]>::to_vec));
        let handle = std::thread::spawn(move || {
            Self::build(&pattern, FACTOR_KIND, order.as_deref(), SPLIT_MIN_EQUATIONS)
        });
        let mut s = Self::build(&LowerPattern::stand_in(), FACTOR_KIND, None, usize::MAX)?;
        s.stats = SolverStats::default();
        s.analysis = Some(handle);
        Ok(s)
    }

    /// Wait for an analysis running on another thread, if any, and take it in.
    fn take_analysis(&mut self) -> Result<(), SolverError> {
        if let Some(h) = self.analysis.take() {
            let a = h
                .join()
                .map_err(|_| SolverError::Internal("symbolic analysis thread panicked".into()))??;
            // What the caller set or added meanwhile (the ordering's time, the negative
            // pivots of a restored run, work to run beside the factorisation) is kept.
            let (before, negative_pivots) = (std::mem::take(&mut self.stats), self.negative_pivots);
            let beside = self.beside.take();
            *self = a;
            self.stats.symbolic_s += before.symbolic_s;
            self.negative_pivots = negative_pivots;
            self.beside = beside;
        }
        Ok(())
    }

    /// As [`SparseCholesky::new`], choosing simplicial or supernodal factorisation by
    /// `threshold` (faer's flop-ratio rule; [`FACTOR_KIND`] in production, both kinds in tests).
    pub fn with_threshold(
        pattern: &LowerPattern,
        threshold: SupernodalThreshold,
    ) -> Result<Self, SolverError> {
        Self::build(pattern, threshold, None, usize::MAX)
    }

    /// `split_min`: the smallest system factorised by halves ([`SPLIT_MIN_EQUATIONS`]; lowered
    /// by tests).
    fn build(
        pattern: &LowerPattern,
        threshold: SupernodalThreshold,
        order: Option<&[usize]>,
        split_min: usize,
    ) -> Result<Self, SolverError> {
        let t = std::time::Instant::now();
        let inverse: Vec<usize> = match order {
            Some(fwd) => {
                if fwd.len() != pattern.n {
                    return Err(SolverError::Internal(format!(
                        "ordering of {} equations for a matrix of order {}",
                        fwd.len(),
                        pattern.n
                    )));
                }
                let mut inv = vec![0; fwd.len()];
                for (k, &i) in fwd.iter().enumerate() {
                    inv[i] = k;
                }
                inv
            }
            None => Vec::new(),
        };
        // By halves: the whole matrix's analysis only when an LDLᵀ (or a failed LLᵀ by halves)
        // needs it ([`SparseCholesky::whole`]), its storage then too.
        let split = match order {
            Some(fwd) if threshold.0 == 0.0 && pattern.n >= split_min => {
                SplitCholesky::new(pattern, fwd, &inverse).map_err(SolverError::Internal)?
            }
            _ => None,
        };
        let (symbolic, prepermute_due, l_values, mem, pending, factor_nnz) = match &split {
            Some(sp) => (
                Self::analyse(&LowerPattern::stand_in(), threshold, None, &[])?.0,
                false,
                Vec::new(),
                MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
                None,
                sp.factor_len(),
            ),
            None => {
                let (symbolic, prepermute_due) =
                    Self::analyse(pattern, threshold, order, &inverse)?;
                let (l_values, mem, pending) = Storage::start(&symbolic)?;
                let nnz = symbolic.len_val();
                (symbolic, prepermute_due, l_values, mem, pending, nnz)
            }
        };
        let stats = SolverStats {
            symbolic_s: t.elapsed().as_secs_f64(),
            factor_nnz,
            ..Default::default()
        };
        Ok(Self {
            whole_due: split.is_some(),
            symbolic,
            pre: None,
            prepermute_due,
            l_values,
            mem,
            pending,
            analysis: None,
            beside: None,
            factor: Factor::None,
            last_ldlt: false,
            spare: None,
            concurrent_min: CONCURRENT_LDLT_VALUES,
            split,
            negative_pivots: 0,
            stats,
        })
    }

    /// faer's symbolic analysis of the whole matrix in the order `order` (AMD if None;
    /// `inverse`: the order's inverse), and whether the matrix is to be kept permuted.
    fn analyse(
        pattern: &LowerPattern,
        threshold: SupernodalThreshold,
        order: Option<&[usize]>,
        inverse: &[usize],
    ) -> Result<(SymbolicCholesky<usize>, bool), SolverError> {
        let ordering = match order {
            Some(fwd) => {
                SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(fwd, inverse, pattern.n))
            }
            None => SymmetricOrdering::Amd,
        };
        let symbolic = factorize_symbolic_cholesky(
            symbolic(pattern),
            Side::Lower,
            ordering,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: threshold,
                ..Default::default()
            },
        )
        .map_err(|e| SolverError::Internal(format!("{e:?}")))?;
        let supernodal = matches!(symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_));
        let prepermute_due =
            supernodal && pattern.nnz() <= PREPERMUTE_MAX_NNZ && symbolic.perm().is_some();
        Ok((symbolic, prepermute_due))
    }

    /// The whole matrix's analysis, if it was left for when it is needed (a solver by
    /// halves meeting an indefinite matrix).
    fn whole(&mut self, pattern: &LowerPattern) -> Result<(), SolverError> {
        if !self.whole_due {
            return Ok(());
        }
        let t = std::time::Instant::now();
        let order = self.split.as_ref().map(|s| s.order().to_vec());
        let mut inverse = vec![0; pattern.n];
        for (k, &i) in order.iter().flatten().enumerate() {
            inverse[i] = k;
        }
        (self.symbolic, self.prepermute_due) =
            Self::analyse(pattern, FACTOR_KIND, order.as_deref(), &inverse)?;
        self.whole_due = false;
        self.stats.symbolic_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Wait for the factor storage being prepared on another thread, if any.
    fn take_storage(&mut self) -> Result<(), SolverError> {
        if let Some(h) = self.pending.take() {
            let s = h
                .join()
                .map_err(|_| SolverError::Internal("factor storage thread panicked".into()))??;
            (self.l_values, self.mem) = (s.l_values, s.mem);
        }
        Ok(())
    }

    /// The factor storage ready for a numeric factorisation: the one prepared on another
    /// thread, or a new one after [`SparseCholesky::release`].
    fn ready_storage(&mut self) -> Result<(), SolverError> {
        self.take_storage()?;
        if self.l_values.len() != self.symbolic.len_val() {
            let s = Storage::new(&self.symbolic)?;
            (self.l_values, self.mem) = (s.l_values, s.mem);
        }
        Ok(())
    }

    /// Scratch memory of the numeric factorisations and solves of `symbolic`.
    fn scratch(symbolic: &SymbolicCholesky<usize>) -> Result<MemBuffer, SolverError> {
        MemBuffer::try_new(Self::scratch_req(symbolic))
            .map_err(|e| SolverError::Internal(format!("{e:?}")))
    }

    /// Size of [`SparseCholesky::scratch`].
    fn scratch_req(symbolic: &SymbolicCholesky<usize>) -> faer::dyn_stack::StackReq {
        symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()))
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
    }

    /// Keep the matrix permuted from the second factorisation on (a supernodal factor reads
    /// the lower triangle of the permuted matrix, which faer would otherwise build at every
    /// factorisation: ~5 % of a small nonlinear run). Not at the first: a run that
    /// factorises once (a linear step) would pay the second symbolic analysis for nothing
    /// (+0.1–0.2 s at 1e5 equations).
    fn prepermute(&mut self, pattern: &LowerPattern) -> Result<(), SolverError> {
        self.prepermute_due = false;
        let t = std::time::Instant::now();
        let Some(perm) = self.symbolic.perm() else {
            return Ok(());
        };
        let (fwd, inv) = perm.arrays();
        let (p, symbolic) = Prepermuted::new(pattern, fwd, inv)?;
        // The storage under way (if any) belongs to the old analysis: wait for it, drop it.
        self.take_storage()?;
        let (l_values, mem, pending) = Storage::start(&symbolic)?;
        (self.l_values, self.mem, self.pending) = (l_values, mem, pending);
        self.stats.factor_nnz = symbolic.len_val();
        self.symbolic = symbolic;
        self.pre = Some(p);
        self.stats.symbolic_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Numeric factorisation of the matrix with the analysed pattern and these values.
    pub fn factorize(&mut self, pattern: &LowerPattern, values: &[f64]) -> Result<(), SolverError> {
        // Not positive definite by halves: the whole matrix's LLᵀ gives the verdict (and the
        // equation) the sequential factorisation gives.
        if let Some(Ok(())) = self.factorize_split(values)? {
            return Ok(());
        }
        self.factorize_whole(pattern, values)
    }

    /// The LLᵀ by halves ([`SplitCholesky`]), if this analysis has one: None if not, else
    /// whether the matrix was positive definite (Err: the equation of a failed pivot).
    fn factorize_split(
        &mut self,
        values: &[f64],
    ) -> Result<Option<Result<(), usize>>, SolverError> {
        self.take_analysis()?;
        let Some(split) = self.split.as_mut() else {
            return Ok(None);
        };
        let t = std::time::Instant::now();
        self.factor = Factor::None;
        if let Some(work) = self.beside.take() {
            std::thread::spawn(work);
        }
        let out = split.factorize(values, TINY_PIVOT);
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        self.stats.factorisations += 1;
        Ok(Some(match out {
            SplitOutcome::Ok => {
                self.factor = Factor::Split;
                self.negative_pivots = 0;
                Ok(())
            }
            SplitOutcome::NotPositiveDefinite(k) => Err(split.order()[k]),
        }))
    }

    /// The indefinite factorisation by halves ([`SplitCholesky::factorize_indefinite`]),
    /// if this analysis has one (None if not; the analysis already taken in). Counted as
    /// the sequential path counts: one factorisation, two when it ended in an LDLᵀ (the
    /// LLᵀ attempt and the LDLᵀ), one of them LDLᵀ.
    fn factorize_split_indefinite(&mut self, values: &[f64]) -> Option<IndefiniteOutcome> {
        let split = self.split.as_mut()?;
        let t = std::time::Instant::now();
        self.factor = Factor::None;
        if let Some(work) = self.beside.take() {
            std::thread::spawn(work);
        }
        let out = split.factorize_indefinite(values, TINY_PIVOT);
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        self.stats.factorisations += 1;
        if !matches!(out, IndefiniteOutcome::Llt) {
            self.stats.factorisations += 1;
            self.stats.ldlt_factorisations += 1;
        }
        match out {
            IndefiniteOutcome::Llt => {
                self.factor = Factor::Split;
                self.negative_pivots = 0;
            }
            IndefiniteOutcome::Ldlt(negative) => {
                self.factor = Factor::Split;
                self.negative_pivots = negative;
            }
            _ => {}
        }
        Some(out)
    }

    /// The whole matrix's LLᵀ by faer on one core.
    fn factorize_whole(
        &mut self,
        pattern: &LowerPattern,
        values: &[f64],
    ) -> Result<(), SolverError> {
        self.prepare(pattern, values)?;
        let t = std::time::Instant::now();
        let a = matrix(&self.pre, pattern, values);
        if let Some(work) = self.beside.take() {
            std::thread::spawn(work);
        }
        let stack = MemStack::new(&mut self.mem);
        let res = self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            a,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        );
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        self.stats.factorisations += 1;
        let res = res.map(|_| ());
        self.finish_llt(pattern, values, res)
    }

    /// What every numeric factorisation starts with: the analysis and the factor storage
    /// taken in, the matrix kept permuted from the second factorisation on and filled with
    /// `values` (the time of the fill counts as factorisation time).
    fn prepare(&mut self, pattern: &LowerPattern, values: &[f64]) -> Result<(), SolverError> {
        self.take_analysis()?;
        self.whole(pattern)?;
        if self.prepermute_due && self.stats.factorisations > 0 {
            self.prepermute(pattern)?;
        }
        let t = std::time::Instant::now();
        self.ready_storage()?;
        self.factor = Factor::None;
        if let Some(p) = self.pre.as_mut() {
            p.fill(values);
        }
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// The outcome of an LLᵀ of `values` in `l_values`: a pivot that is round-off of its
    /// diagonal entry or not positive is [`SolverError::NotPositiveDefinite`].
    fn finish_llt(
        &mut self,
        pattern: &LowerPattern,
        values: &[f64],
        res: Result<(), faer::linalg::cholesky::llt::factor::LltError>,
    ) -> Result<(), SolverError> {
        match res {
            Ok(_) => {
                // A pivot that is round-off of its diagonal entry is a zero pivot (the
                // supernodal kernels leave it a tiny positive number on a mechanism).
                if let Some(k) = self.tiny_pivot(pattern, values) {
                    let equation = match (&self.pre, self.symbolic.perm()) {
                        (Some(p), _) => p.order[k],
                        (None, Some(p)) => p.arrays().0[k],
                        (None, None) => k,
                    };
                    return Err(SolverError::NotPositiveDefinite { equation });
                }
                self.factor = Factor::Llt;
                self.negative_pivots = 0;
                Ok(())
            }
            Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => {
                // faer reports simplicial pivots 1-based and supernodal ones 0-based, in the
                // permuted order; map back to the original equation.
                let index = match self.symbolic.raw() {
                    SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                    SymbolicCholeskyRaw::Supernodal(_) => index,
                }
                .min(pattern.n.saturating_sub(1));
                let equation = match (&self.pre, self.symbolic.perm()) {
                    (Some(p), _) => p.order[index],
                    (None, Some(p)) => p.arrays().0[index],
                    (None, None) => index,
                };
                Err(SolverError::NotPositiveDefinite { equation })
            }
        }
    }

    /// Whether the solver holds a factor a solve can use (a successful factorisation, not
    /// released since).
    pub fn has_factor(&self) -> bool {
        self.factor != Factor::None
    }

    /// Solve A x = b in place (b is overwritten by x). Requires a successful `factorize`
    /// or `factorize_indefinite`.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        assert!(
            self.factor != Factor::None,
            "solve called without a valid factorisation"
        );
        let t = std::time::Instant::now();
        if self.factor == Factor::Split {
            if let Some(split) = self.split.as_mut() {
                split.solve_in_place(b);
            }
            self.stats.solve_s += t.elapsed().as_secs_f64();
            return;
        }
        let n = b.len();
        let stack = MemStack::new(&mut self.mem);
        // A kept-permuted matrix: solve for P x from P b.
        let pb = match self.pre.as_mut() {
            Some(p) => {
                for (r, &i) in p.rhs.iter_mut().zip(&p.order) {
                    *r = b[i];
                }
                &mut p.rhs[..]
            }
            None => &mut b[..],
        };
        let rhs = MatMut::from_column_major_slice_mut(pb, n, 1);
        if self.factor == Factor::Llt {
            LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
                Conj::No,
                rhs,
                Par::Seq,
                stack,
            );
        } else {
            LdltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
                Conj::No,
                rhs,
                Par::Seq,
                stack,
            );
        }
        if let Some(p) = self.pre.as_ref() {
            for (&i, &r) in p.order.iter().zip(&p.rhs) {
                b[i] = r;
            }
        }
        self.stats.solve_s += t.elapsed().as_secs_f64();
    }

    /// Factorise a symmetric matrix that may be indefinite: LLᵀ first; if it meets a
    /// non-positive pivot, LDLᵀ (no pivoting, same symbolic analysis and ordering). Returns
    /// the number of negative pivots of D (the inertia index: 0 for a positive-definite
    /// matrix; ≥ 1 past a limit point or bifurcation). A zero or non-finite pivot is
    /// [`SolverError::Singular`]. A solver by halves does this by halves
    /// ([`SplitCholesky::factorize_indefinite`]: LLᵀ or LDLᵀ per block, the same inertia).
    pub fn factorize_indefinite(
        &mut self,
        pattern: &LowerPattern,
        values: &[f64],
    ) -> Result<usize, SolverError> {
        self.take_analysis()?;
        let (numeric0, ldlt0) = (self.stats.numeric_s, self.stats.ldlt_factorisations);
        if self.last_ldlt {
            self.whole(pattern)?;
        }
        let out = if self.last_ldlt && self.symbolic.len_val() >= self.concurrent_min {
            self.factorize_both(pattern, values)
        } else if let Some(split) = self.factorize_split_indefinite(values) {
            match split {
                IndefiniteOutcome::Llt => Ok(0),
                IndefiniteOutcome::Ldlt(negative) => Ok(negative),
                IndefiniteOutcome::Singular => Err(SolverError::Singular),
                // A half's trailing block unusable: the whole matrix's LDLᵀ (the matrix is
                // filled there).
                IndefiniteOutcome::Whole => {
                    self.stats.split_ldlt_to_whole += 1;
                    self.prepare(pattern, values)?;
                    self.factorize_ldlt(pattern, values)
                }
            }
        } else {
            match self.factorize(pattern, values) {
                Ok(()) => Ok(0),
                // (A kept-permuted matrix was filled by the failed LLᵀ.)
                Err(SolverError::NotPositiveDefinite { .. }) => {
                    self.factorize_ldlt(pattern, values)
                }
                Err(e) => Err(e),
            }
        };
        // (A solver by halves stays by halves after a whole-matrix LDLᵀ.)
        self.last_ldlt = self.factor == Factor::Ldlt && self.split.is_none();
        if self.stats.ldlt_factorisations > ldlt0 {
            self.stats.indefinite_s += self.stats.numeric_s - numeric0;
        }
        out
    }

    /// LDLᵀ of the matrix (a kept-permuted matrix must already hold `values`); the number
    /// of negative pivots.
    fn factorize_ldlt(
        &mut self,
        pattern: &LowerPattern,
        values: &[f64],
    ) -> Result<usize, SolverError> {
        let t = std::time::Instant::now();
        self.ready_storage()?;
        self.factor = Factor::None;
        let a = matrix(&self.pre, pattern, values);
        let stack = MemStack::new(&mut self.mem);
        let ok = self
            .symbolic
            .factorize_numeric_ldlt(
                &mut self.l_values,
                a,
                Side::Lower,
                LdltRegularization::default(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .is_ok();
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        self.stats.factorisations += 1;
        self.stats.ldlt_factorisations += 1;
        self.finish_ldlt(ok)
    }

    /// LLᵀ and LDLᵀ of the same matrix at once, one on each core (the next tangent after an
    /// indefinite one is mostly indefinite too: its LLᵀ attempt, which fails at a late pivot,
    /// then no longer delays the LDLᵀ). Each is the factorisation
    /// [`SparseCholesky::factorize_indefinite`] would compute alone, in its own buffers, so the
    /// factor kept (the LLᵀ if it succeeds, else the LDLᵀ) is the same to the bit.
    fn factorize_both(
        &mut self,
        pattern: &LowerPattern,
        values: &[f64],
    ) -> Result<usize, SolverError> {
        self.prepare(pattern, values)?;
        let t = std::time::Instant::now();
        // (Sized for this analysis: the kept-permuted one replaces the first only before the
        // second factorisation, but a stale pair is not used in any case.)
        let spare = match self
            .spare
            .take()
            .filter(|s| s.0.len() == self.symbolic.len_val())
        {
            Some(s) => s,
            None => {
                let s = Storage::new(&self.symbolic)?;
                (s.l_values, s.mem)
            }
        };
        let (mut l2, mut mem2) = spare;
        let a = matrix(&self.pre, pattern, values);
        let (symbolic, l1, mem1) = (&self.symbolic, &mut self.l_values, &mut self.mem);
        let (llt, ldlt) = rayon::join(
            || {
                symbolic
                    .factorize_numeric_llt(
                        l1,
                        a,
                        Side::Lower,
                        LltRegularization::default(),
                        Par::Seq,
                        MemStack::new(mem1),
                        Default::default(),
                    )
                    .map(|_| ())
            },
            || {
                symbolic
                    .factorize_numeric_ldlt(
                        &mut l2,
                        a,
                        Side::Lower,
                        LdltRegularization::default(),
                        Par::Seq,
                        MemStack::new(&mut mem2),
                        Default::default(),
                    )
                    .is_ok()
            },
        );
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        self.stats.factorisations += 1;
        self.stats.concurrent_ldlt += 1;
        let out = match self.finish_llt(pattern, values, llt) {
            Ok(()) => Ok(0),
            Err(SolverError::NotPositiveDefinite { .. }) => {
                // As if the LDLᵀ had run after the failed LLᵀ: counted so.
                self.stats.factorisations += 1;
                self.stats.ldlt_factorisations += 1;
                std::mem::swap(&mut self.l_values, &mut l2);
                std::mem::swap(&mut self.mem, &mut mem2);
                self.finish_ldlt(ldlt)
            }
            Err(e) => Err(e),
        };
        self.spare = Some((l2, mem2));
        out
    }

    /// The outcome of an LDLᵀ in `l_values` (`ok`: faer's factorisation succeeded): the
    /// number of negative pivots, or [`SolverError::Singular`] for a zero or non-finite one.
    fn finish_ldlt(&mut self, ok: bool) -> Result<usize, SolverError> {
        if !ok {
            return Err(SolverError::Singular);
        }
        let d = self.ldlt_diagonal();
        // Pivots below this relative size are treated as zero (singular tangent).
        let scale = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if d.iter()
            .any(|v| !v.is_finite() || v.abs() <= SINGULAR_PIVOT * scale)
        {
            return Err(SolverError::Singular);
        }
        self.factor = Factor::Ldlt;
        self.negative_pivots = d.iter().filter(|v| **v < 0.0).count();
        Ok(self.negative_pivots)
    }

    /// First equation (elimination order) of the last LLᵀ factor whose pivot l_jj² is at
    /// most [`TINY_PIVOT`] times the matrix's diagonal entry a_jj: what is left of a_jj
    /// after elimination is round-off, a zero pivot (a mechanism).
    fn tiny_pivot(&self, pattern: &LowerPattern, values: &[f64]) -> Option<usize> {
        let l = self.ldlt_diagonal();
        let perm = self.symbolic.perm().map(|p| p.arrays().0);
        let tiny = |k: usize| {
            let a = match (&self.pre, perm) {
                (Some(p), _) => {
                    let (cp, ri) = (p.pattern.col_ptr(), p.pattern.row_idx());
                    (cp[k] < cp[k + 1] && ri[cp[k]] == k).then(|| p.values[cp[k]])
                }
                (None, Some(fwd)) => pattern.position(fwd[k], fwd[k]).map(|q| values[q]),
                (None, None) => pattern.position(k, k).map(|q| values[q]),
            };
            a.is_some_and(|a| l[k] * l[k] <= TINY_PIVOT * a.abs())
        };
        // On both cores for a large system (random reads of the matrix diagonal: ~30 ms at
        // 5e5 equations, with the other core idle); the first such equation either way.
        if l.len() >= PARALLEL_PIVOT_CHECK {
            use rayon::prelude::*;
            (0..l.len())
                .into_par_iter()
                .with_min_len(PARALLEL_PIVOT_CHECK / 4)
                .find_first(|&k| tiny(k))
        } else {
            (0..l.len()).find(|&k| tiny(k))
        }
    }

    /// Diagonal of the last factor (permuted order): D of LDLᵀ, or the diagonal of L of LLᵀ.
    fn ldlt_diagonal(&self) -> Vec<f64> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                // Column j of L starts with its diagonal entry, which holds D_j.
                let cp = s.col_ptr();
                (0..s.nrows()).map(|j| self.l_values[cp[j]]).collect()
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                // Each supernode is a dense column-major block (rows × cols) whose leading
                // square part has D on its diagonal.
                let mut d = Vec::with_capacity(s.nrows());
                let (begin, end, cpv) =
                    (s.supernode_begin(), s.supernode_end(), s.col_ptr_for_val());
                for k in 0..s.n_supernodes() {
                    let ncols = end[k] - begin[k];
                    let nrows = (cpv[k + 1] - cpv[k]) / ncols.max(1);
                    for c in 0..ncols {
                        d.push(self.l_values[cpv[k] + c * nrows + c]);
                    }
                }
                d
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lower pattern and values of the 1-D Laplacian of order n (tridiagonal 2, −1).
    fn laplacian_1d(n: usize) -> (LowerPattern, Vec<f64>) {
        let mut col_ptr = vec![0];
        let (mut row_idx, mut vals) = (vec![], vec![]);
        for j in 0..n {
            row_idx.push(j);
            vals.push(2.0);
            if j + 1 < n {
                row_idx.push(j + 1);
                vals.push(-1.0);
            }
            col_ptr.push(row_idx.len());
        }
        (
            LowerPattern {
                n,
                col_ptr,
                row_idx,
            },
            vals,
        )
    }

    /// A released factor is rebuilt by the next factorisation; work beside it runs.
    #[test]
    fn released_factor_is_rebuilt_and_work_runs_beside() {
        // The 1-D Laplacian of the test below: after `release` the next factorisation
        // allocates the storage anew and gives the same solution to the last bit; work
        // handed for the next factorisation runs once.
        let n = 50;
        let (p, vals) = laplacian_1d(n);
        let b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let mut s = SparseCholesky::new(&p).unwrap();
        let ran = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let r = ran.clone();
        s.beside_next_factorisation(Box::new(move || {
            r.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        }));
        s.factorize(&p, &vals).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        s.release();
        s.factorize(&p, &vals).unwrap();
        let mut y = b.clone();
        s.solve_in_place(&mut y);
        assert_eq!(x, y);
        // The work's thread is detached: wait for it (a few milliseconds at most).
        for _ in 0..1000 {
            if ran.load(std::sync::atomic::Ordering::SeqCst) > 0 {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert_eq!(ran.load(std::sync::atomic::Ordering::SeqCst), 1);
    }

    /// 1-D Laplacian (tridiagonal 2, −1): solution of A x = e checked through the residual.
    #[test]
    fn solves_a_tridiagonal_system() {
        let n = 50;
        let (p, vals) = laplacian_1d(n);
        let mut s = SparseCholesky::new(&p).unwrap();
        s.factorize(&p, &vals).unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        let mut ax = vec![0.0; n];
        p.sym_mul(&vals, &x, &mut ax);
        // Condition number ~ n², so round-off residual ~1e-12 is generous.
        for i in 0..n {
            assert!((ax[i] - b[i]).abs() < 1e-10);
        }
    }

    /// An indefinite matrix falls back to LDLᵀ, solves, and reports its negative pivots.
    #[test]
    fn ldlt_fallback_counts_negative_pivots() {
        // Tridiagonal (d_j, −1) with two negative diagonal entries far apart: exactly two
        // negative eigenvalues (the off-diagonals are small against |d|).
        let n = 40;
        let mut col_ptr = vec![0];
        let mut row_idx = vec![];
        let mut vals = vec![];
        for j in 0..n {
            row_idx.push(j);
            vals.push(if j == 7 || j == 30 { -10.0 } else { 10.0 });
            if j + 1 < n {
                row_idx.push(j + 1);
                vals.push(-1.0);
            }
            col_ptr.push(row_idx.len());
        }
        let p = LowerPattern {
            n,
            col_ptr,
            row_idx,
        };
        let mut s = SparseCholesky::new(&p).unwrap();
        assert_eq!(s.factorize_indefinite(&p, &vals).unwrap(), 2);
        let b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        let mut ax = vec![0.0; n];
        p.sym_mul(&vals, &x, &mut ax);
        for i in 0..n {
            assert!((ax[i] - b[i]).abs() < 1e-12);
        }
        // A positive-definite matrix goes through LLᵀ with zero negative pivots.
        let pos: Vec<f64> = vals.iter().map(|v| v.abs()).collect();
        assert_eq!(s.factorize_indefinite(&p, &pos).unwrap(), 0);
        assert_eq!(s.stats.ldlt_factorisations, 1);
    }

    /// The 9-point Laplacian of an m × m grid (8 on the diagonal, −1 to the 8 neighbours)
    /// shifted by −σ: lower-triangle pattern and values.
    fn shifted_laplacian(m: usize, sigma: f64) -> (LowerPattern, Vec<f64>) {
        let n = m * m;
        let mut col_ptr = vec![0];
        let mut row_idx = vec![];
        let mut vals = vec![];
        for j in 0..n {
            let (x, y) = (j % m, j / m);
            row_idx.push(j);
            vals.push(8.0 - sigma);
            if x + 1 < m {
                row_idx.push(j + 1);
                vals.push(-1.0);
            }
            if y + 1 < m {
                if x > 0 {
                    row_idx.push(j + m - 1);
                    vals.push(-1.0);
                }
                row_idx.push(j + m);
                vals.push(-1.0);
                if x + 1 < m {
                    row_idx.push(j + m + 1);
                    vals.push(-1.0);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let p = LowerPattern {
            n,
            col_ptr,
            row_idx,
        };
        (p, vals)
    }

    /// After an indefinite tangent the LDLᵀ is computed beside the LLᵀ attempt: the factor
    /// kept is the one the sequential fallback computes, to the bit (an indefinite matrix's
    /// LDLᵀ, a positive-definite one's LLᵀ), with the same inertia.
    #[test]
    fn concurrent_ldlt_keeps_the_sequential_factor() {
        let m = 30;
        let (p, indefinite) = shifted_laplacian(m, 0.37);
        let (_, definite) = shifted_laplacian(m, -0.5);
        let b: Vec<f64> = (0..m * m).map(|i| (i as f64 * 0.1).sin()).collect();
        let solve = |s: &mut SparseCholesky| {
            let mut x = b.clone();
            s.solve_in_place(&mut x);
            x.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        };
        let mut seq = SparseCholesky::new(&p).unwrap();
        seq.concurrent_min = usize::MAX;
        let mut both = SparseCholesky::new(&p).unwrap();
        both.concurrent_min = 0;
        for vals in [
            &indefinite,
            &indefinite,
            &indefinite,
            &definite,
            &indefinite,
        ] {
            let a = seq.factorize_indefinite(&p, vals).unwrap();
            let c = both.factorize_indefinite(&p, vals).unwrap();
            assert_eq!(a, c);
            assert_eq!(seq.factor, both.factor);
            assert_eq!(solve(&mut seq), solve(&mut both));
        }
        // The 2nd, 3rd and 4th factorisations ran beside an LDLᵀ (after an indefinite one).
        assert_eq!(both.stats.concurrent_ldlt, 3);
        assert_eq!(seq.stats.concurrent_ldlt, 0);
        assert_eq!(both.stats.factorisations, seq.stats.factorisations);
        assert_eq!(
            both.stats.ldlt_factorisations,
            seq.stats.ldlt_factorisations
        );
    }

    /// Supernodal LDLᵀ: the 9-point matrix 9I − T⊗T of an m×m grid (T = tridiag(1, 1, 1),
    /// the stencil of a Q4 mesh) shifted by σ has exactly as many negative pivots as
    /// eigenvalues 9 − (1 + 2cos jh)(1 + 2cos kh), h = π/(m+1), below σ (Sylvester).
    #[test]
    fn ldlt_inertia_of_shifted_laplacian() {
        let m = 40;
        let n = m * m;
        let sigma = 0.37;
        let (p, vals) = shifted_laplacian(m, sigma);
        let h = std::f64::consts::PI / (m + 1) as f64;
        let mut expected = 0;
        for j in 1..=m {
            for k in 1..=m {
                let t = (1.0 + 2.0 * (j as f64 * h).cos()) * (1.0 + 2.0 * (k as f64 * h).cos());
                if 9.0 - t < sigma {
                    expected += 1;
                }
            }
        }
        assert!(expected > 5);
        for th in [
            SupernodalThreshold::FORCE_SUPERNODAL,
            SupernodalThreshold::FORCE_SIMPLICIAL,
        ] {
            let mut s = SparseCholesky::with_threshold(&p, th).unwrap();
            let supernodal = matches!(s.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_));
            assert_eq!(supernodal, th.0 == 0.0);
            // The second factorisation of a supernodal solver runs on the kept-permuted
            // matrix: the same inertia and solution.
            assert_eq!(s.factorize_indefinite(&p, &vals).unwrap(), expected);
            assert!(s.pre.is_none());
            assert_eq!(s.factorize_indefinite(&p, &vals).unwrap(), expected);
            assert_eq!(s.pre.is_some(), supernodal);
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
            let mut x = b.clone();
            s.solve_in_place(&mut x);
            let mut ax = vec![0.0; n];
            p.sym_mul(&vals, &x, &mut ax);
            let err = ax
                .iter()
                .zip(&b)
                .map(|(a, c)| (a - c).abs())
                .fold(0.0, f64::max);
            // Indefinite, condition ~1e3–1e4 near σ: 1e-9 leaves room for round-off growth.
            assert!(err < 1e-9, "residual {err}");
        }
    }

    /// Nested dissection of an m × m grid numbered row by row (x fastest): each rectangle
    /// split across its longer side by a grid line, which separates the 9-point stencil's
    /// halves; rectangles of up to 4 nodes numbered as they come.
    fn grid_dissection(m: usize) -> Vec<usize> {
        fn nd(m: usize, x: (usize, usize), y: (usize, usize), out: &mut Vec<usize>) {
            let (w, h) = (x.1 - x.0, y.1 - y.0);
            if w == 0 || h == 0 {
                return;
            }
            if w * h <= 4 {
                for j in y.0..y.1 {
                    for i in x.0..x.1 {
                        out.push(i + j * m);
                    }
                }
                return;
            }
            if w >= h {
                let c = x.0 + w / 2;
                nd(m, (x.0, c), y, out);
                nd(m, (c + 1, x.1), y, out);
                nd(m, (c, c + 1), y, out);
            } else {
                let c = y.0 + h / 2;
                nd(m, x, (y.0, c), out);
                nd(m, x, (c + 1, y.1), out);
                nd(m, x, (c, c + 1), out);
            }
        }
        let mut out = Vec::with_capacity(m * m);
        nd(m, (0, m), (0, m), &mut out);
        out
    }

    /// The LLᵀ by halves of a positive-definite matrix solves as the whole-matrix one does,
    /// to round-off; an indefinite one goes by LDLᵀ by halves with the whole matrix's
    /// inertia; a mechanism is reported.
    #[test]
    fn split_factorisation_matches_the_whole_one() {
        let m = 41;
        let n = m * m;
        let order = grid_dissection(m);
        let (p, definite) = shifted_laplacian(m, -0.5);
        let (_, indefinite) = shifted_laplacian(m, 0.37);
        let mut split = SparseCholesky::build(&p, FACTOR_KIND, Some(&order), 0).unwrap();
        assert!(split.is_split());
        let sp = split.split.as_ref().unwrap().split;
        // The top separator is the middle grid line.
        assert_eq!((sp.n1, sp.n2, sp.s), (20 * m, 20 * m, m));
        let mut whole = SparseCholesky::with_ordering(&p, Some(&order)).unwrap();
        assert!(!whole.is_split());
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
        for _ in 0..2 {
            split.factorize(&p, &definite).unwrap();
            whole.factorize(&p, &definite).unwrap();
            assert_eq!(split.factor, Factor::Split);
            let (mut x, mut y) = (b.clone(), b.clone());
            split.solve_in_place(&mut x);
            whole.solve_in_place(&mut y);
            // Condition number ≤ 17/0.5: the two round-off paths agree to ~1e-15; 1e-12
            // leaves room.
            let norm = y.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            for (a, c) in x.iter().zip(&y) {
                assert!((a - c).abs() <= 1e-12 * norm, "{a} against {c}");
            }
        }
        // Indefinite: LDLᵀ by halves, the same negative pivots as the whole matrix's LDLᵀ,
        // the same solution to round-off (condition ~1e3–1e4 near σ: 1e-11 of the solution).
        let a = split.factorize_indefinite(&p, &indefinite).unwrap();
        let c = whole.factorize_indefinite(&p, &indefinite).unwrap();
        assert!(a > 5);
        assert_eq!(a, c);
        assert_eq!(split.factor, Factor::Split);
        assert_eq!(whole.factor, Factor::Ldlt);
        let (mut x, mut y) = (b.clone(), b.clone());
        split.solve_in_place(&mut x);
        whole.solve_in_place(&mut y);
        let norm = y.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        for (a, c) in x.iter().zip(&y) {
            assert!((a - c).abs() <= 1e-11 * norm, "{a} against {c}");
        }
        // And back to a definite matrix: by halves again (after the concurrent LDLᵀ/LLᵀ
        // pair, which needs the last factorisation indefinite).
        assert_eq!(split.factorize_indefinite(&p, &definite).unwrap(), 0);
        assert_eq!(split.factorize_indefinite(&p, &definite).unwrap(), 0);
        assert_eq!(split.factor, Factor::Split);
        // A zero row in half 2, in half 1 and in the separator: the equation of the
        // whole-matrix factorisation.
        for eq in [order[sp.n1 + 3], order[5], order[n - 2]] {
            let mut v = definite.clone();
            for j in 0..n {
                for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                    if j == eq || p.row_idx[q] == eq {
                        v[q] = 0.0;
                    }
                }
            }
            v[p.position(eq, eq).unwrap()] = 0.0;
            let e1 = split.factorize(&p, &v).unwrap_err();
            let e2 = whole.factorize(&p, &v).unwrap_err();
            assert_eq!(e1, e2);
            assert_eq!(e1, SolverError::NotPositiveDefinite { equation: eq });
        }
    }

    /// The 9-point matrix of [`shifted_laplacian`] (σ = 0) with every stored entry moved by
    /// a pseudo-random amount in [−0.3, 0.3) (no symmetry of the grid left to make the
    /// spectrum special), and the same matrix dense.
    fn perturbed_laplacian(m: usize) -> (LowerPattern, Vec<f64>, faer::Mat<f64>) {
        let (p, mut vals) = shifted_laplacian(m, 0.0);
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for v in vals.iter_mut() {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            *v += 0.6 * ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
        }
        let n = p.n;
        let mut a = faer::Mat::<f64>::zeros(n, n);
        for j in 0..n {
            for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[q];
                a[(i, j)] = vals[q];
                a[(j, i)] = vals[q];
            }
        }
        (p, vals, a)
    }

    /// Smallest eigenvalue of the principal submatrix of `a` on `rows`.
    fn smallest_eigenvalue(a: &faer::Mat<f64>, rows: &[usize]) -> f64 {
        let b = faer::Mat::<f64>::from_fn(rows.len(), rows.len(), |i, j| a[(rows[i], rows[j])]);
        b.self_adjoint_eigenvalues(Side::Lower).unwrap()[0]
    }

    /// LDLᵀ by halves: on indefinite matrices whose negative eigenvalues lie only in the
    /// separator's Schur complement (halves by LLᵀ) or in the halves as well (LDLᵀ
    /// throughout), the negative pivots are the matrix's negative eigenvalues (faer's dense
    /// symmetric eigenvalues, an independent computation) and the solution is the dense LU
    /// solve's to round-off; a positive-definite one is factorised by LLᵀ throughout, or by
    /// LDLᵀ with no negative pivot right after an indefinite one.
    #[test]
    fn ldlt_by_halves_inertia_and_solution() {
        use faer::linalg::solvers::Solve;
        let m = 21;
        let n = m * m;
        let order = grid_dissection(m);
        let (p, base, a0) = perturbed_laplacian(m);
        let mut split = SparseCholesky::build(&p, FACTOR_KIND, Some(&order), 0).unwrap();
        let sp = split.split.as_ref().unwrap().split;
        let sep: Vec<usize> = order[sp.n1 + sp.n2..].to_vec();
        let border = |r: std::ops::Range<usize>| -> Vec<usize> {
            order[r].iter().chain(&sep).copied().collect()
        };
        let lam = a0.self_adjoint_eigenvalues(Side::Lower).unwrap();
        // The border matrices' smallest eigenvalues lie above the whole matrix's
        // (interlacing); a shift between them makes A indefinite with B1 and B2 definite.
        let b_min = smallest_eigenvalue(&a0, &border(0..sp.n1))
            .min(smallest_eigenvalue(&a0, &border(sp.n1..sp.n1 + sp.n2)));
        assert!(b_min > lam[0], "{b_min} against {}", lam[0]);
        let only_separator = 0.5 * (lam[0] + b_min.min(lam[1]));
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
        // After an indefinite border matrix its half goes to LDLᵀ at once (and so does S),
        // also for the definite matrix that follows; the one after that is LLᵀ again.
        let definite = lam[0] - 0.5;
        for (sigma, blocks) in [
            (definite, [false, false, false]),
            (only_separator, [false, false, true]),
            (0.37, [true, true, true]),
            (3.0, [true, true, true]),
            (definite, [true, true, true]),
            (definite, [false, false, false]),
        ] {
            let mut vals = base.clone();
            for j in 0..n {
                vals[p.position(j, j).unwrap()] -= sigma;
            }
            let a = faer::Mat::<f64>::from_fn(n, n, |i, j| {
                a0[(i, j)] - if i == j { sigma } else { 0.0 }
            });
            let ev = a.self_adjoint_eigenvalues(Side::Lower).unwrap();
            let expected = ev.iter().filter(|&&v| v < 0.0).count();
            // The count is not a matter of round-off: no eigenvalue near 0.
            let gap = ev.iter().fold(f64::INFINITY, |g, v| g.min(v.abs()));
            assert!(gap > 1e-3, "σ = {sigma}: eigenvalue {gap} near 0");
            let negative = split.factorize_indefinite(&p, &vals).unwrap();
            assert_eq!(negative, expected, "σ = {sigma}");
            assert_eq!(split.negative_pivots, expected);
            assert_eq!(split.factor, Factor::Split);
            assert_eq!(
                split.split.as_ref().unwrap().ldlt_blocks(),
                blocks,
                "σ = {sigma}"
            );
            let mut x = b.clone();
            split.solve_in_place(&mut x);
            let rhs = faer::Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
            let y = a.partial_piv_lu().solve(&rhs);
            let norm = (0..n).fold(0.0_f64, |s, i| s.max(y[(i, 0)].abs()));
            let diff = (0..n).fold(0.0_f64, |s, i| s.max((x[i] - y[(i, 0)]).abs()));
            // Two solves of a matrix of condition κ = max|λ| / min|λ| (25–240 here) agree to
            // ~κ·1e-16 of the solution (measured 1.4e-15–4.9e-14, at most 2.4e-16·κ);
            // 1e-15·κ leaves a factor 4 for the growth of the unpivoted LDLᵀ.
            let kappa = ev.iter().fold(0.0_f64, |s, v| s.max(v.abs())) / gap;
            assert!(
                diff <= 1e-15 * kappa * norm,
                "σ = {sigma}: {diff} of {norm}, κ {kappa}"
            );
        }
        assert_eq!(split.stats.split_ldlt_to_whole, 0);
        // Four factorisations ended in LDLᵀ, each counted as the LLᵀ attempt and the LDLᵀ.
        assert_eq!(split.stats.ldlt_factorisations, 4);
        assert_eq!(split.stats.factorisations, 10);
    }

    /// The growth guard of LDLᵀ by halves ([`super::split::TRAILING_GROWTH`]): half 1's
    /// border matrix B₁ = [A₁₁ A₁₃; A₃₁ A₃₃] is factorised by unpivoted LDLᵀ through its
    /// trailing (separator) block, whose product stands in for A₃₃ − L₃₁ D₁ L₃₁ᵀ. With the
    /// first separator column's pivot there made ε = 1e-9, the multipliers of the separator
    /// rows coupled to it are ~1/ε, and the trailing growth max_j Σ_k M_jk² |D_k| ~1e9 is
    /// far past its bound (1e6 × ~8, the separator's diagonal): the factorisation goes to
    /// the whole matrix (counted in `split_ldlt_to_whole`), where that pivot is not small
    /// (half 2 adds to it); its negative pivots are still the dense eigenvalues' count and
    /// its solution the dense LU's. The pivot is placed by moving that column's diagonal
    /// entry by its pivot minus ε, the pivot taken from an unpivoted dense LDLᵀ of B₁
    /// written here (the columns before it do not depend on that entry).
    #[test]
    fn ldlt_by_halves_falls_back_to_the_whole_matrix_past_the_growth_guard() {
        use faer::linalg::solvers::Solve;
        let m = 21;
        let n = m * m;
        let order = grid_dissection(m);
        let (p, mut vals) = shifted_laplacian(m, 0.37);
        let mut split = SparseCholesky::build(&p, FACTOR_KIND, Some(&order), 0).unwrap();
        let sp = split.split.as_ref().unwrap().split;
        let dense = |vals: &[f64]| {
            let mut a = faer::Mat::<f64>::zeros(n, n);
            for j in 0..n {
                for t in p.col_ptr[j]..p.col_ptr[j + 1] {
                    a[(p.row_idx[t], j)] = vals[t];
                    a[(j, p.row_idx[t])] = vals[t];
                }
            }
            a
        };
        // B₁ in its elimination order: half 1's own columns, then the separator's.
        let rows: Vec<usize> = order[..sp.n1]
            .iter()
            .chain(&order[sp.n1 + sp.n2..])
            .copied()
            .collect();
        let a = dense(&vals);
        let nb = rows.len();
        let q = sp.n1;
        let mut l = faer::Mat::<f64>::from_fn(nb, nb, |i, j| a[(rows[i], rows[j])]);
        let mut d = vec![0.0; q + 1];
        for j in 0..=q {
            d[j] = l[(j, j)] - (0..j).map(|k| l[(j, k)] * l[(j, k)] * d[k]).sum::<f64>();
            for i in j + 1..nb {
                let s: f64 = (0..j).map(|k| l[(i, k)] * l[(j, k)] * d[k]).sum();
                l[(i, j)] = (l[(i, j)] - s) / d[j];
            }
        }
        let eps = 1e-9;
        vals[p.position(rows[q], rows[q]).unwrap()] += eps - d[q];
        let a = dense(&vals);
        let ev = a.self_adjoint_eigenvalues(Side::Lower).unwrap();
        let expected = ev.iter().filter(|&&v| v < 0.0).count();
        // The count is not a matter of round-off: no eigenvalue near 0.
        let gap = ev.iter().fold(f64::INFINITY, |g, v| g.min(v.abs()));
        assert!(expected > 0 && gap > 1e-3, "{expected} negative, gap {gap}");
        let negative = split.factorize_indefinite(&p, &vals).unwrap();
        assert_eq!(split.stats.split_ldlt_to_whole, 1, "the guard did not act");
        assert_eq!(negative, expected);
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
        let mut x = b.clone();
        split.solve_in_place(&mut x);
        let y = a
            .partial_piv_lu()
            .solve(faer::Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
        let norm = (0..n).fold(0.0_f64, |s, i| s.max(y[(i, 0)].abs()));
        let diff = (0..n).fold(0.0_f64, |s, i| s.max((x[i] - y[(i, 0)]).abs()));
        // Two solves of a matrix of condition κ = max|λ| / min|λ| agree to ~κ·1e-16 of
        // the solution; 1e-15·κ leaves a factor 4 for the unpivoted LDLᵀ's growth, as in
        // `ldlt_by_halves_inertia_and_solution`.
        let kappa = ev.iter().fold(0.0_f64, |s, v| s.max(v.abs())) / gap;
        assert!(diff <= 1e-15 * kappa * norm, "{diff} of {norm}, κ {kappa}");
    }

    /// LDLᵀ by halves of a singular matrix (a zero row and column) in half 1, half 2 or
    /// the separator: [`SolverError::Singular`], as the whole matrix's LDLᵀ says; the
    /// separator's zero row makes both halves' trailing blocks singular, which goes to the
    /// whole matrix's LDLᵀ.
    #[test]
    fn ldlt_by_halves_reports_singular() {
        let m = 21;
        let n = m * m;
        let order = grid_dissection(m);
        let (p, vals) = shifted_laplacian(m, 0.37);
        let mut split = SparseCholesky::build(&p, FACTOR_KIND, Some(&order), 0).unwrap();
        let mut whole = SparseCholesky::with_ordering(&p, Some(&order)).unwrap();
        assert!(split.is_split() && !whole.is_split());
        let sp = split.split.as_ref().unwrap().split;
        for (k, eq) in [order[5], order[sp.n1 + 3], order[n - 2]]
            .into_iter()
            .enumerate()
        {
            let mut v = vals.clone();
            for j in 0..n {
                for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                    if j == eq || p.row_idx[q] == eq {
                        v[q] = 0.0;
                    }
                }
            }
            assert_eq!(
                split.factorize_indefinite(&p, &v),
                Err(SolverError::Singular)
            );
            assert_eq!(
                whole.factorize_indefinite(&p, &v),
                Err(SolverError::Singular)
            );
            assert!(!split.has_factor());
            assert_eq!(split.stats.split_ldlt_to_whole, usize::from(k == 2));
        }
    }

    /// A singular matrix (zero row) is reported, not solved.
    #[test]
    fn reports_non_positive_pivot() {
        let p = LowerPattern {
            n: 2,
            col_ptr: vec![0, 1, 2],
            row_idx: vec![0, 1],
        };
        let mut s = SparseCholesky::new(&p).unwrap();
        let err = s.factorize(&p, &[1.0, 0.0]).unwrap_err();
        assert_eq!(err, SolverError::NotPositiveDefinite { equation: 1 });
    }
}
