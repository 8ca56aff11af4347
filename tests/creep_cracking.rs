//! Concrete that cracks and creeps: `kind = "concrete"` with `creep = "mc90"` (the MC90
//! Maxwell chain and shrinkage in series with the crack laws, docs/theory-time.md §9).
//! Run with `cargo nextest run --release -E 'binary(creep_cracking)'`.

mod common;

// MC90 references from the test's own implementation (tests/common/mc90.rs), never the
// library's `mc90_time`/`chain` functions under test.
use common::mc90::{self as mc90, creep_coefficient, relaxation_function, shrinkage_strain};
use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::materials::mc90_time::{CementClass, CreepShrinkageParams};

/// One record per converged increment: time, displacements, Gauss-point stresses and
/// strains, number of cracked points.
#[derive(Debug, Clone, Default)]
struct Rec {
    time: f64,
    u: Vec<f64>,
    stress: Vec<[f64; 3]>,
    cracked: usize,
}

#[derive(Default)]
struct Keep(Vec<Rec>);

impl Observer for Keep {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let g = &sys.families.continuum.gauss.committed;
        self.0.push(Rec {
            time: sys.time.t_to,
            u: sys.displacements().to_vec(),
            stress: g.iter().map(|o| o.stress).collect(),
            cracked: sys
                .families
                .continuum
                .points
                .committed
                .iter()
                .filter(|p| p.n_cracks() > 0)
                .count(),
        });
        Ok(())
    }
}

fn run(text: &str) -> Vec<Rec> {
    let model = segfem::input::parse(text, "creep_cracking.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut k = Keep::default();
    steps::run(&model, &mut k).unwrap_or_else(|e| panic!("{e}"));
    k.0
}

/// MC90 keys shared by both concrete kinds: fcm 45 MPa, cement N, ν = 0.2.
const ELASTIC_CREEP: &str = r#"
[[materials]]
name = "c"
kind = "elastic_creep"
fcm = 45e6
nu = 0.2
cement = "N"
"#;

/// The cracking concrete with the same creep keys (with creep its compression plasticity
/// starts at 0.4 f_cm by default, the limit of MC90's linear creep).
const CRACKING_CREEP: &str = r#"
[[materials]]
name = "c"
kind = "concrete"
creep = "mc90"
fcm = 45e6
nu = 0.2
cement = "N"
"#;

/// A 6 m simply supported beam, 0.3 × 0.6 m, under self weight from day 28, with creep and
/// shrinkage for 1e4 days: extreme fibre stresses ≈ ±1.1 MPa, far from cracking and from
/// 0.4 f_cm.
fn uncracked_beam(material: &str) -> String {
    format!(
        r#"{material}rh = 0.70
h0 = 0.200
density = 2500.0
[[regions]]
name = "r"
material = "c"
thickness = 0.3
[mesh]
type = "banded"
length = 6.0
nx = 12
element = "Q8"
bands = [{{ region = "r", depth = 0.6, rows = 3 }}]
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
name = "load"
kind = "load"
loads = {{ g = 1.0 }}
[[steps]]
name = "creep"
kind = "time"
from = 28.0
duration = 1e4
"#
    )
}

#[test]
fn uncracked_concrete_reproduces_elastic_creep() {
    // Where nothing cracks or yields the series of chain and crack law is the chain alone:
    // the local equation is solved by its first (elastic) evaluation and the stress is
    // σ_n + E''D1(Δε − Δε'' − Δε_sh) computed in another order. Round-off: 1e-11 of the
    // largest displacement and stress (was 1e-9; docs/validation.md, tolerance changes;
    // measured 1.4e-13 and 5.6e-13: the two orders differ by round-off accumulated over ~30
    // increments; a missing creep or shrinkage term or a wrong age changes the deflection by
    // tens of per cent).
    let a = run(&uncracked_beam(ELASTIC_CREEP));
    let b = run(&uncracked_beam(CRACKING_CREEP));
    assert_eq!(a.len(), b.len(), "same increments");
    assert!(a.len() > 20);
    let umax = a
        .iter()
        .flat_map(|r| r.u.iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    let smax = a
        .iter()
        .flat_map(|r| r.stress.iter().flatten())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut worst_u: f64 = 0.0;
    let mut worst_s: f64 = 0.0;
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!(ra.time, rb.time);
        assert_eq!(rb.cracked, 0, "nothing cracks");
        for (x, y) in ra.u.iter().zip(&rb.u) {
            worst_u = worst_u.max((x - y).abs() / umax);
        }
        for (x, y) in ra.stress.iter().flatten().zip(rb.stress.iter().flatten()) {
            worst_s = worst_s.max((x - y).abs() / smax);
        }
    }
    eprintln!("uncracked: worst |Δu|/umax = {worst_u:.2e}, |Δσ|/σmax = {worst_s:.2e}");
    assert!(worst_u < 1e-11 && worst_s < 1e-11);
    // And the beam really crept: the deflection grows by more than 1 + φ/2.
    let first = a[0].u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let last = a
        .last()
        .unwrap()
        .u
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(last > 1.8 * first, "{first} → {last}");
}

/// Strip fcm 45 MPa, RH 50 %, h0 = 0.1 m, drying from day 7; 1 m long, 0.1 × 0.1 m, both ends
/// held in x (free laterally): restrained shrinkage gives uniaxial tension σx.
const STRIP_DATA: (f64, f64, f64, f64) = (45e6, 0.5, 0.1, 7.0);

fn strip(to: f64, extra: &str) -> String {
    format!(
        r#"
[[materials]]
name = "c"
kind = "concrete"
creep = "mc90"
fcm = 45e6
nu = 0.2
cement = "N"
rh = 0.5
h0 = 0.1
drying_start = 7.0
[[regions]]
name = "r"
material = "c"
thickness = 0.1
[mesh]
type = "banded"
length = 1.0
nx = 4
element = "Q4"
bands = [{{ region = "r", depth = 0.1, rows = 1 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0
[[supports]]
name = "right"
line = [[1.0, 0.0], [1.0, 0.1]]
ux = 0.0
[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0
[[steps]]
name = "shrink"
kind = "time"
from = 7.0
to = {to}
substeps = 60
first_substep = 0.1
{extra}
"#
    )
}

/// Stress of a fully restrained member under MC90 shrinkage from age t_s, by superposition
/// of the MC90 relaxation function (step-by-step solution of ∫ J dR = 1, independent of the
/// chain): σ(t) = −Σ_k R(t, t_k) Δε_sh,k with Δε_sh,k over [t_{k−1}, t_k] applied at the
/// midpoint age. Ages in days, stress in Pa (tension positive).
fn restrained_stress(p: &CreepShrinkageParams, t: f64, n: usize) -> f64 {
    let ts = p.t_shrinkage_start;
    // Geometric grid in t − ts from 0.01 d.
    let times: Vec<f64> = std::iter::once(ts)
        .chain((0..=n).map(|k| ts + 0.01 * ((t - ts) / 0.01).powf(k as f64 / n as f64)))
        .collect();
    let mut s = 0.0;
    for w in times.windows(2) {
        let d_sh = shrinkage_strain(p, w[1]) - shrinkage_strain(p, w[0]);
        let tm = 0.5 * (w[0] + w[1]);
        let r = if t - tm > 1e-3 {
            *relaxation_function(p, tm, &geometric(1e-3, t - tm, 40))
                .last()
                .unwrap()
        } else {
            mc90::eci_at(p, tm)
        };
        s -= r * d_sh;
    }
    s
}

fn geometric(a: f64, b: f64, per_decade: usize) -> Vec<f64> {
    let n = (((b / a).log10() * per_decade as f64).ceil() as usize).max(1);
    (0..=n)
        .map(|k| a * (b / a).powf(k as f64 / n as f64))
        .collect()
}

#[test]
fn restrained_shrinkage_cracks_when_the_stress_reaches_ftm() {
    check_restrained_strip("");
}

/// The same with error-controlled substeps: the crack forms inside a time step, the pairs
/// around it are shortened until they agree, and the result meets the same closed forms.
#[test]
fn restrained_shrinkage_with_error_controlled_substeps() {
    check_restrained_strip("substep_tolerance = 0.01");
}

fn check_restrained_strip(extra: &str) {
    let (fcm, rh, h0, ts) = STRIP_DATA;
    let p = CreepShrinkageParams::new(fcm, rh, h0, CementClass::N, ts);
    // f_tm of the concrete (MC90 mean, 28 days; the crack criterion does not age).
    let ftm = 1.4e6 * (fcm / 10e6).powf(2.0 / 3.0);
    let rec = run(&strip(3000.0, extra));
    eprintln!("{extra}: {} increments", rec.len());
    // Before cracking the FE stress follows the superposition integral: the chain
    // reproduces MC90 relaxation within ~1 % and the 60 log-spaced substeps add < 1 %; 3 %
    // of f_tm leaves room for both and fails without creep (the elastic stress
    // −E ε_sh is ~2× larger) or with creep of the wrong age.
    let onset = rec
        .iter()
        .position(|r| r.cracked > 0)
        .expect("the strip cracks");
    assert!(onset > 5, "cracks after some shrinkage ({onset})");
    let mut worst: f64 = 0.0;
    for r in &rec[1..onset] {
        let want = restrained_stress(&p, r.time, 40);
        let got = r.stress[0][0];
        worst = worst.max((got - want).abs() / ftm);
        assert!(r.stress[0][1].abs() < 1e-3 * ftm, "uniaxial");
    }
    eprintln!("restrained strip: worst |σ − σ_exact| = {worst:.4} f_tm before cracking");
    assert!(worst < 0.03);
    // Crack onset: the closed form's time where σ(t) = f_tm, found by bisection, lies in the
    // FE's last uncracked substep interval (widened by the 3 % stress tolerance at the
    // local slope of σ(t)).
    let (mut lo, mut hi) = (ts + 1.0, 3000.0);
    assert!(restrained_stress(&p, hi, 40) > ftm);
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        if restrained_stress(&p, mid, 40) >= ftm {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let t_cr = hi;
    let (t_a, t_b) = (rec[onset - 1].time, rec[onset].time);
    let slope = (restrained_stress(&p, t_b, 40) - restrained_stress(&p, t_a, 40)) / (t_b - t_a);
    let widen = 0.03 * ftm / slope;
    // Age-adjusted effective modulus (Trost–Bažant, χ = 0.8) for comparison only (printed):
    // σ = −ε_sh(t)/J_χ with loading age t0 = the drying start. Shrinkage is not applied at
    // t0 but grows as √t, mostly on older, less creeping concrete, so χ = 0.8 over-relaxes
    // the stress and puts the onset late; the superposition above is exact for MC90.
    let aaem = |t: f64| {
        // MC90 defines φ against the 28-day modulus: J = 1/E_ci(t0) + φ/E_ci.
        -shrinkage_strain(&p, t)
            / (1.0 / mc90::eci_at(&p, ts) + 0.8 * creep_coefficient(&p, t, ts) / mc90::eci(&p))
    };
    let (mut lo2, mut hi2) = (ts + 1.0, 1e5);
    for _ in 0..60 {
        let mid = (lo2 * hi2).sqrt();
        if aaem(mid) >= ftm {
            hi2 = mid;
        } else {
            lo2 = mid;
        }
    }
    eprintln!(
        "crack onset: FE in ({t_a:.1}, {t_b:.1}] d, superposition {t_cr:.1} d (±{widen:.1} d), AAEM χ = 0.8: {hi2:.1} d"
    );
    assert!(
        t_cr > t_a - widen && t_cr <= t_b + widen,
        "onset {t_cr} not in ({t_a}, {t_b}] ± {widen}"
    );
}

/// A 0.1 m square Q4 specimen of creeping concrete (fcm 45 MPa, RH 70 %, h0 0.2 m, no
/// shrinkage), held on its left edge in x and at a corner in y, loaded on day 28 by a
/// uniform compression `stress` [Pa] and held for 1e4 days.
fn specimen(stress: f64, nonlinear: bool) -> String {
    format!(
        r#"{CRACKING_CREEP}rh = 0.70
h0 = 0.200
shrinkage = false
nonlinear_creep = {nonlinear}
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
[[load_cases]]
name = "P"
line_loads = [{{ line = [[0.1, 0.0], [0.1, 0.1]], q = [{q}, 0.0] }}]
[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0 }}
increments = 4
[[steps]]
name = "creep"
kind = "time"
from = 28.0
duration = 1e4
"#,
        q = stress * 0.1
    )
}

#[test]
fn nonlinear_creep_multiplies_creep_by_the_mc90_factor() {
    // σ = −0.5 f_cm held from day 28: MC90 multiplies φ by exp[1.5 (0.5 − 0.4)] = 1.1618.
    // With the stress held, the chain strain, the plastic strain (rate-independent) and the
    // load-step strain are the same with and without the option, so the creep strain
    // ε(t) − ε(t0) must scale by exactly that factor. 1e-6: the Newton tolerance of the
    // substeps (the law is linear in the factor); a factor applied to the whole strain, or
    // not at all, misses by > 5 %.
    let sigma = -0.5 * 45e6;
    let lin = run(&specimen(sigma, false));
    let nl = run(&specimen(sigma, true));
    assert_eq!(lin.len(), nl.len());
    let k = (1.5_f64 * 0.1).exp();
    let at_load = |r: &[Rec]| r.iter().rposition(|x| x.time == 28.0).unwrap();
    let (i0, j0) = (at_load(&lin), at_load(&nl));
    assert_eq!(i0, j0);
    let e = |r: &Rec| r.u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!((e(&lin[i0]) - e(&nl[j0])).abs() < 1e-12, "same load step");
    for (a, b) in lin[i0 + 1..].iter().zip(&nl[j0 + 1..]) {
        let (ca, cb) = (e(a) - e(&lin[i0]), e(b) - e(&nl[j0]));
        if a.time - 28.0 >= 1.0 {
            assert!(
                (cb / ca / k - 1.0).abs() < 1e-6,
                "t = {}: creep ratio {} vs {k}",
                a.time,
                cb / ca
            );
        }
    }
    // The linear run really crept: ≥ 1.5× the load-step shortening after 1e4 days.
    assert!(e(lin.last().unwrap()) > 1.5 * e(&lin[i0]));
}

#[test]
fn creep_option_bad_input_names_the_key() {
    let base = |extra: &str| {
        format!(
            r#"
[[materials]]
name = "c"
kind = "concrete"
fcm = 45e6
{extra}
[[regions]]
name = "r"
material = "c"
thickness = 0.1
[mesh]
type = "banded"
length = 1.0
nx = 1
bands = [{{ region = "r", depth = 0.1, rows = 1 }}]
[[supports]]
name = "s"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0
[[supports]]
name = "s2"
point = [1.0, 0.0]
uy = 0.0
[[steps]]
name = "t"
kind = "time"
from = 28.0
duration = 10.0
"#
        )
    };
    for (extra, field, says) in [
        ("rh = 0.7", "materials[0].rh", "creep = \"mc90\" only"),
        ("creep = \"b3\"", "materials[0].creep", "expected mc90"),
        ("creep = \"mc90\"\nh0 = 0.2", "materials[0].rh", "missing"),
        (
            "creep = \"mc90\"\nrh = 0.7\nh0 = 0.2\nE = 30e9",
            "materials[0].E",
            "remove E",
        ),
        (
            "creep = \"mc90\"\nrh = 0.7\nh0 = 0.2\nviscoplastic = { fluidity = 1.0 }",
            "materials[0].viscoplastic",
            "two time laws",
        ),
    ] {
        let err = match segfem::input::parse(&base(extra), "bad.toml") {
            Ok(_) => panic!("accepted: {extra}"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(field) && err.contains(says), "{extra}: {err}");
    }
    // The option itself is accepted.
    segfem::input::parse(&base("creep = \"mc90\"\nrh = 0.7\nh0 = 0.2"), "ok.toml")
        .unwrap_or_else(|e| panic!("{e}"));
}

/// Simply supported RC beam, span 4.5 m, 0.25 × 0.5 m, 3 Ø20 (942 mm²) at d = 0.45 m,
/// loaded at the thirds by 2 × `p` [N] on day 28 (M = 1.5 p in the middle third) and held
/// for 1e4 days, creep without shrinkage. Elastic bearing blocks at the supports.
fn rc_beam(p: f64) -> String {
    let q = p / 0.25;
    format!(
        r#"
[[materials]]
name = "c"
kind = "concrete"
creep = "mc90"
fcm = 45e6
nu = 0.2
rh = 0.70
h0 = 0.2
shrinkage = false
[[materials]]
name = "bearing"
kind = "elastic"
E = 35e9
nu = 0.2
[[materials]]
name = "steel"
kind = "rebar"
E = 200e9
fy = 500e6
[[regions]]
name = "r"
material = "c"
thickness = 0.25
[[regions]]
name = "b"
material = "bearing"
thickness = 0.25
boxes = [[[0.0, 0.0], [0.25, 0.1]], [[4.25, 0.0], [4.5, 0.1]]]
[mesh]
type = "banded"
length = 4.5
nx = 18
element = "Q8"
bands = [{{ region = "r", depth = 0.5, rows = 5 }}]
[[bars]]
name = "bottom"
material = "steel"
path = [[0.0, 0.05], [4.5, 0.05]]
area = 9.42e-4
[[supports]]
name = "left"
point = [0.125, 0.0]
ux = 0.0
uy = 0.0
[[supports]]
name = "right"
point = [4.375, 0.0]
uy = 0.0
[[load_cases]]
name = "P"
line_loads = [
  {{ line = [[1.375, 0.5], [1.625, 0.5]], q = [0.0, -{q}] }},
  {{ line = [[2.875, 0.5], [3.125, 0.5]], q = [0.0, -{q}] }},
]
[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0 }}
increments = 10
[[steps]]
name = "sustained"
kind = "time"
from = 28.0
duration = 1e4
"#
    )
}

#[test]
fn cracked_rc_beam_long_term_curvature_matches_the_aaem() {
    let p = 66.7e3;
    // Moment in the middle third: the reaction p times the shear span (supports at 0.125 m).
    let m = p * 1.375;
    let text = rc_beam(p);
    let model = segfem::input::parse(&text, "rc.toml").unwrap().model;
    let node = |x: f64, y: f64| {
        model
            .nodes
            .iter()
            .position(|n| (n[0] - x).abs() < 1e-9 && (n[1] - y).abs() < 1e-9)
            .unwrap()
    };
    let (x1, x2) = (1.75, 2.75);
    let ids = [node(x1, 0.0), node(x1, 0.5), node(x2, 0.0), node(x2, 0.5)];
    let rec = run(&text);
    // Mean curvature of the middle third from the section rotations θ = (u_bot − u_top)/h.
    let kappa = |r: &Rec| {
        let th = |b: usize, t: usize| (r.u[2 * b] - r.u[2 * t]) / 0.5;
        (th(ids[2], ids[3]) - th(ids[0], ids[1])) / (x2 - x1)
    };
    let i0 = rec.iter().rposition(|r| r.time == 28.0).unwrap();
    let (k0, k1) = (kappa(&rec[i0]), kappa(rec.last().unwrap()));
    assert!(rec[i0].cracked > 0);
    // AAEM on the cracked section (Gilbert & Ranzi): compression zone d_n from the
    // short-term analysis, held in time; MC90 J with the chain's load-step compliance
    // J0 = J(t0 + 0.1 d, t0) (docs/theory-time.md §2), χ = 0.8.
    let cp = CreepShrinkageParams::new(45e6, 0.7, 0.2, CementClass::N, 7.0);
    let t0 = 28.0;
    let j0 = mc90::compliance(&cp, t0 + 0.1, t0);
    let jt = mc90::compliance(&cp, t0 + 1e4, t0);
    let (b, d, as_, es) = (0.25, 0.45, 9.42e-4, 200e9);
    let e0 = 1.0 / j0;
    let n0 = es / e0;
    let rho_n = as_ * n0 / (b * d);
    let dn = d * ((2.0 * rho_n + rho_n * rho_n).sqrt() - rho_n);
    let (ac, bc, ic) = (b * dn, b * dn * dn / 2.0, b * dn.powi(3) / 3.0);
    // Short-term: top strain ε0 and curvature κ0 (y down from the top, N = 0, M about top).
    let solve = |a: [[f64; 2]; 2], r: [f64; 2]| {
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        [
            (r[0] * a[1][1] - a[0][1] * r[1]) / det,
            (a[0][0] * r[1] - a[1][0] * r[0]) / det,
        ]
    };
    let sec = |e: f64| {
        [
            [e * ac + es * as_, e * bc + es * as_ * d],
            [e * bc + es * as_ * d, e * ic + es * as_ * d * d],
        ]
    };
    let [eps0, kap0] = solve(sec(e0), [0.0, m]);
    // Long term: Δσ = Ē(Δε − (J(t) − J0) σ0), Ē = 1/(J0 + χ (J(t) − J0)).
    let eb = 1.0 / (j0 + 0.8 * (jt - j0));
    let c = eb * (jt - j0) * e0;
    let [_, dkap] = solve(
        sec(eb),
        [c * (ac * eps0 + bc * kap0), c * (bc * eps0 + ic * kap0)],
    );
    // Uncracked section (full depth and the bar), same AAEM; cracking moment from f_tm at
    // the bottom fibre of the short-term uncracked section.
    let h = 0.5;
    let secu = |e: f64| {
        [
            [e * b * h + es * as_, e * b * h * h / 2.0 + es * as_ * d],
            [
                e * b * h * h / 2.0 + es * as_ * d,
                e * b * h.powi(3) / 3.0 + es * as_ * d * d,
            ],
        ]
    };
    let [eu0, ku0] = solve(secu(e0), [0.0, m]);
    let cu = eb * (jt - j0) * e0;
    let [_, dku] = solve(
        secu(eb),
        [
            cu * (b * h * eu0 + b * h * h / 2.0 * ku0),
            cu * (b * h * h / 2.0 * eu0 + b * h.powi(3) / 3.0 * ku0),
        ],
    );
    let ftm = 1.4e6 * 4.5_f64.powf(2.0 / 3.0);
    let mcr = m * ftm / (e0 * (eu0 + ku0 * h));
    // Tension stiffening as Gilbert & Ranzi and EC2 7.4.3 interpolate it:
    // κ = ζ κ_cr + (1 − ζ) κ_uncr, ζ = 1 − β (M_cr/M)², β = 1 short term, 0.5 sustained.
    let zeta = |beta: f64| 1.0 - beta * (mcr / m).powi(2);
    let ec2_0 = zeta(1.0) * kap0 + (1.0 - zeta(1.0)) * ku0;
    let ec2_t = zeta(0.5) * (kap0 + dkap) + (1.0 - zeta(0.5)) * (ku0 + dku);
    eprintln!(
        "RC beam M = {m:.0} N m = {:.2} M_cr: FE κ0 = {k0:.4e}, κ(1e4 d) = {k1:.4e}; \
         AAEM cracked {kap0:.4e} → {:.4e}, uncracked {ku0:.4e} → {:.4e}; \
         with tension stiffening {ec2_0:.4e} → {ec2_t:.4e}",
        m / mcr,
        kap0 + dkap,
        ku0 + dku
    );
    // 10 %: χ = 0.8 is fixed (the chain follows MC90's J, the AAEM only approximates its
    // integral), β = 0.5 is a code estimate of how much tension stiffening survives under
    // sustained load (the FE's smeared Hinton law relaxes by creep in series), and the FE
    // curvature is the mean over the middle third. The short-term value is printed, not
    // asserted: there the Hinton tail (α = 5e-4) stiffens more than β = 1 assumes.
    assert!(
        (k1 / ec2_t - 1.0).abs() < 0.10,
        "long-term curvature {k1:.4e} vs AAEM with tension stiffening {ec2_t:.4e}"
    );
    // Creep really acted on the cracked member: the curvature grew by more than 30 %.
    assert!(k1 > 1.3 * k0);
}

/// One converged increment of the segmental beam with opened joints.
#[derive(Debug, Clone)]
struct JointRow {
    time: f64,
    /// Largest opening of the first joint (x = 2 m) [m].
    opening: f64,
    /// Closed depth of the first joint [m].
    contact: f64,
    /// Largest contact stress of the first joint [Pa].
    sigma_max: f64,
    /// Anchor-to-anchor elongation of the tendon's line, u_x(6, 0.1) − u_x(0, 0.1) [m].
    delta: f64,
    /// Tendon force [N] (0 without the tendon).
    force: f64,
    /// Cracked Gauss points.
    cracked: usize,
}

#[derive(Default)]
struct JointKeep(Vec<JointRow>);

impl Observer for JointKeep {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let j = segfem::results::joints::summarise(sys, 0);
        let node = |x: f64| {
            sys.model
                .nodes
                .iter()
                .position(|p| (p[0] - x).abs() < 1e-9 && (p[1] - 0.1).abs() < 1e-9)
                .expect("anchor node")
        };
        let (a, b) = (node(0.0), node(6.0));
        self.0.push(JointRow {
            time: sys.time.t_to,
            opening: j.max_opening,
            contact: j.contact_depth,
            sigma_max: j
                .profile
                .iter()
                .fold(0.0_f64, |m, p| m.max(p.normal_stress)),
            delta: sys.displacements()[2 * b] - sys.displacements()[2 * a],
            force: sys
                .families
                .tendons
                .states
                .committed
                .first()
                .and_then(|t| t.as_ref())
                .map_or(0.0, |t| t.forces()[0]),
            cracked: sys
                .families
                .continuum
                .points
                .committed
                .iter()
                .filter(|p| p.n_cracks() > 0)
                .count(),
        });
        Ok(())
    }
}

/// Sustained load of the opened-joint beam: Q [kN] at each load point.
const Q_OPEN: f64 = 120.0;

/// Three dry-jointed segments (2 m each, 0.3 × 0.5 m, Q8, 10 rows) of the creeping, cracking
/// concrete (fcm 45 MPa, RH 70 %, h0 0.15 m, MC90 shrinkage from day 7, all cast on day 0),
/// end blocks of 0.25 m in `elastic_creep` concrete of the same data (the anchors are single
/// nodes), simply supported over 6 m; Q at x = 1 m and 5 m (constant moment over both joints)
/// and the prestress on day 28, held 10⁴ d. Prestress: with `tendon`, a straight external
/// tendon at y = 0.1 m (e = 0.15 m below the centroid), 560 mm² at that initial stress [Pa];
/// without, a pair of horizontal forces `p` [N] at the same anchor nodes.
fn opened_joint_beam(tendon: Option<f64>, p: f64) -> String {
    let data = "fcm = 45e6\nnu = 0.2\ncement = \"N\"\nrh = 0.70\nh0 = 0.15\nshrinkage = true\ndrying_start = 7.0\n";
    let prestress = match tendon {
        Some(s) => format!(
            "[[tendons]]\nname = \"T\"\nkind = \"external\"\nanchor_plate = 0.0\npoints = [[0.0, 0.1], [6.0, 0.1]]\n\
             area = 560e-6\nEp = 195e9\nfptk = 1860e6\ninitial_stress = {s}\n\n\
             [[load_cases]]\nname = \"P\"\npoint_loads = []\n"
        ),
        None => format!(
            "[[load_cases]]\nname = \"P\"\npoint_loads = [\n  {{ point = [0.0, 0.1], force = [{p}, 0.0] }},\n  \
             {{ point = [6.0, 0.1], force = [{m}, 0.0] }},\n]\n",
            m = -p
        ),
    };
    format!(
        r#"
[[materials]]
name = "c"
kind = "concrete"
creep = "mc90"
{data}
[[materials]]
name = "block"
kind = "elastic_creep"
{data}
[[regions]]
name = "web"
material = "c"
thickness = 0.3
[[regions]]
name = "ends"
material = "block"
thickness = 0.3
boxes = [[[0.0, 0.0], [0.25, 0.5]], [[5.75, 0.0], [6.0, 0.5]]]
[[joint_materials]]
name = "dry"
kind = "dry"
friction = 0.7
[mesh]
type = "segmental"
segments = [2.0, 2.0, 2.0]
nx_per_segment = 8
element = "Q8"
joint_material = "dry"
bands = [{{ region = "web", depth = 0.5, rows = 10 }}]
[[supports]]
name = "left"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0
[[supports]]
name = "right"
point = [6.0, 0.0]
uy = 0.0
{prestress}
[[load_cases]]
name = "Q"
point_loads = [
  {{ point = [1.0, 0.5], force = [0.0, -1e3] }},
  {{ point = [5.0, 0.5], force = [0.0, -1e3] }},
]
[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0, Q = {Q_OPEN} }}
increments = 10
[[steps]]
name = "sustained"
kind = "time"
from = 28.0
duration = 1e4
"#
    )
}

fn run_joints(text: &str) -> Vec<JointRow> {
    let model = segfem::input::parse(text, "opened_joints.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut k = JointKeep::default();
    steps::run(&model, &mut k).unwrap_or_else(|e| panic!("{e}"));
    k.0
}

/// Issue 19 item 4: a segmental beam with opened joints under a sustained load, opening and
/// tendon force over 10⁴ days. Two closed forms: (1) with the prestress as constant end
/// forces the beam is one linear ageing viscoelastic body of one age (nothing cracks, no
/// point reaches 0.4 f_cm) under constant loads with unilateral joints, so its stresses and
/// contact zone stay as they are and every relative displacement — the joint opening — grows
/// with the creep function (free shrinkage of a statically determinate beam adds no stress
/// and no opening); (2) with the tendon, the force method of the age-adjusted effective
/// modulus (Trost–Bažant): the tendon is the redundant, compatible with the concrete's
/// elongation along its line.
#[test]
fn opened_joints_under_sustained_load_follow_creep_and_the_force_method() {
    use common::mc90::compliance;
    let p = CreepShrinkageParams::new(45e6, 0.70, 0.15, CementClass::N, 7.0);
    let t0 = 28.0;
    let (ep, ap, l) = (195e9, 560e-6, 6.0);
    // The tendon run first: its force at the end of loading is the end force of the others.
    let tendon = run_joints(&opened_joint_beam(Some(714e6), 0.0));
    let n_load = tendon.iter().position(|r| r.time > t0).unwrap() - 1;
    let p0 = tendon[n_load].force;
    let free = run_joints(&opened_joint_beam(None, p0));
    let eta = 0.02;
    let more = run_joints(&opened_joint_beam(None, p0 * (1.0 + eta)));
    let (a0, b0, c0) = (&free[n_load], &more[n_load], &tendon[n_load]);
    eprintln!(
        "t0: P0 = {:.1} kN; opening {:.4} mm (tendon run {:.4}), contact depth {:.3} m, σ_max {:.2} MPa, δ = {:.4} mm",
        p0 / 1e3,
        a0.opening * 1e3,
        c0.opening * 1e3,
        a0.contact,
        a0.sigma_max / 1e6,
        a0.delta * 1e3
    );
    // Same state at t0 (same forces on the same structure; the tendon's are the span force
    // along the same line): 1e-6 (Newton tolerance).
    assert!(
        (a0.opening / c0.opening - 1.0).abs() < 1e-6 && (a0.delta / c0.delta - 1.0).abs() < 1e-6
    );
    // The joint is open and stays so, nothing cracks.
    assert!(a0.opening > 1e-5 && a0.contact < 0.45);
    assert!(tendon.iter().chain(&free).all(|r| r.cracked == 0));

    // (1) Constant end forces: opening(t)/opening(t0) = J(t, t0)/J(t0 + 0.1 d, t0) (the
    // load step is the chain's 0.1-day response, docs/theory-time.md §2). 2 %: the chain
    // follows MC90 within 0.6 % from 1 d and 1.8 % at 0.1 d, the default 5 substeps per
    // decade add < 1 % (tests/time.rs constant-stress test); the joint's penalty contact
    // (a non-creeping spring) is stiff. The contact zone and stress stay: 1 %.
    let j0 = compliance(&p, t0 + 0.1, t0);
    let mut worst: f64 = 0.0;
    for r in &free[n_load + 1..] {
        let rho = compliance(&p, r.time, t0) / j0;
        worst = worst.max((r.opening / a0.opening / rho - 1.0).abs());
        assert!(
            (r.contact - a0.contact).abs() < 0.01 * a0.contact,
            "contact at {}",
            r.time
        );
        assert!(
            (r.sigma_max / a0.sigma_max - 1.0).abs() < 0.01,
            "σ_max at {}",
            r.time
        );
    }
    eprintln!("constant forces: worst |w/w0 / (J/J0) − 1| = {worst:.4}");
    assert!(worst < 0.02);

    // (2) Tendon: ΔP = [δ0 φ + Δε_cs L] / [L/(E_p A_p) − d (1 + χ φ)] with δ0 the elongation of
    // the tendon's line at t0 under the loads (constant forces run), φ = J(t,t0)/J(t0+0.1,t0)
    // − 1, Δε_cs the free shrinkage since t0 (uniform: no stress, no opening in the
    // determinate beam), d = ∂δ/∂P at the opened state (end forces 2 % larger) and χ = 0.8.
    // The opening is not linear in P (less prestress, shallower contact, faster opening),
    // so it follows by superposition in time of the instantaneous response w_el(P) (the
    // quadratic through the constant-force runs at P0, 1.02 P0 and P0 + ΔP(10⁴ d)) with the
    // MC90 creep function, each increment dP(τ) creeping from its own age τ:
    //   w(t) = w_el(P0) J(t, t0)/J0 + Σ w_el'(P(τ)) J(t, τ)/J0 ΔP(τ),   J0 = J(t0 + 0.1, t0).
    let d = (b0.delta - a0.delta) / (eta * p0);
    let kp = ep * ap / l;
    let aaem = |t: f64| {
        let phi = compliance(&p, t, t0) / j0 - 1.0;
        let d_sh = shrinkage_strain(&p, t) - shrinkage_strain(&p, t0);
        let den = 1.0 / kp - d * (1.0 + 0.8 * phi);
        (a0.delta * phi / den, d_sh * l / den)
    };
    let t_end = tendon.last().unwrap().time;
    let (dp_c, dp_s) = aaem(t_end);
    let p_end = p0 + dp_c + dp_s;
    let secant = run_joints(&opened_joint_beam(None, p_end));
    // Quadratic w_el(P) through the three instantaneous states (Newton's divided differences).
    let (x, y) = (
        [p0, p0 * (1.0 + eta), p_end],
        [a0.opening, b0.opening, secant[n_load].opening],
    );
    let f01 = (y[1] - y[0]) / (x[1] - x[0]);
    let f02 = (y[2] - y[0]) / (x[2] - x[0]);
    let f012 = (f02 - f01) / (x[2] - x[1]);
    let slope = |pp: f64| f01 + f012 * ((pp - x[0]) + (pp - x[1]));
    eprintln!(
        "d = {d:.4e} m/N, ∂w/∂P at P0 {:.4e}, at P_end {:.4e} m/N, L/(Ep Ap) = {:.4e} m/N; ΔP(1e4 d) AAEM: creep {:.2} kN, shrinkage {:.2} kN",
        slope(p0),
        slope(p_end),
        1.0 / kp,
        dp_c / 1e3,
        dp_s / 1e3
    );
    let times: Vec<f64> = tendon[n_load..].iter().map(|r| r.time).collect();
    let dps: Vec<f64> = times
        .iter()
        .map(|&t| {
            let (c, s) = aaem(t);
            c + s
        })
        .collect();
    let opening_at = |k: usize| {
        let t = times[k];
        let mut w = a0.opening * compliance(&p, t, t0) / j0;
        for i in 1..=k {
            let tau = 0.5 * (times[i - 1] + times[i]);
            let pm = p0 + 0.5 * (dps[i - 1] + dps[i]);
            let jt = if t - tau > 0.1 {
                compliance(&p, t, tau)
            } else {
                compliance(&p, tau + 0.1, tau)
            };
            w += slope(pm) * jt / j0 * (dps[i] - dps[i - 1]);
        }
        w
    };
    eprintln!("   t [d]    P FE    P AAEM [kN]    w FE    w superposition [mm]   (constant forces: w [mm])");
    let (mut worst_p, mut worst_w): (f64, f64) = (0.0, 0.0);
    for (k, (r, f)) in tendon[n_load + 1..]
        .iter()
        .zip(&free[n_load + 1..])
        .enumerate()
    {
        let dp = dps[k + 1];
        let w = opening_at(k + 1);
        eprintln!(
            "  {:7.1} {:8.2} {:8.2} {:10.4} {:8.4} {:10.4}",
            r.time,
            r.force / 1e3,
            (p0 + dp) / 1e3,
            r.opening * 1e3,
            w * 1e3,
            f.opening * 1e3
        );
        worst_p = worst_p.max(((r.force - p0) - dp).abs());
        worst_w = worst_w.max((r.opening - w).abs());
    }
    let last = tendon.last().unwrap();
    let dp_fe = last.force - p0;
    let dw_fe = last.opening - a0.opening;
    eprintln!(
        "worst |ΔP − ΔP_AAEM| = {:.2} kN of ΔP(1e4 d) = {:.2} kN; worst |w − w_AAEM| = {:.4} mm of Δw = {:.4} mm",
        worst_p / 1e3,
        dp_fe / 1e3,
        worst_w * 1e3,
        dw_fe * 1e3
    );
    eprintln!(
        "tendon run: contact depth {:.3} → {:.3} m, σ_max {:.2} → {:.2} MPa; constant forces: {:.3} → {:.3} m",
        c0.contact,
        last.contact,
        c0.sigma_max / 1e6,
        last.sigma_max / 1e6,
        a0.contact,
        free.last().unwrap().contact
    );
    // 5 % of the final ΔP: χ = 0.8 is fixed (MC90's effective ageing coefficient for a
    // restraint building up from t0 = 28 d is ≈ 0.8 at 10⁴ d, other values earlier), the
    // flexibility d is the tangent at P0 (its term is 9–17 % of the denominator), and shrinkage
    // grows as √t rather than like φ (the AAEM's assumption); a missing creep or shrinkage
    // term, or a tendon not compatible with the concrete, fails it.
    assert!(
        dp_fe < 0.0 && worst_p < 0.05 * dp_fe.abs(),
        "ΔP {worst_p} of {dp_fe}"
    );
    // 10 % of the opening's growth: superposition in time is exact for a linear structure;
    // the unilateral joint is not (its contact depth changes with P), and w_el(P) is a
    // quadratic through three states.
    assert!(worst_w < 0.10 * dw_fe, "w {worst_w} of {dw_fe}");
}

/// One converged increment of the reinforced restrained strip: time, mean σx of the
/// concrete and mean steel stress of each element, cracked points of each element, and the
/// restraint force N read from the reactions at x = 0 (tension positive) [d, Pa, N].
#[derive(Debug, Clone, Default)]
struct StripRow {
    time: f64,
    concrete: Vec<f64>,
    steel: Vec<f64>,
    cracked: Vec<usize>,
    restraint: f64,
}

#[derive(Default)]
struct StripRows(Vec<StripRow>);

impl Observer for StripRows {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let m = sys.model;
        let ne = m.elements.len();
        let gauss = &sys.families.continuum.gauss.committed;
        let points = &sys.families.continuum.points.committed;
        let mut concrete = vec![0.0; ne];
        let mut cracked = vec![0; ne];
        for e in 0..ne {
            let range = sys.gp_offset[e]..sys.gp_offset[e + 1];
            let n = range.len() as f64;
            concrete[e] = gauss[range.clone()]
                .iter()
                .map(|g| g.stress[0])
                .sum::<f64>()
                / n;
            cracked[e] = points[range].iter().filter(|p| p.n_cracks() > 0).count();
        }
        let (mut steel, mut count) = (vec![0.0; ne], vec![0.0; ne]);
        for (i, &(b, p)) in sys.bar_gps.iter().enumerate() {
            let e = m.bars[b].points[p].element;
            steel[e] += sys.families.bars.out.committed[i].stress;
            count[e] += 1.0;
        }
        for (s, c) in steel.iter_mut().zip(&count) {
            *s /= c;
        }
        // The left supports push the strip to the left when it pulls: N = −Σ f_int,x there.
        let restraint = -m
            .nodes
            .iter()
            .enumerate()
            .filter(|(_, q)| q[0].abs() < 1e-9)
            .map(|(i, _)| s.f_int[2 * i])
            .sum::<f64>();
        self.0.push(StripRow {
            time: sys.time.t_to,
            concrete,
            steel,
            cracked,
            restraint,
        });
        Ok(())
    }
}

/// The strip of [`strip`] with a bar along its axis (y = 0.05 m, A_s = 1e-4 m², ρ = 1 %,
/// E_s = 200 GPa) and its second element (x from 0.25 to 0.5 m) of the same concrete with
/// f_tm lowered to `ft_weak`, so that the one crack forms there.
fn reinforced_strip(ft_weak: f64) -> String {
    strip(3000.0, "")
        .replace(
            "[[regions]]",
            &format!(
                r#"[[materials]]
name = "weak"
kind = "concrete"
crack_integration = "implicit"
creep = "mc90"
fcm = 45e6
ftm = {ft_weak}
nu = 0.2
cement = "N"
rh = 0.5
h0 = 0.1
drying_start = 7.0
[[materials]]
name = "steel"
kind = "rebar"
E = 200e9
fy = 500e6
[[regions]]
name = "w"
material = "weak"
thickness = 0.1
boxes = [[[0.25, 0.0], [0.5, 0.1]]]
[[regions]]"#
            ),
        )
        .replace(
            "[[supports]]\nname = \"left\"",
            "[[bars]]\nname = \"bar\"\nmaterial = \"steel\"\npath = [[0.0, 0.05], [1.0, 0.05]]\narea = 1e-4\n[[supports]]\nname = \"left\"",
        )
}

/// Issue 19 item 4: a reinforced strip, both ends held, shrinking from day 7. Perfect bond
/// and fixed ends keep the strain zero before cracking, so the steel carries nothing and the
/// concrete alone takes the restrained-shrinkage stress of the plain strip (Gilbert's
/// restrained member before cracking, N = σ_c A_c). After the one crack, statics and
/// compatibility of the fully restrained member (Gilbert, ACI Struct. J. 89 (1992) 269–276,
/// with the crack smeared over its element of length L_c): the same force N in every section,
/// N = σ_c,i A_c + σ_s,i A_s, and zero total elongation of the elastic steel, Σ L_i σ_s,i = 0,
/// give N = A_c σ̄_c (σ̄_c the length mean of the concrete stress) and at the crack
/// σ_s,cr = (N − σ_c,cr A_c)/A_s = A_c (L − L_c)(σ_c,u − σ_c,cr) / (L A_s),
/// bounded by the cracking force carried by the steel alone, N_cr/A_s = f_t A_c/A_s.
#[test]
fn reinforced_restrained_strip_steel_stress_before_and_after_cracking() {
    let (fcm, rh, h0, ts) = STRIP_DATA;
    let p = CreepShrinkageParams::new(fcm, rh, h0, CementClass::N, ts);
    let ftm = 1.4e6 * (fcm / 10e6).powf(2.0 / 3.0);
    let ft = 0.9 * ftm;
    let (a_c, a_s, l, l_c) = (0.01, 1e-4, 1.0, 0.25);
    let model = segfem::input::parse(&reinforced_strip(ft), "reinforced_strip.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut rows = StripRows::default();
    steps::run(&model, &mut rows).unwrap_or_else(|e| panic!("{e}"));
    let rows = rows.0;
    let onset = rows
        .iter()
        .position(|r| r.cracked.iter().any(|&c| c > 0))
        .expect("the strip cracks");
    assert!(onset > 5, "cracks after some shrinkage ({onset})");
    // The crack forms in the weak element only.
    assert!(rows[onset].cracked[1] > 0, "{:?}", rows[onset].cracked);
    // Before cracking: steel stress zero and N = σ_c A_c, within the Newton tolerance (a
    // force residual ~1e-4 of the load norm: 0.5 % of the cracking force's steel stress
    // f_t A_c/A_s is far above it and far below any share of the shrinkage stress the steel
    // would take with a wrong bond, −E_s ε_sh ≈ 60 MPa = 16 % of it); the concrete stress
    // against the superposition integral within 3 % of f_tm as for the plain strip (chain
    // vs MC90 relaxation ~1 %, 60 log-spaced substeps < 1 %).
    let s_cr = ft * a_c / a_s;
    let (mut worst_s, mut worst_c): (f64, f64) = (0.0, 0.0);
    for r in &rows[1..onset] {
        let want = restrained_stress(&p, r.time, 40);
        for e in 0..4 {
            worst_s = worst_s.max(r.steel[e].abs() / s_cr);
            worst_c = worst_c.max((r.concrete[e] - want).abs() / ftm);
        }
        assert!(
            (r.restraint - r.concrete[0] * a_c).abs() < 0.005 * ft * a_c,
            "N {} vs σ_c A_c {}",
            r.restraint,
            r.concrete[0] * a_c
        );
    }
    eprintln!(
        "before cracking: |σ_s| ≤ {worst_s:.2e} f_t A_c/A_s, |σ_c − σ_exact| ≤ {worst_c:.4} f_tm"
    );
    assert!(worst_s < 0.005 && worst_c < 0.03);
    // Crack onset: the closed form's time where σ(t) = f_t of the weak element lies in the
    // FE's last uncracked substep interval, widened by the 3 % stress tolerance at the local
    // slope of σ(t).
    let (mut lo, mut hi) = (ts + 1.0, 3000.0);
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        if restrained_stress(&p, mid, 40) >= ft {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (t_a, t_b) = (rows[onset - 1].time, rows[onset].time);
    let slope = (restrained_stress(&p, t_b, 40) - restrained_stress(&p, t_a, 40)) / (t_b - t_a);
    let widen = 0.03 * ftm / slope;
    eprintln!("crack onset: FE in ({t_a:.1}, {t_b:.1}] d, superposition {hi:.1} d (±{widen:.1} d)");
    assert!(hi > t_a - widen && hi <= t_b + widen);
    // After cracking, while the crack is the only one: the steel stress at the crack against
    // the statics above, from the concrete stresses of the cracked and uncracked elements;
    // 1 % of f_t A_c/A_s (Newton tolerance as above, and the four bar points of an element
    // averaged where the Q4 strain varies slightly across the crack element).
    let mut checked = 0;
    let (mut peak, mut worst): (f64, f64) = (0.0, 0.0);
    for r in &rows[onset..] {
        if r.cracked[0] + r.cracked[2] + r.cracked[3] > 0 {
            break;
        }
        let sigma_u = (r.concrete[0] + r.concrete[2] + r.concrete[3]) / 3.0;
        let want = a_c * (l - l_c) * (sigma_u - r.concrete[1]) / (l * a_s);
        let n_mean = a_c * (l_c * r.concrete[1] + (l - l_c) * sigma_u) / l;
        assert!(
            (r.steel[1] - want).abs() < 0.01 * s_cr,
            "t = {}: σ_s,cr {} vs {}",
            r.time,
            r.steel[1],
            want
        );
        assert!((r.restraint - n_mean).abs() < 0.01 * ft * a_c);
        assert!(r.steel[1] > 0.0 && r.steel[1] <= s_cr * (1.0 + 0.01));
        peak = peak.max(r.steel[1]);
        worst = worst.max((r.steel[1] - want).abs() / s_cr);
        checked += 1;
    }
    let last = &rows[onset + checked - 1];
    eprintln!(
        "after cracking: {checked} increments with one crack, worst |σ_s,cr − statics| = {worst:.1e} f_t A_c/A_s; σ_s,cr up to {:.1} MPa (bound f_t A_c/A_s = {:.1} MPa); at {:.0} d σ_s,cr = {:.1} MPa, σ_c,u = {:.2} MPa, σ_c,cr = {:.2} MPa, N = {:.1} kN",
        peak / 1e6,
        s_cr / 1e6,
        last.time,
        last.steel[1] / 1e6,
        last.concrete[0] / 1e6,
        last.concrete[1] / 1e6,
        last.restraint / 1e3
    );
    assert!(checked > 5, "{checked} increments with one crack");
}

/// Steel stress [Pa] at age `t` [d] of a reinforced member free to shorten (internal
/// restraint only), area ratio A_c/A_s = `ratio`, steel modulus `e_s` [Pa], under MC90
/// shrinkage from the drying start:
/// perfect bond makes the steel strain the concrete strain, ε = σ_s/E_s, and equilibrium
/// σ_c A_c + σ_s A_s = 0, so the concrete stress history solves the Volterra equation
/// −c σ_c(t) = ε_sh(t) + ∫ J(t, τ) dσ_c(τ), c = A_c/(A_s E_s) (MC90 J = 1/E_ci(τ) + φ(t, τ)/E_ci), solved step
/// by step on `n` geometric steps with each stress increment at the mid-age of its step.
fn internally_restrained_steel(
    p: &CreepShrinkageParams,
    t: f64,
    ratio: f64,
    e_s: f64,
    n: usize,
) -> f64 {
    let c = ratio / e_s;
    let ts = p.t_shrinkage_start;
    let times: Vec<f64> = std::iter::once(ts)
        .chain((0..=n).map(|k| ts + 0.01 * ((t - ts) / 0.01).powf(k as f64 / n as f64)))
        .collect();
    let j =
        |t: f64, tau: f64| 1.0 / mc90::eci_at(p, tau) + creep_coefficient(p, t, tau) / mc90::eci(p);
    let (mut ages, mut steps) = (Vec::new(), Vec::new());
    let mut sigma = 0.0;
    for w in times.windows(2) {
        let tau = 0.5 * (w[0] + w[1]);
        let history: f64 = ages
            .iter()
            .zip(&steps)
            .map(|(&a, &d): (&f64, &f64)| j(w[1], a) * d)
            .sum();
        let d = -(shrinkage_strain(p, w[1]) + history + c * sigma) / (c + j(w[1], tau));
        ages.push(tau);
        steps.push(d);
        sigma += d;
    }
    -sigma * ratio
}

/// Issue 19 item 4, the steel before cracking of a member free to shorten: the reinforced
/// strip with its right end released, so the bar alone restrains the shrinkage (steel in
/// compression, concrete in tension, no crack at ρ = 1 %). Steel stress against the
/// step-by-step solution of the compatibility of bar and creeping concrete above; the
/// age-adjusted effective modulus (χ = 0.8, σ_s = E_s ε_sh/(1 + n_e ρ), n_e = E_s J_χ) is
/// printed for comparison.
#[test]
fn reinforced_free_strip_steel_takes_the_compatible_share_of_shrinkage() {
    let (fcm, rh, h0, ts) = STRIP_DATA;
    let p = CreepShrinkageParams::new(fcm, rh, h0, CementClass::N, ts);
    let ftm = 1.4e6 * (fcm / 10e6).powf(2.0 / 3.0);
    let (a_c, a_s, e_s) = (0.01, 1e-4, 200e9);
    let right = "[[supports]]\nname = \"right\"\nline = [[1.0, 0.0], [1.0, 0.1]]\nux = 0.0\n";
    let text = reinforced_strip(ftm).replace(right, "");
    assert!(!text.contains("name = \"right\""));
    let model = segfem::input::parse(&text, "free_strip.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut rows = StripRows::default();
    steps::run(&model, &mut rows).unwrap_or_else(|e| panic!("{e}"));
    let rows = rows.0;
    let last = rows.last().unwrap();
    let scale = internally_restrained_steel(&p, last.time, a_c / a_s, e_s, 100).abs();
    // The chain reproduces MC90 creep within ~1 %, the 60 log-spaced substeps add < 1 % and
    // the 100-step closed form < 0.5 %: 3 % of the final steel stress. Without creep the
    // steel stress would be E_s ε_sh/(1 + n ρ), ~11 % larger in magnitude at 3000 d.
    let mut worst: f64 = 0.0;
    for r in &rows[1..] {
        assert!(
            r.cracked.iter().all(|&c| c == 0),
            "no crack at t = {}",
            r.time
        );
        let want = internally_restrained_steel(&p, r.time, a_c / a_s, e_s, 100);
        for e in 0..4 {
            worst = worst.max((r.steel[e] - want).abs() / scale);
            // Free end: the bar's compression balances the concrete's tension.
            assert!((r.steel[e] * a_s + r.concrete[e] * a_c).abs() < 1e-3 * scale * a_s);
        }
        assert!(r.restraint.abs() < 1e-3 * scale * a_s);
    }
    let j_chi =
        1.0 / mc90::eci_at(&p, ts) + 0.8 * creep_coefficient(&p, last.time, ts) / mc90::eci(&p);
    let aaem = e_s * shrinkage_strain(&p, last.time) / (1.0 + e_s * j_chi * a_s / a_c);
    let elastic = e_s * shrinkage_strain(&p, last.time)
        / (1.0 + e_s / mc90::eci_at(&p, last.time) * a_s / a_c);
    eprintln!(
        "free reinforced strip at {:.0} d: σ_s FE {:.2} MPa, closed form {:.2} MPa (worst {worst:.4} of it over the history), AAEM χ = 0.8 {:.2} MPa, no creep {:.2} MPa; σ_c {:.3} MPa",
        last.time,
        last.steel[0] / 1e6,
        -scale / 1e6,
        aaem / 1e6,
        elastic / 1e6,
        last.concrete[0] / 1e6
    );
    assert!(worst < 0.03);
}
