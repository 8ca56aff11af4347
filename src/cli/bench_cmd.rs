//! The `segfem bench` command: one function per `--case`, printing one row per size or
//! refinement (the cases themselves are in [`super::bench`]).

use segfem::model::ElementKind;
use std::process::ExitCode;

use crate::stdout_failed;

pub(crate) fn bench(dofs: Vec<f64>, element: Vec<String>) -> ExitCode {
    outln!(
        "{:>4} {:>9} {:>7} {:>7} {:>8} {:>8} {:>8} {:>7} {:>8} {:>9} {:>12}",
        "elem",
        "dofs",
        "mesh s",
        "setup s",
        "assemb s",
        "order s",
        "factor s",
        "solve s",
        "total s",
        "peak MiB",
        "tip uy [m]"
    );
    for e in &element {
        let kind = match ElementKind::from_name(e) {
            Some(k) if k.grid_layout().is_some() => k,
            Some(_) => {
                eprintln!("error: --element: the bench meshes quadrilaterals, not '{e}'");
                return ExitCode::from(2);
            }
            None => {
                eprintln!(
                    "error: --element: unknown element '{e}' ({})",
                    ElementKind::names()
                );
                return ExitCode::from(2);
            }
        };
        for &n in &dofs {
            match super::bench::run_case(kind, n as usize) {
                Ok(r) => outln!(
                    "{:>4} {:>9} {:>7.3} {:>7.3} {:>8.3} {:>8.3} {:>8.3} {:>7.3} {:>8.3} {:>9.0} {:>12.5e}",
                    r.kind, r.dofs, r.mesh_s, r.setup_s, r.assembly_s, r.ordering_s, r.factor_s, r.solve_s, r.total_s,
                    r.peak_bytes as f64 / 1048576.0, r.tip_uy
                ),
                Err(err) => {
                    eprintln!("error: {err}");
                    return ExitCode::from(3);
                }
            }
        }
    }
    ExitCode::SUCCESS
}

pub(crate) fn bench_bare(path: &std::path::Path) -> ExitCode {
    match super::bench::bare_factorisation(path) {
        Ok(r) => {
            outln!("{}", serde_json::to_string(&r).expect("row serialises"));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

pub(crate) fn bench_seed_failure(refine: Vec<usize>, concrete: bool) -> ExitCode {
    outln!(
        "{:>28} {:>9} {:>5} {:>6} {:>8} {:>7} {:>8} {:>10} {:>10} {:>9} {:>7}  failure; end",
        "case",
        "equations",
        "incs",
        "iters",
        "total s",
        "CPU s",
        "Q max",
        "uy [m]",
        "σp [MPa]",
        "open [mm]",
        "crushed"
    );
    for r in refine {
        match super::bench::seed_failure_case(r, concrete) {
            Ok(x) => {
                outln!(
                    "{:>28} {:>9} {:>5} {:>6} {:>8.3} {:>7.2} {:>8.1} {:>10.4e} {:>10.1} {:>9.2} {:>7}  {}; {}",
                    x.case,
                    x.equations,
                    x.increments,
                    x.iterations,
                    x.total_s,
                    x.cpu_s,
                    x.q_max,
                    x.deflection,
                    x.tendon_stress / 1e6,
                    x.max_opening * 1e3,
                    x.crushed,
                    x.mode,
                    x.end
                );
                let (t, s) = (&x.timings, &x.timings.solver);
                outln!(
                    "{:>28} assembly {:.3} s, {} factorisations ({} LDLT, {:.3} s; {} by halves to whole) {:.3} s ({:.2} ms each, factor {} values), solves {:.3} s",
                    "",
                    t.assembly_s,
                    s.factorisations,
                    s.ldlt_factorisations,
                    s.indefinite_s,
                    s.split_ldlt_to_whole,
                    s.numeric_s,
                    1e3 * s.numeric_s / s.factorisations.max(1) as f64,
                    s.factor_nnz,
                    s.solve_s
                );
                print_line_searches(&t.line_searches);
                if let Some(p) = &x.path_error {
                    outln!(
                        "{:>28} IMPL-EX path error {:.1e} at the peak ({}), largest {:.1e}",
                        "",
                        p.at_peak,
                        if p.flagged() {
                            "flagged"
                        } else {
                            "not flagged"
                        },
                        p.largest
                    );
                }
            }
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(3);
            }
        }
    }
    ExitCode::SUCCESS
}

/// The line-search counters of a run (summary.json `line_searches`), one line.
fn print_line_searches(l: &segfem::analysis::steps::LineSearchStats) {
    outln!(
        "{:>18} line searches: {} ({} after an overshoot, {} stopped at s = 1), trial points {} without the tangent ({} of them reassembled in part; {:.2} s) and {} with it ({:.2} s), {} of these taken over by the iteration",
        "",
        l.searches,
        l.after_overshoot,
        l.full_step,
        l.residual_trials,
        l.full_step_again,
        l.residual_s,
        l.tangent_trials,
        l.tangent_s,
        l.reused
    );
}

/// Print one row per refinement factor of a seed-beam benchmark `case`.
pub(crate) fn bench_rc(refine: Vec<usize>) -> ExitCode {
    outln!(
        "{:>18} {:>9} {:>5} {:>6} {:>8} {:>8} {:>9} {:>9}  end",
        "case",
        "equations",
        "incs",
        "iters",
        "total s",
        "CPU s",
        "P max kN",
        "w [mm]"
    );
    for r in refine {
        match super::bench::rc_case(r) {
            Ok(x) => {
                outln!(
                    "{:>18} {:>9} {:>5} {:>6} {:>8.2} {:>8.2} {:>9.1} {:>9.2}  {}",
                    x.case,
                    x.equations,
                    x.increments,
                    x.iterations,
                    x.total_s,
                    x.cpu_s,
                    x.p_max / 1e3,
                    x.deflection * 1e3,
                    x.end
                );
                let (t, s) = (&x.timings, &x.timings.solver);
                outln!(
                    "{:>18} assembly {:.2} s, line searches {:.2} s, ordering + symbolic {:.3} s, {} factorisations ({} LDLT, {:.2} s; {} by halves to whole) {:.2} s ({:.1} ms each, factor {} values), solves {:.2} s",
                    "",
                    t.assembly_s,
                    t.line_search_s,
                    s.symbolic_s,
                    s.factorisations,
                    s.ldlt_factorisations,
                    s.indefinite_s,
                    s.split_ldlt_to_whole,
                    s.numeric_s,
                    1e3 * s.numeric_s / s.factorisations.max(1) as f64,
                    s.factor_nnz,
                    s.solve_s
                );
                print_line_searches(&t.line_searches);
            }
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(3);
            }
        }
    }
    ExitCode::SUCCESS
}

pub(crate) fn bench_panels(file: Option<&std::path::Path>) -> ExitCode {
    let path = file.unwrap_or(std::path::Path::new("validation/panels/panels.csv"));
    match super::panel_bench::series(path) {
        Ok((report, secs)) => {
            outln!("{report}");
            outln!("total time of the series: {secs:.1} s");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Print the shear-beam series (validation/beams/beams.csv, or `file`) under each concrete
/// model option (or those of `set`) on two meshes (or those of `set`).
pub(crate) fn bench_beams(
    file: Option<&std::path::Path>,
    set: &super::beam_bench::SeriesSettings,
) -> ExitCode {
    let path = file.unwrap_or(std::path::Path::new("validation/beams/beams.csv"));
    match super::beam_bench::series(path, set) {
        Ok((report, secs)) => {
            outln!("{report}");
            outln!("total time of the series: {secs:.1} s");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

pub(crate) fn bench_material_point() -> ExitCode {
    outln!("{:>26} {:>14}", "concrete point", "updates/s");
    for (label, rate) in super::bench::material_point_rates(2_000_000) {
        outln!("{label:>26} {rate:>14.3e}");
    }
    ExitCode::SUCCESS
}

pub(crate) fn bench_seed(
    refine: Vec<usize>,
    case: fn(usize) -> Result<super::bench::NonlinearRow, String>,
) -> ExitCode {
    outln!(
        "{:>22} {:>9} {:>5} {:>6} {:>7} {:>10} {:>9} {:>8} {:>13}",
        "case",
        "equations",
        "incs",
        "iters",
        "factors",
        "factor ms",
        "assemb s",
        "total s",
        "midspan uy [m]"
    );
    for r in refine {
        match case(r) {
            Ok(x) => outln!(
                "{:>22} {:>9} {:>5} {:>6} {:>7} {:>10.2} {:>9.3} {:>8.3} {:>13.5e}",
                x.case,
                x.equations,
                x.increments,
                x.iterations,
                x.factorisations,
                x.factor_mean_s * 1e3,
                x.assembly_s,
                x.total_s,
                x.result
            ),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(3);
            }
        }
    }
    ExitCode::SUCCESS
}
