//! Isoparametric shape functions: quadrilaterals Q4, Q8 (serendipity), Q9 (Lagrange) and
//! 2- and 3-node lines.
//!
//! Node order follows VTK (so cells are written without reordering): corners counter-clockwise
//! starting at (−1, −1), then mid-side nodes of edges 0–1, 1–2, 2–3, 3–0, then (Q9) the centre.
//! Lines: the two ends, then (3-node) the middle.

/// Maximum number of nodes of any element kind.
pub const MAX_NODES: usize = 9;

// The element kinds are model data (crate::model); shape functions read them.
use crate::model::QuadKind;

/// Natural coordinates of the nodes of a Q9 (the first 4 / 8 are those of Q4 / Q8).
pub const NODE_XI: [[f64; 2]; 9] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
];

/// Shape function values and natural derivatives at one point.
#[derive(Debug, Clone, Copy)]
pub struct ShapeValues {
    /// Number of nodes in use.
    pub n: usize,
    /// N_i.
    pub n_val: [f64; MAX_NODES],
    /// ∂N_i/∂ξ.
    pub d_xi: [f64; MAX_NODES],
    /// ∂N_i/∂η.
    pub d_eta: [f64; MAX_NODES],
}

impl QuadKind {
    /// Number of nodes.
    pub fn n_nodes(self) -> usize {
        match self {
            QuadKind::Q4 => 4,
            QuadKind::Q8 => 8,
            QuadKind::Q9 => 9,
        }
    }

    /// Nodes per edge (2 for Q4, 3 otherwise).
    pub fn nodes_per_edge(self) -> usize {
        match self {
            QuadKind::Q4 => 2,
            _ => 3,
        }
    }

    /// Local node indices of edge `e` (0..4), ordered start, end, [middle]; edges run
    /// counter-clockwise so the element lies to the left of each edge.
    pub fn edge_nodes(self, e: usize) -> Vec<usize> {
        let a = e;
        let b = (e + 1) % 4;
        match self {
            QuadKind::Q4 => vec![a, b],
            _ => vec![a, b, 4 + e],
        }
    }

    /// VTK cell type id.
    pub fn vtk_cell_type(self) -> u8 {
        match self {
            QuadKind::Q4 => 9,
            QuadKind::Q8 => 23,
            QuadKind::Q9 => 28,
        }
    }

    /// Default Gauss rule order per direction for full integration.
    pub fn full_gauss_order(self) -> usize {
        match self {
            QuadKind::Q4 => 2,
            _ => 3,
        }
    }

    /// Evaluate shape functions and their natural derivatives at (ξ, η).
    pub fn eval(self, xi: f64, eta: f64) -> ShapeValues {
        let mut s = ShapeValues {
            n: self.n_nodes(),
            n_val: [0.0; MAX_NODES],
            d_xi: [0.0; MAX_NODES],
            d_eta: [0.0; MAX_NODES],
        };
        match self {
            QuadKind::Q4 => {
                for i in 0..4 {
                    let (a, b) = (NODE_XI[i][0], NODE_XI[i][1]);
                    s.n_val[i] = 0.25 * (1.0 + a * xi) * (1.0 + b * eta);
                    s.d_xi[i] = 0.25 * a * (1.0 + b * eta);
                    s.d_eta[i] = 0.25 * b * (1.0 + a * xi);
                }
            }
            QuadKind::Q8 => {
                for i in 0..4 {
                    let (a, b) = (NODE_XI[i][0], NODE_XI[i][1]);
                    let (p, q) = (1.0 + a * xi, 1.0 + b * eta);
                    let r = a * xi + b * eta - 1.0;
                    s.n_val[i] = 0.25 * p * q * r;
                    s.d_xi[i] = 0.25 * a * q * (r + p);
                    s.d_eta[i] = 0.25 * b * p * (r + q);
                }
                for i in 4..8 {
                    let (a, b) = (NODE_XI[i][0], NODE_XI[i][1]);
                    if a == 0.0 {
                        s.n_val[i] = 0.5 * (1.0 - xi * xi) * (1.0 + b * eta);
                        s.d_xi[i] = -xi * (1.0 + b * eta);
                        s.d_eta[i] = 0.5 * b * (1.0 - xi * xi);
                    } else {
                        s.n_val[i] = 0.5 * (1.0 + a * xi) * (1.0 - eta * eta);
                        s.d_xi[i] = 0.5 * a * (1.0 - eta * eta);
                        s.d_eta[i] = -eta * (1.0 + a * xi);
                    }
                }
            }
            QuadKind::Q9 => {
                let (lx, dlx) = lagrange3(xi);
                let (ly, dly) = lagrange3(eta);
                // 1-D index (0: −1, 1: 0, 2: +1) of each node's coordinate.
                let idx = |v: f64| -> usize {
                    if v < -0.5 {
                        0
                    } else if v > 0.5 {
                        2
                    } else {
                        1
                    }
                };
                for i in 0..9 {
                    let (ix, iy) = (idx(NODE_XI[i][0]), idx(NODE_XI[i][1]));
                    s.n_val[i] = lx[ix] * ly[iy];
                    s.d_xi[i] = dlx[ix] * ly[iy];
                    s.d_eta[i] = lx[ix] * dly[iy];
                }
            }
        }
        s
    }
}

/// Quadratic Lagrange polynomials on nodes (−1, 0, 1) and their derivatives.
fn lagrange3(x: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * x * (x - 1.0), 1.0 - x * x, 0.5 * x * (x + 1.0)],
        [x - 0.5, -2.0 * x, x + 0.5],
    )
}

/// Shape functions of a 2- or 3-node line at r ∈ [−1, 1], nodes ordered (start, end, middle).
/// Returns (N, dN/dr) with `n` entries used.
pub fn line_shape(n: usize, r: f64) -> ([f64; 3], [f64; 3]) {
    match n {
        2 => ([0.5 * (1.0 - r), 0.5 * (1.0 + r), 0.0], [-0.5, 0.5, 0.0]),
        3 => {
            let (l, dl) = lagrange3(r);
            ([l[0], l[2], l[1]], [dl[0], dl[2], dl[1]])
        }
        _ => panic!("line elements have 2 or 3 nodes, not {n}"),
    }
}

/// Jacobian of the map (ξ, η) → (x, y): returns (J, det J, J⁻¹) with
/// J = [[∂x/∂ξ, ∂y/∂ξ], [∂x/∂η, ∂y/∂η]].
pub fn jacobian(s: &ShapeValues, coords: &[[f64; 2]]) -> ([[f64; 2]; 2], f64, [[f64; 2]; 2]) {
    let mut j = [[0.0; 2]; 2];
    for i in 0..s.n {
        j[0][0] += s.d_xi[i] * coords[i][0];
        j[0][1] += s.d_xi[i] * coords[i][1];
        j[1][0] += s.d_eta[i] * coords[i][0];
        j[1][1] += s.d_eta[i] * coords[i][1];
    }
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let inv = [
        [j[1][1] / det, -j[0][1] / det],
        [-j[1][0] / det, j[0][0] / det],
    ];
    (j, det, inv)
}

/// Cartesian derivatives (∂N/∂x, ∂N/∂y) from natural ones and J⁻¹.
pub fn cartesian_derivatives(s: &ShapeValues, inv: &[[f64; 2]; 2]) -> [[f64; 2]; MAX_NODES] {
    let mut d = [[0.0; 2]; MAX_NODES];
    for i in 0..s.n {
        d[i][0] = inv[0][0] * s.d_xi[i] + inv[0][1] * s.d_eta[i];
        d[i][1] = inv[1][0] * s.d_xi[i] + inv[1][1] * s.d_eta[i];
    }
    d
}

/// Map natural coordinates to global ones.
pub fn map_point(s: &ShapeValues, coords: &[[f64; 2]]) -> [f64; 2] {
    let mut x = [0.0; 2];
    for i in 0..s.n {
        x[0] += s.n_val[i] * coords[i][0];
        x[1] += s.n_val[i] * coords[i][1];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [QuadKind; 3] = [QuadKind::Q4, QuadKind::Q8, QuadKind::Q9];

    /// Kronecker property N_i(x_j) = δ_ij and partition of unity with zero-sum derivatives.
    #[test]
    fn kronecker_and_partition_of_unity() {
        for k in KINDS {
            for j in 0..k.n_nodes() {
                let s = k.eval(NODE_XI[j][0], NODE_XI[j][1]);
                for i in 0..k.n_nodes() {
                    let d = if i == j { 1.0 } else { 0.0 };
                    assert!((s.n_val[i] - d).abs() < 1e-14, "{k:?} N{i} at node {j}");
                }
            }
            let s = k.eval(0.3, -0.7);
            let sum: f64 = s.n_val[..s.n].iter().sum();
            let sx: f64 = s.d_xi[..s.n].iter().sum();
            let se: f64 = s.d_eta[..s.n].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14 && sx.abs() < 1e-14 && se.abs() < 1e-14);
        }
    }

    /// Derivatives against central finite differences (error O(h²) ≈ 1e-10 with h = 1e-5).
    #[test]
    fn derivatives_match_finite_differences() {
        let h = 1e-5;
        for k in KINDS {
            let (x, e) = (0.21, -0.43);
            let s = k.eval(x, e);
            let (sp, sm) = (k.eval(x + h, e), k.eval(x - h, e));
            let (tp, tm) = (k.eval(x, e + h), k.eval(x, e - h));
            for i in 0..s.n {
                assert!((s.d_xi[i] - (sp.n_val[i] - sm.n_val[i]) / (2.0 * h)).abs() < 1e-8);
                assert!((s.d_eta[i] - (tp.n_val[i] - tm.n_val[i]) / (2.0 * h)).abs() < 1e-8);
            }
        }
    }

    /// Line shape functions interpolate nodes in (start, end, middle) order.
    #[test]
    fn line_shapes_interpolate_their_nodes() {
        for (n, pts) in [(2, vec![-1.0, 1.0]), (3, vec![-1.0, 1.0, 0.0])] {
            for (j, r) in pts.iter().enumerate() {
                let (v, _) = line_shape(n, *r);
                for (i, vi) in v.iter().take(n).enumerate() {
                    assert!((vi - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
                }
            }
        }
    }
}
