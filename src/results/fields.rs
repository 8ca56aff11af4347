//! Field recovery for output: Gauss-point stress and strain extrapolated to nodes and
//! averaged, cell averages, principal stresses.

use crate::analysis::system::System;
use crate::elements::continuum::extrapolation_weights;
use crate::fem::shape::MAX_NODES;
use rayon::prelude::*;

/// Nodal and cell fields of one converged state.
pub struct Fields {
    /// Nodal stress (σx, σy, τxy) [Pa], averaged over the elements sharing a node.
    pub node_stress: Vec<[f64; 3]>,
    /// Nodal strain (εx, εy, γxy) [-].
    pub node_strain: Vec<[f64; 3]>,
    /// Cell-average stress [Pa].
    pub cell_stress: Vec<[f64; 3]>,
    /// Cell-average strain [-].
    pub cell_strain: Vec<[f64; 3]>,
}

/// Principal stresses (σ1 ≥ σ2) of a plane-stress state [Pa].
pub fn principal(s: &[f64; 3]) -> (f64, f64) {
    let c = 0.5 * (s[0] + s[1]);
    let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
    (c + r, c - r)
}

/// Elements per parallel chunk of [`recover`]: the extrapolated values of one chunk are kept
/// at a time (~2 MB) instead of those of every element (120 MB of fresh memory at 5e5 dofs).
const CHUNK: usize = 4096;

/// Recover the fields from the committed Gauss outputs of a system. Element values are
/// computed in parallel, a chunk of elements at a time; the nodal sums run in element order
/// (results do not depend on the thread count or the chunk size).
pub fn recover(sys: &System) -> Fields {
    let model = sys.model;
    let nn = model.nodes.len();
    let ne_all = model.elements.len();
    type Extrapolated = [[[f64; 3]; 2]; MAX_NODES];
    let mut ns = vec![[0.0; 3]; nn];
    let mut ne = vec![[0.0; 3]; nn];
    let mut count = vec![0u32; nn];
    let mut cell_stress = vec![[0.0; 3]; ne_all];
    let mut cell_strain = vec![[0.0; 3]; ne_all];
    let mut x_buf: Vec<Extrapolated> = vec![[[[0.0; 3]; 2]; MAX_NODES]; CHUNK.min(ne_all)];
    for start in (0..ne_all).step_by(CHUNK) {
        let end = (start + CHUNK).min(ne_all);
        let elements = &model.elements[start..end];
        elements
            .par_iter()
            .zip(&mut cell_stress[start..end])
            .zip(&mut cell_strain[start..end])
            .zip(&mut x_buf[..end - start])
            .enumerate()
            .for_each(|(i, (((el, cs), ce), x))| {
                let e = start + i;
                let g = sys.element_gauss(e);
                let len = g.len() as f64;
                *cs = [0.0; 3];
                *ce = [0.0; 3];
                for o in g {
                    for c in 0..3 {
                        cs[c] += o.stress[c] / len;
                        ce[c] += o.strain[c] / len;
                    }
                }
                let w = extrapolation_weights(el.kind, el.integration);
                *x = [[[0.0; 3]; 2]; MAX_NODES];
                for a in 0..el.nodes.len() {
                    for (k, o) in g.iter().enumerate() {
                        for c in 0..3 {
                            x[a][0][c] += w[a][k] * o.stress[c];
                            x[a][1][c] += w[a][k] * o.strain[c];
                        }
                    }
                }
            });
        for (el, x) in elements.iter().zip(&x_buf) {
            for (a, &n) in el.nodes.iter().enumerate() {
                for c in 0..3 {
                    ns[n][c] += x[a][0][c];
                    ne[n][c] += x[a][1][c];
                }
                count[n] += 1;
            }
        }
    }
    for n in 0..nn {
        if count[n] > 0 {
            for c in 0..3 {
                ns[n][c] /= count[n] as f64;
                ne[n][c] /= count[n] as f64;
            }
        }
    }
    Fields {
        node_stress: ns,
        node_strain: ne,
        cell_stress,
        cell_strain,
    }
}
