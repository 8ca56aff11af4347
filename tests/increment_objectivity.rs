//! Increment objectivity (issue 38 items 3 and 9): the peak load and the failure mode of the
//! concrete seed beam with the increment count changed by a factor 8, with and without the
//! error-controlled increments (`[solver] increment_tolerance`), on its load steps and its
//! arc-length step to failure (docs/validation.md, "Error-controlled increments").

/// The benchmark cases of the `segfem` binary (not part of the library); this test runs one.
#[path = "../src/cli/bench.rs"]
#[allow(dead_code)]
mod bench;

/// The beam bench of the `segfem` binary and the panel bench whose CSV reader it shares.
#[path = "../src/cli/beam_bench.rs"]
#[allow(dead_code)]
mod beam_bench;
#[path = "../src/cli/panel_bench.rs"]
#[allow(dead_code)]
mod panel_bench;

mod common;

/// The bundled `seed-beam` example (MC90 concrete) refined `refine` × with its increments
/// `scale` × as many (load steps: `scale` × the increments; the arc-length step to failure:
/// 1/`scale` of the first load increment and so of every arc, `scale` × the increment
/// limit) and, with `tolerance`, `[solver] increment_tolerance` set.
fn seed_text(refine: usize, scale: f64, tolerance: Option<f64>) -> String {
    let text = include_str!("../examples/seed-beam.toml");
    for key in [
        "increments = 8\n",
        "increments = 42\n",
        "initial_increment = 2.0\n",
        "increments = 400\n",
    ] {
        assert!(text.contains(key), "the example has no {key:?}");
    }
    let mut t = bench::refine_seed_mesh(text, refine)
        .replace(
            "increments = 8\n",
            &format!("increments = {}\n", count(8, scale)),
        )
        .replace(
            "increments = 42\n",
            &format!("increments = {}\n", count(42, scale)),
        )
        .replace(
            "initial_increment = 2.0\n",
            &format!("initial_increment = {}\n", 2.0 / scale),
        )
        .replace(
            "increments = 400\n",
            &format!("increments = {}\n", count(400, scale)),
        );
    if let Some(tol) = tolerance {
        assert!(!t.contains("[solver]"));
        t.push_str(&format!("\n[solver]\nincrement_tolerance = {tol}\n"));
    }
    t
}

/// `n` increments `scale` × as many (rounded, at least 1).
fn count(n: usize, scale: f64) -> usize {
    ((n as f64 * scale).round() as usize).max(1)
}

/// Measurement (not a check): `SEGFEM_REFINE`, `SEGFEM_SCALE`, `SEGFEM_TOL`,
/// `SEGFEM_IMPLEX_FORCE_TOL` and `SEGFEM_IMPLEX_NORM` (`increment_tolerance`,
/// `implex_force_tolerance`, `implex_force_norm`; none: off / the default) select a run of
/// the seed beam; prints its row (docs/validation.md).
#[test]
#[ignore = "measurement, run by hand"]
fn measure_seed_beam() {
    let var = |k: &str| std::env::var(k).ok();
    let refine = var("SEGFEM_REFINE").map_or(1, |v| v.parse().unwrap());
    let scale = var("SEGFEM_SCALE").map_or(1.0, |v| v.parse().unwrap());
    let tol = var("SEGFEM_TOL").map(|v| v.parse::<f64>().unwrap());
    let force = var("SEGFEM_IMPLEX_FORCE_TOL").map(|v| v.parse::<f64>().unwrap());
    let mut text = seed_text(refine, scale, tol);
    if let Some(f) = force {
        if !text.contains("[solver]") {
            text.push_str("\n[solver]\n");
        }
        text.push_str(&format!("implex_force_tolerance = {f}\n"));
        if let Some(n) = var("SEGFEM_IMPLEX_NORM") {
            text.push_str(&format!("implex_force_norm = \"{n}\"\n"));
        }
    }
    let row = bench::seed_failure_of(&text, refine, true).unwrap_or_else(|e| panic!("{e}"));
    let t = &row.timings;
    eprintln!(
        "MEASURE refine {refine} scale {scale} tol {tol:?} force {force:?} (cuts {}, over {}, max {:.2e}): Q_max {:.2} kN, mode '{}', end '{}', tendon {:.0} MPa, crushed {}, {} increments ({} rejected pairs), {} iterations, max pair error {:.3}, {:.1} s wall, {:.1} s CPU",
        t.implex_force_cuts,
        t.implex_force_over_tolerance,
        t.implex_force_max_error,
        row.q_max,
        row.mode,
        row.end,
        row.tendon_stress / 1e6,
        row.crushed,
        row.increments,
        t.increments_rejected,
        row.iterations,
        t.increment_max_error,
        row.total_s,
        row.cpu_s
    );
    eprintln!("MEASURE path error {:?}", row.path_error);
}

/// The seed beam's run to failure from `seed_text(1, scale, tolerance)` (coarse mesh).
fn seed_run(scale: f64, tolerance: Option<f64>) -> bench::FailureRow {
    bench::seed_failure_of(&seed_text(1, scale, tolerance), 1, true)
        .unwrap_or_else(|e| panic!("scale {scale}, tolerance {tolerance:?}: {e}"))
}

/// What the two runs of an objectivity test must share: the failure the seed's concrete
/// beam reaches by any increment count (tendon yield at 0.9 f_ptk = 1710 MPa, the run on
/// to L/60, no crushed point: docs/validation.md "The seed beam") and a peak load within
/// 2 % (issue 38's objectivity criterion; the peak is set by the tendon's yield force times
/// the lever arm at the opened joint, which no increment size changes by more than the
/// last increment's overshoot, below 0.5 % here).
fn assert_same_failure(coarse: &bench::FailureRow, fine: &bench::FailureRow) {
    for r in [coarse, fine] {
        assert_eq!(r.mode, "tendon yield", "{}", r.end);
        assert_eq!(r.end, "deflection L/60 reached");
        assert!(
            r.tendon_stress >= 0.999 * 0.9 * 1900e6,
            "tendon {:.0} MPa",
            r.tendon_stress / 1e6
        );
        assert_eq!(r.crushed, 0, "crushed points at the end");
    }
    assert!(
        (coarse.q_max - fine.q_max).abs() < 0.02 * fine.q_max,
        "Q_max {:.2} kN (coarse) vs {:.2} kN (8x the increments)",
        coarse.q_max,
        fine.q_max
    );
}

/// With the program's defaults (fixed increments) the seed beam on concrete, coarse mesh,
/// reaches the same failure at the example's increments and at 8 × as many (load steps
/// 64 + 336, arcs from 0.25 kN instead of 2 kN): measured 173.88 and 173.73 kN
/// (docs/validation.md). About 8 s wall in release.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: 8x the increments to failure"
)]
fn seed_beam_failure_does_not_depend_on_the_increment_count() {
    let coarse = seed_run(1.0, None);
    let fine = seed_run(8.0, None);
    eprintln!(
        "Q_max {:.2} kN ({} increments), 8x {:.2} kN ({})",
        coarse.q_max, coarse.increments, fine.q_max, fine.increments
    );
    assert_same_failure(&coarse, &fine);
    assert!(fine.increments > 4 * coarse.increments, "not 8x finer");
    // Its peak does not move, and the path error at the peak does not flag it (measured
    // 4.0e-3 at 1x, docs/validation.md "How sure the peak is").
    for r in [&coarse, &fine] {
        let p = r.path_error.as_ref().expect("an IMPL-EX path error");
        assert!(!p.flagged() && p.at_peak > 0.0, "{p:?}");
    }
}

/// With `[solver] increment_tolerance = 0.05` the arcs of the step to failure are paired
/// and sized by their error as the load increments: at ¼ of the example's increments
/// (2 + 11 load increments, arcs from 8 kN) and at twice them (a factor 8 apart) the beam
/// reaches the same failure, within 2 %. The control ran: pairs were rejected and the
/// largest kept pair's error (summary.json `increment_max_error`) is reported. Measured
/// 174.17 kN at ¼ (docs/validation.md). About 15 s wall in release.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: error-controlled runs to failure"
)]
fn seed_beam_failure_with_error_control_does_not_depend_on_the_increment_count() {
    let coarse = seed_run(0.25, Some(0.05));
    let fine = seed_run(2.0, Some(0.05));
    eprintln!(
        "Q_max {:.2} kN ({} increments, {} rejected pairs, largest error {:.3}), 8x {:.2} kN ({}, {}, {:.3})",
        coarse.q_max,
        coarse.increments,
        coarse.timings.increments_rejected,
        coarse.timings.increment_max_error,
        fine.q_max,
        fine.increments,
        fine.timings.increments_rejected,
        fine.timings.increment_max_error
    );
    assert_same_failure(&coarse, &fine);
    for r in [&coarse, &fine] {
        let t = &r.timings;
        assert!(t.increments_rejected > 0, "no pair rejected");
        assert!(t.increment_max_error > 0.0, "no pair error reported");
        // Pairs kept above the tolerance are counted exactly when the largest kept error
        // is above it.
        assert_eq!(
            t.increments_over_tolerance > 0,
            t.increment_max_error > 0.05,
            "{t:?}"
        );
    }
}

/// summary.json and the report state the estimated path error of a run to failure in arc
/// length with the control (the seed beam at ¼ of its increments, tol 0.05, through the
/// `segfem` command): the largest kept pair error, the pairs rejected and those kept above
/// the tolerance (a joint opening inside a pair: measured 1.9, docs/validation.md), as
/// the same row of the report.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: an error-controlled run to failure"
)]
fn summary_and_report_state_the_path_error_of_an_arc_length_run() {
    use common::{code, segfem, stderr, TempDir};
    let tmp = TempDir::new("arc-path-error");
    std::fs::write(tmp.join("m.toml"), seed_text(1, 0.25, Some(0.05))).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.join("out/summary.json")).unwrap())
            .unwrap();
    let t = &summary["timings"];
    let e = t["increment_max_error"].as_f64().expect("a path error");
    let over = t["increments_over_tolerance"].as_u64().unwrap_or(0);
    let rejected = t["increments_rejected"].as_u64().unwrap_or(0);
    assert!(e > 0.05 && over > 0 && rejected > 0, "{t}");
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = std::fs::read_to_string(tmp.join("out/report.html")).unwrap();
    assert!(
        html.contains(&format!(
            "largest kept {e:.3} of the displacement change over a pair; {rejected} pairs rejected; {over} kept above the tolerance"
        )),
        "no path-error row"
    );
}

/// The shear beam `id` of validation/beams/beams.csv and the model keys of the bench's
/// option named `option`.
fn shear_beam(id: &str, option: &str) -> (beam_bench::Beam, &'static str) {
    use crate::beam_bench::{options, read_beams};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/beams/beams.csv");
    let beam = read_beams(&path)
        .unwrap()
        .into_iter()
        .find(|b| b.id == id)
        .unwrap();
    let keys = options().into_iter().find(|o| o.0 == option).unwrap().1;
    (beam, keys)
}

/// The path error at the peak flags a peak that depends on the increment (issue 38 item
/// 3: "it says how sure it is"): OA1 (no stirrups, brittle diagonal tension; 10 Q8 rows,
/// the default model, fixed increments) at 0.2 mm plate increments is flagged (measured
/// 1.6e-2 against the limit 1e-2) and its verdict says so, and halving the
/// increment does move its peak by more than 5 % (measured 457.1 → 411.9 kN, 10 %;
/// the converged peak is 364.6–378.7 kN, docs/validation.md). About 11 s CPU in release.
#[test]
#[cfg_attr(debug_assertions, ignore = "release test: two shear beam runs")]
fn shear_beam_peak_that_depends_on_the_increment_is_flagged() {
    use crate::beam_bench::run_beam_solver;
    let (beam, keys) = shear_beam("OA1", "fixed, seed β");
    let run = |inc_mm: f64| run_beam_solver(&beam, keys, 10, -20e-3, inc_mm * 1e-3, "").unwrap();
    let (coarse, half) = (run(0.2), run(0.1));
    let p = coarse
        .ultimate
        .as_ref()
        .and_then(|u| u.path_error.clone())
        .expect("a path error");
    eprintln!(
        "OA1 peak {:.1} kN at 0.2 mm ({p:?}), {:.1} kN at 0.1 mm",
        coarse.p_peak / 1e3,
        half.p_peak / 1e3
    );
    assert!(p.flagged(), "{p:?}");
    let verdict = coarse.ultimate.as_ref().unwrap().to_string();
    assert!(
        verdict.contains("may depend on the increment size"),
        "{verdict}"
    );
    assert!(
        coarse.p_peak > 1.05 * half.p_peak,
        "the flagged peak {:.1} kN did not move at half the increment ({:.1} kN)",
        coarse.p_peak / 1e3,
        half.p_peak / 1e3
    );
}

/// summary.json and the report state the path error at the peak of a run with the
/// defaults (the concrete seed beam at the example's increments, through the `segfem`
/// command): `ultimate.path_error` with the peak's and the largest error (measured 4.0e-3
/// and 3.3e-2), not flagged (its peak is the same at 8× the increments, above), so no
/// warning about the increment size; the report's row gives the same figures.
#[test]
#[cfg_attr(debug_assertions, ignore = "release test: a run to failure")]
fn summary_and_report_state_the_path_error_at_the_peak() {
    use common::{code, segfem, stderr, TempDir};
    let tmp = TempDir::new("peak-path-error");
    std::fs::write(tmp.join("m.toml"), seed_text(1, 1.0, None)).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.join("out/summary.json")).unwrap())
            .unwrap();
    let p = &summary["ultimate"]["path_error"];
    let (at_peak, largest) = (
        p["at_peak"].as_f64().unwrap(),
        p["largest"].as_f64().unwrap(),
    );
    assert!(0.0 < at_peak && at_peak <= largest && at_peak < p["limit"].as_f64().unwrap());
    let warnings = summary["warnings"].to_string();
    assert!(!warnings.contains("increment size"), "{warnings}");
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = std::fs::read_to_string(tmp.join("out/report.html")).unwrap();
    assert!(
        html.contains(&format!("{at_peak:.1e} at the peak"))
            && html.contains(&format!("largest {largest:.1e}")),
        "no path-error row"
    );
}

/// Measurement (not a check): a shear beam of docs/validation.md ("Shear beams"):
/// `SEGFEM_BEAM` (OA1, B1), `SEGFEM_ROWS` (10), `SEGFEM_INC_MM` (plate increment, 0.2),
/// `SEGFEM_PUSH_MM` (20), `SEGFEM_OPTION` (the bench's model option, "fixed, seed β"),
/// `SEGFEM_TOL` (`increment_tolerance`), `SEGFEM_IMPLEX_TOL` (`implex_tolerance`),
/// `SEGFEM_IMPLEX_FORCE_TOL` (`implex_force_tolerance`), `SEGFEM_IMPLEX_NORM`
/// (`implex_force_norm`), `SEGFEM_COMPRESSION` (`compression_integration`) (each none: off
/// / the default); prints its peak, increments, CPU time and the controls' counts. With
/// `SEGFEM_DUMP` set to a file it writes the model text there instead of running (for
/// `segfem run` with two binaries on the same input).
#[test]
#[ignore = "measurement, run by hand"]
fn measure_shear_beam() {
    use crate::beam_bench::run_beam_solver;
    let var = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
    let id = var("SEGFEM_BEAM", "OA1");
    let rows: usize = var("SEGFEM_ROWS", "10").parse().unwrap();
    let inc: f64 = var("SEGFEM_INC_MM", "0.2").parse().unwrap();
    let push: f64 = var("SEGFEM_PUSH_MM", "20").parse().unwrap();
    let option = var("SEGFEM_OPTION", "fixed, seed β");
    let tol = std::env::var("SEGFEM_TOL").ok();
    let implex_tol = std::env::var("SEGFEM_IMPLEX_TOL").ok();
    let force_tol = std::env::var("SEGFEM_IMPLEX_FORCE_TOL").ok();
    let norm = std::env::var("SEGFEM_IMPLEX_NORM")
        .ok()
        .map(|v| format!("\"{v}\""));
    let (beam, keys) = shear_beam(&id, &option);
    let keys = match std::env::var("SEGFEM_COMPRESSION") {
        Ok(v) => format!("{keys}compression_integration = \"{v}\"\n"),
        Err(_) => keys.to_string(),
    };
    let keys = keys.as_str();
    let mut solver = String::new();
    for (key, v) in [
        ("increment_tolerance", &tol),
        ("implex_tolerance", &implex_tol),
        ("implex_force_tolerance", &force_tol),
        ("implex_force_norm", &norm),
    ] {
        if let Some(v) = v {
            solver.push_str(&format!("{key} = {v}\n"));
        }
    }
    if let Ok(path) = std::env::var("SEGFEM_DUMP") {
        let text = crate::beam_bench::beam_toml(&beam, keys, rows, -push * 1e-3, inc * 1e-3);
        std::fs::write(path, text + &solver).unwrap();
        return;
    }
    let cpu0 = bench::process_cpu_s();
    let r = run_beam_solver(&beam, keys, rows, -push * 1e-3, inc * 1e-3, &solver).unwrap();
    let counts = r
        .controls
        .map_or("counts lost (no equilibrium at the end)".to_string(), |c| {
            format!(
                "implex cuts / over / max {:?}, force {:?}, pairs rejected {}",
                c.implex, c.implex_force, c.pairs_rejected
            )
        });
    eprintln!(
        "MEASURE {id} {rows} rows, {inc} mm, tol {tol:?}, implex {implex_tol:?}, force {force_tol:?} {norm:?}, {option}: peak {:.1} kN (test {:.0} kN, {:+.1} %), end {:.2} of peak, {:?}, {} increments, {:.1} s CPU, {counts}",
        r.p_peak / 1e3,
        beam.test.0 / 1e3,
        100.0 * (r.p_peak / beam.test.0 - 1.0),
        r.end_ratio,
        r.ultimate.as_ref().map(|u| u.mode.clone()),
        r.increments,
        bench::process_cpu_s() - cpu0
    );
    eprintln!(
        "MEASURE path error {:?}",
        r.ultimate.as_ref().and_then(|u| u.path_error.clone())
    );
}

/// The global IMPL-EX error control (`[solver] implex_force_tolerance = 5e-3`,
/// docs/theory-concrete.md §5.2) makes the brittle shear peak of OA1 (Vecchio & Shim, no
/// stirrups; 10 Q8 rows, the default model: fixed cracks, seed β, IMPL-EX) independent of
/// the plate increment over a factor 8: at 0.2 mm and at 0.025 mm the peaks agree within
/// 2 % (issue 38's objectivity goal; measured 386.4 and 382.0 kN, 1.2 %, where fixed
/// increments give 457.1 and 374.6 kN, 22 %; docs/validation.md "Shear beams"), and the
/// coarse run is cut where cracks run ahead of their extrapolation (more increments than
/// the ~107 of fixed 0.2 mm plate increments to the same end). Both within 4 % of the
/// fixed 0.0125 mm run's 378.7 kN (the converged figure, up to the ~1 % scatter of the
/// brittle peak between the fine fixed runs). About 45 s CPU in release.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: two shear-beam runs to failure"
)]
fn shear_beam_peak_with_the_global_implex_control_does_not_depend_on_the_increment() {
    use crate::beam_bench::run_beam_solver;
    let (beam, keys) = shear_beam("OA1", "fixed, seed β");
    let solver = "implex_force_tolerance = 5e-3\n";
    let run =
        |inc_mm: f64| run_beam_solver(&beam, keys, 10, -20e-3, inc_mm * 1e-3, solver).unwrap();
    let (coarse, fine) = (run(0.2), run(0.025));
    eprintln!(
        "OA1 peak {:.1} kN ({} increments) at 0.2 mm, {:.1} kN ({}) at 0.025 mm",
        coarse.p_peak / 1e3,
        coarse.increments,
        fine.p_peak / 1e3,
        fine.increments
    );
    assert!(
        (coarse.p_peak - fine.p_peak).abs() < 0.02 * fine.p_peak,
        "peak {:.1} kN (0.2 mm) vs {:.1} kN (0.025 mm)",
        coarse.p_peak / 1e3,
        fine.p_peak / 1e3
    );
    assert!(coarse.increments > 150, "not cut: {}", coarse.increments);
    for r in [&coarse, &fine] {
        assert!(
            (r.p_peak / 378.7e3 - 1.0).abs() < 0.04,
            "{:.1} kN against the fine fixed run's 378.7 kN",
            r.p_peak / 1e3
        );
    }
}

/// The global IMPL-EX control in the energy norm (`implex_force_norm = "energy"`,
/// docs/theory-concrete.md §5.2), end to end on the concrete seed beam at the example's
/// increments with the tolerance 3e-3 that brings OA1's peaks within 2 % on 10 and 20 rows:
/// it cuts (measured 67 cuts, 17 increments kept above the tolerance, largest kept 1.39e-2;
/// 69, 18 in docs/validation.md before session 25), counts the increments kept above the tolerance exactly when the
/// largest kept error exceeds it, and the beam reaches the fixed increments' failure:
/// tendon yield, L/60, no crushing, the peak within 0.5 % (measured 173.99 kN both; the peak is the tendon's yield force times the lever arm at the opened joint,
/// which the cuts before it do not move). About 5 s CPU in release.
#[test]
#[cfg_attr(debug_assertions, ignore = "release test: a controlled run to failure")]
fn seed_beam_with_the_energy_norm_control_keeps_its_failure() {
    let fixed = seed_run(1.0, None);
    let text = seed_text(1, 1.0, None)
        + "\n[solver]\nimplex_force_tolerance = 3e-3\nimplex_force_norm = \"energy\"\n";
    let controlled = bench::seed_failure_of(&text, 1, true).unwrap();
    let t = &controlled.timings;
    eprintln!(
        "Q_max {:.2} kN fixed, {:.2} kN controlled ({} cuts, {} kept above, largest {:.2e})",
        fixed.q_max,
        controlled.q_max,
        t.implex_force_cuts,
        t.implex_force_over_tolerance,
        t.implex_force_max_error
    );
    assert!(t.implex_force_cuts > 0, "no cut");
    assert!(t.implex_force_max_error > 0.0);
    assert_eq!(
        t.implex_force_over_tolerance > 0,
        t.implex_force_max_error > 3e-3,
        "{t:?}"
    );
    assert_eq!(controlled.mode, "tendon yield");
    assert_eq!(controlled.end, "deflection L/60 reached");
    assert_eq!(controlled.crushed, 0);
    assert!(
        (controlled.q_max - fixed.q_max).abs() < 5e-3 * fixed.q_max,
        "{:.2} against {:.2} kN",
        controlled.q_max,
        fixed.q_max
    );
}

/// summary.json and the report state what the global IMPL-EX control did (the concrete seed
/// beam at the example's increments with `implex_force_tolerance = 5e-3`, through the
/// `segfem` command; measured 51 cuts, 5 increments kept above the tolerance, largest kept
/// error 1.03e-2, docs/validation.md): the cuts, the increments kept above the tolerance
/// and the largest kept error, consistent with each other (kept above the tolerance exactly
/// when the largest kept error exceeds it), and the same figures in the report's row.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "release test: an IMPL-EX-controlled run to failure"
)]
fn summary_and_report_state_the_global_implex_error() {
    use common::{code, segfem, stderr, TempDir};
    let tmp = TempDir::new("implex-force-error");
    let text = seed_text(1, 1.0, None) + "\n[solver]\nimplex_force_tolerance = 5e-3\n";
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.join("out/summary.json")).unwrap())
            .unwrap();
    let t = &summary["timings"];
    let e = t["implex_force_max_error"].as_f64().expect("a force error");
    let cuts = t["implex_force_cuts"].as_u64().unwrap_or(0);
    let over = t["implex_force_over_tolerance"].as_u64().unwrap_or(0);
    assert!(e > 0.0 && cuts > 0, "{t}");
    assert_eq!(over > 0, e > 5e-3, "{t}");
    assert!(
        t.get("implex_max_error").is_none(),
        "the point measure was off: {t}"
    );
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = std::fs::read_to_string(tmp.join("out/report.html")).unwrap();
    assert!(
        html.contains(&format!(
            "largest kept {e:.2e} of the force scale; {cuts} increments cut for it; {over} kept above the tolerance"
        )),
        "no IMPL-EX force row"
    );
}
