//! Membrane panels in shear through the engine: closed forms of the rotating-crack truss
//! and of strut crushing with compression softening (docs/validation.md, "Membrane
//! panels").

/// The panel bench of the `segfem` binary (not part of the library).
#[path = "../src/cli/panel_bench.rs"]
#[allow(dead_code)]
mod panel_bench;

use panel_bench::{run_panel, Panel};

fn panel(rho: [f64; 2], fcm: f64) -> Panel {
    Panel {
        id: "closed form".into(),
        lab: String::new(),
        thickness: 0.07,
        size: 1.0,
        fcm,
        rho,
        fy: [400e6; 2],
        es: [200e9; 2],
        normal: [0.0; 2],
        agg: 0.016,
        v_test: f64::NAN,
    }
}

/// Unequal reinforcement ρx = 2 %, ρy = 1 %, f_y = 400 MPa, C30, crack band (a 1 m element
/// keeps no tension across its cracks): the rotating cracks follow the strut onto the
/// stronger steel after the weaker one yields, and the panel reaches the rotating-crack
/// truss strength v_u = √(ρx ρy) f_y = 5.657 MPa with both layers yielded. Tolerance 1 %:
/// the truss neglects the concrete's residual tension (crack band, < 1e-3 f_tm at the
/// strains at failure) and the arc length may stop just short of the plateau.
#[test]
fn unequally_reinforced_panel_reaches_the_rotating_truss_strength() {
    let p = panel([0.02, 0.01], 30e6);
    let keys = "crack_model = \"rotating\"\ntension_softening = \"crack_band\"\n";
    let r = run_panel(&p, keys, 1).unwrap();
    let v_u = (0.02_f64 * 0.01).sqrt() * 400e6;
    eprintln!("rotating: v = {:.4e}, {}", r.v_peak, r.mode);
    assert!(
        (r.v_peak - v_u).abs() < 0.01 * v_u,
        "peak {:.4e} vs √(ρxρy) f_y = {v_u:.4e} ({})",
        r.v_peak,
        r.mode
    );
    assert!(
        r.steel_at_peak.iter().all(|s| *s >= 0.999),
        "{:?}",
        r.steel_at_peak
    );
}

/// Peak shear of an equally reinforced (ρ) panel whose steel stays elastic, with rotating
/// cracks and Vecchio–Collins compression softening, in closed form: the strut stays at
/// 45°, σ2 = −2v, ρ σ_s = v, ε_x = ε_y = v/(ρ E_s), ε1 = 2v/(ρ E_s) − ε2 and
/// 2v = β(ε1) σ_c(x), x = −ε2/β(ε1) (no concrete tension). For each curve strain x the
/// fixed point β = β(β σ_c/(ρ E_s) + β x) is found by iteration (a contraction: |dβ/dε1|
/// (σ_c/(ρE_s) + x) < 0.3 here);
/// the peak is the largest v over a fine x grid.
///
/// Every function here is written out from its source, not taken from the library (the code
/// under test): σ_c is the MC90 uniaxial curve (CEB-FIP MC90 eq. 2.1-26)
/// σ_c = f_cm (k η − η²)/(1 + (k − 2) η), η = x/ε_c1, ε_c1 = 0.0022, k = E_ci ε_c1/f_cm,
/// E_ci = 21 500 MPa (f_cm/10 MPa)^⅓ (eq. 2.1-16); β = 1/(1 + C_d), C_d = 0.27 (ε1/ε_c1 −
/// 0.37) ≥ 0 (Vecchio & Collins 1993, J. Struct. Eng. 119(12), strength-and-strain form),
/// floored at β_min = 0.4. The grid stops at 1.5 ε_c1: past ε_c1 both σ_c and β fall, so the
/// peak lies below ε_c1, well inside the ascending branch where the MC90 formula holds.
fn crushing_peak(fcm: f64, rho: f64, es: f64) -> f64 {
    let eps_c1 = 0.0022;
    let eci = 21_500e6 * (fcm / 10e6).powf(1.0 / 3.0);
    let k = eci * eps_c1 / fcm;
    let sigma_c = |x: f64| {
        let eta = x / eps_c1;
        fcm * (k * eta - eta * eta) / (1.0 + (k - 2.0) * eta)
    };
    let beta = |eps1: f64| {
        let cd = (0.27 * (eps1 / eps_c1 - 0.37)).max(0.0);
        (1.0 / (1.0 + cd)).max(0.4)
    };
    let mut best: f64 = 0.0;
    for i in 1..=6000 {
        let x = 1.5 * eps_c1 * i as f64 / 6000.0;
        let s = sigma_c(x);
        let mut b = 1.0;
        for _ in 0..200 {
            b = beta(b * s / (rho * es) + b * x);
        }
        best = best.max(0.5 * b * s);
    }
    best
}

/// Over-reinforced panel (ρx = ρy = 5 %, ρ f_y = 20 MPa, C30): with compression softening
/// the strut crushes before the steel yields, at the closed-form peak of
/// [`crushing_peak`] (tolerance 0.3 %, was 1 % (docs/validation.md, tolerance changes): the
/// arc length samples the peak and the closed form neglects the crack-band tension; measured
/// 1.1021e7 against 1.1021e7 (< 1e-4), while a 5 % error in the Vecchio–Collins coefficient
/// 0.27 moves the peak by 1 %), well below the f_cm/2 = 15 MPa of the unsoftened
/// strut; without compression softening the peak is f_cm/2 (1 %).
#[test]
fn over_reinforced_panel_fails_by_strut_crushing_with_compression_softening() {
    let p = panel([0.05, 0.05], 30e6);
    let want = crushing_peak(30e6, 0.05, 200e9);
    let keys = "crack_model = \"rotating\"\ntension_softening = \"crack_band\"\n";
    let soft = format!("{keys}compression_reduction = \"vecchio_collins_1993\"\n");
    let r = run_panel(&p, &soft, 1).unwrap();
    eprintln!(
        "VC93: v = {:.4e} (closed form {want:.4e}), {}",
        r.v_peak, r.mode
    );
    assert!(
        (r.v_peak - want).abs() < 0.003 * want,
        "peak {:.4e} vs closed form {want:.4e}",
        r.v_peak
    );
    assert!(
        r.steel_at_peak.iter().all(|s| *s < 1.0),
        "{:?}",
        r.steel_at_peak
    );
    assert!(r.mode.contains("crushing"), "{}", r.mode);
    assert!(want < 0.9 * 15e6, "softening must matter here: {want}");
    let plain = run_panel(&p, keys, 1).unwrap();
    eprintln!("no softening: v = {:.4e}, {}", plain.v_peak, plain.mode);
    assert!(
        (plain.v_peak - 15e6).abs() < 0.01 * 15e6,
        "{:.4e}",
        plain.v_peak
    );
}

/// Mesh objectivity of the panel (issue item 5): the unequally reinforced panel and the
/// over-reinforced softened panel give the same peak on 1 × 1 and 4 × 4 meshes within 1 %
/// (a uniform state: a difference would come from a spurious localisation or from the
/// crack band's element size entering the peak).
#[test]
fn panel_peaks_do_not_depend_on_the_mesh() {
    let keys = "crack_model = \"rotating\"\ntension_softening = \"crack_band\"\n";
    let soft = format!("{keys}compression_reduction = \"vecchio_collins_1993\"\n");
    for (rho, k) in [([0.02, 0.01], keys.to_string()), ([0.05, 0.05], soft)] {
        let p = panel(rho, 30e6);
        let a = run_panel(&p, &k, 1).unwrap().v_peak;
        let b = run_panel(&p, &k, 4).unwrap().v_peak;
        eprintln!("ρ = {rho:?}: 1×1 {a:.4e}, 4×4 {b:.4e}");
        assert!((a - b).abs() < 0.01 * a, "1×1 {a:.4e} vs 4×4 {b:.4e}");
    }
}

/// Known deviation: the same unequally reinforced panel (ρx = 2 %, ρy = 1 %) with the fixed
/// crack and the seed's shear retention (the default crack model). The 45° crack cannot let
/// its strut turn onto the stronger x steel, so after the weak y layer yields (the 45° truss
/// gives ρy f_y = 4.0 MPa) the panel carries little more, well below the rotating-crack truss
/// v_u = √(ρx ρy) f_y = 5.657 MPa. Asserted: the peak lies above ρy f_y (the weak layer
/// yields, the truss holds until then) and inside the measured band 4.0 … 4.6 MPa (≈ 20 %
/// below v_u), so that a regression and an unexplained improvement both fail
/// (docs/validation.md, "Concrete, bars and path following").
#[test]
fn fixed_crack_on_the_unequal_panel_stalls_below_the_rotating_truss_a_known_deviation() {
    let p = panel([0.02, 0.01], 30e6);
    let r = run_panel(&p, "tension_softening = \"crack_band\"\n", 1).unwrap();
    let v_u = (0.02_f64 * 0.01).sqrt() * 400e6;
    let v_weak = 0.01 * 400e6;
    eprintln!(
        "fixed, seed β: v = {:.4e} ({:.3} of v_u), {}; steel {:?}",
        r.v_peak,
        r.v_peak / v_u,
        r.mode,
        r.steel_at_peak
    );
    // The weak layer yields at the peak (its strain over the yield strain ≥ 1, 0.1 % for
    // the increment that reaches it).
    assert!(r.steel_at_peak[1] >= 0.999, "{:?}", r.steel_at_peak);
    // Known-deviation band (measured, see the doc comment).
    assert!(
        r.v_peak > v_weak && r.v_peak < 4.6e6,
        "peak {:.4e} outside the known band 4.0 … 4.6 MPa (v_u = {v_u:.4e})",
        r.v_peak
    );
}

/// The PV panel series (validation/panels/panels.csv, 23 panels with a measured strength,
/// one element each) under the option recommended for membranes (rotating cracks with
/// Vecchio–Collins 1993 compression softening) against the seed's model (fixed cracks,
/// seed β). A **known deviation** (docs/validation.md, "Panel series"): the target
/// (mean test/predicted 1.00 ± 0.05, COV < 10 %) is not met — measured mean 0.957 and COV
/// 15.6 % (scatter from PV2, PV12, PV23/PV25; the recalled strengths are unverified: three
/// searches found no citable copy, validation/panels/sources.md; a hand MCFT solution of
/// the symmetric panels gives the same PV23/PV25 under-prediction, so it is not a numerical
/// artefact). Re-measured on 2026-11-23: unchanged. The
/// bands (mean 0.93–0.98, COV 14–17 %) are the measured values with the round-off of one
/// more or less increment at a peak, so that a regression and an unexplained improvement
/// both fail; and the rotating option must scatter less than the seed's model (26.7 %),
/// whose fixed cracks stall near ρ_weak f_y on the unequally reinforced panels.
///
/// **Change detector, not validation** (issue 42; docs/validation.md, "Change detectors"):
/// the mean and COV bands are this program's own measurement on strengths recalled, not
/// checked against the paper; every one of the file's 23 panels with a measured strength
/// must take part (the file, not a run, fixes that count).
#[test]
fn panel_series_change_detector() {
    use crate::panel_bench::{mean_cov, options, read_panels};
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/panels/panels.csv");
    let panels: Vec<Panel> = read_panels(&path)
        .unwrap()
        .into_iter()
        .filter(|p| p.v_test.is_finite())
        .collect();
    assert_eq!(
        panels.len(),
        23,
        "panels with a measured strength in panels.csv"
    );
    // Every row names its laboratory (the `series` column), for the per-lab statistics.
    assert!(
        panels.iter().all(|p| !p.lab.is_empty()),
        "a panel without its series"
    );
    let opts = options();
    let key = |name: &str| opts.iter().find(|o| o.0 == name).unwrap().1;
    let ratios = |keys: &str| -> Vec<f64> {
        panels
            .iter()
            .map(|p| p.v_test / run_panel(p, keys, 1).unwrap().v_peak)
            .collect()
    };
    let (m_rot, c_rot) = mean_cov(&ratios(key("rotating, VC93")));
    let (m_fix, c_fix) = mean_cov(&ratios(key("fixed, seed β")));
    eprintln!(
        "rotating VC93: mean {m_rot:.3}, COV {c_rot:.3}; fixed seed β: {m_fix:.3}, {c_fix:.3}"
    );
    assert!((0.93..0.98).contains(&m_rot), "mean {m_rot:.3}");
    assert!((0.14..0.17).contains(&c_rot), "COV {c_rot:.3}");
    assert!(c_rot < c_fix, "COV rotating {c_rot:.3}, fixed {c_fix:.3}");
}
