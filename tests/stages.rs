//! Construction stages (docs/theory-stages.md): a segment activated onto a deflected
//! cantilever is stress-free when placed; a removed support releases its reaction as a
//! load; staged and one-shot linear elastic analyses agree; creep moves moment into the
//! support of two spans made continuous (ageing-coefficient closed form), and a beam cast
//! continuous in one go shows no redistribution.
//! Run with `cargo nextest run --release -E 'binary(stages)'`.

mod common;

use segfem::analysis::steps::{self, Observer, Snapshot};
// φ and χ come from the test's own MC90 (tests/common/mc90.rs), not the library's.
use common::mc90::{compliance, relaxation_function};
use segfem::materials::mc90_time::{CementClass, CreepShrinkageParams};
use segfem::model::{Dir, Model};

/// One record per step end: step, time, displacements, Gauss stresses, vertical reaction of
/// every support.
#[derive(Debug, Clone)]
struct Rec {
    step: usize,
    time: f64,
    u: Vec<f64>,
    stress: Vec<[f64; 3]>,
    reactions: Vec<f64>,
}

struct Keep<'m> {
    model: &'m Model,
    recs: Vec<Rec>,
}

impl Observer for Keep<'_> {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        if !s.end_of_step {
            return Ok(());
        }
        let sys = s.system;
        let reactions = self
            .model
            .supports
            .iter()
            .map(|sp| {
                sp.dofs
                    .iter()
                    .filter(|(_, d, _)| *d == Dir::Y)
                    .map(|(n, _, _)| s.f_int[2 * n + 1] - s.f_ext[2 * n + 1])
                    .sum()
            })
            .collect();
        self.recs.push(Rec {
            step: s.step,
            time: sys.time.t_to,
            u: sys.displacements().to_vec(),
            stress: sys
                .families
                .continuum
                .gauss
                .committed
                .iter()
                .map(|g| g.stress)
                .collect(),
            reactions,
        });
        Ok(())
    }
}

fn model(text: &str) -> Model {
    segfem::input::parse(text, "stages.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model
}

fn run(m: &Model) -> Vec<Rec> {
    let mut k = Keep {
        model: m,
        recs: Vec::new(),
    };
    steps::run(m, &mut k).unwrap_or_else(|e| panic!("{e}"));
    k.recs
}

/// Gauss-point indices of the elements of region `name`.
fn region_points(m: &Model, name: &str) -> Vec<usize> {
    let r = m.regions.iter().position(|r| r.name == name).unwrap();
    let mut out = Vec::new();
    let mut g = 0;
    for e in &m.elements {
        let n = segfem::elements::continuum::rule(e.kind, e.integration).len();
        if e.region == r {
            out.extend(g..g + n);
        }
        g += n;
    }
    out
}

/// Node nearest a point.
fn node_at(m: &Model, p: [f64; 2]) -> usize {
    (0..m.nodes.len())
        .min_by(|&a, &b| {
            let d = |n: usize| (m.nodes[n][0] - p[0]).hypot(m.nodes[n][1] - p[1]);
            d(a).total_cmp(&d(b))
        })
        .unwrap()
}

/// Largest |σ| component over all points [Pa].
fn max_stress(s: &[[f64; 3]]) -> f64 {
    s.iter().flatten().fold(0.0_f64, |a, b| a.max(b.abs()))
}

/// Largest componentwise difference of two stress fields [Pa].
fn stress_diff(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

const E: f64 = 30e9;

/// A Q8 cantilever 0.5 m deep clamped at x = 0, 8 elements per metre: segment A, and
/// with `with_b` the part x > 2 m as segment B (`boxes`); `p1` pulls down the mid-depth node
/// at x = 2 m, `p2` the end face at x = `length`.
fn cantilever(length: f64, with_b: bool, steps: &str) -> String {
    let nx = (8.0 * length) as usize;
    let b = if with_b {
        r#"
[[regions]]
name = "B"
material = "c"
thickness = 0.2
boxes = [[[2.0, -1.0], [4.0, 1.0]]]
"#
    } else {
        ""
    };
    format!(
        r#"
[[materials]]
name = "c"
kind = "elastic"
E = {E}
nu = 0.2

[[regions]]
name = "A"
material = "c"
thickness = 0.2
{b}
[mesh]
type = "banded"
length = {length}
origin = [0.0, -0.25]
nx = {nx}
element = "Q8"
bands = [{{ region = "A", depth = 0.5, rows = 4 }}]

[[supports]]
name = "wall"
line = [[0.0, -0.25], [0.0, 0.25]]
ux = 0.0
uy = 0.0

[[load_cases]]
name = "p1"
point_loads = [{{ point = [2.0, 0.0], force = [0.0, -40e3] }}]

[[load_cases]]
name = "p2"
line_loads = [{{ line = [[{length}, -0.25], [{length}, 0.25]], q = [0.0, -40e3] }}]
{steps}
"#
    )
}

/// Largest |value| of a vector.
fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// A segment placed onto a deflected cantilever carries no stress when placed, is placed
/// at its design position, and from then on deforms with the whole cantilever: the staged
/// state is the superposition of A alone under p1 and the whole cantilever under p2 (linear
/// elasticity), and the free end moves by the beam-theory deflection under p2.
#[test]
fn segment_activated_on_a_deflected_cantilever_is_stress_free_when_placed() {
    let staged = model(&cantilever(
        4.0,
        true,
        r#"
[[steps]]
name = "A alone"
kind = "linear"
loads = { p1 = 1.0 }

[[steps]]
name = "place B"
kind = "linear"
loads = { p1 = 1.0 }
activate = ["B"]

[[steps]]
name = "tip load"
kind = "linear"
loads = { p1 = 1.0, p2 = 1.0 }
"#,
    ));
    let rec = run(&staged);
    assert_eq!(rec.len(), 3);
    assert_eq!(rec[2].step, 2);
    let b = region_points(&staged, "B");
    let a = region_points(&staged, "A");
    let scale = max_stress(&rec[0].stress);
    assert!(scale > 1e6, "A is bent by p1: {scale} Pa");
    // Before and right after placing, B carries nothing: exactly zero before (inactive),
    // round-off after (its strains are measured from the displacements it was placed at).
    for r in &rec[..2] {
        let sb: Vec<[f64; 3]> = b.iter().map(|&g| r.stress[g]).collect();
        assert!(
            max_stress(&sb) <= 1e-9 * scale,
            "B stressed: {}",
            max_stress(&sb)
        );
    }
    // Placing changes nothing in A (round-off).
    let sa = |r: &Rec| a.iter().map(|&g| r.stress[g]).collect::<Vec<_>>();
    assert!(stress_diff(&sa(&rec[0]), &sa(&rec[1])) <= 1e-9 * scale);
    // A alone (a 2 m cantilever) under p1, and the whole cantilever under p2.
    let short = model(&cantilever(
        2.0,
        false,
        "[[steps]]\nname = \"p1\"\nkind = \"linear\"\nloads = { p1 = 1.0 }\n",
    ));
    let u1 = run(&short).pop().unwrap().u;
    let whole = model(&cantilever(
        4.0,
        true,
        "[[steps]]\nname = \"p2\"\nkind = \"linear\"\nloads = { p2 = 1.0 }\n",
    ));
    let r2 = run(&whole).pop().unwrap();
    // Superposition, to round-off (1e-9 of the largest displacement): nodes of A move by
    // both parts, nodes born with B (placed at u = 0) by the second only.
    let tol = 1e-9 * max_abs(&rec[2].u);
    for (n, x) in staged.nodes.iter().enumerate() {
        let from_p1 = if x[0] <= 2.0 + 1e-9 {
            let m = node_at(&short, *x);
            [u1[2 * m], u1[2 * m + 1]]
        } else {
            [0.0; 2]
        };
        for k in 0..2 {
            let expected = from_p1[k] + r2.u[2 * n + k];
            let got = rec[2].u[2 * n + k];
            assert!(
                (got - expected).abs() <= tol,
                "node {n} at {x:?}: {got:e} m, superposition {expected:e} m"
            );
        }
    }
    // B carries exactly what p2 puts into it.
    let sb = |r: &Rec| b.iter().map(|&g| r.stress[g]).collect::<Vec<_>>();
    let d = stress_diff(&sb(&rec[2]), &sb(&r2));
    assert!(
        d <= 1e-9 * max_stress(&r2.stress),
        "B stresses differ by {d} Pa"
    );
    // Free end: δ = P L³/(3EI) + P L/(κ G A) (Timoshenko beam, κ = 5/6) under p2. 2 %: the
    // fully clamped edge and the end traction's local effects differ from beam theory by a
    // fraction of the ≈ 1 % shear term; the Q8 mesh error is far below (the T&G
    // cantilever in tests/verification.rs).
    let tip = node_at(&staged, [4.0, 0.0]);
    let (p, l, t, h, nu): (f64, f64, f64, f64, f64) = (40e3 * 0.5, 4.0, 0.2, 0.5, 0.2);
    let i = t * h * h * h / 12.0;
    let g = E / (2.0 * (1.0 + nu));
    let closed = p * l.powi(3) / (3.0 * E * i) + p * l / (5.0 / 6.0 * g * t * h);
    let fe = -rec[2].u[2 * tip + 1];
    eprintln!("tip deflection after placing: FE {fe:.4e} m, beam theory {closed:.4e} m");
    assert!(
        (fe / closed - 1.0).abs() < 0.02,
        "tip deflection after placing: FE {fe:.4e} m, beam theory {closed:.4e} m"
    );
}

/// Staged without load in the meantime: placing B before any load gives the one-shot
/// analysis of the whole cantilever bit for bit in stresses (the reference displacements
/// are zero).
#[test]
fn staged_and_one_shot_agree_for_a_linear_elastic_cantilever() {
    let steps_staged = r#"
[[steps]]
name = "A"
kind = "linear"
loads = {}

[[steps]]
name = "place B and load"
kind = "linear"
loads = { p1 = 1.0, p2 = 1.0 }
activate = ["B"]
"#;
    let rec = run(&model(&cantilever(4.0, true, steps_staged)));
    let one = run(&model(&cantilever(
        4.0,
        true,
        "[[steps]]\nname = \"both\"\nkind = \"linear\"\nloads = { p1 = 1.0, p2 = 1.0 }\n",
    )));
    // 1e-9: the same equations solved with (staged) and without the held rows.
    let d = stress_diff(&rec[1].stress, &one[0].stress);
    assert!(
        d <= 1e-9 * max_stress(&one[0].stress),
        "stresses differ by {d} Pa"
    );
    let du = rec[1]
        .u
        .iter()
        .zip(&one[0].u)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        du <= 1e-9 * max_abs(&one[0].u),
        "displacements differ by {du} m"
    );
}

/// A 2 × 4 m two-span beam, 0.4 m deep, on pins at the ends and a mid support `mid` that
/// the steps may remove; `q` on the top face, `r` a point force at the mid support node.
fn two_spans(supports: &str, r: f64, steps: &str) -> String {
    format!(
        r#"
[[materials]]
name = "c"
kind = "elastic"
E = {E}
nu = 0.2

[[regions]]
name = "beam"
material = "c"
thickness = 0.3

[mesh]
type = "banded"
length = 8.0
origin = [0.0, -0.2]
nx = 40
element = "Q8"
bands = [{{ region = "beam", depth = 0.4, rows = 4 }}]

[[supports]]
name = "left"
point = [0.0, -0.2]
ux = 0.0
uy = 0.0

[[supports]]
name = "right"
point = [8.0, -0.2]
uy = 0.0
{supports}
[[load_cases]]
name = "q"
line_loads = [{{ line = [[0.0, 0.2], [8.0, 0.2]], q = [0.0, -20e3] }}]

[[load_cases]]
name = "r"
point_loads = [{{ point = [4.0, -0.2], force = [0.0, {r}] }}]
{steps}
"#
    )
}

const MID: &str = r#"
[[supports]]
name = "mid"
point = [4.0, -0.2]
uy = 0.0
"#;

/// Removing the mid support releases its reaction as a load: before the removal the beam
/// is the two-pin beam under q and the reaction applied as a force; after it, the two-pin
/// beam under q alone (staged and one-shot identical for a linear elastic beam).
#[test]
fn removed_support_releases_its_reaction_as_a_load() {
    let staged = model(&two_spans(
        MID,
        0.0,
        r#"
[[steps]]
name = "on three supports"
kind = "linear"
loads = { q = 1.0 }

[[steps]]
name = "strike mid"
kind = "load"
increments = 2
loads = { q = 1.0 }
remove = ["mid"]
"#,
    ));
    let rec = run(&staged);
    let r_mid = rec[0].reactions[2];
    // Two-span continuous beam: R_mid = 5/4 q L = 100 kN; 1 %: shear deformation of this
    // beam (L/h = 10, a correction of order (h/L)²) and the point support's local
    // flexibility lower the redundant slightly.
    let closed = 1.25 * 20e3 * 4.0;
    eprintln!("mid reaction {r_mid:.1} N, 5qL/4 = {closed:.1} N");
    assert!(
        (r_mid / closed - 1.0).abs() < 0.01,
        "mid reaction {r_mid:.1} N against 5qL/4 = {closed:.1} N"
    );
    // After the removal the support carries nothing.
    assert!(rec[1].reactions[2].abs() <= 1e-9 * closed);
    // The same beam on two pins with q and the reaction as a force.
    let with_r = model(&two_spans(
        "",
        r_mid,
        r#"
[[steps]]
name = "q and R"
kind = "linear"
loads = { q = 1.0, r = 1.0 }

[[steps]]
name = "q alone"
kind = "linear"
loads = { q = 1.0, r = 0.0 }
"#,
    ));
    let two = run(&with_r);
    // 1e-8: the solves differ (three supports against two) only by round-off, and the
    // reaction is carried over as its printed f64 (17 significant digits).
    for (s, o) in [(&rec[0], &two[0]), (&rec[1], &two[1])] {
        let scale = max_stress(&o.stress);
        let d = stress_diff(&s.stress, &o.stress);
        assert!(
            d <= 1e-8 * scale,
            "stresses differ by {d} Pa (scale {scale})"
        );
        let umax = o.u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let du =
            s.u.iter()
                .zip(&o.u)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(du <= 1e-8 * umax, "displacements differ by {du} m");
    }
}

/// MC90 creep keys shared by the creep cases (no shrinkage: the spans bend under load only).
const CREEP: &str = r#"
[[materials]]
name = "c"
kind = "elastic_creep"
fcm = 45e6
nu = 0.2
cement = "N"
rh = 0.7
h0 = 0.2
shrinkage = false
"#;

/// Two 3.8 m spans, 0.4 m deep, on piers at x = 3.8 and 4.2 m joined by a 0.4 m
/// closure (`closure`, activated by the steps or present from the start); q on both spans.
fn spans_with_closure(steps: &str) -> String {
    format!(
        r#"{CREEP}
[[regions]]
name = "spans"
material = "c"
thickness = 0.3

[[regions]]
name = "closure"
material = "c"
thickness = 0.3
boxes = [[[3.9, -1.0], [4.1, 1.0]]]

[mesh]
type = "banded"
length = 8.0
origin = [0.0, -0.2]
nx = 40
element = "Q8"
bands = [{{ region = "spans", depth = 0.4, rows = 4 }}]

[[supports]]
name = "left"
point = [0.0, -0.2]
ux = 0.0
uy = 0.0

[[supports]]
name = "pier1"
point = [3.8, -0.2]
uy = 0.0

[[supports]]
name = "pier2"
point = [4.2, -0.2]
ux = 0.0
uy = 0.0

[[supports]]
name = "right"
point = [8.0, -0.2]
uy = 0.0

[[load_cases]]
name = "q"
line_loads = [
  {{ line = [[0.0, 0.2], [3.8, 0.2]], q = [0.0, -20e3] }},
  {{ line = [[4.2, 0.2], [8.0, 0.2]], q = [0.0, -20e3] }},
]
{steps}
"#
    )
}

const T0: f64 = 28.0;
const T_END: f64 = T0 + 10_000.0;

/// Cast continuous in one go and loaded at 28 d: homogeneous creep scales the elastic
/// displacements, which stay compatible with the supports, so no moment moves.
#[test]
fn continuous_beam_cast_in_one_go_shows_no_redistribution() {
    let m = model(&spans_with_closure(&format!(
        r#"
[[steps]]
name = "load"
kind = "load"
loads = {{ q = 1.0 }}

[[steps]]
name = "creep"
kind = "time"
from = {T0}
to = {T_END}
"#
    )));
    let rec = run(&m);
    let (r0, r1) = (rec[0].reactions[0], rec[1].reactions[0]);
    // 1e-4: Newton stops at a force residual of 1e-6 of the load; the staged case below
    // moves ~25 % of the continuity moment.
    assert!(
        (r1 / r0 - 1.0).abs() < 1e-4,
        "end reaction moved from {r0:.2} to {r1:.2} N"
    );
}

/// Two simply supported spans loaded at 28 d and made continuous right after by a closure
/// cast between them: creep builds up the support moment
/// M(t) = M_cont φ/(1 + χ φ) (ageing-coefficient method, Trost–Bažant), with φ and χ of the
/// same MC90 compliance the material's Maxwell chain follows.
#[test]
fn creep_moves_moment_into_the_support_of_spans_made_continuous() {
    let staged = model(&spans_with_closure(&format!(
        r#"
[[steps]]
name = "simple spans"
kind = "load"
loads = {{ q = 1.0 }}

[[steps]]
name = "closure"
kind = "load"
loads = {{ q = 1.0 }}
activate = ["closure"]

[[steps]]
name = "creep"
kind = "time"
from = {T0}
to = {T_END}
"#
    )));
    let rec = run(&staged);
    // The continuity moment of the same beam cast in one go, elastic at 28 d.
    let once = model(&spans_with_closure(
        r#"
[[steps]]
name = "load"
kind = "load"
loads = { q = 1.0 }
"#,
    ));
    let one = run(&once);
    // Left span (pins at 0 and 3.8 m): R_left = q L/2 − M/L, so moments are in proportion
    // to the drop of the left end reaction from its simply supported value.
    let r_simple = rec[0].reactions[0];
    let l = 3.8;
    assert!(
        (r_simple / (20e3 * l / 2.0) - 1.0).abs() < 1e-6,
        "simply supported span: R = qL/2"
    );
    let m_cont = (r_simple - one[0].reactions[0]) * l;
    let m_t = (r_simple - rec[2].reactions[0]) * l;
    assert!((rec[2].time - T_END).abs() < 1e-9);
    // Closed form with the MC90 functions of the material (fcm 45 MPa, RH 70 %, h0 0.2 m,
    // cement N): φ relative to the chain's instantaneous modulus 1/J(t0 + 0.1 d, t0)
    // (docs/theory-time.md §2), χ from the MC90 relaxation function R(t, t0).
    let p = CreepShrinkageParams::new(45e6, 0.7, 0.2, CementClass::N, 7.0);
    let j0 = compliance(&p, T0 + 0.1, T0);
    let e0 = 1.0 / j0;
    let phi = compliance(&p, T_END, T0) / j0 - 1.0;
    let durations: Vec<f64> = {
        let (a, b, n) = (1e-3_f64, T_END - T0, 240);
        (0..=n)
            .map(|k| a * (b / a).powf(k as f64 / n as f64))
            .collect()
    };
    let r = *relaxation_function(&p, T0, &durations).last().unwrap();
    let chi = e0 / (e0 - r) - 1.0 / phi;
    let closed = phi / (1.0 + chi * phi);
    let ratio = m_t / m_cont;
    eprintln!(
        "M(t)/M_cont: FE {ratio:.4}, closed form {closed:.4} (φ = {phi:.3}, χ = {chi:.3}, M_cont = {m_cont:.1} N m)"
    );
    // 2 % (was 5 %, issue 42; docs/validation.md, tolerance changes): the ageing-coefficient
    // method is exact for a strain imposed at t0 and held, approximate for the restraint of a
    // creep rotation growing like φ(t, t0); the chain follows MC90's J within 1 %
    // (docs/validation.md). Measured 0.69 %. At 5 % a 13 % error in φ0 (β(fcm)'s 5.3 → 6.0)
    // passed (FE 0.7056); at 2 % it fails.
    assert!(
        (ratio / closed - 1.0).abs() < 0.02,
        "M(t)/M_cont: FE {ratio:.4}, closed form {closed:.4} (φ = {phi:.3}, χ = {chi:.3})"
    );
}
