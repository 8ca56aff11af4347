//! The 6-node triangle (T6) in a model file: an explicit mesh of straight-sided T6 with a
//! bar embedded across them (the bar cut through the triangles on their reference domain).
//! Its patch test and convergence rate are in tests/verification.rs, its Gmsh import in
//! tests/gmsh_import.rs.

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::model::{ElementKind, Model};
use std::fmt::Write;

/// Last converged displacements, internal forces and bar stresses.
#[derive(Default)]
struct Last {
    u: Vec<f64>,
    f_int: Vec<f64>,
    /// Stress [Pa] of every bar point, in the order of the model's bar points.
    bars: Vec<f64>,
}

impl Observer for Last {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        self.u = s.system.displacements().to_vec();
        self.f_int = s.f_int.to_vec();
        self.bars = (s.system.families.bars.out.committed.iter())
            .map(|o| o.stress)
            .collect();
        Ok(())
    }
}

/// An `nx` × `ny` grid of cells over [0, lx] × [0, ly], each cell split along its diagonal
/// into two T6; interior corner nodes moved by up to 12 % of a cell, mid-side nodes at the
/// middle of their (straight) edges. Returns nodes [m] and T6 node lists (VTK order).
fn t6_plate(nx: usize, ny: usize, lx: f64, ly: f64) -> (Vec<[f64; 2]>, Vec<[usize; 6]>) {
    let (gx, gy) = (2 * nx + 1, 2 * ny + 1);
    let id = |i: usize, j: usize| j * gx + i;
    let (hx, hy) = (lx / nx as f64, ly / ny as f64);
    let mut nodes = vec![[0.0; 2]; gx * gy];
    // Corners first (even grid indices), then every other node at the midpoint of the two
    // corners it lies between (along x, along y, or along the cell's diagonal).
    for j in (0..gy).step_by(2) {
        for i in (0..gx).step_by(2) {
            let mut p = [hx * (i / 2) as f64, hy * (j / 2) as f64];
            if i > 0 && j > 0 && i < gx - 1 && j < gy - 1 {
                let k = id(i, j) as f64;
                p[0] += 0.12 * hx * (1.7 * k).sin();
                p[1] += 0.12 * hy * (2.3 * k).cos();
            }
            nodes[id(i, j)] = p;
        }
    }
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    for j in 0..gy {
        for i in 0..gx {
            nodes[id(i, j)] = match (i % 2, j % 2) {
                (0, 0) => continue,
                (1, 0) => mid(nodes[id(i - 1, j)], nodes[id(i + 1, j)]),
                (0, 1) => mid(nodes[id(i, j - 1)], nodes[id(i, j + 1)]),
                _ => mid(nodes[id(i - 1, j - 1)], nodes[id(i + 1, j + 1)]),
            };
        }
    }
    let mut elements = Vec::new();
    for r in 0..ny {
        for c in 0..nx {
            let (i, j) = (2 * c, 2 * r);
            let (c0, c1, c2, c3) = (id(i, j), id(i + 2, j), id(i + 2, j + 2), id(i, j + 2));
            let diag = id(i + 1, j + 1);
            elements.push([c0, c1, c2, id(i + 1, j), id(i + 2, j + 1), diag]);
            elements.push([c0, c2, c3, diag, id(i + 1, j + 2), id(i, j + 1)]);
        }
    }
    (nodes, elements)
}

/// A plate (3 m × 1 m × 0.3 m, E_c = 30 GPa, ν = 0.2) of 36 straight-sided, distorted T6
/// with a steel bar (A_s = 2000 mm², E_s = 200 GPa) along y = 0.37 m from end to end,
/// stretched by δ = 0.3 mm at x = 3 m (x = 0 held in x, one corner in y). The uniform
/// strain ε = δ/L, σ_y = 0 is the exact solution (the bar's force is constant along it and
/// leaves only at the held ends), so: the bar takes σ_s = E_s δ/L at every point, the
/// pull is (E_c A_c + E_s A_s) δ/L (closed form; the bar's share is 4.4 % of it), every
/// node moves by (δ x/L, −ν δ y/L), and the bar's pieces add up to its length. Tolerances:
/// 1e-9 relative (a direct solve of a well-conditioned system: round-off) and 1e-12 L for the
/// length (the cut points are located to 1e-14 of a segment, docs/theory-bars.md).
#[test]
fn bar_embedded_across_triangles_carries_the_closed_form_force() {
    let (lx, ly, t) = (3.0, 1.0, 0.3);
    let (ec, nu, es, a_s) = (30e9, 0.2, 200e9, 2.0e-3);
    let (y_bar, delta) = (0.37, 3e-4);
    let (nodes, elements) = t6_plate(6, 3, lx, ly);
    let mut text = format!(
        r#"[[materials]]
name = "c"
kind = "elastic"
E = {ec}
nu = {nu}

[[materials]]
name = "steel"
kind = "rebar"
E = {es}
fy = 500e6

[[regions]]
name = "plate"
material = "c"
thickness = {t}

[mesh]
type = "explicit"
nodes = ["#
    );
    let pts: Vec<String> = nodes
        .iter()
        .map(|p| format!("[{:.17e}, {:.17e}]", p[0], p[1]))
        .collect();
    text.push_str(&pts.join(", "));
    text.push_str("]\n\n[[mesh.blocks]]\nregion = \"plate\"\nelement = \"T6\"\nelements = [");
    let els: Vec<String> = elements
        .iter()
        .map(|e| {
            let ids: Vec<String> = e.iter().map(|n| (n + 1).to_string()).collect();
            format!("[{}]", ids.join(", "))
        })
        .collect();
    text.push_str(&els.join(", "));
    let _ = write!(
        text,
        r#"]

[[bars]]
name = "bar"
path = [[0.0, {y_bar}], [{lx}, {y_bar}]]
area = {a_s}
material = "steel"

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, {ly}]]
ux = 0.0

[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0

[[supports]]
name = "pull"
line = [[{lx}, 0.0], [{lx}, {ly}]]
ux = {delta}

[[load_cases]]
name = "none"

[[steps]]
name = "stretch"
kind = "linear"
loads = {{ none = 1.0 }}
"#
    );
    let model: Model = segfem::input::parse(&text, "t6-bar.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    assert!(model.elements.iter().all(|e| e.kind == ElementKind::T6));
    let bar = &model.bars[0];
    // The bar crosses all 6 columns, two triangles in most: at least 12 pieces, each in a
    // triangle, its points inside the host's reference triangle.
    assert!(bar.n_pieces >= 12, "{} pieces", bar.n_pieces);
    let length: f64 = bar.points.iter().map(|p| p.point.weight_length).sum();
    assert!((length - lx).abs() < 1e-12 * lx, "length {length}");
    for p in &bar.points {
        let (x, e) = (p.point.xi, p.point.eta);
        assert!(
            x >= -1e-9 && e >= -1e-9 && x + e <= 1.0 + 1e-9,
            "({x}, {e})"
        );
    }
    let mut last = Last::default();
    steps::run(&model, &mut last).unwrap();
    let eps = delta / lx;
    for (k, s) in last.bars.iter().enumerate() {
        assert!(
            (s - es * eps).abs() < 1e-9 * es * eps,
            "bar point {k}: {s} Pa vs {} Pa",
            es * eps
        );
    }
    for (k, p) in model.nodes.iter().enumerate() {
        let u = [eps * p[0], -nu * eps * p[1]];
        assert!(
            (last.u[2 * k] - u[0]).abs() < 1e-9 * delta
                && (last.u[2 * k + 1] - u[1]).abs() < 1e-9 * delta,
            "node {k} at {p:?}"
        );
    }
    let pull: f64 = (0..model.nodes.len())
        .filter(|&k| (model.nodes[k][0] - lx).abs() < 1e-12)
        .map(|k| last.f_int[2 * k])
        .sum();
    let exact = (ec * ly * t + es * a_s) * eps;
    assert!(
        (pull - exact).abs() < 1e-9 * exact,
        "pull {pull} N vs (E_c A_c + E_s A_s) δ/L = {exact} N"
    );
}
