//! Q8: the 8-node serendipity quadrilateral. 3 × 3 Gauss, reduced 2 × 2.

use super::{biquadratic_hull, shape_values, square_extrapolation, square_rule};
use super::{Domain, ElementKindInfo};
use crate::fem::quadrature::Point2;
use crate::fem::shape::{ShapeValues, MAX_NODES, NODE_XI};

/// The Q8 descriptor.
pub static Q8: ElementKindInfo = ElementKindInfo {
    name: "Q8",
    description: "8-node serendipity quadrilateral",
    n_nodes: 8,
    n_corners: 4,
    order: 2,
    edges: &[&[0, 1, 4], &[1, 2, 5], &[2, 3, 6], &[3, 0, 7]],
    // The Q9's nodes without the centre.
    node_xi: NODE_XI.split_at(8).0,
    domain: Domain::Square,
    eval,
    full_rule: || square_rule(3),
    reduced_rule: Some(|| square_rule(2)),
    incompatible_modes: false,
    extrapolation,
    hull,
    vtk_cell: 23,
    gmsh_type: 16,
};

fn eval(xi: f64, eta: f64) -> ShapeValues {
    let mut s = shape_values(8);
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
    s
}

fn extrapolation(rule: &[Point2]) -> [[f64; 9]; MAX_NODES] {
    square_extrapolation(Q8.node_xi, rule)
}

/// Q8 written as a Q9 with the centre value of the serendipity map.
fn hull(c: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut z = [0.0; 2];
    for d in 0..2 {
        z[d] = -0.25 * (c[0][d] + c[1][d] + c[2][d] + c[3][d])
            + 0.5 * (c[4][d] + c[5][d] + c[6][d] + c[7][d]);
    }
    biquadratic_hull(c, z)
}
