//! Losses of bonded tendons through the engine and the monitors (docs/theory-prestress.md,
//! "Losses and relaxation of bonded tendons"): relaxation of a grouted tendon against the
//! MC90 function, creep of the concrete at the tendon against the age-adjusted effective
//! modulus closed form, and the elastic shortening of pre-tensioned tendons against n·σ_c.
//! Run with `cargo test --release --test bonded_losses`.

mod common;

// MC90 references from the test's own implementation (tests/common/mc90.rs).
use common::mc90::{compliance, relaxation_loss};
use segfem::analysis::steps;
use segfem::materials::mc90_time::{CementClass, CreepShrinkageParams, RelaxationClass};
use segfem::model::Model;
use segfem::results::recorder::Recorder;

const EP: f64 = 195e9;
const AP: f64 = 1e-3;
const FPTK: f64 = 1860e6;
const S0: f64 = 1300e6;
/// Prism 4 m × 0.4 m, 0.3 m thick: A_c = 0.12 m².
const AC: f64 = 0.12;

/// Concentric prism free to shorten and to contract laterally (left edge ux = 0, bottom-left
/// corner uy = 0), `material` lines, one tendon along the centroid (`tendon` lines), the
/// monitors of the tests at midspan, then `steps`.
fn prism(material: &str, tendon: &str, steps: &str) -> String {
    format!(
        r#"
[[materials]]
name = "c"
{material}
nu = 0.2
[[regions]]
name = "r"
material = "c"
thickness = 0.3
[mesh]
type = "banded"
length = 4.0
nx = 16
element = "Q8"
bands = [{{ region = "r", depth = 0.4, rows = 2 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.4]]
ux = 0.0
[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0
[[tendons]]
name = "T"
points = [[0.0, 0.2], [4.0, 0.2]]
area = {AP}
Ep = {EP}
fptk = {FPTK}
{tendon}
[[monitors]]
name = "stress"
kind = "tendon_stress"
tendon = "T"
point = [2.0, 0.2]
[[monitors]]
name = "force"
kind = "tendon_force"
tendon = "T"
point = [2.0, 0.2]
[[monitors]]
name = "loss"
kind = "tendon_loss"
tendon = "T"
point = [2.0, 0.2]
[[monitors]]
name = "elastic"
kind = "tendon_loss_elastic"
tendon = "T"
point = [2.0, 0.2]
[[monitors]]
name = "creep"
kind = "tendon_loss_creep"
tendon = "T"
point = [2.0, 0.2]
[[monitors]]
name = "relaxation"
kind = "tendon_loss_relaxation"
tendon = "T"
point = [2.0, 0.2]
[[monitors]]
name = "mean_loss"
kind = "tendon_loss"
tendon = "T"
[[monitors]]
name = "u1"
kind = "displacement"
point = [1.0, 0.2]
component = "x"
[[monitors]]
name = "u3"
kind = "displacement"
point = [3.0, 0.2]
component = "x"
{steps}
"#
    )
}

/// Post-tensioned, no friction, stressed at the start and grouted in the second step.
const POST: &str = r#"kind = "bonded"
jacking_stress = 1300e6
jacking = "start"
friction = 0.0
wobble = 0.0
grouted_in_step = "grout"
relaxation_class = 2"#;

const POST_STEPS: &str = r#"
[[steps]]
name = "stress"
kind = "load"
[[steps]]
name = "grout"
kind = "load"
[[steps]]
name = "creep"
kind = "time"
from = 28.0
duration = 1e4
"#;

/// Monitor rows (time [d], values in monitor order) of every converged increment.
fn run(text: &str, tag: &str) -> (Model, Vec<(f64, Vec<f64>)>) {
    let model = segfem::input::parse(text, "bonded.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let dir = std::env::temp_dir().join(format!("segfem-bonded-{tag}-{}", std::process::id()));
    let rows = {
        let mut rec = Recorder::new(&model, dir.clone(), false).unwrap();
        steps::run(&model, &mut rec).unwrap_or_else(|e| panic!("{e}"));
        rec.rows
            .iter()
            .map(|r| (r.time, r.monitors.clone()))
            .collect()
    };
    let _ = std::fs::remove_dir_all(dir);
    (model, rows)
}

/// Every row: force = A_p σ, the parts add up to the total, σ = σ_0 − total loss.
fn check_book(rows: &[(f64, Vec<f64>)], s0: f64) {
    for (t, m) in rows {
        assert!((m[1] - AP * m[0]).abs() < 1e-9 * AP * s0, "t = {t}: {m:?}");
        assert!(
            (m[3] + m[4] + m[5] - m[2]).abs() < 1e-6 * s0,
            "t = {t}: {m:?}"
        );
        assert!((s0 - m[2] - m[0]).abs() < 1e-6 * s0, "t = {t}: {m:?}");
    }
}

/// A grouted tendon at 0.7 f_ptk in a practically rigid elastic prism (E = 1e16 Pa: the
/// concrete's shortening is ~1e-8 of the tendon strain) relaxes at constant strain, so its
/// stress must follow the MC90 relaxation ρ(t) σ_0 of class 2 (the same check as the
/// external tendons'): within 0.1 % of σ_0 everywhere and 3 % of the loss from 1 d on (the
/// chain's fit of the MC90 power law is 1.6 % worst for class 2 at 0.7, theory-time.md §3).
/// The whole loss is booked as relaxation; the monitors agree with each other.
#[test]
fn grouted_tendon_relaxes_as_mc90_at_constant_strain() {
    let text = prism("kind = \"elastic\"\nE = 1e16", POST, POST_STEPS);
    let (_, rows) = run(&text, "relax");
    check_book(&rows, S0);
    let mut worst: f64 = 0.0;
    for (t, m) in &rows[2..] {
        let d = t - 28.0;
        let want = relaxation_loss(RelaxationClass::Class2, S0 / FPTK, d) * S0;
        assert!(
            (m[2] - want).abs() < 1e-3 * S0,
            "t = {d}: {} vs {want}",
            m[2]
        );
        assert!((m[5] - m[2]).abs() < 1e-3 * m[2].max(1e3), "{m:?}");
        if d >= 1.0 {
            worst = worst.max((m[5] / want - 1.0).abs());
        }
    }
    eprintln!("bonded relaxation: worst relative error from 1 d: {worst:.4}");
    assert!(worst < 0.03);
    let last = &rows.last().unwrap().1;
    // Uniform tendon: the mean loss is the midspan loss.
    assert!((last[6] - last[2]).abs() < 1e-3 * last[2], "{last:?}");
}

/// A grouted tendon in a creeping concentric prism (MC90 fcm 45 MPa, RH 70 %, h0 0.2 m,
/// cement N, cast on day 0, stressed and grouted on day 28, no shrinkage), 1e4 days, class 2
/// relaxation.
///
/// 1. The creep part of the loss is E_p times the concrete's shortening at the tendon during
///    the time step, measured from the concrete's displacements between x = 1 and 3 m (the
///    uniform zone): within 3 %. The bond makes the steel strain follow the concrete
///    exactly (without relaxation the two agree to 1e-5); what remains is the interaction
///    the split books with creep: the chain also relaxes the strain lost by creep, ≈ 2 %
///    of the creep part here.
/// 2. The total against the age-adjusted effective modulus closed form (Trost–Bažant): with
///    compatibility Δε_p = Δε_c, equilibrium A_p Δσ_p + A_c Δσ_c = 0,
///
///      loss = [E_p |σ_c0| ΔJ + R] / [1 + E_p ρ (J_0 + χ ΔJ)],
///
///    ΔJ = J(t, t_0) − J_0, ρ = A_p/A_c, χ = 0.8, R the FE's relaxation part (checked in 3),
///    J(t, t_0) of MC90 and J_0 the model's instantaneous compliance measured at stressing
///    (the chain's instantaneous modulus at 28 d is below MC90's E_ci(t_0), see the note in
///    docs/validation.md). Within 2 %: χ from 0.6 to 0.9 moves the closed form by ±1 %
///    (E_p ρ J_0 ≈ 0.05), the chain reproduces J(t, t_0) within 0.6 % and the default
///    substeps add < 0.7 % (theory-time.md §2).
/// 3. The relaxation part lies below the constant-strain MC90 value ρ(t) σ_0 (the tendon
///    shortens as the concrete creeps and the linear chain relaxes the lost strain no more)
///    and above 80 % of it (the shortening is ~7 % of the strain).
///
/// 1–3 check the model against itself (its own J_0 and relaxation). 4 is the independent
/// reference: MC90 compliance, the code relaxation and EC2's combined-loss formula, with the
/// measured difference asserted as a known-deviation band.
#[test]
fn grouted_tendon_loses_concrete_creep_and_relaxation() {
    let material = "kind = \"elastic_creep\"\nfcm = 45e6\nrh = 0.70\nh0 = 0.200\ncement = \"N\"\nshrinkage = false\ndrying_start = 7.0";
    let text = prism(material, POST, POST_STEPS);
    let (_, rows) = run(&text, "creep");
    check_book(&rows, S0);
    let p = CreepShrinkageParams::new(45e6, 0.70, 0.200, CementClass::N, 7.0);
    let (t0, t) = (28.0, 28.0 + 1e4);
    let rho = AP / AC;
    let sc0 = S0 * rho;
    let strain = |m: &[f64]| (m[8] - m[7]) / 2.0;
    let j0 = -strain(&rows[0].1) / sc0;
    let dj = compliance(&p, t, t0) - j0;
    let last = &rows.last().unwrap().1;
    let d_eps = strain(last) - strain(&rows[1].1);
    let r = last[5];
    let closed = (EP * sc0 * dj + r) / (1.0 + EP * rho * (j0 + 0.8 * dj));
    let code = relaxation_loss(RelaxationClass::Class2, S0 / FPTK, t - t0) * S0;
    eprintln!(
        "creep + relaxation: FE loss {:.4e} (elastic {:.3e}, creep {:.4e}, relaxation {:.4e}); E_p Δε_c {:.4e}; closed form {closed:.4e}; MC90 relaxation at constant strain {code:.4e}; J0 {j0:.4e} (MC90 {:.4e})",
        last[2], last[3], last[4], last[5], -EP * d_eps, compliance(&p, t0, t0)
    );
    // Nothing lost before the time step: the tendon is held at lock-off until grouting.
    assert!(rows[1].1[2].abs() < 1e-6 * S0, "{:?}", rows[1]);
    assert!(
        (last[4] / (-EP * d_eps) - 1.0).abs() < 0.03,
        "{} vs {}",
        last[4],
        -EP * d_eps
    );
    assert!(
        (last[2] / closed - 1.0).abs() < 0.02,
        "{} vs {closed}",
        last[2]
    );
    assert!(r < code && r > 0.8 * code, "relaxation {r} vs {code}");

    // 4. Independent reference: the age-adjusted effective modulus with MC90's own
    //    compliance, J_0 = 1/E_ci(t_0) and J(t, t_0), and the code relaxation as EC2
    //    5.10.6 (5.46) takes it, 0.8 ρ(t) σ_0 (reduced for the falling strain), χ = 0.8:
    //      loss = [E_p σ_c0 (J − J_0) + 0.8 ρ σ_0] / [1 + E_p ρ_s (J_0 + χ (J − J_0))].
    //    Nothing here comes from the run.
    let j0_code = compliance(&p, t0, t0);
    let dj_code = compliance(&p, t, t0) - j0_code;
    let den = 1.0 + EP * rho * (j0_code + 0.8 * dj_code);
    let reference = (EP * sc0 * dj_code + 0.8 * code) / den;
    let creep_code = EP * sc0 * dj_code / den;
    eprintln!(
        "independent reference {reference:.4e} (creep {creep_code:.4e}, relaxation {:.4e}); FE {:.4e}: {:+.2} %",
        0.8 * code / den,
        last[2],
        100.0 * (last[2] / reference - 1.0)
    );
    // Known deviation, measured +2.6 % (band +1 … +4 %, so that a regression and an
    // unexplained improvement both fail). Its two causes pull apart: the chain's
    // instantaneous compliance at 28 d is 14 % above MC90's 1/E_ci(t_0) (the chain cannot
    // hold MC90's creep of the first hours, docs/theory-time.md) while J(t, t_0) agrees at
    // long durations, so less creep follows the stressing (≈ −8 % of the creep part); and
    // the chain relaxes the steel at 96 % of the constant-strain value (checked in 3) where
    // EC2 takes 80 % (+9 % of the relaxation part).
    let dev = last[2] / reference - 1.0;
    assert!(
        (0.01..0.04).contains(&dev),
        "total {:.4e} vs reference {reference:.4e}: {:+.2} % (known deviation band +1 … +4 %)",
        last[2],
        100.0 * dev
    );
}

/// Elastic shortening of pre-tensioned tendons at release, computed by the model: a tendon
/// at σ_0 in the bed, bonded from the start, loses Δσ = n σ_c,p with n = E_p/E_c and σ_c,p
/// the concrete stress at the tendon level from the force after the loss. On the transformed
/// section (A_c gross concrete, the steel added with n) Δσ = n σ_0 A_p (1/A_t + e²/I_t)
/// with A_t = A_c + n A_p, I_t about the transformed centroid, e the tendon's eccentricity
/// from it. Concentric (e = 0) and eccentric (e = 0.1 m below the centroid) prisms, elastic
/// concrete, no supports that restrain bending; at midspan within 0.5 % (plane sections hold
/// 2.5 depths from the ends; Q8 in pure bending is exact to ~0.1 %).
#[test]
fn pretensioned_elastic_shortening_is_n_sigma_c() {
    let ec = 35e9;
    let n = EP / ec;
    for y in [0.2, 0.1] {
        let tendon = "kind = \"pretensioned\"\ninitial_stress = 1300e6";
        let text = prism(
            &format!("kind = \"elastic\"\nE = {ec}"),
            tendon,
            "[[steps]]\nname = \"release\"\nkind = \"load\"\n",
        )
        .replace(
            "[[0.0, 0.2], [4.0, 0.2]]",
            &format!("[[0.0, {y}], [4.0, {y}]]"),
        )
        .replace("point = [2.0, 0.2]", &format!("point = [2.0, {y}]"));
        let (model, rows) = run(&text, "pre");
        assert!(model.bars[0].post_tension.is_none() && model.bars[0].initial_stress == S0);
        let m = &rows[0].1;
        check_book(&rows, S0);
        // Transformed section of the 0.3 × 0.4 m prism with the steel at y.
        let (b, h) = (0.3, 0.4);
        let at = AC + n * AP;
        let yt = (AC * 0.5 * h + n * AP * y) / at;
        let it = b * h.powi(3) / 12.0 + AC * (0.5 * h - yt).powi(2) + n * AP * (y - yt).powi(2);
        let e = y - yt;
        let want = n * S0 * AP * (1.0 / at + e * e / it);
        eprintln!(
            "pre-tensioned, y = {y}: loss {:.5e} vs n σ_c {want:.5e}",
            m[3]
        );
        assert!((m[3] / want - 1.0).abs() < 0.005, "{} vs {want}", m[3]);
        assert!((m[2] - m[3]).abs() < 1e-9 * S0);
    }
}
