//! Shear-critical beam OA1 of Vecchio & Shim (2004), no stirrups, through the engine
//! (docs/validation.md, "Shear beams"; data and sources in validation/beams/).

/// The beam bench of the `segfem` binary (not part of the library) and the panel bench
/// whose CSV reader it shares.
#[path = "../src/cli/beam_bench.rs"]
#[allow(dead_code)]
mod beam_bench;
#[path = "../src/cli/panel_bench.rs"]
#[allow(dead_code)]
mod panel_bench;

use beam_bench::{options, read_beams, run_beam, Beam, PLATE_INCREMENT};

/// The beam `id` of validation/beams/beams.csv.
fn beam(id: &str) -> Beam {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/beams/beams.csv");
    read_beams(&path)
        .unwrap()
        .into_iter()
        .find(|b| b.id == id)
        .unwrap_or_else(|| panic!("{id} not in beams.csv"))
}

/// The concrete keys of the bench's model option `name` (`beam_bench::options`).
fn option(name: &str) -> &'static str {
    options()
        .into_iter()
        .find(|o| o.0 == name)
        .unwrap_or_else(|| panic!("no bench option {name:?}"))
        .1
}

/// OA1 fails in diagonal tension at P_u = 332 kN (9.2 mm), the load falling suddenly. On
/// the coarse mesh (10 rows through the depth; both runs about 18 s of CPU in release):
///
/// * the two crack models bracket the measured peak — fixed cracks with shear retention
///   (aggregate interlock, VC93) carry stress across the inclined crack and over-estimate
///   it (stress locking), rotating cracks carry no shear on their faces and under-estimate
///   it (Rots 1988; Rots & Blaauwendraad 1989);
/// * both stay within 0.6–1.6 × P_u: a beam without its bars would fail at first flexural
///   cracking, below 0.3 P_u, and one with elastic uncracked concrete would not fail;
/// * the fixed-crack run ends more than 20 % below its peak (a brittle failure traced past
///   the peak, as in the test).
#[test]
fn oa1_peaks_bracket_the_test_and_the_failure_is_brittle() {
    let oa1 = &beam("OA1");
    let p_u = oa1.test.0;
    let fixed = run_beam(
        oa1,
        option("fixed, aggregate β, VC93"),
        10,
        -0.02,
        PLATE_INCREMENT,
    )
    .unwrap();
    let rot = run_beam(oa1, option("rotating, VC93"), 10, -0.02, PLATE_INCREMENT).unwrap();
    eprintln!(
        "OA1: fixed {:.1} kN (end {:.2} of peak, {:?}), rotating {:.1} kN ({:?}); test {:.0} kN",
        fixed.p_peak / 1e3,
        fixed.end_ratio,
        fixed.ultimate.as_ref().map(|u| &u.mode),
        rot.p_peak / 1e3,
        rot.ultimate.as_ref().map(|u| &u.mode),
        p_u / 1e3
    );
    assert!(
        rot.p_peak < p_u && p_u < fixed.p_peak,
        "rotating {:.0} kN, test {:.0} kN, fixed {:.0} kN",
        rot.p_peak / 1e3,
        p_u / 1e3,
        fixed.p_peak / 1e3
    );
    for r in [&fixed, &rot] {
        let ratio = p_u / r.p_peak;
        assert!((0.6..1.6).contains(&ratio), "test/predicted {ratio:.2}");
    }
    // Stress locking (docs/theory-concrete.md §5.5b), measured at the fixed-crack peak:
    // cracked points carry a principal tension well past f_tm at an angle of 15° or more to
    // their crack axes (3.6 f_tm measured; asserted > 1.5 f_tm: a run without locking
    // stays at f_tm up to the IMPL-EX overshoot of a few per cent).
    assert!(
        fixed.locking.max_ratio_inclined > 1.5,
        "{:?}",
        fixed.locking
    );
    assert!(
        fixed.end_ratio < 0.8,
        "end of run {:.2} of the peak",
        fixed.end_ratio
    );
}

/// B1 (D5 stirrups at 190 mm, shear-compression, P_u = 434 kN at 22.0 mm) with the default
/// model (fixed cracks, seed β, IMPL-EX as the RC example), coarse mesh (10 rows), at
/// converged plate increments (issue 42 item 5; about 30 s of CPU): pushed to 20 mm at 0.05
/// and 0.025 mm, the two peaks within 2 % of each other (measured 423.9 / 424.2 kN, 0.1 %;
/// the 0.2 mm bench figure, 431.5 kN, is 1.8 % above: docs/validation.md, "Converged plate
/// increments"), the converged peak within 10 % of P_u (the acceptance band for beams with
/// stirrups; measured test/predicted 1.02), and the run's verdict naming the concrete
/// crushed, as in the test. The 20-row mesh (416.0 kN, −1.9 %) is left to `segfem bench
/// --case beams`: minutes of CPU.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: 1,200 increments of a shear beam"
)]
fn b1_default_model_converged_in_the_increment_reaches_the_measured_peak_by_crushing() {
    let b1 = &beam("B1");
    let p_u = b1.test.0;
    let keys = option("fixed, seed β");
    let coarse = run_beam(b1, keys, 10, -0.02, 0.05e-3).unwrap();
    let fine = run_beam(b1, keys, 10, -0.02, 0.025e-3).unwrap();
    for r in [&coarse, &fine] {
        let u = r.ultimate.as_ref().expect("a verdict");
        eprintln!(
            "B1: {:.1} kN at {:.1} mm, {} {:?}; test {:.0} kN",
            r.p_peak / 1e3,
            r.deflection * 1e3,
            u.mode,
            u.events,
            p_u / 1e3
        );
        assert!(
            u.mode == "concrete crushing" || u.events.iter().any(|e| e.0 == "concrete crushing"),
            "{} {:?}",
            u.mode,
            u.events
        );
    }
    assert!(
        (coarse.p_peak - fine.p_peak).abs() < 0.02 * fine.p_peak,
        "peak {:.1} kN (0.05 mm) vs {:.1} kN (0.025 mm)",
        coarse.p_peak / 1e3,
        fine.p_peak / 1e3
    );
    assert!(
        (fine.p_peak / p_u - 1.0).abs() < 0.10,
        "peak {:.1} kN vs {:.0} kN",
        fine.p_peak / 1e3,
        p_u / 1e3
    );
}

/// OA1 with fixed cracks (seed β) and the Rankine tension cut-off
/// (`principal_stress_limit = "tensile_strength"`, docs/theory-concrete.md §5.5b), IMPL-EX
/// as in the bench, coarse mesh, about 12 s of CPU:
///
/// * no cracked point carries a principal tension above f_tm at an angle to its crack axes
///   (the cut-off's closed form, round-off 1e-9);
/// * the run reaches a limit point ("loss of equilibrium"), not a Newton stall: until
///   session 14 the cut-off returned its consistent tangent, whose symmetric part is
///   indefinite, and the run stopped at 319–366 kN on the rising branch ("no convergence");
/// * the peak, 409.8 kN measured (test/predicted 0.81), within 0.78–0.86: below the
///   default model's 457 kN at these increments (0.73; the cut-off must lower it) and within ±5 % of the
///   measured value (the mesh and the data fixed: a change of this size is a change of the
///   model, not round-off).
#[test]
fn oa1_rankine_cut_off_removes_stress_locking() {
    let oa1 = &beam("OA1");
    let keys = option("fixed, seed β, Rankine cut-off");
    let r = run_beam(oa1, keys, 10, -0.02, PLATE_INCREMENT).unwrap();
    eprintln!(
        "OA1 cut-off: {:.1} kN at {:.1} mm, {:?}; {:?}",
        r.p_peak / 1e3,
        r.deflection * 1e3,
        r.ultimate.as_ref().map(|u| (&u.mode, &u.events)),
        r.locking
    );
    assert!(
        r.locking.max_ratio_inclined <= 1.0 + 1e-9,
        "{:?}",
        r.locking
    );
    assert_eq!(
        r.ultimate.as_ref().map(|u| u.mode.as_str()),
        Some("loss of equilibrium")
    );
    let ratio = oa1.test.0 / r.p_peak;
    assert!((0.78..0.86).contains(&ratio), "test/predicted {ratio:.3}");
}

/// OA1 with the softening cut-off (`principal_stress_limit = "softening"`,
/// docs/theory-concrete.md §5.5b), IMPL-EX as in the bench, coarse mesh, about 15 s of CPU:
///
/// * no cracked point carries a principal tension above f_tm at an angle to its cracks (the
///   cap never exceeds f_tm; round-off 1e-9);
/// * a limit point ("loss of equilibrium"), the load falling at least 8 % past the peak
///   (12 % measured; the fixed cut-off's run stops within 2 % of its peak): the inclined
///   tension softens;
/// * the peak, 363.3 kN measured (test/predicted 0.914), within 0.88–0.95: below the fixed
///   cut-off's 409.8 kN (0.81; the softening must lower it) and within ±4 % of the measured
///   value (mesh and data fixed: a change of this size is a change of the model).
#[test]
fn oa1_softening_cut_off_softens_past_the_peak() {
    let oa1 = &beam("OA1");
    let keys = option("fixed, seed β, softening cut-off");
    let r = run_beam(oa1, keys, 10, -0.02, PLATE_INCREMENT).unwrap();
    eprintln!(
        "OA1 softening cut-off: {:.1} kN at {:.1} mm, end {:.3}, {:?}; {:?}",
        r.p_peak / 1e3,
        r.deflection * 1e3,
        r.end_ratio,
        r.ultimate.as_ref().map(|u| (&u.mode, &u.events)),
        r.locking
    );
    assert!(
        r.locking.max_ratio_inclined <= 1.0 + 1e-9,
        "{:?}",
        r.locking
    );
    assert_eq!(
        r.ultimate.as_ref().map(|u| u.mode.as_str()),
        Some("loss of equilibrium")
    );
    assert!(r.end_ratio < 0.92, "end {:.3} of the peak", r.end_ratio);
    let ratio = oa1.test.0 / r.p_peak;
    assert!((0.88..0.95).contains(&ratio), "test/predicted {ratio:.3}");
}

/// B1 (stirrups) with the Rankine cut-off, IMPL-EX, coarse mesh, about 13 s of CPU: until
/// session 14 Newton stalled at 258 kN (the cut-off's indefinite symmetrised tangent); now
/// the run reaches the limit point by crushing, as the test and the model without the
/// cut-off: peak within 10 % of P_u (the criterion; 426.0 kN measured, 1.02),
/// "loss of equilibrium" with concrete crushing among the events, and no cracked point
/// above f_tm at an angle to its cracks (round-off 1e-9).
#[test]
fn b1_rankine_cut_off_reaches_the_measured_peak_by_crushing() {
    let b1 = &beam("B1");
    let p_u = b1.test.0;
    let keys = option("fixed, seed β, Rankine cut-off");
    let r = run_beam(b1, keys, 10, -0.02, PLATE_INCREMENT).unwrap();
    let u = r.ultimate.as_ref().expect("a verdict");
    eprintln!(
        "B1 cut-off: {:.1} kN at {:.1} mm, {} {:?}; {:?}",
        r.p_peak / 1e3,
        r.deflection * 1e3,
        u.mode,
        u.events,
        r.locking
    );
    assert!(
        (r.p_peak / p_u - 1.0).abs() < 0.10,
        "peak {:.1} kN vs {:.0} kN",
        r.p_peak / 1e3,
        p_u / 1e3
    );
    assert_eq!(u.mode, "loss of equilibrium");
    assert!(
        u.events.iter().any(|e| e.0 == "concrete crushing"),
        "{:?}",
        u.events
    );
    assert!(
        r.locking.max_ratio_inclined <= 1.0 + 1e-9,
        "{:?}",
        r.locking
    );
}

/// The mean inclined crack spacing of the beams by the CEB-FIP MC90 formula
/// (`beam_bench::crack_spacing`) against a hand calculation from the data of beams.csv:
/// OA1 (d = 461.3 mm, x = 160.9 mm, h_ef = (h − x)/3 = 130.4 mm, ρ_ef = 6.04 %,
/// φ = 27.7 mm, s_x = 85.1 mm, no stirrups) s_45 = √2 s_x = 120.3 mm; B1 (its M25 layer
/// with E_s = 210 GPa: x = 181.2 mm, ρ_ef = 8.48 %, s_x = 60.6 mm; D5 stirrups, φ = 6.40 mm,
/// ρ_w = 0.148 %, s_y = 801 mm) s_45 = 79.6 mm. Tolerance 0.1 mm (the hand values' rounding).
#[test]
fn crack_spacing_of_the_beams_follows_mc90() {
    use crate::beam_bench::crack_spacing;
    for (id, want) in [("OA1", 0.1203), ("B1", 0.0796)] {
        let s = crack_spacing(&beam(id));
        assert!((s - want).abs() < 1e-4, "{id}: s_rm = {s} m, hand {want} m");
    }
}

/// OA1 with the default model (fixed cracks, seed β, IMPL-EX) at converged plate increments
/// (issue 42 item 5; docs/validation.md "Converged plate increments" and "Error-controlled
/// increments"), coarse mesh (10 rows), about 20 s of CPU in release for both runs:
///
/// * the peak at 0.05 and 0.025 mm plate increments agrees within 2 % (issue 38's
///   objectivity criterion; measured 370.9 / 374.6 kN, 1.0 %; at the bench's 0.2 mm it is
///   457.1 kN, 22 % above: IMPL-EX's first-order error in the increment);
/// * the failure is brittle as in the test: a limit point ("loss of equilibrium") and the
///   run ending below 0.8 of its peak (measured 0.65);
/// * **a known deviation**: the converged peak misses docs/validation.md's acceptance band
///   (|P/P_test − 1| ≤ 10 %) by over-estimating it, +12.8 % measured. Fixed cracks lock
///   stress across the inclined crack (docs/theory-concrete.md §5.5b), so the model must be
///   above the test; asserted between P_test and 1.15 P_test, so that both an unexplained
///   improvement (into the band) and a regression fail and are looked at.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: 1,200 increments of a shear beam"
)]
fn oa1_default_model_converged_in_the_increment_a_known_deviation_above_the_band() {
    let oa1 = &beam("OA1");
    let p_u = oa1.test.0;
    let keys = option("fixed, seed β");
    let coarse = run_beam(oa1, keys, 10, -0.02, 0.05e-3).unwrap();
    let fine = run_beam(oa1, keys, 10, -0.02, 0.025e-3).unwrap();
    eprintln!(
        "OA1 default: {:.1} kN (0.05 mm), {:.1} kN (0.025 mm, end {:.2} of peak, {:?}); test {:.0} kN",
        coarse.p_peak / 1e3,
        fine.p_peak / 1e3,
        fine.end_ratio,
        fine.ultimate.as_ref().map(|u| &u.mode),
        p_u / 1e3
    );
    assert!(
        (coarse.p_peak - fine.p_peak).abs() < 0.02 * fine.p_peak,
        "peak {:.1} kN (0.05 mm) vs {:.1} kN (0.025 mm)",
        coarse.p_peak / 1e3,
        fine.p_peak / 1e3
    );
    for r in [&coarse, &fine] {
        let u = r.ultimate.as_ref().expect("a verdict");
        assert_eq!(u.mode, "loss of equilibrium");
        assert!(r.end_ratio < 0.8, "end {:.2} of the peak", r.end_ratio);
    }
    let ratio = fine.p_peak / p_u;
    assert!(
        (1.0..1.15).contains(&ratio),
        "P/P_test = {ratio:.3} (known deviation: +12.8 % measured)"
    );
}
