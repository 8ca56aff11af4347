//! Increment objectivity (issue 38 items 3 and 9): the peak load and the failure mode of the
//! concrete seed beam with the increment count changed by a factor 8, with and without the
//! error-controlled increments (`[solver] increment_tolerance`), on its load steps and its
//! arc-length step to failure (docs/validation.md, "Error-controlled increments").

/// The benchmark cases of the `segfem` binary (not part of the library); this test runs one.
#[path = "../src/cli/bench.rs"]
#[allow(dead_code)]
mod bench;

/// The bundled `seed-beam` example (MC90 concrete) refined `refine` × with its increments
/// `scale` × as many (load steps: `scale` × the increments; the arc-length step to failure:
/// 1/`scale` of the first load increment and so of every arc, `scale` × the increment
/// limit) and, with `tolerance`, `[solver] increment_tolerance` set.
fn seed_text(refine: usize, scale: usize, tolerance: Option<f64>) -> String {
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
        .replace("increments = 8\n", &format!("increments = {}\n", 8 * scale))
        .replace(
            "increments = 42\n",
            &format!("increments = {}\n", 42 * scale),
        )
        .replace(
            "initial_increment = 2.0\n",
            &format!("initial_increment = {}\n", 2.0 / scale as f64),
        )
        .replace(
            "increments = 400\n",
            &format!("increments = {}\n", 400 * scale),
        );
    if let Some(tol) = tolerance {
        assert!(!t.contains("[solver]"));
        t.push_str(&format!("\n[solver]\nincrement_tolerance = {tol}\n"));
    }
    t
}

/// Measurement (not a check): `SEGFEM_REFINE`, `SEGFEM_SCALE`, `SEGFEM_TOL` (none: off)
/// select a run of the seed beam; prints its row (docs/validation.md).
#[test]
#[ignore = "measurement, run by hand"]
fn measure_seed_beam() {
    let var = |k: &str| std::env::var(k).ok();
    let refine = var("SEGFEM_REFINE").map_or(1, |v| v.parse().unwrap());
    let scale = var("SEGFEM_SCALE").map_or(1, |v| v.parse().unwrap());
    let tol = var("SEGFEM_TOL").map(|v| v.parse::<f64>().unwrap());
    let row = bench::seed_failure_of(&seed_text(refine, scale, tol), refine, true)
        .unwrap_or_else(|e| panic!("{e}"));
    let t = &row.timings;
    eprintln!(
        "MEASURE refine {refine} scale {scale} tol {tol:?}: Q_max {:.2} kN, mode '{}', end '{}', tendon {:.0} MPa, crushed {}, {} increments ({} rejected pairs), {} iterations, max pair error {:.3}, {:.1} s wall, {:.1} s CPU",
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
}
