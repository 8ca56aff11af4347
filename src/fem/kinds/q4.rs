//! Q4: the 4-node bilinear quadrilateral. 2 × 2 Gauss (full and reduced); the incompatible
//! bending modes apply (`crate::elements::incompatible`).

use super::{shape_values, square_extrapolation, square_rule, Domain, ElementKindInfo};
use crate::fem::quadrature::Point2;
use crate::fem::shape::{ShapeValues, MAX_NODES, NODE_XI};

/// The Q4 descriptor.
pub static Q4: ElementKindInfo = ElementKindInfo {
    name: "Q4",
    description: "4-node bilinear quadrilateral",
    n_nodes: 4,
    n_corners: 4,
    order: 1,
    edges: &[&[0, 1], &[1, 2], &[2, 3], &[3, 0]],
    // The Q9's corner nodes.
    node_xi: NODE_XI.split_at(4).0,
    domain: Domain::Square,
    eval,
    full_rule: rule,
    reduced_rule: Some(rule),
    incompatible_modes: true,
    extrapolation,
    hull,
    vtk_cell: 9,
    gmsh_type: 3,
};

fn eval(xi: f64, eta: f64) -> ShapeValues {
    let mut s = shape_values(4);
    for i in 0..4 {
        let (a, b) = (NODE_XI[i][0], NODE_XI[i][1]);
        s.n_val[i] = 0.25 * (1.0 + a * xi) * (1.0 + b * eta);
        s.d_xi[i] = 0.25 * a * (1.0 + b * eta);
        s.d_eta[i] = 0.25 * b * (1.0 + a * xi);
    }
    s
}

fn rule() -> &'static [Point2] {
    square_rule(2)
}

fn extrapolation(rule: &[Point2]) -> [[f64; 9]; MAX_NODES] {
    square_extrapolation(Q4.node_xi, rule)
}

fn hull(c: &[[f64; 2]]) -> Vec<[f64; 2]> {
    c[..4].to_vec()
}
