//! The seed's validation beam (docs/validation.md, "The seed beam"): a 7.2 m dry-jointed segmental
//! box beam with one external tendon, from the bundled example. Checks the behaviour the seed
//! reports (joints closed at service load, first opening between 56 and 70 kN, tendon stress rising
//! faster once joints open) and compares deflections and the largest opening with the
//! seed's computed values; then the run on to failure against statics of the opened joint.

/// The benchmark cases of the `segfem` binary (not part of the library); this test runs one.
#[path = "../src/cli/bench.rs"]
#[allow(dead_code)]
mod bench;

mod common;

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::results::joints::summarise;

/// One row per converged increment: Q [kN], midspan deflection [m], tendon stress [Pa],
/// largest opening [m], all joint points closed and compressed.
#[derive(Default)]
struct Rows(Vec<Row>);

/// Q, deflection, tendon stress, opening, all closed (see [`Rows`]).
type Row = (f64, f64, f64, f64, bool);

impl Observer for Rows {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        // Load-controlled steps only (up to Q = 140 kN, the seed's table); the example's
        // step on to failure is checked by `seed_beam_example_fails_by_tendon_yield`.
        if s.step > 2 {
            return Ok(());
        }
        let m = s.system.model;
        let mid = m
            .nodes
            .iter()
            .position(|p| (p[0] - 3.6).abs() < 1e-9 && p[1].abs() < 1e-9)
            .expect("midspan soffit node");
        let stress = s.system.families.tendons.states.committed[0]
            .as_ref()
            .map(|t| t.stresses()[1])
            .unwrap_or(0.0);
        let mut open = 0.0f64;
        let mut compressed = true;
        for j in 0..m.joints.len() {
            let sm = summarise(s.system, j);
            open = open.max(sm.max_opening);
            compressed &= sm.profile.iter().all(|p| p.closed && p.normal_stress > 0.0);
        }
        self.0.push((
            s.factors[1],
            s.system.displacements()[2 * mid + 1],
            stress,
            open,
            compressed,
        ));
        Ok(())
    }
}

fn at(rows: &[(f64, f64, f64, f64, bool)], q: f64) -> (f64, f64, f64, f64, bool) {
    *rows
        .iter()
        .min_by(|a, b| (a.0 - q).abs().total_cmp(&(b.0 - q).abs()))
        .unwrap()
}

#[test]
fn seed_beam_behaves_as_the_seed_reports() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/seed-beam-elastic.toml"
    ))
    .unwrap();
    let model = segfem::input::parse(&text, "seed-beam.toml").unwrap().model;
    let mut rows = Rows::default();
    steps::run(&model, &mut rows).unwrap();
    let r = &rows.0;
    let u0 = r[0].1; // after self weight and prestress (Q = 0)
                     // Service load: every joint closed with compression over its whole depth.
    let s56 = at(r, 56.0);
    assert!(
        (s56.0 - 56.0).abs() < 1e-9 && s56.4,
        "joints must be closed and compressed at Q = 56 kN"
    );
    // Elastic deflection from Q = 56 kN against the hand value of docs/validation.md "The seed
    // beam" (1.7 mm, beam theory without shear deformation: the FE value is a few per cent larger).
    let d56 = u0 - s56.1;
    assert!(
        (d56 - 1.7e-3).abs() < 0.1 * 1.7e-3,
        "deflection at 56 kN: {d56}"
    );
    // A joint open by Q = 70 kN.
    assert!(at(r, 70.0).3 > 0.0, "a joint must be open at Q = 70 kN");
    // Tendon stress grows markedly faster once the joints open.
    let rate = |a: f64, b: f64| (at(r, b).2 - at(r, a).2) / (b - a);
    assert!(
        rate(100.0, 140.0) > 10.0 * rate(14.0, 56.0),
        "{} vs {}",
        rate(100.0, 140.0),
        rate(14.0, 56.0)
    );
    // Deflections at every reference load: see
    // `seed_beam_deflections_change_detector`.
    let open140 = at(r, 140.0).3 * 1e3;
    assert!(
        ((open140 - 6.0) / 6.0).abs() < 0.25,
        "largest opening at 140 kN: {open140:.2} mm vs 6 mm"
    );
}

/// The `seed-beam` example (MC90 concrete of f_cm = 45 MPa, IMPL-EX cracking, the tendon's
/// anchors on their default 0.17 m anchor plates, the jacks on 0.2 m bearings, the supports
/// on 0.2 m bearings, program solver defaults) continued by arc length to L/60: the tendon
/// yields (0.9 f_ptk) with no concrete point crushed, and the peak load follows from
/// statics of the opened midspan joint, M_u = T_y (d_p − a/2) with the tendon at
/// d_p = 0.50 m below the top (held at the deviators), a = T_y/(0.85 f_cm b) in the 1.20 m
/// top flange, less the self-weight moment (25 kN/m³ on the 0.27 m² section, span 7.2 m):
/// Q_u = (M_u − M_sw)/2.4 m = 177.1 kN. Band 5 %: the tendon loses eccentricity between the
/// deviators as the beam deflects towards L/60 (≈ 1–2 % of the 0.49 m lever arm), the MC90
/// compression block at the joint is not the rectangular one (≈ 1 %), and the coarse mesh's
/// 0.1 m top row resolves the 21 mm block only to ≈ 2 % of the lever arm. Measured: yield at
/// 172.1 kN (−2.8 %), peak 173.9 kN (−1.8 %).
#[test]
fn seed_beam_with_concrete_fails_by_tendon_yield_at_the_statics_load() {
    let row = bench::seed_failure_case(1, true).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(row.mode, "tendon yield", "{}", row.end);
    // The run finished: the arc-length step reached its stop deflection L/60.
    assert_eq!(row.end, "deflection L/60 reached");
    assert!(
        row.tendon_stress >= 0.999 * 0.9 * 1900e6,
        "tendon {:.0} MPa ({})",
        row.tendon_stress / 1e6,
        row.end
    );
    assert_eq!(row.crushed, 0, "crushed points at the end");
    let q_u = statics_ultimate_load();
    let q = row.q_max * 1e3;
    assert!(
        (q - q_u).abs() < 0.05 * q_u,
        "Q_max {:.1} kN vs statics {:.1} kN",
        q / 1e3,
        q_u / 1e3
    );
}

/// The same MC90-concrete beam refined 2× (12 rows through the depth, 6,731 equations)
/// runs to L/60 and its tendon yields too, and its peak load is the coarse run's within 2 %
/// (mesh objectivity): at tendon yield Q is set by the yield force T_y times the lever arm
/// at the opened joint, d_p − a/2 ≈ 0.49 m, whose only mesh-dependent part is the depth of
/// the compression block at the joint (a ≈ 21 mm in statics; one element row of the
/// coarse mesh is 0.1 m, so its resolution moves the lever arm by at most ≈ 1–2 %).
/// Measured 174.4 kN against the coarse 173.9 kN. Release only (≈ 12 s wall on a loaded
/// machine; minutes unoptimised). Refined 4×:
/// `seed_beam_with_concrete_refined_4x_peaks_at_the_tendon_yield_load` below.
#[test]
#[cfg_attr(debug_assertions, ignore = "release test: the 2× mesh to failure")]
fn seed_beam_with_concrete_refined_reaches_tendon_yield_as_the_coarse_mesh() {
    let coarse = bench::seed_failure_case(1, true).unwrap_or_else(|e| panic!("{e}"));
    let fine = bench::seed_failure_case(2, true).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "coarse: Q_max {:.1} kN, {} increments, {} iterations, {:.1} s; 2x: Q_max {:.1} kN, {} increments, {} iterations, {:.1} s ({})",
        coarse.q_max,
        coarse.increments,
        coarse.iterations,
        coarse.total_s,
        fine.q_max,
        fine.increments,
        fine.iterations,
        fine.total_s,
        fine.end
    );
    assert_eq!(fine.equations, 6731, "not the 2× mesh");
    assert_eq!(fine.end, "deflection L/60 reached");
    assert_eq!(fine.mode, "tendon yield", "{}", fine.end);
    assert!(
        fine.tendon_stress >= 0.999 * 0.9 * 1900e6,
        "tendon {:.0} MPa",
        fine.tendon_stress / 1e6
    );
    // Mesh objectivity of the peak (reason above): 2 %.
    assert!(
        (fine.q_max - coarse.q_max).abs() < 0.02 * coarse.q_max,
        "Q_max {:.1} kN (2×) vs {:.1} kN (coarse)",
        fine.q_max,
        coarse.q_max
    );
    assert_eq!(fine.crushed, 0, "crushed points at the end");
    // And against statics of the opened joint within 5 % (as the coarse test).
    let q_u = statics_ultimate_load() / 1e3;
    assert!(
        (fine.q_max - q_u).abs() < 0.05 * q_u,
        "{} vs {q_u}",
        fine.q_max
    );
}

/// The same MC90-concrete beam refined 4× (24 rows through the depth, 25,547 equations; the
/// loads on their 0.2 m plates) reaches its peak near tendon yield. With the smooth IMPL-EX
/// law (issue 21, docs/theory-concrete.md §5.2) the web just under the flange beside the
/// opened joints crushes first: a limit point with the tendon at ≥ 95 % of its yield stress
/// (statics: the capacity is set by tendon yield, so a crushing limit that comes first must
/// come within a few per cent of it), where the secant continued past the extrapolated
/// strain (the law before) carried more crack tension and ran on to yield at L/60. Its
/// peak is compared with the coarse run within 4 %: the
/// coarse mesh's top row (0.1 m, Gauss points 21 mm from its faces) is four times the
/// statics compression block at the opened joint (a ≈ 21 mm), so the coarse lever arm
/// d_p − a/2 ≈ 0.49 m is resolved only to ≈ 0.02 m (4 %); the 4× rows (25 mm) resolve it.
/// And with statics of the opened joint within 5 % (the rectangular block against the MC90
/// curve, 1 %; the tendon hardening past 0.9 f_ptk on the way to L/60, ≤ 3 %).
/// Heavy release test: ≈ 4 min on 2 idle cores (10 min at a load average of 8).
///
/// Known deviation since issue 38 (docs/validation.md, "MC90 concrete: the bundled
/// example"): the bundled example (anchor plates and bearings with their local zones
/// instead of elastic 0.3 m end blocks) refined 4× stops by crushing of the same web row
/// beside J2 at 146.7 kN (tendon 1451 MPa; 159.6 kN with the old solver settings), so this
/// test is ignored until that limit is understood; run it with `--run-ignored all`.
#[test]
#[ignore = "known deviation since issue 38: the 4× run stops by web crushing at 146.7 kN (docs/validation.md)"]
fn seed_beam_with_concrete_refined_4x_peaks_at_the_tendon_yield_load() {
    let coarse = bench::seed_failure_case(1, true).unwrap_or_else(|e| panic!("{e}"));
    let fine = bench::seed_failure_case(4, true).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "coarse: Q_max {:.1} kN; 4x: Q_max {:.1} kN, tendon {:.0} MPa, {} increments, {} iterations, {:.1} s wall, {:.1} s CPU ({}; {})",
        coarse.q_max,
        fine.q_max,
        fine.tendon_stress / 1e6,
        fine.increments,
        fine.iterations,
        fine.total_s,
        fine.cpu_s,
        fine.end,
        fine.mode
    );
    assert_eq!(fine.equations, 25547, "not the 4× mesh");
    // The run reaches L/60 with its tendon yielded, or a limit point by local crushing (a
    // known deviation, docs/validation.md): points of the web just under the flange beside
    // the opened joints J2 and J5, cracked twice, crush. Crushing of the compression zone
    // would take whole rows of points: fewer than 9 (one Q8 element's points) crushed at
    // the end. The tendon at ≥ 95 % of 0.9 f_ptk (reason above).
    assert!(
        fine.mode == "tendon yield" || fine.mode == "concrete crushing",
        "{}",
        fine.mode
    );
    assert!(fine.crushed < 9, "{} crushed points", fine.crushed);
    assert!(
        fine.tendon_stress >= 0.95 * 0.9 * 1900e6,
        "tendon {:.0} MPa",
        fine.tendon_stress / 1e6
    );
    // Mesh objectivity of the peak (reason above): 4 %.
    assert!(
        (fine.q_max - coarse.q_max).abs() < 0.04 * coarse.q_max,
        "Q_max {:.1} kN (4×) vs {:.1} kN (coarse)",
        fine.q_max,
        coarse.q_max
    );
    // Statics of the opened joint (reason above): 5 %.
    let q_u = statics_ultimate_load() / 1e3;
    assert!(
        (fine.q_max - q_u).abs() < 0.05 * q_u,
        "Q_max {:.1} kN vs statics {q_u:.1} kN",
        fine.q_max
    );
}

/// Ultimate load Q_u [N] of the seed beam from statics of the opened midspan joint:
/// M_u = T_y (d_p − a/2), T_y = 0.9 f_ptk A_p, tendon at d_p = 0.50 m below the top (held at
/// the deviators), a = T_y/(0.85 f_cm b) in the 1.20 m top flange; less the self-weight
/// moment (25 kN/m³ on the 0.27 m² section, span 7.2 m); Q_u = (M_u − M_sw)/2.4 m.
fn statics_ultimate_load() -> f64 {
    let t_y = 0.9 * 1900e6 * 560e-6;
    let a = t_y / (0.85 * 45e6 * 1.20);
    let m_u = t_y * (0.50 - a / 2.0);
    let m_sw = 25e3 * (0.70 * 0.10 + 0.20 * 0.40 + 1.20 * 0.10) * 7.2f64.powi(2) / 8.0;
    (m_u - m_sw) / 2.4
}

/// The bundled example through the `segfem` binary, as the README runs it: it goes on past
/// Q = 140 kN to failure, says which failure it reached (terminal and summary.json), and
/// writes the columns of the validation plots. The tendon yields first (elastic concrete
/// cannot crush) and the peak load matches statics of the opened joint within 3 %: the
/// elastic contact block is triangular, not the rectangular block of the hand formula
/// (lever arm c/3 against a/2, ≈ 0.5 %), the tendon loses some eccentricity between the
/// deviators (≈ 1 %), and the increments of up to 4 kN bound how close a converged
/// increment comes to the peak (≈ 1 %).
#[test]
fn seed_beam_example_fails_by_tendon_yield_at_the_statics_load() {
    use common::{code, segfem, stdout, TempDir};
    let tmp = TempDir::new("seed-failure");
    let o = segfem(
        tmp.path(),
        &["example", "seed-beam-elastic", "-o", "seed-beam.toml"],
    );
    assert_eq!(code(&o), 0);
    let o = segfem(tmp.path(), &["run", "seed-beam.toml", "-o", "seed"]);
    assert_eq!(code(&o), 0, "{}", common::stderr(&o));
    let out = stdout(&o);
    let line = out
        .lines()
        .find(|l| l.starts_with("ultimate: "))
        .unwrap_or_else(|| panic!("no ultimate line in\n{out}"));
    assert!(line.starts_with("ultimate: tendon yield at Q = "), "{line}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.join("seed/summary.json")).unwrap())
            .unwrap();
    let u = &summary["ultimate"];
    assert_eq!(u["mode"], "tendon yield", "{u}");
    assert_eq!(u["load_case"], "Q", "{u}");
    assert_eq!(u["ended"], "completed", "{u}");
    let (at, peak) = (
        u["at_factor"].as_f64().unwrap(),
        u["peak_factor"].as_f64().unwrap(),
    );
    // Q is in kN (the load case's unit force is 1 kN).
    let q_u = statics_ultimate_load() / 1e3;
    assert!(
        ((peak - q_u) / q_u).abs() < 0.03,
        "peak Q {peak:.1} kN vs statics {q_u:.1} kN"
    );
    // The tendon yields at the peak (within one increment of 4 kN), well past 140 kN.
    assert!(
        at > 140.0 && at <= peak && peak - at < 4.0,
        "yield at {at}, peak {peak}"
    );
    // history.csv: Q, midspan deflection, tendon stress and largest opening; the tendon
    // reaches 0.9 f_ptk and the last row is at L/60.
    let h = std::fs::read_to_string(tmp.join("seed/history.csv")).unwrap();
    let head: Vec<&str> = h.lines().next().unwrap().split(',').collect();
    let col = |name: &str| {
        head.iter()
            .position(|c| c.split(' ').next() == Some(name))
            .unwrap_or_else(|| panic!("no column {name} in {head:?}"))
    };
    let last: Vec<f64> = h
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap_or(f64::NAN))
        .collect();
    assert!((last[col("tendon_stress")] - 1710e6).abs() < 1e3);
    assert!(last[col("midspan_uy")] <= -0.12, "{last:?}");
    assert!(last[col("deflection_Q")] < last[col("midspan_uy")]);
    assert!(last[col("max_opening")] > 0.006);
    // The README's plot command: deflection with the seed's points, tendon stress and
    // opening in their own figures, the deformed shape at Q = 140 kN (output 3) × 20.
    let refs = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/validation/seed-beam-reference.csv"
    );
    let o = segfem(
        tmp.path(),
        &[
            "plot",
            "seed",
            "--x",
            "Q",
            "--y",
            "deflection_Q",
            "--ref",
            refs,
            "--also",
            "tendon_stress,max_opening",
            "--step",
            "3",
            "--scale",
            "20",
        ],
    );
    assert_eq!(code(&o), 0, "{}", common::stderr(&o));
    for f in [
        "curves",
        "curves_tendon_stress",
        "curves_max_opening",
        "deformed",
    ] {
        assert!(tmp.join(&format!("seed/figures/{f}.png")).is_file(), "{f}");
    }
}

/// The seed's computed deflections [mm] at Q = 56 … 140 kN (validation/seed-beam-reference.csv).
fn seed_reference() -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/validation/seed-beam-reference.csv"
    ))
    .unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let mut it = l.split(',').map(|v| v.trim().parse::<f64>().unwrap());
            (it.next().unwrap(), -it.next().unwrap() * 1e3)
        })
        .collect()
}

/// The load-controlled steps (to Q = 140 kN) of `text`, the step on to failure cut off:
/// rows as in [`Rows`] and the deflection from Q = 0 [mm] at each reference load.
fn deflections(text: &str) -> (Vec<Row>, Vec<f64>) {
    let cut = text
        .find("[[steps]]\nname = \"failure\"")
        .expect("failure step");
    let model = segfem::input::parse(&text[..cut], "seed-beam.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut rows = Rows::default();
    steps::run(&model, &mut rows).unwrap_or_else(|e| panic!("{e}"));
    let r = rows.0;
    let u0 = r[0].1;
    let d = seed_reference()
        .iter()
        .map(|&(q, _)| (u0 - at(&r, q).1) * 1e3)
        .collect();
    (r, d)
}

fn example_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/seed-beam-elastic.toml"
    ))
    .unwrap()
}

/// The `seed-beam` example (MC90 concrete, IMPL-EX cracking, anchor plates, load and
/// support bearings: what `segfem bench --case seed-failure-concrete` runs), without the
/// step on to failure.
fn mc90_text() -> String {
    let t = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/seed-beam.toml"
    ))
    .unwrap();
    let cut = t.find("[[steps]]\nname = \"failure\"").unwrap();
    assert!(t.contains("kind = \"concrete\""));
    // `deflections` cuts at the failure step: give it an empty one.
    t[..cut].to_string() + "\n[[steps]]\nname = \"failure\"\n"
}

/// Known deviations from the seed's deflections (docs/validation.md, the seed beam): the
/// deflection [mm] segfem gives at each reference load. Elastic concrete, nonlinear
/// geometry (the example): much stiffer than the seed from 70 to 112 kN (−74, −59, −37,
/// −24 %: the seed's beam softens from 70 kN on, ours only once the joints open wide;
/// the seed's crack model and mesh are not given), +13 % at 56 kN, −8 % and +6 % at 126
/// and 140 kN.
const ELASTIC_MM: [f64; 7] = [1.749, 2.349, 5.574, 12.126, 21.835, 33.032, 44.337];

/// MC90 concrete (the `seed-beam` example): as the elastic run to 84 kN, softer from 98 kN on
/// (cracking of the web beside the opened joints, docs/validation.md): −21, +2, +18, +33 %
/// against the seed at 98 … 140 kN. Issue 25 (IMPL-EX cracks linear in the increment)
/// moved 98 kN by −5.4 % and the other loads by < 2 %; issue 38 (anchor plates and
/// bearings with their local zones instead of elastic 0.3 m end blocks and the RC
/// example's solver settings) moved them by −1.2 … +2.8 % (98 kN: 14.782 → 15.199 mm).
const MC90_MM: [f64; 7] = [1.765, 2.398, 6.024, 15.199, 29.496, 42.533, 55.815];

/// Each deflection against its known-deviation value, so that a regression and an
/// unexplained improvement both fail. Tolerance `tol` relative, stated by the caller.
fn check_band(what: &str, got: &[f64], known: &[f64], tol: f64) {
    for ((&(q, seed), &d), &k) in seed_reference().iter().zip(got).zip(known) {
        eprintln!(
            "{what}, Q = {q} kN: {d:.3} mm (known {k:.3} mm, seed {seed:.2} mm, {:+.0} %)",
            100.0 * (d / seed - 1.0)
        );
    }
    // All loads printed first, so that a failure shows the whole curve.
    for ((&(q, seed), &d), &k) in seed_reference().iter().zip(got).zip(known) {
        assert!(
            (d / k - 1.0).abs() < tol,
            "{what}, Q = {q} kN: {d:.3} mm outside the known-deviation band {k:.3} mm ± {:.0} % (seed {seed} mm)",
            100.0 * tol
        );
    }
}

/// **Change detector, not validation** (issue 42; docs/validation.md, "Change detectors"):
/// the band values are this program's own earlier output, not an external reference.
/// The example (elastic concrete, nonlinear geometry) at every reference load within 2 % of
/// its known-deviation value (the only nonlinearities are the joints' contact and the
/// geometry; the increments and the solver tolerance move these values by < 0.5 %). The
/// band at 140 kN (43.4–45.2 mm) rejects the same beam with linear geometry (35.6 mm),
/// which the old ±25 % band around the seed's 41.85 mm admitted.
#[test]
fn seed_beam_deflections_change_detector() {
    let text = example_text();
    let (_, d) = deflections(&text);
    check_band("elastic", &d, &ELASTIC_MM, 0.02);
    let linear = text.replace("geometry = \"nonlinear\"", "geometry = \"linear\"");
    assert_ne!(linear, text);
    let (_, dl) = deflections(&linear);
    assert!(
        (dl[6] / ELASTIC_MM[6] - 1.0).abs() > 0.02,
        "linear geometry at 140 kN: {:.2} mm inside the band",
        dl[6]
    );
}

/// **Change detector, not validation** (issue 42; docs/validation.md, "Change detectors"):
/// the band values are this program's own earlier output, not an external reference.
/// The MC90-concrete example at every reference load within 4 % of its known-deviation
/// value: cracking makes the path depend on the increments more than the elastic run
/// (IMPL-EX cracks lag one increment; changes of the crack algorithm between sessions moved
/// these values by up to 2 %).
#[test]
fn seed_beam_with_concrete_deflections_change_detector() {
    let (r, d) = deflections(&mc90_text());
    check_band("MC90", &d, &MC90_MM, 0.04);
    // The load-controlled steps reached 140 kN.
    assert!((r.last().unwrap().0 - 140.0).abs() < 1e-9);
}
