//! T6: the 6-node quadratic triangle (Zienkiewicz, Taylor & Zhu, *The Finite Element
//! Method: Its Basis and Fundamentals*, 7th ed., §6.5 and table 6.3). Natural coordinates
//! (ξ, η) on the triangle ξ, η ≥ 0, ξ + η ≤ 1 with area coordinates L₁ = 1 − ξ − η,
//! L₂ = ξ, L₃ = η; nodes: corners 0, 1, 2 counter-clockwise, then the mid-sides of edges
//! 0–1, 1–2, 2–0 (VTK 22 and Gmsh 9 order).
//!
//! Rule: the 3-point rule of degree 2 at the interior points (L = ⅔, ⅙, ⅙), weights ⅙.
//! For a straight-sided T6 the strains are linear, so the stiffness integrand BᵀDB is of
//! degree 2 and this rule integrates it exactly; 3 points × 3 strains give the element's 9
//! deformation modes (12 dofs less 3 rigid), so it has no spurious mode. It is the standard
//! full rule of the element (Zienkiewicz et al., table 6.3); a 6-point rule would only add
//! cost. There is no reduced rule. Extrapolation to the nodes is the linear field through
//! the 3 points, evaluated at the nodes.

use super::{shape_values, Domain, ElementKindInfo};
use crate::fem::quadrature::Point2;
use crate::fem::shape::{ShapeValues, MAX_NODES};

/// The T6 descriptor.
pub static T6: ElementKindInfo = ElementKindInfo {
    name: "T6",
    description: "6-node quadratic triangle",
    n_nodes: 6,
    n_corners: 3,
    order: 2,
    edges: &[&[0, 1, 3], &[1, 2, 4], &[2, 0, 5]],
    node_xi: &[
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [0.5, 0.5],
        [0.0, 0.5],
    ],
    domain: Domain::Triangle,
    eval,
    full_rule: rule,
    reduced_rule: None,
    incompatible_modes: false,
    extrapolation,
    hull,
    vtk_cell: 22,
    gmsh_type: 9,
};

fn eval(xi: f64, eta: f64) -> ShapeValues {
    let mut s = shape_values(6);
    let (l1, l2, l3) = (1.0 - xi - eta, xi, eta);
    s.n_val[..6].copy_from_slice(&[
        l1 * (2.0 * l1 - 1.0),
        l2 * (2.0 * l2 - 1.0),
        l3 * (2.0 * l3 - 1.0),
        4.0 * l1 * l2,
        4.0 * l2 * l3,
        4.0 * l3 * l1,
    ]);
    // ∂L₁/∂ξ = ∂L₁/∂η = −1, ∂L₂/∂ξ = 1, ∂L₃/∂η = 1.
    s.d_xi[..6].copy_from_slice(&[
        1.0 - 4.0 * l1,
        4.0 * l2 - 1.0,
        0.0,
        4.0 * (l1 - l2),
        4.0 * l3,
        -4.0 * l3,
    ]);
    s.d_eta[..6].copy_from_slice(&[
        1.0 - 4.0 * l1,
        0.0,
        4.0 * l3 - 1.0,
        -4.0 * l2,
        4.0 * l2,
        4.0 * (l1 - l3),
    ]);
    s
}

fn rule() -> &'static [Point2] {
    const A: f64 = 1.0 / 6.0;
    const B: f64 = 2.0 / 3.0;
    &[(A, A, A), (B, A, A), (A, B, A)]
}

/// The linear field through the rule's first 3 points evaluated at each node: weights
/// w\[a\]\[g\] with Σ_g w\[a\]\[g\] f(p_g) = f(x_a) for every linear f (Cramer's rule on
/// the 3 × 3 system of the basis 1, ξ, η).
fn extrapolation(rule: &[Point2]) -> [[f64; 9]; MAX_NODES] {
    let p = [rule[0], rule[1], rule[2]];
    // Barycentric coordinates of x in the triangle of the 3 points are the weights.
    let det = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
    let mut w = [[0.0; 9]; MAX_NODES];
    for (a, x) in T6.node_xi.iter().enumerate() {
        let b1 = ((x[0] - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (x[1] - p[0].1)) / det;
        let b2 = ((p[1].0 - p[0].0) * (x[1] - p[0].1) - (x[0] - p[0].0) * (p[1].1 - p[0].1)) / det;
        w[a][..3].copy_from_slice(&[1.0 - b1 - b2, b1, b2]);
    }
    w
}

/// Corners and the edges' Bézier control points 2 m − (a + b)/2: the quadratic map's
/// control net, whose convex hull contains the element.
fn hull(c: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out = c[..3].to_vec();
    for e in T6.edges {
        let (a, b, m) = (c[e[0]], c[e[1]], c[e[2]]);
        out.push([
            2.0 * m[0] - 0.5 * (a[0] + b[0]),
            2.0 * m[1] - 0.5 * (a[1] + b[1]),
        ]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::shape::jacobian;
    use crate::model::ElementKind;

    /// The 3-point rule integrates every monomial ξ^i η^j of degree ≤ 2 over the reference
    /// triangle exactly: ∫ ξ^i η^j = i! j! / (i + j + 2)! (closed form).
    #[test]
    fn rule_is_exact_to_degree_2() {
        let fact = |n: u32| (1..=n).product::<u32>().max(1) as f64;
        for i in 0..=2u32 {
            for j in 0..=(2 - i) {
                let exact = fact(i) * fact(j) / fact(i + j + 2);
                let num: f64 = rule()
                    .iter()
                    .map(|p| p.0.powi(i as i32) * p.1.powi(j as i32) * p.2)
                    .sum();
                assert!((num - exact).abs() < 1e-15, "ξ^{i} η^{j}");
            }
        }
        for i in 0..=4u32 {
            for j in 0..=(4 - i) {
                let exact = fact(i) * fact(j) / fact(i + j + 2);
                let num: f64 = Domain::Triangle
                    .exact_rule()
                    .iter()
                    .map(|p| p.0.powi(i as i32) * p.1.powi(j as i32) * p.2)
                    .sum();
                // The 6-point rule's tabulated 15 digits.
                assert!((num - exact).abs() < 1e-14, "6-point ξ^{i} η^{j}");
            }
        }
    }

    /// The shape functions reproduce any quadratic field u = Σ N_a u(x_a) exactly (the
    /// element's completeness), and on a straight-sided triangle det J = 2 × its area.
    #[test]
    fn quadratic_completeness_and_jacobian() {
        let f = |p: [f64; 2]| {
            0.4 - 1.1 * p[0] + 0.7 * p[1] + 2.3 * p[0] * p[1] - 0.9 * p[0] * p[0]
                + 1.3 * p[1] * p[1]
        };
        for &(x, e) in &[(0.1, 0.2), (0.6, 0.3), (0.0, 0.9), (0.25, 0.25)] {
            let s = ElementKind::T6.eval(x, e);
            let v: f64 = (0..6).map(|a| s.n_val[a] * f(T6.node_xi[a])).sum();
            assert!((v - f([x, e])).abs() < 1e-14);
        }
        let c = [
            [1.0, 1.0],
            [4.0, 1.5],
            [2.0, 3.0],
            [2.5, 1.25],
            [3.0, 2.25],
            [1.5, 2.0],
        ];
        let area = 0.5 * ((4.0 - 1.0) * (3.0 - 1.0) - (2.0 - 1.0) * (1.5 - 1.0));
        let (_, det, _) = jacobian(&ElementKind::T6.eval(0.3, 0.2), &c);
        assert!((det - 2.0 * area).abs() < 1e-13);
    }
}
