//! Smeared bar layers (`[[bar_layers]]`) through the engine, against closed forms of a
//! reinforced block in uniaxial stress.

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::model::Model;

/// Control force [N], lateral displacement of the top-right node [m] and layer stresses
/// [Pa] of each converged increment.
#[derive(Default)]
struct Trace {
    rows: Vec<(f64, f64, Vec<f64>)>,
    uy_dof: usize,
}

impl Observer for Trace {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let sys = snap.system;
        self.rows.push((
            snap.control_force.unwrap_or(f64::NAN),
            sys.displacements()[self.uy_dof],
            sys.families
                .bars
                .out
                .committed
                .iter()
                .map(|o| o.stress)
                .collect(),
        ));
        Ok(())
    }
}

const E_C: f64 = 30e9;
const NU: f64 = 0.2;
const E_S: f64 = 200e9;
const FY: f64 = 500e6;
const T: f64 = 0.2;
const RHO: f64 = 0.02;
/// Block 0.4 × 0.3 m, 2 × 2 elements.
const LX: f64 = 0.4;
const LY: f64 = 0.3;

/// The block pulled in x at its right edge to `ux` (left edge held in x, one corner in y),
/// with a layer along `dir` in 2 × 2 `element`s.
fn block(element: &str, dir: [f64; 2], ux: f64, increments: usize) -> String {
    format!(
        r#"
[[materials]]
name = "host"
kind = "elastic"
E = {E_C}
nu = {NU}

[[materials]]
name = "b500"
kind = "rebar"
E = {E_S}
fy = {FY}

[[regions]]
name = "r"
material = "host"
thickness = {T}

[mesh]
type = "banded"
length = {LX}
nx = 2
element = "{element}"
bands = [{{ region = "r", depth = {LY}, rows = 2 }}]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, {LY}]]
ux = 0.0

[[supports]]
name = "pin"
point = [0.0, 0.0]
uy = 0.0

[[bar_layers]]
name = "mesh"
material = "b500"
region = "r"
direction = [{}, {}]
ratio = {RHO}

[[steps]]
name = "pull"
kind = "displacement"
control = {{ line = [[{LX}, 0.0], [{LX}, {LY}]], component = "x", value = {ux} }}
increments = {increments}
"#,
        dir[0], dir[1]
    )
}

fn model(text: &str) -> Model {
    match segfem::input::parse(text, "test.toml") {
        Ok(b) => b.model,
        Err(e) => panic!("{e}"),
    }
}

fn run(m: &Model) -> Trace {
    let top_right = m
        .nodes
        .iter()
        .position(|x| (x[0] - LX).abs() < 1e-9 && (x[1] - LY).abs() < 1e-9)
        .expect("a node at the top-right corner");
    let mut t = Trace {
        uy_dof: 2 * top_right + 1,
        ..Default::default()
    };
    steps::run(m, &mut t).unwrap_or_else(|e| panic!("{e}"));
    t
}

/// Layer along x: uniaxial stress, the block's force is (E_c + ρ E_s) ε t H while the steel
/// is elastic and E_c ε t H + ρ f_y t H once it yields; the lateral strain is −ν ε (the layer
/// adds no stiffness across it). Q4 (2 × 2 points) and Q8 (3 × 3) hosts. The field is
/// uniform, so the FE solution is exact: 1e-9 relative (round-off of a linear solve).
#[test]
fn layer_along_the_load_adds_rho_es_and_yields_at_rho_fy() {
    let eps_y = FY / E_S;
    for element in ["Q4", "Q8"] {
        // 10 increments to 2.5 ε_y: elastic, then yielded.
        let ux = 2.5 * eps_y * LX;
        let m = model(&block(element, [1.0, 0.0], ux, 10));
        assert_eq!(m.bars.len(), 1);
        let n_pts = if element == "Q4" { 4 } else { 9 };
        assert_eq!(
            m.bars[0].points.len(),
            4 * n_pts,
            "one point per host Gauss point"
        );
        let area: f64 = m.bars[0].points.iter().map(|p| p.point.weight_length).sum();
        assert!(
            (area - LX * LY).abs() < 1e-12,
            "weights sum to the area: {area}"
        );
        let t = run(&m);
        assert_eq!(t.rows.len(), 10);
        for (i, (f, uy, stress)) in t.rows.iter().enumerate() {
            let eps = ux * (i + 1) as f64 / 10.0 / LX;
            let sigma_s = (E_S * eps).min(FY);
            let expect = (E_C * eps + RHO * sigma_s) * T * LY;
            assert!(
                (f - expect).abs() <= 1e-9 * expect,
                "{element} ε = {eps:.3e}: F = {f:.6e}, closed form {expect:.6e}"
            );
            assert!((uy + NU * eps * LY).abs() <= 1e-9 * NU * eps * LY);
            for s in stress {
                assert!(
                    (s - sigma_s).abs() <= 1e-9 * sigma_s,
                    "{s:e} vs {sigma_s:e}"
                );
            }
        }
    }
}

/// Layer across the load (direction y): σ_y = 0 in the composite, so the concrete's lateral
/// stress balances the steel's, ε_y = −ν E' ε_x / (E' + ρ E_s) with E' = E_c/(1 − ν²), and
/// the force is E'(ε_x + ν ε_y) t H — stiffer than the plain block by the restrained
/// Poisson contraction. Elastic throughout (ε_x = 1e-3). Exact to round-off (uniform field).
#[test]
fn layer_across_the_load_restrains_the_poisson_contraction() {
    let eps_x = 1e-3;
    let m = model(&block("Q8", [0.0, 2.0], eps_x * LX, 1));
    let t = run(&m);
    let (f, uy, stress) = t.rows.last().expect("one increment");
    let e1 = E_C / (1.0 - NU * NU);
    let eps_y = -NU * e1 * eps_x / (e1 + RHO * E_S);
    let expect_f = e1 * (eps_x + NU * eps_y) * T * LY;
    assert!(
        (f - expect_f).abs() <= 1e-9 * expect_f,
        "F = {f:.6e} vs {expect_f:.6e} (plain block {:.6e})",
        E_C * eps_x * T * LY
    );
    assert!((uy - eps_y * LY).abs() <= 1e-9 * (eps_y * LY).abs());
    for s in stress {
        assert!((s - E_S * eps_y).abs() <= 1e-9 * (E_S * eps_y).abs());
    }
}

/// Bad layer input names the key.
#[test]
fn bad_layers_are_rejected_with_the_key() {
    let good = block("Q4", [1.0, 0.0], 1e-4, 1);
    for (from, to, key) in [
        ("ratio = 0.02", "ratio = 2.0", "bar_layers[0].ratio"),
        (
            "direction = [1, 0]",
            "direction = [0, 0]",
            "bar_layers[0].direction",
        ),
        (
            "region = \"r\"\ndirection",
            "region = \"x\"\ndirection",
            "bar_layers[0].region",
        ),
        (
            "material = \"b500\"\nregion",
            "material = \"host\"\nregion",
            "bar_layers[0].material",
        ),
    ] {
        assert!(good.contains(from), "{from}");
        let text = good.replacen(from, to, 1);
        match segfem::input::parse(&text, "m.toml") {
            Ok(_) => panic!("{to}: accepted"),
            Err(e) => assert!(e.to_string().contains(key), "{to}: {e}"),
        }
    }
    let boxed = good.replacen(
        "ratio = 0.02",
        "ratio = 0.02\nboxes = [[[5.0, 5.0], [6.0, 6.0]]]",
        1,
    );
    match segfem::input::parse(&boxed, "m.toml") {
        Ok(_) => panic!("box outside the mesh accepted"),
        Err(e) => assert!(e.to_string().contains("bar_layers[0].boxes"), "{e}"),
    }
}
