//! One descriptor per continuum element kind ([`ElementKindInfo`]): name, nodes, corners,
//! edges, reference domain, shape functions, quadrature, nodal extrapolation, VTK and Gmsh
//! ids. The model's enum [`ElementKind`] dispatches to its kind's descriptor
//! ([`ElementKind::info`]); every other module asks the descriptor, none matches on the kind.
//!
//! Adding a kind (docs/architecture.md, "Adding a continuum element kind"): a file here that
//! fills an [`ElementKindInfo`], its variant in `ElementKind` (src/model/element_data.rs) and
//! its line in [`ALL`] and [`ElementKind::info`].

mod q4;
mod q8;
mod q9;
mod t6;

use super::quadrature::{gauss, gauss_square, Point2};
use super::shape::{ShapeValues, MAX_NODES};
use crate::model::element_data::Integration;
use crate::model::ElementKind;

/// Every continuum element kind, in the order of their variants.
pub const ALL: [ElementKind; 4] = [
    ElementKind::Q4,
    ElementKind::Q8,
    ElementKind::Q9,
    ElementKind::T6,
];

/// The reference domain of an element kind's natural coordinates (ξ, η).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// The square [−1, 1]² (quadrilaterals).
    Square,
    /// The triangle ξ ≥ 0, η ≥ 0, ξ + η ≤ 1 (triangles; ξ, η are the area coordinates
    /// L₂, L₃, L₁ = 1 − ξ − η).
    Triangle,
}

impl Domain {
    /// Whether (ξ, η) lies in the domain within `tol` (in natural coordinates).
    pub fn inside(self, p: [f64; 2], tol: f64) -> bool {
        match self {
            Domain::Square => p[0].abs() <= 1.0 + tol && p[1].abs() <= 1.0 + tol,
            Domain::Triangle => p[0] >= -tol && p[1] >= -tol && p[0] + p[1] <= 1.0 + tol,
        }
    }

    /// The domain's centre (the starting guess of an inverse mapping).
    pub fn centre(self) -> [f64; 2] {
        match self {
            Domain::Square => [0.0, 0.0],
            Domain::Triangle => [1.0 / 3.0, 1.0 / 3.0],
        }
    }

    /// The domain's vertices, counter-clockwise.
    pub fn vertices(self) -> &'static [[f64; 2]] {
        match self {
            Domain::Square => &[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
            Domain::Triangle => &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        }
    }

    /// The points of a grid of `n` points per side over the domain (square: n × n, ξ and η
    /// from −1 to 1; triangle: the points (i, j)/(n − 1) with i + j ≤ n − 1), in (ξ, η).
    pub fn grid(self, n: usize) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        match self {
            Domain::Square => {
                let at = |i: usize| -1.0 + 2.0 * i as f64 / (n - 1) as f64;
                for i in 0..n {
                    for j in 0..n {
                        out.push([at(i), at(j)]);
                    }
                }
            }
            Domain::Triangle => {
                let at = |i: usize| i as f64 / (n - 1) as f64;
                for i in 0..n {
                    for j in 0..n - i {
                        out.push([at(i), at(j)]);
                    }
                }
            }
        }
        out
    }

    /// A rule integrating polynomials of degree 4 exactly over the domain (areas and body
    /// forces of curved quadratic elements): 3 × 3 Gauss on the square, the 6-point rule of
    /// degree 4 on the triangle (Dunavant 1985, Int. J. Numer. Meth. Eng. 21, table for p = 4).
    pub fn exact_rule(self) -> Vec<Point2> {
        match self {
            Domain::Square => gauss_square(3),
            Domain::Triangle => {
                let (a, wa) = (0.445_948_490_915_965, 0.223_381_589_678_011 / 2.0);
                let (b, wb) = (0.091_576_213_509_771, 0.109_951_743_655_322 / 2.0);
                vec![
                    (a, a, wa),
                    (1.0 - 2.0 * a, a, wa),
                    (a, 1.0 - 2.0 * a, wa),
                    (b, b, wb),
                    (1.0 - 2.0 * b, b, wb),
                    (b, 1.0 - 2.0 * b, wb),
                ]
            }
        }
    }
}

/// Everything that distinguishes one continuum element kind. Node order follows VTK (cells
/// are written without reordering): corners counter-clockwise, then mid-side nodes of the
/// edges in edge order, then any interior node.
#[derive(Debug)]
pub struct ElementKindInfo {
    /// The name in model files and messages (`"Q8"`); matched case-insensitively.
    pub name: &'static str,
    /// One-line description for messages and docs.
    pub description: &'static str,
    /// Number of nodes.
    pub n_nodes: usize,
    /// Number of corner nodes (the first `n_corners` nodes).
    pub n_corners: usize,
    /// Polynomial order along an edge (1: linear, 2: quadratic).
    pub order: usize,
    /// Local node indices of each edge, ordered start, end, [middle]; edges run
    /// counter-clockwise so the element lies to the left of each edge.
    pub edges: &'static [&'static [usize]],
    /// Natural coordinates (ξ, η) of the nodes.
    pub node_xi: &'static [[f64; 2]],
    /// Reference domain of (ξ, η).
    pub domain: Domain,
    /// Shape functions and their natural derivatives at (ξ, η).
    pub eval: fn(f64, f64) -> ShapeValues,
    /// The full integration rule (built once; the element loop must not allocate).
    pub full_rule: fn() -> &'static [Point2],
    /// The reduced rule, if the kind has one (`integration = "reduced"`).
    pub reduced_rule: Option<fn() -> &'static [Point2]>,
    /// Whether the Q4 incompatible bending modes apply (`integration = "incompatible"`).
    pub incompatible_modes: bool,
    /// Nodal extrapolation weights from the points of a rule of this kind: value at node a
    /// = Σ_g w\[a\]\[g\] · value at point g.
    pub extrapolation: fn(&[Point2]) -> [[f64; 9]; MAX_NODES],
    /// Points whose convex hull contains the element with nodes at the given coordinates
    /// [m] (the Bernstein control net of its map), for bounding boxes.
    pub hull: fn(&[[f64; 2]]) -> Vec<[f64; 2]>,
    /// VTK cell type id.
    pub vtk_cell: u8,
    /// Gmsh element type id.
    pub gmsh_type: i64,
}

impl ElementKind {
    /// The kind's descriptor.
    pub fn info(self) -> &'static ElementKindInfo {
        match self {
            ElementKind::Q4 => &q4::Q4,
            ElementKind::Q8 => &q8::Q8,
            ElementKind::Q9 => &q9::Q9,
            ElementKind::T6 => &t6::T6,
        }
    }

    /// The kind named `s` in a model file or on the command line (case-insensitive), if any.
    pub fn from_name(s: &str) -> Option<Self> {
        ALL.into_iter()
            .find(|k| k.info().name.eq_ignore_ascii_case(s))
    }

    /// The names of all kinds, "Q4, Q8, Q9 or T6", for messages.
    pub fn names() -> String {
        let n: Vec<&str> = ALL.iter().map(|k| k.info().name).collect();
        match n.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => n.join(""),
        }
    }

    /// The kind of a Gmsh element type id, if it is a continuum kind.
    pub fn from_gmsh(t: i64) -> Option<Self> {
        ALL.into_iter().find(|k| k.info().gmsh_type == t)
    }

    /// Number of nodes.
    pub fn n_nodes(self) -> usize {
        self.info().n_nodes
    }

    /// Number of corner nodes.
    pub fn n_corners(self) -> usize {
        self.info().n_corners
    }

    /// The local node lists of the edges (start, end, [middle]), counter-clockwise.
    pub fn edges(self) -> &'static [&'static [usize]] {
        self.info().edges
    }

    /// Local node indices of edge `e`, ordered start, end, [middle].
    pub fn edge_nodes(self, e: usize) -> &'static [usize] {
        self.info().edges[e]
    }

    /// VTK cell type id.
    pub fn vtk_cell_type(self) -> u8 {
        self.info().vtk_cell
    }

    /// Shape functions and their natural derivatives at (ξ, η).
    pub fn eval(self, xi: f64, eta: f64) -> ShapeValues {
        (self.info().eval)(xi, eta)
    }

    /// The Gauss points of the kind under a rule (incompatible modes integrate by the full
    /// rule; a kind without a reduced rule, refused at input, falls back to its full rule).
    pub fn rule(self, integration: Integration) -> &'static [Point2] {
        let info = self.info();
        match (integration, info.reduced_rule) {
            (Integration::Reduced, Some(r)) => r(),
            _ => (info.full_rule)(),
        }
    }

    /// The structured-grid layout of a quadrilateral kind: its order (grid steps per element
    /// side) and whether it has a centre node; None for kinds the grid generators cannot
    /// make (triangles).
    pub fn grid_layout(self) -> Option<(usize, bool)> {
        let info = self.info();
        (info.domain == Domain::Square).then(|| (info.order, info.node_xi.contains(&[0.0, 0.0])))
    }

    /// Offsets (i, j) in grid steps of node `a` from the element's lower-left grid point, for
    /// a quadrilateral of grid order `order` ([`Self::grid_layout`]).
    pub fn grid_offset(self, a: usize, order: usize) -> (usize, usize) {
        let [x, y] = self.info().node_xi[a];
        let step = |v: f64| ((v + 1.0) * 0.5 * order as f64).round() as usize;
        (step(x), step(y))
    }

    /// Number of nodes of a structured grid of `nx` × `ny` elements of this quadrilateral
    /// kind (f64: checked before anything is allocated); None for non-grid kinds.
    pub fn grid_nodes(self, nx: f64, ny: f64) -> Option<f64> {
        let (o, centre) = self.grid_layout()?;
        let o = o as f64;
        let all = (o * nx + 1.0) * (o * ny + 1.0);
        Some(if o > 1.0 && !centre {
            all - nx * ny
        } else {
            all
        })
    }
}

/// Tensor-product Gauss rules on the square, built once: 2 × 2 and 3 × 3.
pub(crate) fn square_rule(n: usize) -> &'static [Point2] {
    static RULES: std::sync::OnceLock<[Vec<Point2>; 2]> = std::sync::OnceLock::new();
    let r = RULES.get_or_init(|| [gauss_square(2), gauss_square(3)]);
    &r[usize::from(n != 2)]
}

/// Extrapolation weights of a tensor-product Gauss rule on the square (2 × 2 or 3 × 3): the
/// tensor-product Lagrange interpolant through the points evaluated at each node.
pub(crate) fn square_extrapolation(node_xi: &[[f64; 2]], rule: &[Point2]) -> [[f64; 9]; MAX_NODES] {
    let order = if rule.len() == 4 { 2 } else { 3 };
    let r = gauss(order);
    let lag = |x: f64, i: usize| -> f64 {
        let mut v = 1.0;
        for (j, pj) in r.points.iter().enumerate() {
            if j != i {
                v *= (x - pj) / (r.points[i] - pj);
            }
        }
        v
    };
    let mut w = [[0.0; 9]; MAX_NODES];
    for (a, &[xi, eta]) in node_xi.iter().enumerate() {
        for g in 0..order * order {
            w[a][g] = lag(xi, g % order) * lag(eta, g / order);
        }
    }
    w
}

/// The control net of a biquadratic map with the given corner, mid-side and centre
/// coordinates (Q8 and Q9 node order): its convex hull contains the element.
pub(crate) fn biquadratic_hull(c: &[[f64; 2]], centre: [f64; 2]) -> Vec<[f64; 2]> {
    // Lagrange grid L[iy][ix], ix/iy = 0, 1, 2 for −1, 0, +1.
    let l = [[c[0], c[4], c[1]], [c[7], centre, c[5]], [c[3], c[6], c[2]]];
    let conv = |a: [f64; 2], m: [f64; 2], b: [f64; 2]| -> [f64; 2] {
        [
            2.0 * m[0] - 0.5 * (a[0] + b[0]),
            2.0 * m[1] - 0.5 * (a[1] + b[1]),
        ]
    };
    let mut rows = [[[0.0; 2]; 3]; 3];
    for iy in 0..3 {
        rows[iy] = [l[iy][0], conv(l[iy][0], l[iy][1], l[iy][2]), l[iy][2]];
    }
    let mut out = Vec::with_capacity(9);
    for ((&a, &m), &b) in rows[0].iter().zip(&rows[1]).zip(&rows[2]) {
        out.push(a);
        out.push(conv(a, m, b));
        out.push(b);
    }
    out
}

/// Quadratic Lagrange polynomials on nodes (−1, 0, 1) and their derivatives.
pub(crate) fn lagrange3(x: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * x * (x - 1.0), 1.0 - x * x, 0.5 * x * (x + 1.0)],
        [x - 0.5, -2.0 * x, x + 0.5],
    )
}

/// An empty [`ShapeValues`] for `n` nodes.
pub(crate) fn shape_values(n: usize) -> ShapeValues {
    ShapeValues {
        n,
        n_val: [0.0; MAX_NODES],
        d_xi: [0.0; MAX_NODES],
        d_eta: [0.0; MAX_NODES],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kind's descriptor is consistent: node counts, edges' nodes in range and the
    /// edges' end points the corners in order, Kronecker property at its nodes, partition
    /// of unity, derivatives against central differences (error O(h²) ≈ 1e-10, h = 1e-5),
    /// rule weights summing to the domain's area, name and Gmsh id round trips.
    #[test]
    fn descriptors_are_consistent() {
        for k in ALL {
            let i = k.info();
            assert_eq!(i.node_xi.len(), i.n_nodes, "{k:?}");
            assert_eq!(i.edges.len(), i.n_corners, "{k:?}");
            for (e, nodes) in i.edges.iter().enumerate() {
                assert_eq!(nodes.len(), i.order + 1, "{k:?}");
                assert_eq!(nodes[0], e);
                assert_eq!(nodes[1], (e + 1) % i.n_corners);
                for &n in nodes.iter().skip(2) {
                    let [a, b] = [i.node_xi[nodes[0]], i.node_xi[nodes[1]]];
                    let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
                    assert_eq!(i.node_xi[n], m, "{k:?} edge {e}");
                }
            }
            for (j, p) in i.node_xi.iter().enumerate() {
                let s = k.eval(p[0], p[1]);
                for a in 0..i.n_nodes {
                    let d = if a == j { 1.0 } else { 0.0 };
                    assert!((s.n_val[a] - d).abs() < 1e-14, "{k:?} N{a} at node {j}");
                }
            }
            let (x, e, h) = (0.21, 0.13, 1e-5);
            let s = k.eval(x, e);
            let sum: f64 = s.n_val[..s.n].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14);
            let (sp, sm) = (k.eval(x + h, e), k.eval(x - h, e));
            let (tp, tm) = (k.eval(x, e + h), k.eval(x, e - h));
            for a in 0..s.n {
                assert!((s.d_xi[a] - (sp.n_val[a] - sm.n_val[a]) / (2.0 * h)).abs() < 1e-8);
                assert!((s.d_eta[a] - (tp.n_val[a] - tm.n_val[a]) / (2.0 * h)).abs() < 1e-8);
            }
            let area = match i.domain {
                Domain::Square => 4.0,
                Domain::Triangle => 0.5,
            };
            // A kind without a reduced rule integrates "reduced" by its full rule.
            for rule in [Integration::Full, Integration::Reduced] {
                let w: f64 = k.rule(rule).iter().map(|p| p.2).sum();
                assert!((w - area).abs() < 1e-14, "{k:?} {rule:?}");
            }
            let w: f64 = i.domain.exact_rule().iter().map(|p| p.2).sum();
            assert!((w - area).abs() < 1e-14);
            assert_eq!(ElementKind::from_name(&i.name.to_lowercase()), Some(k));
            assert_eq!(ElementKind::from_gmsh(i.gmsh_type), Some(k));
        }
        assert_eq!(ElementKind::from_name("Q5"), None);
    }

    /// Extrapolation reproduces at the nodes any field the rule's points determine: a
    /// linear field exactly (every rule here has at least 3 points in general position).
    #[test]
    fn extrapolation_reproduces_linear_fields() {
        for k in ALL {
            let i = k.info();
            for rule in [Integration::Full, Integration::Reduced] {
                let pts = k.rule(rule);
                let w = (i.extrapolation)(pts);
                let f = |p: [f64; 2]| 0.3 + 1.7 * p[0] - 0.9 * p[1];
                for (a, &x) in i.node_xi.iter().enumerate() {
                    let v: f64 = pts
                        .iter()
                        .enumerate()
                        .map(|(g, p)| w[a][g] * f([p.0, p.1]))
                        .sum();
                    assert!((v - f(x)).abs() < 1e-13, "{k:?} {rule:?} node {a}");
                }
            }
        }
    }
}
