//! Q9: the 9-node Lagrange quadrilateral. 3 × 3 Gauss, reduced 2 × 2.

use super::{biquadratic_hull, lagrange3, shape_values, square_extrapolation, square_rule};
use super::{Domain, ElementKindInfo};
use crate::fem::quadrature::Point2;
use crate::fem::shape::{ShapeValues, MAX_NODES, NODE_XI};

/// The Q9 descriptor.
pub static Q9: ElementKindInfo = ElementKindInfo {
    name: "Q9",
    description: "9-node Lagrange quadrilateral",
    n_nodes: 9,
    n_corners: 4,
    order: 2,
    edges: &[&[0, 1, 4], &[1, 2, 5], &[2, 3, 6], &[3, 0, 7]],
    node_xi: &NODE_XI,
    domain: Domain::Square,
    eval,
    full_rule: || square_rule(3),
    reduced_rule: Some(|| square_rule(2)),
    incompatible_modes: false,
    extrapolation,
    hull,
    vtk_cell: 28,
    gmsh_type: 10,
};

fn eval(xi: f64, eta: f64) -> ShapeValues {
    let mut s = shape_values(9);
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
    s
}

fn extrapolation(rule: &[Point2]) -> [[f64; 9]; MAX_NODES] {
    square_extrapolation(Q9.node_xi, rule)
}

fn hull(c: &[[f64; 2]]) -> Vec<[f64; 2]> {
    biquadratic_hull(c, c[8])
}
