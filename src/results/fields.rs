//! Field recovery for output: Gauss-point stress and strain extrapolated to nodes and
//! averaged, cell averages, principal stresses.

use crate::analysis::system::System;
use crate::elements::continuum::extrapolate_to_nodes;

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

/// Recover the fields from the committed Gauss outputs of a system.
pub fn recover(sys: &System) -> Fields {
    let model = sys.model;
    let nn = model.nodes.len();
    let mut ns = vec![[0.0; 3]; nn];
    let mut ne = vec![[0.0; 3]; nn];
    let mut count = vec![0u32; nn];
    let mut cs = Vec::with_capacity(model.elements.len());
    let mut ce = Vec::with_capacity(model.elements.len());
    for (e, el) in model.elements.iter().enumerate() {
        let g = &sys.gauss[sys.gp_offset[e]..sys.gp_offset[e + 1]];
        let s: Vec<[f64; 3]> = g.iter().map(|o| o.stress).collect();
        let t: Vec<[f64; 3]> = g.iter().map(|o| o.strain).collect();
        let avg = |v: &[[f64; 3]]| {
            let mut a = [0.0; 3];
            for x in v {
                for c in 0..3 {
                    a[c] += x[c] / v.len() as f64;
                }
            }
            a
        };
        cs.push(avg(&s));
        ce.push(avg(&t));
        let xs = extrapolate_to_nodes(el.kind, el.integration, &s);
        let xe = extrapolate_to_nodes(el.kind, el.integration, &t);
        for (a, &n) in el.nodes.iter().enumerate() {
            for c in 0..3 {
                ns[n][c] += xs[a][c];
                ne[n][c] += xe[a][c];
            }
            count[n] += 1;
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
        cell_stress: cs,
        cell_strain: ce,
    }
}
