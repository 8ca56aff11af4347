//! The machinery of an assembly (`System::assemble`): element pieces in chunks computed in
//! parallel into slots of a chunk buffer, then scattered in element order into the global
//! forces and tangent, so results do not depend on the thread count; and the anchor-plate
//! tie transform of external tendons.

use super::responses;
use crate::elements::Response;
use crate::fem::assembly::Assembler;
use crate::materials::point::UpdateError;
use rayon::prelude::*;

/// Elements per parallel chunk: large enough to amortise scheduling, small enough to keep the
/// element-matrix buffer a few tens of MB.
pub(super) const CHUNK: usize = 4096;

/// Fewest continuum chunks of an assembly (down to [`MIN_CHUNK`] elements each): the scatter
/// of a chunk, sequential, runs beside the element work of the next one, so only the last
/// chunk's scatter leaves a core idle.
const MIN_CHUNKS: usize = 8;

/// Smallest continuum chunk [elements]: a small model (the seed beam, a few hundred
/// elements, an assembly in about a millisecond) keeps one chunk, whose scatter has nothing
/// to overlap, rather than pay a hand-over per chunk.
const MIN_CHUNK: usize = 1024;

/// Elements per chunk of the continuum loop of an assembly of `n_el` elements.
pub(super) fn continuum_chunk(n_el: usize) -> usize {
    n_el.div_ceil(MIN_CHUNKS).clamp(MIN_CHUNK, CHUNK)
}

/// Replace a square row-major matrix of order n by its symmetric part.
fn symmetrise(k: &mut [f64], n: usize) {
    for i in 0..n {
        for j in 0..i {
            let m = 0.5 * (k[i * n + j] + k[j * n + i]);
            k[i * n + j] = m;
            k[j * n + i] = m;
        }
    }
}

/// One element's outcome: `None` when it is absent (a tendon not yet stressed), else whether
/// its tangent is symmetric; or why a material point failed.
pub(super) type Outcome = Result<Option<bool>, UpdateError>;

/// Every `CHUNK` pieces with the index of the first.
pub(super) fn chunks<P>(pieces: Vec<P>) -> Vec<(usize, Vec<P>)> {
    let mut out = Vec::new();
    let mut it = pieces.into_iter().peekable();
    let mut start = 0;
    while it.peek().is_some() {
        let c: Vec<P> = it.by_ref().take(CHUNK).collect();
        let n = c.len();
        out.push((start, c));
        start += n;
    }
    out
}

/// Copy the forces of the `n` continuum elements from `first` on out of their chunk buffer
/// (slots of [`responses::ND`] entries) into `forces` (element e at e × ND).
pub(super) fn keep_forces(forces: &mut [f64], first: usize, n: usize, chunk: &[f64]) {
    let nd = responses::ND;
    forces[first * nd..(first + n) * nd].copy_from_slice(&chunk[..n * nd]);
}

/// The forces `fp` and tangent `kp` of a tendon's points carried to the nodes of its ties
/// (`nodes`, the tendon's assembler node list): f = Tᵀ f_p, K = Tᵀ K_p T with
/// T[2p+c][2m+c] = w(p, m), into the slot buffers `fe` and `ke` (2 × nodes.len() dofs).
pub(super) fn tie_transform(
    ties: &[Vec<(usize, f64)>],
    nodes: &[usize],
    fp: &[f64],
    kp: &[f64],
    fe: &mut [f64],
    ke: &mut [f64],
    tangent: bool,
) {
    let nd = 2 * nodes.len();
    let np = 2 * ties.len();
    let col = |n: usize| nodes.iter().position(|&m| m == n).expect("tie node listed");
    // Point p's ties as (local node index, weight).
    let local: Vec<Vec<(usize, f64)>> = ties
        .iter()
        .map(|t| t.iter().map(|&(n, w)| (col(n), w)).collect())
        .collect();
    fe[..nd].iter_mut().for_each(|v| *v = 0.0);
    for (p, tie) in local.iter().enumerate() {
        for &(a, w) in tie {
            fe[2 * a] += w * fp[2 * p];
            fe[2 * a + 1] += w * fp[2 * p + 1];
        }
    }
    if !tangent {
        return;
    }
    // K_p T first (np × nd), then Tᵀ (K_p T).
    let mut kt = vec![0.0; np * nd];
    for i in 0..np {
        for (q, tie) in local.iter().enumerate() {
            for c in 0..2 {
                let k = kp[i * np + 2 * q + c];
                if k == 0.0 {
                    continue;
                }
                for &(b, w) in tie {
                    kt[i * nd + 2 * b + c] += k * w;
                }
            }
        }
    }
    ke[..nd * nd].iter_mut().for_each(|v| *v = 0.0);
    for (p, tie) in local.iter().enumerate() {
        for c in 0..2 {
            let row = &kt[(2 * p + c) * nd..(2 * p + c + 1) * nd];
            for &(a, w) in tie {
                let out = &mut ke[(2 * a + c) * nd..(2 * a + c + 1) * nd];
                out.iter_mut().zip(row).for_each(|(o, r)| *o += w * r);
            }
        }
    }
}

/// Dofs of the largest of elements with these node counts.
pub(super) fn max_dofs(nodes: impl Iterator<Item = usize>) -> usize {
    2 * nodes.max().unwrap_or(0)
}

/// The response buffers of an element of `nd` dofs in its slot.
pub(super) fn slot<'a>(
    fe: &'a mut [f64],
    ke: &'a mut [f64],
    nd: usize,
    tangent: bool,
) -> Response<'a> {
    Response {
        f: &mut fe[..nd],
        k: tangent.then_some(&mut ke[..nd * nd]),
    }
}

/// Compute the responses of one chunk of elements in parallel, element i into slot i of
/// `buf` (`nd` force and `nd²` tangent entries); the outcomes in element order.
pub(super) fn compute_chunk<P: Send>(
    pieces: Vec<P>,
    nd: usize,
    buf: &mut (Vec<f64>, Vec<f64>),
    compute: impl Fn(P, &mut [f64], &mut [f64]) -> Outcome + Sync + Send,
) -> Vec<Outcome> {
    let n = pieces.len().max(1);
    // Grown, never shrunk: a run of many small assemblies must not zero or reallocate them
    // each time (every element writes its own slot before use).
    if buf.0.len() < n * nd {
        buf.0.resize(n * nd, 0.0);
    }
    if buf.1.len() < n * nd * nd {
        buf.1.resize(n * nd * nd, 0.0);
    }
    if nd == 0 {
        return Vec::new();
    }
    pieces
        .into_par_iter()
        .zip(buf.0.par_chunks_mut(nd))
        .zip(buf.1.par_chunks_mut(nd * nd))
        .map(|((p, fe), ke)| compute(p, fe, ke))
        .collect()
}

/// The global forces, force scale and tangent the element responses are scattered into.
pub(super) struct Scatter<'a> {
    pub(super) asm: &'a Assembler,
    pub(super) f_int: Vec<f64>,
    pub(super) f_abs: Vec<f64>,
    pub(super) k_values: Option<Vec<f64>>,
    pub(super) symmetrised: bool,
}

impl Scatter<'_> {
    /// Add the responses of a chunk (elements `start..`, slots of `nd` dofs in `buf`) in
    /// element order; `of(i)` gives element i's nodes and assembler number. Stops at the
    /// first failed element.
    pub(super) fn add_chunk<'n>(
        &mut self,
        results: Vec<Outcome>,
        start: usize,
        nd_slot: usize,
        buf: &mut (Vec<f64>, Vec<f64>),
        of: impl Fn(usize) -> (&'n [usize], usize),
    ) -> Result<(), (usize, UpdateError)> {
        for (i, r) in results.into_iter().enumerate() {
            let e = start + i;
            let Some(symmetric) = r.map_err(|err| (e, err))? else {
                continue;
            };
            let (nodes, number) = of(e);
            let nd = 2 * nodes.len();
            let fe = &buf.0[i * nd_slot..i * nd_slot + nd];
            for (a, &n) in nodes.iter().enumerate() {
                self.f_int[2 * n] += fe[2 * a];
                self.f_int[2 * n + 1] += fe[2 * a + 1];
                self.f_abs[2 * n] += fe[2 * a].abs();
                self.f_abs[2 * n + 1] += fe[2 * a + 1].abs();
            }
            if let Some(k) = self.k_values.as_mut() {
                let s = i * nd_slot * nd_slot;
                let ke = &mut buf.1[s..s + nd * nd];
                if !symmetric {
                    // Slip makes the tangent unsymmetric; the Cholesky path takes its
                    // symmetric part (more iterations, same converged answer).
                    symmetrise(ke, nd);
                    self.symmetrised = true;
                }
                self.asm.add_matrix(number, ke, k);
            }
        }
        Ok(())
    }
}
