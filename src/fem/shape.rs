//! Isoparametric mapping: shape-function values, Jacobian, Cartesian derivatives, and the
//! shape functions of 2- and 3-node lines. Each element kind's own shape functions are in its
//! descriptor ([`crate::fem::kinds`]).
//!
//! Node order follows VTK (so cells are written without reordering): corners counter-clockwise,
//! then mid-side nodes in edge order, then any centre node. Lines: the two ends, then (3-node)
//! the middle.

/// Maximum number of nodes of any element kind.
pub const MAX_NODES: usize = 9;

// Each kind's shape functions are in its descriptor (crate::fem::kinds).
use super::kinds::lagrange3;

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
