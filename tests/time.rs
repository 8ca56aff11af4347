//! Time-dependent analysis through the engine: MC90 creep and shrinkage of concrete by the
//! ageing Maxwell chain, relaxation of external tendons, prestress losses over time.
//! Run with `cargo test --release --test time` (the beam tests take a few seconds).

mod common;

// Expected values come from the test's own MC90 (tests/common/mc90.rs), never from the
// library's `mc90_time`/`chain` functions under test.
use common::mc90::{self, compliance, shrinkage_strain};
use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::materials::mc90_time::{CementClass, CreepShrinkageParams};
use segfem::model::LossPart;

/// One record per converged increment.
#[derive(Debug, Clone, Default)]
struct Rec {
    time: f64,
    strain: [f64; 3],
    stress: [f64; 3],
    u: Vec<f64>,
    forces: Vec<f64>,
    losses: Vec<[f64; 4]>,
}

#[derive(Default)]
struct Keep(Vec<Rec>);

impl Observer for Keep {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let parts = [
            LossPart::Total,
            LossPart::Elastic,
            LossPart::CreepShrinkage,
            LossPart::Relaxation,
        ];
        self.0.push(Rec {
            time: sys.time.t_to,
            strain: sys.families.continuum.gauss.committed[0].strain,
            stress: sys.families.continuum.gauss.committed[0].stress,
            u: sys.displacements().to_vec(),
            forces: sys
                .families
                .tendons
                .states
                .committed
                .iter()
                .map(|t| t.as_ref().map(|t| t.forces()[0]).unwrap_or(0.0))
                .collect(),
            losses: sys
                .families
                .tendons
                .time
                .iter()
                .map(|t| {
                    t.as_ref()
                        .map(|t| parts.map(|p| t.loss(p)))
                        .unwrap_or_default()
                })
                .collect(),
        });
        Ok(())
    }
}

fn run(text: &str) -> Vec<Rec> {
    let model = segfem::input::parse(text, "time.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut k = Keep::default();
    steps::run(&model, &mut k).unwrap();
    k.0
}

/// The test's own MC90 (tests/common/mc90.rs), which builds the expected values of this file
/// and of tests/stages.rs, bonded_losses.rs and creep_cracking.rs, against the hand table of
/// docs/theory-time.md §5 (checks 8, 11, 12: the MC90 formulas evaluated by hand for the check
/// case, 6 significant digits, so 1e-5 relative).
#[test]
fn test_reference_mc90_reproduces_the_hand_table() {
    let p = params(7.0);
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    assert!(rel(mc90::eci(&p), 35495.72e6) < 1e-5);
    for (t, e) in [
        (3.0, 27454.5),
        (7.0, 31324.9),
        (90.0, 37513.1),
        (365.0, 38853.2),
    ] {
        assert!(rel(mc90::eci_at(&p, t), e * 1e6) < 1e-5, "E_ci({t})");
    }
    // (t − t0, φ, J [1e-6/MPa]) for t0 = 28 d; φ printed with 5 decimals.
    for (d, phi, j) in [
        (1.0, 0.27687, 35.9724),
        (10.0, 0.54980, 43.6617),
        (100.0, 1.05003, 57.7542),
        (1000.0, 1.61982, 73.8067),
        (10000.0, 1.82188, 79.4991),
    ] {
        assert!((mc90::creep_coefficient(&p, 28.0 + d, 28.0) - phi).abs() <= 5.01e-6);
        assert!(
            rel(compliance(&p, 28.0 + d, 28.0), j * 1e-12) < 1e-5,
            "J({d})"
        );
    }
    assert!(rel(compliance(&p, 1007.0, 7.0), 91.2130e-12) < 1e-5);
    // ε_cs(7 + d, 7) [1e-6].
    for (d, eps) in [(7.0, -27.654), (100.0, -101.231), (10000.0, -367.202)] {
        assert!(
            rel(shrinkage_strain(&p, 7.0 + d), eps * 1e-6) < 1e-5,
            "ε_cs({d})"
        );
    }
    // Relaxation, class 2 at 0.7 f_ptk: ρ1000 = 2.5 %; at 1000 h = 41.667 d exactly that,
    // at 1e4 d × (240)^0.19 (hand: ln 240 = 5.4806, × 0.19 = 1.04132, e^ = 2.8330).
    use segfem::materials::mc90_time::RelaxationClass::Class2;
    assert!(rel(mc90::relaxation_loss(Class2, 0.7, 1000.0 / 24.0), 0.025) < 1e-12);
    assert!(rel(mc90::relaxation_loss(Class2, 0.7, 1e4), 0.025 * 2.8330) < 1e-4);
    assert_eq!(mc90::relaxation_loss(Class2, 0.5, 1e4), 0.0);
    // Relaxation function: R(t0, t0) = E_ci(t0); for a non-ageing J = (1 + φ)/E it would be
    // E/(1 + φ) — the ageing MC90 J gives R(t0 + 1e4, t0) between E_ci(t0)/(1 + φ) and the
    // AAEM value with χ = 0.8 … 0.9 quoted for MC90 (Bažant 1972; CEB Bulletin 215).
    let (t0, d) = (28.0, 1e4);
    let grid: Vec<f64> = (0..=240)
        .map(|k| 1e-3 * (d / 1e-3_f64).powf(k as f64 / 240.0))
        .collect();
    let r = *mc90::relaxation_function(&p, t0, &grid).last().unwrap();
    let e0 = mc90::eci_at(&p, t0);
    let phi = mc90::creep_coefficient(&p, t0 + d, t0) * mc90::eci(&p) / e0;
    let chi = e0 / (e0 - r) - 1.0 / phi;
    assert!((0.7..0.95).contains(&chi), "χ = {chi}");
}

/// The MC90 data of the check case (docs/theory-time.md §2): fcm 45 MPa, RH 70 %, h = 200 mm,
/// cement N.
fn params(drying_start: f64) -> CreepShrinkageParams {
    CreepShrinkageParams::new(45e6, 0.70, 0.200, CementClass::N, drying_start)
}

const CONCRETE: &str = r#"
[[materials]]
name = "c"
kind = "elastic_creep"
fcm = 45e6
rh = 0.70
h0 = 0.200
cement = "N"
nu = 0.2
"#;

/// A 0.1 m square Q4 specimen, 0.1 m thick, held on its left edge (ux) and at its
/// bottom-left corner (uy): free to contract laterally, so the stress is uniaxial.
fn specimen(shrinkage: bool, stress: f64, t0: f64, steps: &str) -> String {
    format!(
        r#"{CONCRETE}shrinkage = {shrinkage}
drying_start = 7.0
[[regions]]
name = "r"
material = "c"
thickness = 0.1
cast_day = 0.0
[mesh]
type = "banded"
length = 0.1
nx = 1
element = "Q4"
bands = [{{ region = "r", depth = 0.1, rows = 1 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0
[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0
[[load_cases]]
name = "P"
line_loads = [{{ line = [[0.1, 0.0], [0.1, 0.1]], q = [{q}, 0.0] }}]
[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0 }}
[[steps]]
name = "creep"
kind = "time"
from = {t0}
{steps}
"#,
        q = stress * 0.1
    )
}

#[test]
fn creep_under_constant_stress_follows_mc90() {
    // σ = −4 MPa < 0.4 fcm (linear creep). ε(t)/(σ J(t, t0)) within 2 % at every substep
    // from 0.1 to 1e4 days after loading (the first day included: measured 1.8 % at 0.1 d)
    // for t0 = 7, 28, 365 d: the chain itself reproduces J within 0.6 % at
    // 10 steps/decade (docs/theory-time.md §2); the default 5 substeps/decade adds < 0.7 %
    // at 1e4 d; 2 % leaves room for both but fails for a missing creep term (φ ≈ 1.5–2.8)
    // or a wrong loading age (J(1e4, 7) vs J(1e4, 28) differ by 20 %).
    let sigma = -4e6;
    let p = params(7.0);
    for t0 in [7.0, 28.0, 365.0] {
        let rec = run(&specimen(false, sigma, t0, "duration = 1e4"));
        let load = &rec[0];
        assert_eq!(load.time, t0);
        assert!(
            (load.stress[0] / sigma - 1.0).abs() < 1e-9,
            "{:?}",
            load.stress
        );
        // The strain at loading: the chain is fitted to MC90 from 0.1 d on, so a load step
        // gives the 0.1-day response σ J(t0 + 0.1 d, t0), 9–16 % above σ/E_ci(t0)
        // (docs/theory-time.md, instantaneous response). 1 %: the chain's fit at 0.1 d
        // (0.15 % at the material point) and the element's uniform stress (exact).
        let at_loading = sigma * compliance(&p, t0 + 0.1, t0);
        assert!(
            (load.strain[0] / at_loading - 1.0).abs() < 0.01,
            "t0 = {t0} d: strain at loading {} vs σ J(t0 + 0.1 d, t0) = {at_loading}",
            load.strain[0]
        );
        let mut checked = 0;
        let mut worst: f64 = 0.0;
        for r in &rec[1..] {
            let d = r.time - t0;
            assert!(
                (r.stress[0] / sigma - 1.0).abs() < 1e-8,
                "stress held constant"
            );
            let want = sigma * compliance(&p, r.time, t0);
            let ratio = r.strain[0] / want;
            assert!(
                (ratio - 1.0).abs() < 0.02,
                "t0 = {t0} d, t − t0 = {d} d: ε/(σJ) = {ratio}"
            );
            worst = worst.max((ratio - 1.0).abs());
            checked += 1;
        }
        eprintln!("t0 = {t0} d: worst |ε/(σJ) − 1| = {worst:.4} over {checked} substeps");
        assert!(checked >= 20, "checked {checked} substeps");
        // Creep really happened: ε(1e4 d) ≥ 2 × the elastic strain.
        assert!(rec.last().unwrap().strain[0] / load.strain[0] > 2.0);
    }
}

#[test]
fn free_shrinkage_follows_mc90() {
    // No load: the specimen shrinks freely, stress-free, by ε_cs(t) − ε_cs(t_start) in both
    // directions. The imposed strain enters exactly, so the tolerance is round-off (1e-9
    // relative), and the stress must stay ≈ 0 (1 Pa).
    let p = params(7.0);
    let rec = run(&specimen(true, 0.0, 7.0, "to = 10007.0"));
    let mut n = 0;
    for r in &rec[1..] {
        let want = shrinkage_strain(&p, r.time) - shrinkage_strain(&p, 7.0);
        assert!(want < 0.0);
        for c in 0..2 {
            assert!(
                (r.strain[c] / want - 1.0).abs() < 1e-9,
                "t = {}: ε = {:?}, ε_cs = {want}",
                r.time,
                r.strain
            );
        }
        assert!(r.stress.iter().all(|s| s.abs() < 1.0), "{:?}", r.stress);
        n += 1;
    }
    assert!(n > 20);
    // 1e4 days of drying at RH 70 %: ε_cs ≈ −0.3 ‰ (MC90 ε_cso = −3.9e-4 × β_s ≈ 0.8).
    let last = rec.last().unwrap().strain[0];
    assert!(last < -2.5e-4 && last > -4e-4, "{last}");
}

/// A straight member of two precast segments (2 × 1 m, 0.2 m deep, dry joint) cast on
/// days −300 and 0, under a constant axial compression applied on day 28.
fn two_segments() -> String {
    format!(
        r#"{CONCRETE}shrinkage = false
[[regions]]
name = "r"
material = "c"
thickness = 0.2
[[joint_materials]]
name = "dry"
kind = "dry"
friction = 0.7
[mesh]
type = "segmental"
segments = [1.0, 1.0]
nx_per_segment = 4
element = "Q4"
joint_material = "dry"
segment_cast_days = [-300.0, 0.0]
bands = [{{ region = "r", depth = 0.2, rows = 2 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.2]]
ux = 0.0
[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0
[[load_cases]]
name = "P"
line_loads = [{{ line = [[2.0, 0.0], [2.0, 0.2]], q = [-1e6, 0.0] }}]
[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0 }}
[[steps]]
name = "creep"
kind = "time"
from = 28.0
to = 10028.0
"#
    )
}

#[test]
fn younger_segment_creeps_more() {
    // Constant stress −5 MPa in both segments. Each segment's strain must follow J(t, t0) of
    // its own loading age (328 d and 28 d): the chain is identified per age. 2 % as in the
    // specimen test; the joint (penalty contact) adds nothing to the segment strains. A
    // program using one age for all segments fails: J(1e4 + 28, 28)/J(1e4 + 328, 328) = 1.38.
    let text = two_segments();
    let model = segfem::input::parse(&text, "two.toml").unwrap().model;
    let gp = |x: f64| {
        let e = model
            .elements
            .iter()
            .position(|el| {
                let xs: Vec<f64> = el.nodes.iter().map(|&n| model.nodes[n][0]).collect();
                xs.iter().cloned().fold(f64::INFINITY, f64::min) < x
                    && xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max) > x
            })
            .unwrap();
        4 * e
    };
    let (g_old, g_young) = (gp(0.4), gp(1.6));
    struct Strains(Vec<(f64, f64, f64)>, usize, usize);
    impl Observer for Strains {
        fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
            let g = &s.system.families.continuum.gauss.committed;
            self.0
                .push((s.system.time.t_to, g[self.1].strain[0], g[self.2].strain[0]));
            Ok(())
        }
    }
    let mut obs = Strains(Vec::new(), g_old, g_young);
    steps::run(&model, &mut obs).unwrap();
    let p = params(7.0);
    let sigma = -5e6;
    let (t_end, e_old, e_young) = *obs.0.last().unwrap();
    let j_old = compliance(&p, t_end + 300.0, 328.0);
    let j_young = compliance(&p, t_end, 28.0);
    assert!(
        (e_old / (sigma * j_old) - 1.0).abs() < 0.02,
        "old: {e_old} vs {}",
        sigma * j_old
    );
    assert!(
        (e_young / (sigma * j_young) - 1.0).abs() < 0.02,
        "young: {e_young} vs {}",
        sigma * j_young
    );
    assert!(
        e_young < 1.2 * e_old,
        "younger segment creeps more: {e_young} vs {e_old}"
    );
}

/// A 6 m simply supported beam, 0.3 × 0.6 m, creeping concrete, one straight external
/// tendon 0.2 m below the centroid, self weight, prestress on day 28, then 1e4 days.
fn prestressed_beam(relaxation: &str, substeps: &str) -> String {
    format!(
        r#"{CONCRETE}density = 2500.0
[[regions]]
name = "r"
material = "c"
thickness = 0.3
[mesh]
type = "banded"
length = 6.0
nx = 24
element = "Q8"
bands = [{{ region = "r", depth = 0.6, rows = 4 }}]
[[tendons]]
name = "T"
kind = "external"
points = [[0.0, 0.1], [6.0, 0.1]]
area = 1e-3
Ep = 195e9
fptk = 1860e6
initial_stress = 1300e6
{relaxation}
[[supports]]
name = "left"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0
[[supports]]
name = "right"
point = [6.0, 0.0]
uy = 0.0
[[load_cases]]
name = "g"
gravity = [0.0, -9.81]
[[steps]]
name = "prestress"
kind = "load"
loads = {{ g = 1.0 }}
[[steps]]
name = "creep"
kind = "time"
from = 28.0
duration = 1e4
{substeps}
"#
    )
}

fn midspan_uy(text: &str, rec: &Rec) -> f64 {
    let model = segfem::input::parse(text, "b.toml").unwrap().model;
    let mid = model
        .nodes
        .iter()
        .position(|p| (p[0] - 3.0).abs() < 1e-9 && p[1].abs() < 1e-9)
        .unwrap();
    rec.u[2 * mid + 1]
}

#[test]
fn results_do_not_depend_on_the_substeps() {
    // Camber (upward, prestress > self weight) grows by creep; halving every substep must
    // change the 1e4-day deflection and tendon force by < 1 % (the chain algorithm at the
    // default 5 substeps/decade is within 0.1 % of converged, docs/theory-time.md §2).
    let a = prestressed_beam("relaxation_class = 2", "");
    let b = prestressed_beam("relaxation_class = 2", "substeps = 52");
    let (ra, rb) = (run(&a), run(&b));
    assert_eq!(
        ra.len(),
        1 + 26,
        "default: 5 substeps per decade over 0.1 … 1e4 d, + 1"
    );
    let (ua, ub) = (
        midspan_uy(&a, ra.last().unwrap()),
        midspan_uy(&b, rb.last().unwrap()),
    );
    let u0 = midspan_uy(&a, &ra[0]);
    eprintln!("midspan uy: instantaneous {u0:e}, 1e4 d {ua:e} (26 substeps) {ub:e} (52)");
    assert!(
        ua > 0.0 && ua > 1.5 * u0,
        "camber grows by creep: {u0} → {ua}"
    );
    assert!((ua / ub - 1.0).abs() < 0.01, "{ua} vs {ub}");
    let (fa, fb) = (ra.last().unwrap().forces[0], rb.last().unwrap().forces[0]);
    assert!((fa / fb - 1.0).abs() < 0.001, "{fa} vs {fb}");
    // The loss parts add up to the total and the tendon force agrees with the total loss.
    let l = ra.last().unwrap().losses[0];
    assert!((l[1] + l[2] + l[3] - l[0]).abs() < 1e-6 * l[0]);
    assert!(
        (1300e6 - l[0] - fa / 1e-3).abs() < 1e-6 * 1300e6,
        "{l:?} {fa}"
    );
    assert!(
        l[2] > 0.0 && l[3] > 0.0,
        "creep+shrinkage and relaxation losses: {l:?}"
    );
}

/// The same tendon stressed against a practically rigid elastic block: the strain is
/// (nearly) constant, so the stress must follow the MC90 relaxation ρ(t).
#[test]
fn tendon_relaxation_at_constant_strain_follows_mc90() {
    use common::mc90::relaxation_loss;
    use segfem::materials::mc90_time::RelaxationClass;
    // Rigid block: E = 1e16 Pa makes the concrete shortening under 1.3 MN ~1e-8 of the
    // tendon strain, so the strain is constant to that order.
    let text = prestressed_beam("relaxation_class = 2", "")
        .replace("kind = \"elastic_creep\"", "kind = \"elastic\"\nE = 1e16")
        .replace("fcm = 45e6\nrh = 0.70\nh0 = 0.200\ncement = \"N\"\n", "");
    let rec = run(&text);
    let s0 = 1300e6;
    let mut worst: f64 = 0.0;
    for r in &rec[1..] {
        let d = r.time - 28.0;
        let want = relaxation_loss(RelaxationClass::Class2, s0 / 1860e6, d) * s0;
        let got = s0 - r.forces[0] / 1e-3;
        // 0.1 % of σ everywhere, 3 % of the loss from 1 d on (the chain's fit of the MC90
        // power law: 1.6 % worst for class 2 at 0.7, docs/theory-time.md §3).
        assert!((got - want).abs() < 1e-3 * s0, "t = {d}: {got} vs {want}");
        if d >= 1.0 {
            worst = worst.max((got / want - 1.0).abs());
        }
        // The whole loss is booked as relaxation.
        let l = r.losses[0];
        assert!((l[3] - got).abs() < 1e-3 * got.max(1e3), "{l:?} vs {got}");
    }
    eprintln!("relaxation: worst relative error from 1 d: {worst:.4}");
    assert!(worst < 0.03);
    // 1e4 days, class 2 at 0.7 f_ptk: ρ = 2.5 % × (240000 h/1000 h)^0.19 ≈ 7 %.
    let last = s0 - rec.last().unwrap().forces[0] / 1e-3;
    assert!(last > 0.05 * s0 && last < 0.09 * s0, "{last}");
}

/// The seed beam (examples/seed-beam-elastic.toml) with its elastic concrete replaced by the MC90
/// creep material (fcm 45 MPa as the seed's E = 35.5 GPa implies, RH 70 %, h0 0.2 m),
/// prestressed with self weight on day 28 and held for 1e4 days.
fn seed_beam_creep(substeps: &str) -> String {
    let seed = include_str!("../examples/seed-beam-elastic.toml");
    let head = &seed[..seed.find("[[steps]]").unwrap()];
    let text = head
        .replace(
            "kind = \"elastic\"\nE = 35.5e9          # MC90 Eci for fcm = 45 MPa",
            "kind = \"elastic_creep\"\nrh = 0.70\nh0 = 0.200\ncement = \"N\"",
        )
        .replace(
            "deviators = \"held\"",
            "deviators = \"held\"\nrelaxation_class = 2",
        );
    assert!(text.contains("elastic_creep") && text.contains("relaxation_class"));
    format!(
        r#"{text}
[[steps]]
name = "prestress"
kind = "load"
loads = {{ self_weight = 1.0 }}
[[steps]]
name = "long_term"
kind = "time"
from = 28.0
duration = 1e4
{substeps}
"#
    )
}

#[test]
fn seed_beam_long_term_loss_matches_the_ec2_estimate() {
    use common::mc90::creep_coefficient;
    let text = seed_beam_creep("");
    let rec = run(&text);
    let p0 = rec[0].forces[0]; // after the instantaneous step [N]
    let l = rec.last().unwrap().losses[0];
    let fe_loss = l[2] + l[3]; // creep + shrinkage + relaxation [Pa]
                               // Hand estimate, EC2 5.10.6 (2) (MC90 functions), with the stress and eccentricity
                               // averaged along the unbonded tendon (EC2: mean strains along an unbonded tendon):
                               // Δσ = [ε_cs E_p + 0.8 Δσ_pr + α φ σ_c] / [1 + α A_p/A_c (1 + A_c z²/I)(1 + 0.8 φ)].
    let p = params(7.0);
    let (t0, t) = (28.0, 28.0 + 1e4);
    let phi = creep_coefficient(&p, t, t0);
    let eps_cs = -(shrinkage_strain(&p, t) - shrinkage_strain(&p, t0));
    let (ep, ap) = (195e9, 560e-6);
    let alpha = ep / mc90::eci(&p);
    // Box section of the seed beam: bands (width, depth) bottom to top.
    let bands: [(f64, f64); 3] = [(0.70, 0.10), (0.20, 0.40), (1.20, 0.10)];
    let (mut y0, mut ac, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for (b, h) in bands {
        ac += b * h;
        sy += b * h * (y0 + h / 2.0);
        y0 += h;
    }
    let yc = sy / ac;
    let mut ic = 0.0;
    y0 = 0.0;
    for (b, h) in bands {
        ic += b * h * h * h / 12.0 + b * h * (y0 + h / 2.0 - yc).powi(2);
        y0 += h;
    }
    let q = ac * 2548.4 * 9.81; // self weight [N/m]
    let yp = |x: f64| {
        if x < 2.4 {
            0.30 - 0.2 * x / 2.4
        } else if x > 4.8 {
            0.10 + 0.2 * (x - 4.8) / 2.4
        } else {
            0.10
        }
    };
    let n = 7200;
    let (mut sc, mut z2) = (0.0, 0.0);
    for i in 0..=n {
        let x = 7.2 * i as f64 / n as f64;
        let w = if i == 0 || i == n { 0.5 } else { 1.0 } / n as f64;
        let z = yc - yp(x);
        let m = q * x * (7.2 - x) / 2.0;
        sc += w * (p0 / ac + p0 * z * z / ic - m * z / ic); // compression positive
        z2 += w * z * z;
    }
    let rho = mc90::relaxation_loss(
        segfem::materials::mc90_time::RelaxationClass::Class2,
        p0 / ap / 1900e6,
        t - t0,
    ) * p0
        / ap;
    let hand = (eps_cs * ep + 0.8 * rho + alpha * phi * sc)
        / (1.0 + alpha * ap / ac * (1.0 + ac * z2 / ic) * (1.0 + 0.8 * phi));
    eprintln!(
        "seed beam: P0 = {p0:.0} N, σc = {sc:.3e} Pa, φ = {phi:.3}, ε_cs = {eps_cs:.3e}, ρ = {rho:.3e}; loss FE {fe_loss:.4e} Pa (creep+shrinkage {:.4e}, relaxation {:.4e}) vs EC2 {hand:.4e} Pa",
        l[2], l[3]
    );
    // 15 %: the EC2 formula is a sectional age-adjusted-modulus estimate with a fixed ageing
    // coefficient 0.8 (the chain's effective value depends on t0 and duration, 0.6–0.9), it
    // smears the varying eccentricity into mean values and ignores the box's shear lag and
    // the joints; a missing shrinkage (≈ 40 % of the loss here) or creep term fails it.
    assert!(
        (fe_loss / hand - 1.0).abs() < 0.15,
        "FE {fe_loss} vs EC2 {hand}"
    );
    // At 0.46 f_ptk the MC90 relaxation is zero.
    assert!(rho == 0.0 && l[3] == 0.0);
    // The prestress loss over 1e4 days is a few percent to ~15 % of σp0: a sanity bound.
    let s0 = p0 / ap;
    assert!(
        fe_loss > 0.03 * s0 && fe_loss < 0.2 * s0,
        "{fe_loss} of {s0}"
    );
}

#[test]
fn path_steps_after_a_time_step_are_instantaneous() {
    // A displacement step after a time step runs at the clock the time step reached, with
    // no time passing: the controlled dof (uy of the bottom-right corner, which is 0 under
    // uniaxial σx) is held at its current value, so nothing may change — in particular the
    // concrete must not creep further. A program that keeps the last substep's interval
    // (≈ 270 d here) for the path increments adds creep at every increment (εx grows by
    // several % of the elastic strain each), and reports the wrong time. Round-off tolerance.
    let sigma = -4e6;
    let text = format!(
        "{}\n[[steps]]\nname = \"hold\"\nkind = \"displacement\"\nincrements = 3\ncontrol = {{ point = [0.1, 0.0], component = \"y\", value = 0.0 }}\n",
        specimen(false, sigma, 28.0, "to = 1028.0\nsubsteps = 10")
    );
    let rec = run(&text);
    assert_eq!(
        rec.len(),
        1 + 10 + 3,
        "load, 10 substeps, 3 path increments"
    );
    let end_of_creep = &rec[10];
    assert!((end_of_creep.time - 1028.0).abs() < 1e-9);
    for r in &rec[11..] {
        assert_eq!(r.time, 1028.0, "path increments run at the clock");
        for c in 0..2 {
            assert!(
                (r.strain[c] - end_of_creep.strain[c]).abs() < 1e-9 * end_of_creep.strain[0].abs(),
                "no creep during a path step: {:?} vs {:?}",
                r.strain,
                end_of_creep.strain
            );
        }
    }
    // A path step before any time step runs at the start clock (28 d by default), not 0.
    let first = format!(
        "{CONCRETE}shrinkage = false\n[[regions]]\nname = \"r\"\nmaterial = \"c\"\nthickness = 0.1\n[mesh]\ntype = \"banded\"\nlength = 0.1\nnx = 1\nelement = \"Q4\"\nbands = [{{ region = \"r\", depth = 0.1, rows = 1 }}]\n[[supports]]\nname = \"left\"\nline = [[0.0, 0.0], [0.0, 0.1]]\nux = 0.0\n[[supports]]\nname = \"corner\"\npoint = [0.0, 0.0]\nuy = 0.0\n[[steps]]\nname = \"push\"\nkind = \"displacement\"\nincrements = 2\ncontrol = {{ line = [[0.1, 0.0], [0.1, 0.1]], component = \"x\", value = -1e-5 }}\n"
    );
    let rec = run(&first);
    assert_eq!(rec.len(), 2);
    assert!(
        rec.iter().all(|r| r.time == 28.0),
        "{:?}",
        rec.iter().map(|r| r.time).collect::<Vec<_>>()
    );
}

/// One Q4 of `concrete` with the viscoplastic option (`load_steps = "elastic"`) under
/// uniaxial stress: the right edge is moved by the prescribed `u0` [m] in a load step
/// (instantaneous, elastic), then held over the time step given.
fn viscoplastic_specimen(u0: f64, steps: &str) -> String {
    format!(
        r#"
[[materials]]
name = "c"
kind = "concrete"
fcm = 45e6
nu = 0.2
viscoplastic = {{ fluidity = 1e-3, load_steps = "elastic" }}
[[regions]]
name = "r"
material = "c"
thickness = 0.1
[mesh]
type = "banded"
length = 0.1
nx = 1
element = "Q4"
bands = [{{ region = "r", depth = 0.1, rows = 1 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0
[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0
[[supports]]
name = "right"
line = [[0.1, 0.0], [0.1, 0.1]]
ux = {u0}
[[steps]]
name = "push"
kind = "load"
{steps}
"#
    )
}

#[test]
fn viscoplastic_overstress_relaxes_exponentially() {
    // Initial yield at the peak of the MC90 curve (σ_c = f_cm, dσ_c/dκ = 0 there), uniaxial
    // stress. The right edge is moved elastically to σ = −1.02 f_cm (Δt = 0, load_steps =
    // "elastic"), then held for 5 t_r. With the linear overstress function and no hardening
    // the Perzyna law gives the closed form x(t) = x0 exp(−t/t_r), t_r = f_cm/(γ E),
    // x = (|σ| − f_cm)/f_cm (uniaxial stress: n_x = −1, σ_y = 0 by equilibrium).
    // Tolerance 5 % of x0, from the time discretisation: each FE time increment holds its
    // end strain over the whole increment, and at fixed strain the Ottosen flow at uniaxial
    // compression (n_y = 3.3: strongly dilatant) relaxes 11× faster than under uniaxial
    // stress, so the error is first order in Δt/(t_r/11): 10.3 % with 100 log-spaced
    // substeps, 3.8 % with the 400 used here (last substeps ≈ 0.08 t_r). The curvature of
    // the MC90 peak changes σ_c by < 1e-4 f_cm.
    let fcm = 45e6;
    // E_ci of fcm = 45 MPa from the test's MC90 (params() has the same fcm).
    let e = mc90::eci(&params(7.0));
    let gamma = 1e-3;
    let t_r = fcm / (gamma * e);
    let x0 = 0.02;
    let u0 = -(1.0 + x0) * fcm / e * 0.1;
    let text = viscoplastic_specimen(
        u0,
        &format!(
        "[[steps]]\nname = \"hold\"\nkind = \"time\"\nfrom = 28.0\nduration = {}\nfirst_substep = {}\nsubsteps = 400\n",
        5.0 * t_r,
        0.01 * t_r),
    );
    let mut model = segfem::input::parse(&text, "vp.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    match &mut model.materials[0].law {
        segfem::materials::point::Material::Concrete { params, .. } => {
            params.initial_yield_ratio = 1.0
        }
        _ => unreachable!(),
    }
    let mut k = Keep::default();
    steps::run(&model, &mut k).unwrap();
    let rec = k.0;
    let first = &rec[0];
    assert!(
        (first.stress[0] / (-(1.0 + x0) * fcm) - 1.0).abs() < 1e-6,
        "elastic push: {:?}",
        first.stress
    );
    let mut worst: f64 = 0.0;
    for r in &rec[1..] {
        let t = r.time - 28.0;
        let x = -r.stress[0] / fcm - 1.0;
        let want = x0 * (-t / t_r).exp();
        assert!(r.stress[1].abs() < 1e-3 * fcm, "uniaxial: {:?}", r.stress);
        worst = worst.max((x - want).abs() / x0);
    }
    eprintln!("viscoplastic relaxation: worst |x − x0 e^(−t/t_r)|/x0 = {worst:.4}");
    assert!(worst < 0.05, "{worst}");
    // Relaxed: within 1 % of x0 of the steady state σ = −f_cm after 5 t_r.
    let last = -rec.last().unwrap().stress[0] / fcm - 1.0;
    assert!(last < 0.01 * x0 + x0 * (-5f64).exp(), "{last}");
}

#[test]
fn viscoplastic_option_bad_input_names_the_key() {
    let base = viscoplastic_specimen(-1e-5, "");
    for (vp, key, what) in [
        (
            "{ load_steps = \"elastic\" }",
            "viscoplastic.fluidity",
            "missing",
        ),
        ("{ fluidity = -1.0 }", "viscoplastic.fluidity", ""),
        (
            "{ fluidity = 1.0, overstress = \"cubic\" }",
            "viscoplastic.overstress",
            "cubic",
        ),
        (
            "{ fluidity = 1.0, overstress = \"power\" }",
            "viscoplastic.exponent",
            "missing",
        ),
        (
            "{ fluidity = 1.0, exponent = 2.0 }",
            "viscoplastic.exponent",
            "only",
        ),
        ("{ fluidity = 1.0, theta = 2.0 }", "viscoplastic.theta", ""),
        (
            "{ fluidity = 1.0, load_steps = \"never\" }",
            "viscoplastic.load_steps",
            "never",
        ),
    ] {
        let text = base.replace(
            "viscoplastic = { fluidity = 1e-3, load_steps = \"elastic\" }",
            &format!("viscoplastic = {vp}"),
        );
        let err = match segfem::input::parse(&text, "vp.toml") {
            Ok(_) => panic!("{vp}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            err.contains(&format!("materials[0].{key}")) && err.contains(what),
            "{vp}: {err}"
        );
    }
}

/// Per increment: time, first point's crack count, crack strain, strain and stress.
type CrackRec = (f64, usize, f64, [f64; 3], [f64; 3]);

#[derive(Default)]
struct Cracks(Vec<CrackRec>);

impl Observer for Cracks {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let p = &sys.families.continuum.points.committed[0];
        self.0.push((
            sys.time.t_to,
            p.n_cracks(),
            p.crack_strain(),
            sys.families.continuum.gauss.committed[0].strain,
            sys.families.continuum.gauss.committed[0].stress,
        ));
        Ok(())
    }
}

#[test]
fn cracked_point_does_not_creep_open_or_closed() {
    // One Q4 of cracking concrete (with the viscoplastic option, so that time does enter
    // its update): pulled in x until it cracks (ε = 3e-4 ≈ 2.8 ε0), pushed back to zero
    // strain (the crack closes on its secant: unloaded, σx = 0, the point stays cracked),
    // released with σy = −4 MPa acting along the crack, then held for 1e4 days. Chosen
    // coupling (docs/theory-time.md §9): the crack laws are rate-independent and a cracked
    // point does not creep, so the crack strain (1e-13 absolute), the strains (1e-13) and
    // the stresses (4e-3 Pa) must not change over the time step, and σx must stay ≈ 0. A
    // coupling that let time act on the crack direction would open or close it here.
    let text = viscoplastic_specimen(0.0, "")
        .replace(
            "viscoplastic = { fluidity = 1e-3, load_steps = \"elastic\" }",
            "viscoplastic = { fluidity = 1e-3 }",
        )
        .replace(
            "[[supports]]\nname = \"right\"\nline = [[0.1, 0.0], [0.1, 0.1]]\nux = 0\n",
            "",
        )
        .replace(
            "[[steps]]\nname = \"push\"\nkind = \"load\"\n",
            r#"[[supports]]
name = "bottom"
line = [[0.0, 0.0], [0.1, 0.0]]
uy = 0.0
[[load_cases]]
name = "Y"
line_loads = [{ line = [[0.0, 0.1], [0.1, 0.1]], q = [0.0, -4e5] }]
[[steps]]
name = "pull"
kind = "displacement"
increments = 6
control = { line = [[0.1, 0.0], [0.1, 0.1]], component = "x", value = 3e-5 }
[[steps]]
name = "close"
kind = "displacement"
increments = 3
control = { line = [[0.1, 0.0], [0.1, 0.1]], component = "x", value = 0.0 }
[[steps]]
name = "release"
kind = "load"
loads = { Y = 1.0 }
[[steps]]
name = "hold"
kind = "time"
from = 28.0
duration = 1e4
"#,
        );
    assert!(
        text.contains("name = \"hold\"") && !text.contains("name = \"right\""),
        "{text}"
    );
    let model = segfem::input::parse(&text, "crack.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut k = Cracks::default();
    steps::run(&model, &mut k).unwrap();
    let rec = k.0;
    let released = &rec[9];
    assert_eq!(released.1, 1, "cracked: {released:?}");
    assert!(
        released.4[0].abs() < 1e-3 * 45e6 * 0.01,
        "σx released: {released:?}"
    );
    assert!(
        (released.4[1] / -4e6 - 1.0).abs() < 1e-6,
        "σy: {released:?}"
    );
    let held = &rec[10..];
    assert!(held.len() > 20 && (held.last().unwrap().0 - 10028.0).abs() < 1e-6);
    for r in held {
        assert_eq!(r.1, 1);
        assert!(
            (r.2 - released.2).abs() <= 1e-13,
            "crack strain {} vs {}",
            r.2,
            released.2
        );
        for c in 0..3 {
            assert!(
                (r.3[c] - released.3[c]).abs() <= 1e-9 * 1e-4,
                "strain {:?} vs {:?}",
                r.3,
                released.3
            );
            assert!(
                (r.4[c] - released.4[c]).abs() <= 1e-9 * 4e6,
                "stress {:?} vs {:?}",
                r.4,
                released.4
            );
        }
    }
}

/// The seed beam over its life, built from the bundled examples: creep-beam.toml's model
/// (MC90 creep and shrinkage, segments cast 30–90 days before the clock's day 0, class 2
/// relaxation), seed-beam.toml's geometrically nonlinear analysis, the prestress step, then
/// — with `long_term` — creep-beam.toml's 10⁴ days under prestress and self weight, and
/// seed-beam.toml's steps to failure (service, ultimate, arc length to L/60).
fn seed_beam_life(long_term: bool) -> String {
    let creep = include_str!("../examples/creep-beam.toml");
    let seed = include_str!("../examples/seed-beam-elastic.toml");
    let model = &creep[..creep.find("[[steps]]").unwrap()];
    let analysis = &seed[seed.find("[analysis]").unwrap()..seed.find("[[steps]]").unwrap()];
    let prestress = &creep[creep.find("[[steps]]\nname = \"prestress\"").unwrap()
        ..creep.find("[[steps]]\nname = \"long_term\"").unwrap()];
    let time = &creep[creep.find("[[steps]]\nname = \"long_term\"").unwrap()
        ..creep.find("[[steps]]\nname = \"service\"").unwrap()];
    let to_failure = &seed[seed.find("[[steps]]\nname = \"service\"").unwrap()..];
    assert!(analysis.contains("geometry = \"nonlinear\"") && time.contains("to = 10000.0"));
    let time = if long_term { time } else { "" };
    format!("{model}{analysis}{prestress}{time}{to_failure}")
}

/// One converged increment of the seed beam's life.
#[derive(Debug, Clone)]
struct LifeRow {
    /// Step index (0-based: 0 is the prestress step).
    step: usize,
    /// Q [kN] (load factor of case "Q").
    q: f64,
    /// Span forces of the tendon [N]; span 1 lies between the deviators, over the midspan
    /// joints.
    forces: Vec<f64>,
    /// Smallest normal stress over the joints' integration points, compression positive [Pa].
    sigma_min: f64,
    /// x [m] of that point.
    x_min: f64,
    /// Some joint point open.
    open: bool,
    /// Cracked Gauss points of the concrete.
    cracked: usize,
    /// Creep + shrinkage and relaxation losses (length-weighted mean) [Pa].
    losses: [f64; 2],
    /// Analysis clock at the end of the increment [d].
    time: f64,
    /// Vertical displacement of the midspan bottom node (x = 3.6 m, y = 0) [m].
    uy_mid: f64,
}

#[derive(Default)]
struct Life {
    rows: Vec<LifeRow>,
    watch: segfem::results::ultimate::UltimateWatch,
}

/// The midspan bottom node of the seed beam (x = 3.6 m, y = 0).
fn seed_midspan_node(model: &segfem::model::Model) -> usize {
    model
        .nodes
        .iter()
        .position(|p| (p[0] - 3.6).abs() < 1e-9 && p[1].abs() < 1e-9)
        .expect("a node at midspan")
}

impl Observer for Life {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        self.watch.increment(s);
        let sys = s.system;
        let (mut sigma_min, mut x_min, mut open) = (f64::INFINITY, 0.0, false);
        for j in 0..sys.model.joints.len() {
            for p in segfem::results::joints::summarise(sys, j).profile {
                open |= !p.closed;
                if p.normal_stress < sigma_min {
                    (sigma_min, x_min) = (p.normal_stress, p.x[0]);
                }
            }
        }
        let t = sys.families.tendons.time[0].as_ref();
        let mid = seed_midspan_node(sys.model);
        self.rows.push(LifeRow {
            time: sys.time.t_to,
            uy_mid: sys.displacements()[2 * mid + 1],
            step: s.step,
            q: s.factors[1],
            forces: sys.families.tendons.states.committed[0]
                .as_ref()
                .map_or_else(Vec::new, |t| t.forces()),
            sigma_min,
            x_min,
            open,
            cracked: sys
                .families
                .continuum
                .points
                .committed
                .iter()
                .filter(|p| p.n_cracks() > 0)
                .count(),
            losses: t.map_or([0.0; 2], |t| {
                [
                    t.loss(LossPart::CreepShrinkage),
                    t.loss(LossPart::Relaxation),
                ]
            }),
        });
        Ok(())
    }
}

/// Decompression of the first joint: Q [kN], middle-span tendon force [N] and x [m] of the
/// joint point, extrapolated linearly to zero contact stress from the last two increments
/// with every joint closed (the response is linear elastic until a joint opens).
fn decompression(rows: &[LifeRow]) -> (f64, f64, f64) {
    let i = rows
        .iter()
        .position(|r| r.q > 0.0 && (r.open || r.sigma_min <= 0.0))
        .expect("no joint opens");
    let (a, b) = (&rows[i - 2], &rows[i - 1]);
    assert!(
        a.q > 0.0 && b.q > a.q,
        "two closed increments under Q before opening"
    );
    let s = b.sigma_min / (a.sigma_min - b.sigma_min); // fraction of (b − a) past b
    let q = b.q + s * (b.q - a.q);
    assert!(
        q > b.q && q <= rows[i].q,
        "decompression {q} kN outside ({}, {}]",
        b.q,
        rows[i].q
    );
    (q, b.forces[1] + s * (b.forces[1] - a.forces[1]), b.x_min)
}

/// The seed beam pushed to failure from its long-term state (10⁴ days of creep, shrinkage
/// and relaxation after prestress and self weight) against the same beam pushed at once
/// (without a time step the clock stays at its default 28 d: the segments are 28 days older
/// and a little stiffer, which moves deflections but none of the statics checked here).
#[test]
fn seed_beam_fails_from_its_long_term_state_as_statics_says() {
    use common::mc90::creep_coefficient;
    let run_life = |long_term: bool| {
        let model = segfem::input::parse(&seed_beam_life(long_term), "seed-beam-life.toml")
            .unwrap_or_else(|e| panic!("{e}"))
            .model;
        let mut life = Life::default();
        let done = steps::run(&model, &mut life);
        let ultimate = life.watch.finish(&model, done.is_ok()).expect("a verdict");
        done.unwrap();
        (life.rows, ultimate)
    };
    let (short, u_short) = run_life(false);
    let (long, u_long) = run_life(true);

    // (a) Losses at 10⁴ d against EC2 5.10.6 (2) with the MC90 functions, as
    // `seed_beam_long_term_loss_matches_the_ec2_estimate`, here for creep-beam.toml's data:
    // h0 = 0.15 m, drying from day 7, each segment with its own age at loading (cast on days
    // −90 … −30, prestressed on day 0), means along the unbonded tendon, each span's force.
    let end = long.iter().rposition(|r| r.step == 1).unwrap(); // end of the time step
    let [fe_cs, fe_rel] = long[end].losses;
    let p = CreepShrinkageParams::new(45e6, 0.70, 0.15, CementClass::N, 7.0);
    let (ep, ap, l) = (195e9, 560e-6, 7.2);
    let alpha = ep / mc90::eci(&p);
    let bands: [(f64, f64); 3] = [(0.70, 0.10), (0.20, 0.40), (1.20, 0.10)];
    let (mut y0, mut ac, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for (b, h) in bands {
        ac += b * h;
        sy += b * h * (y0 + h / 2.0);
        y0 += h;
    }
    let yc = sy / ac;
    let (mut ic, mut y0) = (0.0, 0.0);
    for (b, h) in bands {
        ic += b * h * h * h / 12.0 + b * h * (y0 + h / 2.0 - yc).powi(2);
        y0 += h;
    }
    let q_sw = ac * 2548.4 * 9.81; // self weight [N/m]
    let m_sw = |x: f64| q_sw * x * (l - x) / 2.0;
    let yp = |x: f64| {
        if x < 2.4 {
            0.30 - 0.2 * x / 2.4
        } else if x > 4.8 {
            0.10 + 0.2 * (x - 4.8) / 2.4
        } else {
            0.10
        }
    };
    // Span forces after prestress and self weight [N] (the instantaneous step).
    let spans = &long[0].forces;
    let n = 7200;
    let (mut phi_sc, mut phi_m, mut eps_cs, mut z2) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..=n {
        let x = l * i as f64 / n as f64;
        let w = if i == 0 || i == n { 0.5 } else { 1.0 } / n as f64;
        let seg = ((x / (l / 7.0)) as usize).min(6);
        let t0 = 90.0 - 10.0 * seg as f64; // age at prestressing [d]
        let t = t0 + 1e4;
        let phi = creep_coefficient(&p, t, t0);
        let pf = spans[((x / 2.4) as usize).min(2)];
        let z = yc - yp(x);
        let sc = pf / ac + pf * z * z / ic - m_sw(x) * z / ic; // compression positive
        phi_sc += w * phi * sc;
        phi_m += w * phi;
        eps_cs += w * -(shrinkage_strain(&p, t) - shrinkage_strain(&p, t0));
        z2 += w * z * z;
    }
    // At σp0 = 0.46 f_ptk MC90 class 2 gives no relaxation (none below 0.5 f_ptk).
    let s0 = spans[1] / ap;
    let rho = mc90::relaxation_loss(
        segfem::materials::mc90_time::RelaxationClass::Class2,
        s0 / 1900e6,
        1e4,
    ) * s0;
    assert!(rho == 0.0 && fe_rel == 0.0, "relaxation {rho}, FE {fe_rel}");
    let hand = (eps_cs * ep + alpha * phi_sc)
        / (1.0 + alpha * ap / ac * (1.0 + ac * z2 / ic) * (1.0 + 0.8 * phi_m));
    eprintln!(
        "seed beam life: spans {spans:?} N; loss at 1e4 d FE {:.1} MPa vs EC2 {:.1} MPa (mean φ {phi_m:.3}, ε_cs {eps_cs:.3e})",
        fe_cs / 1e6,
        hand / 1e6
    );
    // 15 %, the band of the EC2 check on the seed beam and for the same reasons: a fixed
    // ageing coefficient 0.8, a sectional formula with the eccentricity and stress averaged
    // along the unbonded tendon, no shear lag or joints.
    assert!(
        (fe_cs / hand - 1.0).abs() < 0.15,
        "FE {fe_cs} vs EC2 {hand}"
    );

    // (b) Decompression. At a joint the concrete carries the middle span's force P at the
    // tendon's eccentricity and the moment of the loads (statically determinate beam, free
    // body cut through the joint and the middle span), so the contact stress at a point of the
    // joint vanishes at M_dec = P (k + e) with k, e fixed by the section and the tendon: M_dec
    // ∝ P. With M = M_sw(x_J) + a Q (a = 2.4 m, the point loads' lever between them) the long-
    // term decompression load follows from the short-term one:
    // Q_dec,L = [(a Q_dec,S + M_sw) P_L/P_S − M_sw]/a, so ΔQ_dec/Q_dec is Δσ_p/σ_p amplified
    // by M_dec/(M_dec − M_sw) — self weight takes part of the decompression moment.
    let (qs, ps, xs) = decompression(&short);
    let (ql, pl, xl) = decompression(&long);
    let a = 2.4e3; // lever arm [m] × 1 kN per unit of Q [N]
    assert!((xs - xl).abs() < 1e-9, "first opening at x = {xs} vs {xl}");
    let m_dec_s = a * qs + m_sw(xs);
    let ql_beam = (m_dec_s * pl / ps - m_sw(xl)) / a;
    let dp = 1.0 - pl / ps;
    eprintln!(
        "decompression: short Q = {qs:.2} kN (P = {:.1} kN), long Q = {ql:.2} kN (P = {:.1} kN) at x = {xs:.3} m; \
         ΔP/P = {:.2} %, ΔQ/Q = {:.2} % (beam theory {:.2} %, amplification M_dec/(M_dec − M_sw) = {:.3})",
        ps / 1e3,
        pl / 1e3,
        100.0 * dp,
        100.0 * (1.0 - ql / qs),
        100.0 * (1.0 - ql_beam / qs),
        m_dec_s / (m_dec_s - m_sw(xs))
    );
    // 1 % of Q_dec (≈ 0.5 kN): the proportionality is exact for the section forces; what is
    // not is the local stress field at the joint, 0.7 m (1.1 depths) from the deviator and
    // load point, whose share from the deviator forces changes with the ratio of span forces
    // (held deviators: the spans lose differently, < 1 % here), and the nonlinear geometry
    // (the tendon's eccentricity at the joint moves with the sag between deviators, < 0.1 mm
    // of 0.25 m). The linear extrapolation is exact for a linear response.
    assert!(
        (ql - ql_beam).abs() < 0.01 * ql_beam,
        "long-term decompression at Q = {ql:.2} kN vs beam theory {ql_beam:.2} kN"
    );
    assert!(dp > 0.05, "the prestress must have dropped: ΔP/P = {dp}");

    // (c) Ultimate load. The tendon yields at f_py = 0.9 f_ptk whatever its initial stress:
    // Q_u = (T_y z − M_sw)/a depends on T_y = f_py A_p and the lever arm z at the opened
    // joint, not on P0. What the 10⁴ days change is z: the contact block's depth (the aged
    // concrete is stiffer) and the camber (≈ 1 mm, of which the sag between the deviators is
    // a fraction), each well under 1 mm of z ≈ 0.49 m: 1 %.
    let (qu_s, qu_l) = (u_short.peak_factor, u_long.peak_factor);
    eprintln!(
        "ultimate: short {qu_s:.2} kN ({}), long {qu_l:.2} kN ({}); {:+.2} %",
        u_short.mode,
        u_long.mode,
        100.0 * (qu_l / qu_s - 1.0)
    );
    assert!((qu_l / qu_s - 1.0).abs() < 0.01, "Q_u {qu_l} vs {qu_s}");
    // And both against statics of the opened midspan joint (as tests/seed_beam.rs: tendon
    // at d_p = 0.50 m below the top, rectangular block in the 1.20 m top flange), within its
    // 3 % (elastic triangular block, eccentricity lost between the deviators, increments).
    let t_y = 0.9 * 1900e6 * ap;
    let m_u = t_y * (0.50 - t_y / (0.85 * 45e6 * 1.20) / 2.0);
    let q_statics = (m_u - m_sw(l / 2.0)) / a;
    for qu in [qu_s, qu_l] {
        assert!((qu / q_statics - 1.0).abs() < 0.03, "{qu} vs {q_statics}");
    }
    // (d) The same failure: the tendon yields, in the step to failure, and the runs end.
    for u in [&u_short, &u_long] {
        assert_eq!(u.mode, "tendon yield", "{u}");
        assert_eq!(u.ended, "completed", "{u}");
        assert_eq!(u.peak_step, "failure", "{u}");
    }
}

/// The seed beam's life with the cracking, creeping concrete (issue 19 item 5):
/// [`seed_beam_life`] with the concrete `kind = "concrete"`, `creep = "mc90"` (IMPL-EX
/// cracking, the seed beam's concrete variant of docs/performance.md) — or, with
/// `cracking = false`, the `elastic_creep` material it reproduces where nothing cracks —
/// end blocks of 0.3 m at the anchors in `elastic_creep` concrete of the same data (the
/// single-node anchor forces would crush the concrete there, docs/performance.md), and a
/// sustained `q_sus` [kN] at each load point applied with the prestress. Without
/// `to_failure` the run ends with the time step.
fn seed_beam_life_concrete(
    long_term: bool,
    cracking: bool,
    q_sus: f64,
    to_failure: bool,
) -> String {
    let mut text = seed_beam_life(long_term);
    if !to_failure {
        text.truncate(text.find("[[steps]]\nname = \"service\"").unwrap());
    }
    let data = "fcm = 45e6\nrh = 0.70\nh0 = 0.15\ncement = \"N\"\nnu = 0.2\ndensity = 2548.4\n\
                n_units = 5\nshrinkage = true\ndrying_start = 7.0\n";
    let blocks = format!(
        "[[materials]]\nname = \"block\"\nkind = \"elastic_creep\"\n{data}\n\
         [[regions]]\nname = \"block_left\"\nmaterial = \"block\"\nthickness = 0.70\ncast_day = -90.0\n\
         boxes = [[[0.0, 0.0], [0.3, 0.6]]]\n\n\
         [[regions]]\nname = \"block_right\"\nmaterial = \"block\"\nthickness = 0.70\ncast_day = -30.0\n\
         boxes = [[[6.9, 0.0], [7.2, 0.6]]]\n\n[[joint_materials]]"
    );
    let prestress = "name = \"prestress\"\nkind = \"load\"\nloads = { self_weight = 1.0 }";
    assert!(text.contains(prestress) && text.contains("[[joint_materials]]"));
    text = text.replacen("[[joint_materials]]", &blocks, 1).replace(
        prestress,
        &format!(
            "name = \"prestress\"\nkind = \"load\"\nloads = {{ self_weight = 1.0, Q = {q_sus} }}"
        ),
    );
    if cracking {
        text = text.replacen(
            "kind = \"elastic_creep\"",
            "kind = \"concrete\"\ncreep = \"mc90\"\ncrack_integration = \"implex\"",
            1,
        );
        assert!(text.contains("creep = \"mc90\""));
    }
    let first_step = text.find("[[steps]]").unwrap();
    text.insert_str(
        first_step,
        "[solver]\nforce_tolerance = 1e-4\nmax_iterations = 30\nmax_cuts = 8\n\n",
    );
    text
}

/// Issue 19 item 5: the seed beam over its life with the cracking, creeping concrete —
/// prestress, self weight and a sustained Q = 30 kN per load point (about half the
/// decompression load: no joint opens) from day 0, 10⁴ days, then pushed to failure, against
/// the same beam pushed to failure at once. Release test (four runs, ≈ 10 s).
#[test]
fn seed_beam_with_cracking_concrete_over_its_life() {
    use common::mc90::creep_coefficient;
    const Q_SUS: f64 = 30.0; // kN at each load point
    let run_life = |text: String| {
        let model = segfem::input::parse(&text, "seed-beam-life.toml")
            .unwrap_or_else(|e| panic!("{e}"))
            .model;
        let mut life = Life::default();
        let done = steps::run(&model, &mut life);
        let ultimate = life.watch.finish(&model, done.is_ok());
        done.unwrap_or_else(|e| panic!("{e}"));
        (life.rows, ultimate)
    };
    let t0 = std::time::Instant::now();
    let (reference, _) = run_life(seed_beam_life_concrete(true, false, Q_SUS, false));
    let (long, u_long) = run_life(seed_beam_life_concrete(true, true, Q_SUS, true));
    let (short, u_short) = run_life(seed_beam_life_concrete(false, true, Q_SUS, true));
    eprintln!("four runs: {:.1} s", t0.elapsed().as_secs_f64());
    let end = long.iter().rposition(|r| r.step == 1).unwrap();
    eprintln!("history (t [d], uy_mid [mm] cracking / elastic_creep, loss cs [MPa], cracked, σ_min joints [MPa]):");
    for (a, b) in long[..=end].iter().zip(&reference) {
        eprintln!(
            "  {:9.2} {:8.4} {:8.4} {:7.2} {:7.2} {} {:6.3} {} {:?}",
            a.time,
            a.uy_mid * 1e3,
            b.uy_mid * 1e3,
            a.losses[0] / 1e6,
            b.losses[0] / 1e6,
            a.cracked,
            a.sigma_min / 1e6,
            a.open,
            a.forces
                .iter()
                .map(|f| (f / 1e2).round() / 10.0)
                .collect::<Vec<_>>()
        );
    }
    // (a) Before the push nothing cracks and no joint opens: the cracking concrete is the
    // `elastic_creep` point (docs/theory-time.md §9, tested to 1e-13 on a beam in
    // tests/creep_cracking.rs), and no point passes 0.4 f_cm where its compression plasticity
    // starts. Its whole history — deflection and losses at every substep — must then be the
    // `elastic_creep` run's to round-off: 1e-9 of the largest value (two orders of the same
    // arithmetic, accumulated over 51 increments of Newton solves to 1e-4 that take the same
    // iterates). A crack, a plastic point or a creep law that differs where the concrete is
    // uncracked fails it.
    assert_eq!(end + 1, reference.len(), "same increments");
    let scale_u = reference.iter().fold(0.0_f64, |m, r| m.max(r.uy_mid.abs()));
    let scale_l = reference
        .iter()
        .fold(0.0_f64, |m, r| m.max(r.losses[0].abs()));
    for (a, b) in long[..=end].iter().zip(&reference) {
        assert!(
            a.cracked == 0 && !a.open,
            "day {}: cracked {} open {}",
            a.time,
            a.cracked,
            a.open
        );
        assert!(
            (a.uy_mid - b.uy_mid).abs() <= 1e-9 * scale_u,
            "day {}: {} vs {}",
            a.time,
            a.uy_mid,
            b.uy_mid
        );
        assert!(
            (a.losses[0] - b.losses[0]).abs() <= 1e-9 * scale_l,
            "day {}",
            a.time
        );
    }

    // (b) Losses at 10⁴ d against EC2 5.10.6 (2) with the MC90 functions, as in
    // `seed_beam_fails_from_its_long_term_state_as_statics_says`, with the sustained Q's
    // moment in the concrete stress at the tendon: M_Q(x) = Q_sus min(x, 2.4 m, L − x).
    let [fe_cs, fe_rel] = long[end].losses;
    let p = CreepShrinkageParams::new(45e6, 0.70, 0.15, CementClass::N, 7.0);
    let (ep, ap, l) = (195e9, 560e-6, 7.2);
    let alpha = ep / mc90::eci(&p);
    let bands: [(f64, f64); 3] = [(0.70, 0.10), (0.20, 0.40), (1.20, 0.10)];
    let (mut y0, mut ac, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for (b, h) in bands {
        ac += b * h;
        sy += b * h * (y0 + h / 2.0);
        y0 += h;
    }
    let yc = sy / ac;
    let (mut ic, mut y0) = (0.0, 0.0);
    for (b, h) in bands {
        ic += b * h * h * h / 12.0 + b * h * (y0 + h / 2.0 - yc).powi(2);
        y0 += h;
    }
    let q_sw = ac * 2548.4 * 9.81; // self weight [N/m]
    let m_sw = |x: f64| q_sw * x * (l - x) / 2.0;
    let m_q = |x: f64| Q_SUS * 1e3 * x.min(2.4).min(l - x);
    let yp = |x: f64| {
        if x < 2.4 {
            0.30 - 0.2 * x / 2.4
        } else if x > 4.8 {
            0.10 + 0.2 * (x - 4.8) / 2.4
        } else {
            0.10
        }
    };
    let spans = &long[0].forces;
    let n = 7200;
    let (mut phi_sc, mut phi_m, mut eps_cs, mut z2) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..=n {
        let x = l * i as f64 / n as f64;
        let w = if i == 0 || i == n { 0.5 } else { 1.0 } / n as f64;
        let seg = ((x / (l / 7.0)) as usize).min(6);
        let t0 = 90.0 - 10.0 * seg as f64; // age at loading [d]
        let t = t0 + 1e4;
        let phi = creep_coefficient(&p, t, t0);
        let pf = spans[((x / 2.4) as usize).min(2)];
        let z = yc - yp(x);
        let sc = pf / ac + pf * z * z / ic - (m_sw(x) + m_q(x)) * z / ic; // compression +
        phi_sc += w * phi * sc;
        phi_m += w * phi;
        eps_cs += w * -(shrinkage_strain(&p, t) - shrinkage_strain(&p, t0));
        z2 += w * z * z;
    }
    let hand = (eps_cs * ep + alpha * phi_sc)
        / (1.0 + alpha * ap / ac * (1.0 + ac * z2 / ic) * (1.0 + 0.8 * phi_m));
    eprintln!(
        "loss at 1e4 d: FE {:.2} MPa vs EC2 {:.2} MPa ({:+.1} %); relaxation {fe_rel}",
        fe_cs / 1e6,
        hand / 1e6,
        100.0 * (fe_cs / hand - 1.0)
    );
    // 15 %: the band of the EC2 checks above, for the same reasons (fixed ageing
    // coefficient 0.8, sectional formula with means along the unbonded tendon, no shear lag
    // or joints). Relaxation: none at 0.46 f_ptk (MC90 class 2, none below 0.5 f_ptk).
    assert!(
        (fe_cs / hand - 1.0).abs() < 0.15,
        "FE {fe_cs} vs EC2 {hand}"
    );
    assert_eq!(fe_rel, 0.0);

    // (c) Decompression after 10⁴ d against the short-term run by beam theory, as in
    // `seed_beam_fails_from_its_long_term_state_as_statics_says`: M_dec = P (k + e) ∝ P at
    // the joint, M = M_sw(x_J) + 2.4 m · Q. 1 % for the same reasons (local field near the
    // deviator, nonlinear geometry); here also the concrete's instantaneous modulus on the
    // way up, which changes the deflections but not the statically determinate section forces.
    let (qs, ps, xs) = decompression(&short);
    let (ql, pl, xl) = decompression(&long);
    assert!((xs - xl).abs() < 1e-9, "first opening at x = {xs} vs {xl}");
    let a = 2.4e3; // lever arm [m] × 1 kN per unit of Q [N]
    let m_dec_s = a * qs + m_sw(xs);
    let ql_beam = (m_dec_s * pl / ps - m_sw(xl)) / a;
    eprintln!(
        "decompression: short Q = {qs:.2} kN (P = {:.1} kN), long Q = {ql:.2} kN (P = {:.1} kN), beam theory {ql_beam:.2} kN; ΔP/P = {:.2} %, ΔQ/Q = {:.2} %",
        ps / 1e3,
        pl / 1e3,
        100.0 * (1.0 - pl / ps),
        100.0 * (1.0 - ql / qs)
    );
    assert!((ql - ql_beam).abs() < 0.01 * ql_beam, "{ql} vs {ql_beam}");
    assert!(ql > Q_SUS, "the sustained load opens no joint");

    // (d) Ultimate: the tendon yields at f_py whatever its initial stress, and the lever arm
    // at the opened joint is set by the geometry: Q_u does not contain P0 (see the
    // elastic_creep test above). 1 % between the runs: the aged, crept concrete's contact
    // block and the camber each move z by well under 1 mm of 0.49 m; the crack pattern of
    // the push (IMPL-EX, increments) may differ a little. 3 % on the statics of the opened
    // joint (tests/seed_beam.rs).
    let (u_s, u_l) = (u_short.expect("a verdict"), u_long.expect("a verdict"));
    eprintln!(
        "ultimate: short {:.2} kN ({}), long {:.2} kN ({}); {:+.2} %",
        u_s.peak_factor,
        u_s.mode,
        u_l.peak_factor,
        u_l.mode,
        100.0 * (u_l.peak_factor / u_s.peak_factor - 1.0)
    );
    assert!((u_l.peak_factor / u_s.peak_factor - 1.0).abs() < 0.01);
    let t_y = 0.9 * 1900e6 * ap;
    let m_u = t_y * (0.50 - t_y / (0.85 * 45e6 * 1.20) / 2.0);
    let q_statics = (m_u - m_sw(l / 2.0)) / a;
    for u in [&u_s, &u_l] {
        assert!(
            (u.peak_factor / q_statics - 1.0).abs() < 0.03,
            "{} vs {q_statics}",
            u.peak_factor
        );
        assert_eq!(u.mode, "tendon yield", "{u}");
        assert_eq!(u.ended, "completed", "{u}");
        assert_eq!(u.peak_step, "failure", "{u}");
    }
}

/// Error-controlled substeps (`substep_tolerance`, issue 19 item 2): the specimen under
/// constant stress from day 28 held 10⁴ days. Each kept pair of substeps agrees with one
/// substep over the same time to `tol` times the displacement change over the pair; those
/// local errors add up to at most `tol` times the total (monotone) creep strain. The
/// reference is the same chain with 400 log-spaced substeps (80 per decade: converged to
/// ≪ 0.01 %, docs/theory-time.md §2, step-size table).
#[test]
fn substep_tolerance_bounds_the_creep_error() {
    let sigma = -4e6;
    let reference = run(&specimen(
        false,
        sigma,
        28.0,
        "duration = 1e4\nsubsteps = 400",
    ));
    let (e0, e_ref) = (reference[0].strain[0], reference.last().unwrap().strain[0]);
    let creep = e_ref - e0;
    let one_per_decade = run(&specimen(
        false,
        sigma,
        28.0,
        "duration = 1e4\nsubsteps = 6",
    ));
    let coarse_err = (one_per_decade.last().unwrap().strain[0] - e_ref).abs() / creep.abs();
    eprintln!("1 substep per decade: error {coarse_err:.2e} of the creep strain");
    let mut counts = Vec::new();
    for tol in [3e-2, 1e-2, 1e-3] {
        let rec = run(&specimen(
            false,
            sigma,
            28.0,
            &format!("duration = 1e4\nsubstep_tolerance = {tol}"),
        ));
        let last = rec.last().unwrap();
        assert_eq!(last.time, 28.0 + 1e4);
        let err = (last.strain[0] - e_ref).abs() / creep.abs();
        eprintln!(
            "substep_tolerance {tol:e}: {} kept pairs, error {err:.2e} of the creep strain",
            rec.len() - 1
        );
        // The stated accuracy: the accumulated error is at most tol × the change.
        assert!(err <= tol, "tol {tol}: error {err}");
        counts.push(rec.len() - 1);
    }
    // Tighter tolerance, more substeps; and the coarse fixed substeps miss by more than the
    // loosest tolerance allows (so the control is doing something).
    assert!(counts[0] < counts[1] && counts[1] < counts[2], "{counts:?}");
    assert!(coarse_err > 3e-2 / 3.0, "{coarse_err}");
}

#[test]
fn substep_tolerance_bad_input_names_the_key() {
    for (steps, key) in [
        (
            "duration = 1e4\nsubstep_tolerance = 0.0",
            "substep_tolerance",
        ),
        (
            "duration = 1e4\nsubstep_tolerance = 0.9",
            "substep_tolerance",
        ),
        (
            "duration = 1e4\nsubstep_tolerance = nan",
            "substep_tolerance",
        ),
    ] {
        let text = specimen(false, -4e6, 28.0, steps);
        let err = match segfem::input::parse(&text, "time.toml") {
            Ok(_) => panic!("{steps}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(key) && err.contains("time.toml"), "{err}");
    }
    // On a load step it belongs to a time step.
    let text = specimen(false, -4e6, 28.0, "duration = 1e4").replace(
        "kind = \"load\"\n",
        "kind = \"load\"\nsubstep_tolerance = 0.01\n",
    );
    let err = match segfem::input::parse(&text, "time.toml") {
        Ok(_) => panic!("substep_tolerance on a load step accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("substep_tolerance") && err.contains("time step"),
        "{err}"
    );
}

/// The seed beam over its life, pushed to failure, with compression softening of cracked
/// concrete (`compression_reduction = "vecchio_collins_1993"`) on the cracking, creeping
/// concrete. Until session 16 the local iteration of creep in series with cracking, when it
/// did not converge in a push increment, was reported as an internal error and the program
/// panicked ("please report"); it is a strain increment too large for the local series, so
/// the driver must cut the step and go on. The run must end without a panic, either
/// completed or with a step that did not converge (a clear error), and the service phase
/// before the push must complete (the softening acts only on cracked concrete, and nothing
/// cracks before the push: test above).
#[test]
fn seed_beam_life_with_compression_softening_cuts_steps_instead_of_panicking() {
    let text = seed_beam_life_concrete(true, true, 30.0, true).replacen(
        "creep = \"mc90\"",
        "creep = \"mc90\"\ncompression_reduction = \"vecchio_collins_1993\"",
        1,
    );
    assert!(text.contains("vecchio_collins_1993"));
    let model = segfem::input::parse(&text, "seed-beam-life-vc93.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut life = Life::default();
    let done = steps::run(&model, &mut life);
    if let Err(e) = &done {
        let msg = e.to_string();
        eprintln!("{msg}");
        assert!(msg.contains("did not converge"), "{msg}");
    }
    // The service phase (step 1, 10⁴ days) is complete: the push is the last step.
    let last_service = life.rows.iter().rfind(|r| r.step == 1).unwrap();
    assert!(last_service.time > 9_999.0, "{}", last_service.time);
}
