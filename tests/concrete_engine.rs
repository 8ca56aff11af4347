//! Concrete and embedded bars through the FE engine: input → system → path following.
//! Release-mode friendly (each case well under a second).

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::materials::concrete::ConcreteParams;
use segfem::model::Model;

/// What the tests read from each converged increment.
#[derive(Default)]
struct Trace {
    /// (step, control force [N], watched displacement [m], negative pivots, arc λ).
    rows: Vec<(usize, f64, f64, usize, f64)>,
    /// Watched dof (2·node + component).
    dof: usize,
    /// Bar stresses [Pa] of the last increment.
    bar_stress: Vec<f64>,
    /// Largest crack strain and crushed count at the last increment.
    last_states: (f64, usize),
}

impl Observer for Trace {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let sys = snap.system;
        self.rows.push((
            snap.step,
            snap.control_force.unwrap_or(f64::NAN),
            sys.u[self.dof],
            snap.negative_pivots,
            snap.arc_length_factor.unwrap_or(f64::NAN),
        ));
        self.bar_stress = sys.bar_out.iter().map(|o| o.stress).collect();
        self.last_states = (
            sys.committed
                .iter()
                .map(|p| p.crack_strain())
                .fold(0.0, f64::max),
            sys.committed.iter().filter(|p| p.is_crushed()).count(),
        );
        Ok(())
    }
}

fn model(text: &str) -> Model {
    match segfem::input::parse(text, "test.toml") {
        Ok(b) => b.model,
        Err(e) => panic!("{e}"),
    }
}

fn run(m: &Model, dof: usize) -> Trace {
    let mut t = Trace {
        dof,
        ..Default::default()
    };
    steps::run(m, &mut t).unwrap_or_else(|e| panic!("{e}"));
    t
}

/// One 0.1 m Q4 (thickness 0.1 m) of C30 concrete, held at x = 0 (and at the origin in y),
/// its right edge driven in x to each `value` in turn in `n` increments.
fn block(stages: &[(f64, usize)], extra: &str) -> String {
    let mut steps = String::new();
    for (i, (value, n)) in stages.iter().enumerate() {
        steps.push_str(&format!(
            r#"
[[steps]]
name = "s{i}"
kind = "displacement"
control = {{ line = [[0.1, 0.0], [0.1, 0.1]], component = "x", value = {value} }}
increments = {n}
"#
        ));
    }
    format!(
        r#"
[[materials]]
name = "c30"
kind = "concrete"
fcm = 38e6
nu = 0.2
{extra}

[[regions]]
name = "r"
material = "c30"
thickness = 0.1

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]
blocks = [{{ region = "r", element = "Q4", elements = [[1, 2, 3, 4]] }}]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0

[[supports]]
name = "pin"
node = 1
uy = 0.0
{steps}"#
    )
}

/// Uniaxial compression to the peak under displacement control follows the MC90 curve:
/// σ(ε) from the control force / area against `CompressionCurve::stress`. Required 1 %;
/// the material point alone reproduces it to 1e-6, so a failure here is an engine error
/// (load path, control, assembly). The peak must be reached (last point at ε_c1).
#[test]
fn uniaxial_compression_follows_mc90_curve_to_peak() {
    let p = ConcreteParams::from_mc90(38e6, 0.2);
    let eps_end = p.eps_c1;
    let m = model(&block(&[(-eps_end * 0.1, 44)], ""));
    let t = run(&m, 2);
    let curve = p.curve();
    assert_eq!(t.rows.len(), 44);
    for &(_, f, u, _, _) in &t.rows {
        let eps = -u / 0.1;
        let sigma = -f / 0.01; // area 0.1 × 0.1 m²
        let expect = curve.stress(eps);
        assert!(
            (sigma - expect).abs() <= 0.01 * expect,
            "ε = {eps:.3e}: σ = {sigma:.4e}, MC90 {expect:.4e}"
        );
    }
    let (_, f, u, _, _) = *t.rows.last().unwrap();
    assert!((-u / 0.1 - eps_end).abs() < 1e-12);
    assert!((-f / 0.01 - p.fcm).abs() < 0.01 * p.fcm);
}

/// Uniaxial tension: linear to f_tm (Ottosen uniaxial tensile strength = f_tm within
/// 0.2 %, so 1 % on the peak), then the Hinton exponential softening
/// σ = f_tm exp(−(ε − ε0)/α) (1 % of f_tm: the crack forms inside an increment, so the
/// first cracked point may sit on the jump from the elastic line to the curve).
#[test]
fn uniaxial_tension_cracks_at_ftm_and_softens() {
    let p = ConcreteParams::from_mc90(38e6, 0.2);
    let alpha = 2e-4;
    let eps0 = p.ftm / p.ec;
    let eps_end = eps0 + 4.0 * alpha;
    // Fine increments (Δε = ε0/1000, i.e. 0.1 % of f_tm per increment) around cracking.
    let m = model(&block(
        &[
            (0.98 * eps0 * 0.1, 5),
            (1.02 * eps0 * 0.1, 40),
            (eps_end * 0.1, 80),
        ],
        &format!("alpha = {alpha}"),
    ));
    let t = run(&m, 2);
    let peak = t.rows.iter().map(|r| r.1 / 0.01).fold(0.0, f64::max);
    assert!(
        (peak - p.ftm).abs() < 0.01 * p.ftm,
        "peak {peak:.4e} vs f_tm {:.4e}",
        p.ftm
    );
    for &(_, f, u, _, _) in &t.rows {
        let eps = u / 0.1;
        let sigma = f / 0.01;
        let expect = if eps <= eps0 * 0.998 {
            p.ec * eps
        } else if eps >= eps0 * 1.05 {
            p.ftm * (-(eps - eps0) / alpha).exp()
        } else {
            continue; // the increment in which the crack forms
        };
        assert!(
            (sigma - expect).abs() < 0.01 * p.ftm,
            "ε = {eps:.3e}: σ = {sigma:.4e}, expected {expect:.4e}"
        );
    }
    let last = t.rows.last().unwrap().1 / 0.01;
    assert!(last < 0.05 * p.ftm, "softened to {last:.3e}");
    // Crack strain recorded in the states: ε − σ/E on the crack axis ≈ total strain.
    assert!(t.last_states.0 > 0.9 * eps_end);
}
