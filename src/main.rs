//! The segfem command line: parses arguments, calls the library, shows progress.

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize};
use std::sync::Arc;

/// `println!` for the command's report on stdout. When stdout is a pipe the reader closed
/// (`segfem check m.toml | head -3`) the reader has what it wanted: end quietly with
/// status 0 instead of the panic `println!` gives; any other write error is reported.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout().lock(), $($arg)*) {
            stdout_failed(e)
        }
    }};
}

/// `print!` with the same closed-pipe handling as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut o = std::io::stdout().lock();
        if let Err(e) = write!(o, $($arg)*).and_then(|_| o.flush()) {
            stdout_failed(e)
        }
    }};
}

/// End the process after a failed write to stdout: quietly for a closed pipe, with a
/// message and status 1 otherwise.
fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("error: writing to standard output: {e}");
    std::process::exit(1);
}

/// Large blocks on transparent huge pages (cli::hugepages: fewer page faults).
/// Binary-side modules: the benchmark cases and the allocator (not part of the library).
mod cli {
    pub mod beam_bench;
    pub mod bench;
    pub mod bench_cmd;
    pub mod hugepages;
    pub mod panel_bench;
}
use cli::bench_cmd::{
    bench, bench_bare, bench_beams, bench_material_point, bench_panels, bench_rc, bench_seed,
    bench_seed_failure,
};

#[global_allocator]
static ALLOC: cli::hugepages::HugePageAlloc = cli::hugepages::HugePageAlloc;

/// Bundled examples: (name, description, model file text).
const EXAMPLES: &[(&str, &str, &str)] = &[
    (
        "cantilever",
        "plane-stress cantilever under end shear, Q8, linear",
        include_str!("../examples/cantilever.toml"),
    ),
    (
        "seed-beam",
        "the seed's 7.2 m dry-jointed box beam with an external tendon, MC90 concrete, to failure (docs/validation.md)",
        include_str!("../examples/seed-beam.toml"),
    ),
    (
        "seed-beam-elastic",
        "the seed beam on elastic concrete (the seed's elastic comparison, the README's figures)",
        include_str!("../examples/seed-beam-elastic.toml"),
    ),
    (
        "creep-beam",
        "the seed beam with MC90 creep, shrinkage and relaxation over 10 000 days",
        include_str!("../examples/creep-beam.toml"),
    ),
    (
        "cracked-beam-30y",
        "cracked RC beam (MC90 creep and shrinkage with cracking) under sustained load for 30 years",
        include_str!("../examples/cracked-beam-30y.toml"),
    ),
    (
        "segmental-decompression",
        "three dry-jointed segments, eccentric axial force, bent until the joints open",
        include_str!("../examples/segmental-decompression.toml"),
    ),
    (
        "box-beam",
        "7.2 m box-section beam (banded), self weight then two point loads",
        include_str!("../examples/box-beam.toml"),
    ),
    (
        "pt-beam",
        "12 m post-tensioned beam: bonded parabolic tendon, stressing, grouting, service load",
        include_str!("../examples/pt-beam.toml"),
    ),
    (
        "rc-beam",
        "RC beam in four-point bending to failure (concrete, embedded bars, displacement control)",
        include_str!("../examples/rc-beam.toml"),
    ),
    (
        "viaduct",
        "three-span 3 x 40 m segmental viaduct built span by span on falsework ([viaduct] generator): stages, 30 years, gradient, traffic to failure",
        include_str!("../examples/viaduct.toml"),
    ),
    (
        "viaduct-concrete",
        "the viaduct on cracking, crushing, creeping concrete (kind = \"concrete\", creep = \"mc90\"): stages, 30 years, gradient, traffic to tendon yield",
        include_str!("../examples/viaduct-concrete.toml"),
    ),
    (
        "viaduct-explicit",
        "the same viaduct written out table by table: the regions, mesh, supports, tendons and steps its [viaduct] section generates",
        include_str!("../examples/viaduct-explicit.toml"),
    ),
    (
        "viaduct-cantilever",
        "three-span 60 + 100 + 60 m haunched box built by balanced cantilever ([viaduct] generator): erection, 30 years, LM1 influence lines, envelopes and combinations, design checks, failure",
        include_str!("../examples/viaduct-cantilever.toml"),
    ),
    (
        "gmsh-tapered",
        "two segments meshed with Gmsh (prismatic and tapered), dry joint; -o also writes gmsh-tapered.msh",
        include_str!("../examples/gmsh-tapered.toml"),
    ),
];

/// Files an example reads, written beside it by `segfem example NAME -o FILE`:
/// (example, file name, contents).
const COMPANIONS: &[(&str, &str, &str)] = &[(
    "gmsh-tapered",
    "gmsh-tapered.msh",
    include_str!("../examples/gmsh-tapered.msh"),
)];

#[derive(Parser)]
#[command(
    name = "segfem",
    version,
    about = "Finite element analysis of precast segmental concrete members (plane stress)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a model file and write history.csv, summary.json, results.pvd/.vtu and a
    /// checkpoint at every step end (exit status: docs/running.md).
    Run {
        /// Model file (TOML); with --restart, default: the one the checkpoint names.
        #[arg(required_unless_present = "restart")]
        model: Option<PathBuf>,
        /// Output directory (default: the model file's name without extension, beside it).
        #[arg(short, long, conflicts_with = "restart")]
        output: Option<PathBuf>,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
        /// Print every Newton iteration's residual and energy norms.
        #[arg(short, long)]
        verbose: bool,
        /// When a step fails after all step cuts, report it and go on with the next step
        /// from the last converged state.
        #[arg(long)]
        continue_on_failure: bool,
        /// Continue the stopped run in DIR from its last checkpoint (end of a step).
        #[arg(long, value_name = "DIR")]
        restart: Option<PathBuf>,
        /// Stop after step K (1-based) once its checkpoint is written (exit status 4).
        #[arg(long, value_name = "K")]
        stop_after_step: Option<usize>,
        /// Write no field files (.vtu, results.pvd), whatever the steps' `output`: the
        /// history, summary and checkpoint only, with the same numbers.
        #[arg(long, conflicts_with = "restart")]
        no_fields: bool,
        /// Worker threads of the element loops (default: all cores; results are
        /// bit-identical whatever the number).
        #[arg(long, value_name = "N")]
        threads: Option<usize>,
    },
    /// Validate a model file and print a summary, without solving.
    Check {
        /// Model file (TOML).
        model: PathBuf,
    },
    /// List bundled examples, or write one to stdout or a file.
    Example {
        /// Example name.
        name: Option<String>,
        /// Write to this file instead of stdout.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Build and solve banded beams of growing size; print phase times and peak memory.
    Bench {
        /// Target sizes in dofs, comma separated.
        #[arg(long, value_delimiter = ',', default_values_t = vec![1e4, 1e5, 1e6])]
        dofs: Vec<f64>,
        /// Element kinds, comma separated (Q4, Q8, Q9).
        #[arg(long, value_delimiter = ',', default_values_t = vec!["Q4".to_string(), "Q8".to_string()])]
        element: Vec<String>,
        /// Benchmark: "linear" (banded beams of --dofs), "seed" (the seed beam through joint
        /// opening, refined by each factor of --refine), "long_term" (the seed beam with
        /// MC90 creep, shrinkage and relaxation over 1e4 days in 50 substeps, same --refine),
        /// "long_term_concrete" (examples/creep-beam.toml with the cracking, creeping
        /// concrete: 1e4 days in 50 substeps, then the service load; same --refine),
        /// "seed-failure" (the seed beam on to failure by arc length, each --refine) or
        /// "seed-failure-concrete" (the same with the MC90/Ottosen concrete), "rc" (the RC
        /// beam example to failure, refined by each --refine; 5 ≈ 5e4 equations),
        /// "viaduct" (the three-span viaduct example: all stages, 30 years, gradient and
        /// traffic to failure, refined by each --refine; last column: deflection under the
        /// tandem), "viaduct-concrete" (the same on cracking, creeping concrete, to tendon
        /// yield), "viaduct-cantilever" (the balanced-cantilever example: erection, 30 years,
        /// LM1 lines, failure; --refine 1 only) or
        /// "material-point" (concrete material-point updates per second) or "panels" (the
        /// membrane-panel series of validation/panels/panels.csv, or of --model, under each
        /// concrete model option: test/predicted ratios, mean, COV) or "beams" (the
        /// shear-beam series of validation/beams/beams.csv, or of --model, on 10 and 20 rows).
        #[arg(long, default_value = "linear")]
        case: String,
        /// Mesh refinement factors (1 = the example's own mesh). Default 1,4; the
        /// viaduct-cantilever case 1 only; the viaduct-concrete case 1 only: its 4x mesh does not yet get past striking the
        /// first falsework (docs/performance.md).
        #[arg(long, value_delimiter = ',')]
        refine: Vec<usize>,
        /// Instead: time faer's bare Cholesky (AMD, and segfem's ordering) of this model
        /// file's stiffness matrix, the baseline of the whole-process time; prints JSON.
        #[arg(long)]
        model: Option<PathBuf>,
        /// Beams case: plate increment [mm] (default 0.2; brittle shear peaks with IMPL-EX
        /// need 0.05 or less, docs/validation.md).
        #[arg(long)]
        plate_increment_mm: Option<f64>,
        /// Beams case: element rows through the depth of each run, comma separated
        /// (default 10,20).
        #[arg(long, value_delimiter = ',')]
        rows: Vec<usize>,
        /// Beams case: run only this model option (its name as the report prints it, e.g.
        /// "rotating, VC93"); repeat for several (default: all).
        #[arg(long = "option")]
        options: Vec<String>,
    },
    /// Draw figures (PNG and SVG) of a finished run: curves, mesh, deformed shape, fields.
    Plot(PlotArgs),
    /// Write a self-contained HTML report of a finished run.
    Report(ReportArgs),
}

#[derive(clap::Args)]
struct PlotArgs {
    /// Run output directory (with history.csv, results.pvd).
    dir: PathBuf,
    /// x column of the history curve (monitor name).
    #[arg(long)]
    x: Option<String>,
    /// y columns of the history curve, comma separated.
    #[arg(long, value_delimiter = ',')]
    y: Vec<String>,
    /// Reference points: CSV with a header and two columns (x, y).
    #[arg(long = "ref")]
    reference: Option<PathBuf>,
    /// Further run directories drawn on the same chart, comma separated.
    #[arg(long, value_delimiter = ',')]
    runs: Vec<PathBuf>,
    /// Output number (1-based, as listed in results.pvd; default: the last).
    #[arg(long)]
    step: Option<usize>,
    /// Field of the colour map: sx, sy, txy, s1, s2.
    #[arg(long)]
    field: Option<String>,
    /// Colour map of element averages instead of smoothed nodal values.
    #[arg(long)]
    cells: bool,
    /// Magnification of the deformed shape (default: largest displacement = 5 % of model size).
    #[arg(long)]
    scale: Option<f64>,
    /// Output directory (default: DIR/figures).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Further y columns, comma separated, each against --x in its own figure curves_COL.
    #[arg(long, value_delimiter = ',')]
    also: Vec<String>,
    /// Units of the curves: display (mm, kN, MPa) or si (m, N, Pa as in history.csv).
    #[arg(long, default_value = "display", value_parser = ["display", "si"])]
    units: String,
    /// Signs of the curves: engineering (deflection positive down, forces positive) or raw.
    #[arg(long, default_value = "engineering", value_parser = ["engineering", "raw"])]
    sign: String,
}

#[derive(clap::Args)]
struct ReportArgs {
    /// Run output directory.
    dir: PathBuf,
    /// HTML file to write (default: DIR/report.html).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Reference points (CSV, two columns x, y) for a comparison table.
    #[arg(long = "ref")]
    reference: Option<PathBuf>,
    /// x column of the history curve.
    #[arg(long)]
    x: Option<String>,
    /// y column of the history curve.
    #[arg(long)]
    y: Option<String>,
    /// Output number for the drawings (1-based; default: the last).
    #[arg(long)]
    step: Option<usize>,
    /// Units of the curve: display (mm, kN, MPa) or si (m, N, Pa as in history.csv).
    #[arg(long, default_value = "display", value_parser = ["display", "si"])]
    units: String,
    /// Signs of the curve: engineering (deflection positive down, forces positive) or raw.
    #[arg(long, default_value = "engineering", value_parser = ["engineering", "raw"])]
    sign: String,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run {
            model,
            output,
            quiet,
            verbose,
            continue_on_failure,
            restart,
            stop_after_step,
            no_fields,
            threads,
        } => {
            if stop_after_step == Some(0) {
                eprintln!("error: --stop-after-step: steps are numbered from 1");
                return ExitCode::from(2);
            }
            if let Some(n) = threads {
                if n == 0 {
                    eprintln!("error: --threads: at least 1 thread");
                    return ExitCode::from(2);
                }
                if let Err(e) = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build_global()
                {
                    eprintln!("error: --threads: {e}");
                    return ExitCode::from(1);
                }
            }
            let opts = segfem::run::RunOptions {
                verbose,
                continue_on_failure,
                stop_after_step,
                signal: Some(stop_on_signals()),
                restart: restart.is_some(),
                caller_stop: None,
                no_fields,
            };
            let out = match (&restart, &output, &model) {
                (Some(d), _, _) => d.clone(),
                (None, Some(o), _) => o.clone(),
                (None, None, Some(m)) => m.with_extension(""),
                (None, None, None) => unreachable!("clap requires MODEL without --restart"),
            };
            run(model, out, quiet, &opts)
        }
        Command::Check { model } => check(model),
        Command::Example { name, output } => example(name, output),
        Command::Bench {
            dofs,
            element,
            case,
            refine,
            model,
            plate_increment_mm,
            rows,
            options,
        } => {
            let refine = match (refine.is_empty(), case.as_str()) {
                (false, _) => refine,
                (true, "viaduct-concrete" | "viaduct-cantilever") => vec![1],
                (true, _) => vec![1, 4],
            };
            match case.as_str() {
                _ if model.is_some() && case != "panels" && case != "beams" => {
                    bench_bare(model.as_deref().expect("checked"))
                }
                "linear" => bench(dofs, element),
                "seed" => bench_seed(refine, cli::bench::seed_case),
                "long_term" => bench_seed(refine, cli::bench::seed_long_term_case),
                "long_term_concrete" => bench_seed(refine, cli::bench::creep_beam_concrete_case),
                "seed-failure" => bench_seed_failure(refine, false),
                "rc" => bench_rc(refine),
                "viaduct" => bench_seed(refine, cli::bench::viaduct_case),
                "viaduct-concrete" => bench_seed(refine, cli::bench::viaduct_concrete_case),
                "viaduct-cantilever" => bench_seed(refine, cli::bench::viaduct_cantilever_case),
                "material-point" => bench_material_point(),
                "seed-failure-concrete" => bench_seed_failure(refine, true),
                "panels" => bench_panels(model.as_deref()),
                "beams" => {
                    let mut set = cli::beam_bench::SeriesSettings {
                        options,
                        ..Default::default()
                    };
                    if let Some(mm) = plate_increment_mm {
                        set.plate_increment = 1e-3 * mm;
                    }
                    if !rows.is_empty() {
                        set.rows = rows;
                    }
                    bench_beams(model.as_deref(), &set)
                }
                o => {
                    eprintln!("error: --case: unknown case '{o}' (linear, seed, long_term, long_term_concrete, seed-failure, seed-failure-concrete, rc, viaduct, viaduct-concrete, viaduct-cantilever, material-point, panels or beams)");
                    ExitCode::from(2)
                }
            }
        }
        Command::Plot(a) => view_plot(a),
        Command::Report(a) => view_report(a),
    }
}

fn view_plot(a: PlotArgs) -> ExitCode {
    use segfem::view;
    let field = match a
        .field
        .as_deref()
        .map(str::parse::<view::Field>)
        .transpose()
    {
        Ok(f) => f,
        Err(e) => return view_error(e),
    };
    let opts = view::PlotOptions {
        dir: a.dir,
        x: a.x,
        y: a.y,
        reference: a.reference,
        runs: a.runs,
        step: a.step,
        field,
        cells: a.cells,
        scale: a.scale,
        out: a.output,
        units: view::UnitOptions {
            si: a.units == "si",
            raw_sign: a.sign == "raw",
        },
    };
    let extra = match view::extra_curves(&opts, &a.also) {
        Ok(f) => f,
        Err(e) => return view_error(e),
    };
    match view::plot(&opts) {
        Ok(o) => {
            extra.iter().for_each(|f| outln!("{}", f.display()));
            o.notes.iter().for_each(|n| eprintln!("note: {n}"));
            o.files.iter().for_each(|f| outln!("{}", f.display()));
            ExitCode::SUCCESS
        }
        Err(e) => view_error(e),
    }
}

fn view_report(a: ReportArgs) -> ExitCode {
    use segfem::view::report;
    let opts = report::ReportOptions {
        dir: a.dir,
        out: a.output,
        reference: a.reference,
        x: a.x,
        y: a.y,
        step: a.step,
        units: segfem::view::UnitOptions {
            si: a.units == "si",
            raw_sign: a.sign == "raw",
        },
    };
    match report::report(&opts) {
        Ok((path, notes)) => {
            notes.iter().for_each(|n| eprintln!("note: {n}"));
            outln!("{}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => view_error(e),
    }
}

fn view_error(e: segfem::view::ViewError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code())
}

/// Make SIGINT and SIGTERM set a flag (the signal number) that the analysis reads after
/// every increment: it then writes its results and stops. A second signal while the flag
/// is set ends the process at once (status 128 + signal), for a run that does not answer.
fn stop_on_signals() -> Arc<AtomicUsize> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicUsize::new(0));
    let seen = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // Order matters: the shutdown test runs before the flag is set by this signal.
        let ok = signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, seen.clone())
            .and_then(|_| signal_hook::flag::register(sig, seen.clone()))
            .and_then(|_| signal_hook::flag::register_usize(sig, flag.clone(), sig as usize));
        if let Err(e) = ok {
            eprintln!("warning: cannot handle signal {sig} ({e}); it will end the run at once");
        }
    }
    flag
}

fn run(
    model: Option<PathBuf>,
    out: PathBuf,
    quiet: bool,
    opts: &segfem::run::RunOptions,
) -> ExitCode {
    let tty = std::io::stderr().is_terminal() && !quiet;
    let bar = if tty {
        let b = ProgressBar::new_spinner();
        b.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
                .expect("valid template"),
        );
        Some(b)
    } else {
        None
    };
    let mut on_inc = |s: &segfem::analysis::steps::Snapshot| {
        let msg = format!(
            "step {} increment {} converged in {} iterations",
            s.step + 1,
            s.increment,
            s.iterations
        );
        match &bar {
            Some(b) => {
                b.set_message(msg);
                b.tick();
            }
            None if !quiet => eprintln!("{msg}"),
            None => {}
        }
    };
    let res = segfem::run::run_file_opts(model.as_deref(), &out, &mut on_inc, opts);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let shown = model
        .clone()
        .unwrap_or_else(|| out.join(segfem::results::checkpoint::FILE));
    match res {
        Ok(s) => {
            for w in &s.warnings {
                eprintln!("warning: {w}");
            }
            if !quiet {
                outln!(
                    "{}: {} nodes, {} elements, {} equations; {} increments, {} iterations in {:.3} s",
                    shown.display(),
                    s.size.nodes,
                    s.size.elements,
                    s.size.equations,
                    s.timings.increments,
                    s.timings.iterations,
                    s.wall_s
                );
                // The verdict is the headline: what failed and at what load.
                if let Some(u) = &s.ultimate {
                    outln!("{u}");
                }
                for c in &s.design_checks {
                    outln!("{}", c.text);
                }
                for (n, v) in &s.final_monitors {
                    outln!("  {n} = {v:.6e}");
                }
                // The governing traffic positions, so that a later step can put the
                // vehicle there (docs/input.md, `[[influence]]`).
                for line in segfem::results::envelopes::headlines(&s.influence) {
                    outln!("{line}");
                }
                outln!("results in {}", out.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            use segfem::run::RunError;
            // A run that got as far as solving wrote its summary, with the warnings (an
            // earlier run's files removed, ...): said here too, before the error.
            if matches!(
                e,
                RunError::NotConverged(_)
                    | RunError::Mechanism { .. }
                    | RunError::Interrupted { .. }
                    | RunError::Stopped(_)
                    | RunError::Implausible(_)
            ) {
                for w in summary_warnings(&out) {
                    eprintln!("warning: {w}");
                }
            }
            eprintln!("error: {e}");
            match &e {
                segfem::run::RunError::NotConverged(_) => eprintln!(
                    "results up to the last converged increment are in {}",
                    out.display()
                ),
                segfem::run::RunError::Implausible(_) => eprintln!(
                    "all results are in {} (check them before any use)",
                    out.display()
                ),
                _ => {}
            }
            ExitCode::from(e.exit_code().clamp(0, 255) as u8)
        }
    }
}

/// The warnings of `out`/summary.json (empty if it cannot be read).
fn summary_warnings(out: &Path) -> Vec<String> {
    std::fs::read_to_string(out.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| {
            v["warnings"].as_array().map(|a| {
                a.iter()
                    .filter_map(|w| w.as_str().map(String::from))
                    .collect()
            })
        })
        .unwrap_or_default()
}

fn check(model: PathBuf) -> ExitCode {
    match segfem::input::load(&model) {
        Ok(b) => {
            for w in &b.warnings {
                eprintln!("warning: {w}");
            }
            let m = &b.model;
            outln!("{}: valid", model.display());
            outln!("  title:     {}", m.title);
            outln!("  nodes:     {}", m.nodes.len());
            outln!("  elements:  {}", m.elements.len());
            let fixed: Vec<(usize, f64)> = m
                .supports
                .iter()
                .flat_map(|s| s.dofs.iter().map(|(n, d, v)| (2 * n + d.index(), *v)))
                .collect();
            let equations = segfem::fem::dofs::DofMap::new(m.nodes.len(), &fixed).n_eq;
            outln!("  dofs:      {}", m.n_dofs());
            outln!("  equations: {equations} (dofs not held by supports)");
            let names = |v: Vec<&str>| {
                if v.is_empty() {
                    "none".to_string()
                } else {
                    v.join(", ")
                }
            };
            outln!(
                "  materials: {}",
                names(m.materials.iter().map(|x| x.name.as_str()).collect())
            );
            outln!(
                "  joints:    {}",
                names(m.joints.iter().map(|x| x.name.as_str()).collect())
            );
            outln!(
                "  tendons:   {}",
                names(m.tendons.iter().map(|x| x.name.as_str()).collect())
            );
            outln!(
                "  bars:      {}",
                names(m.bars.iter().map(|x| x.name.as_str()).collect())
            );
            outln!(
                "  regions:   {}",
                m.regions
                    .iter()
                    .map(|r| format!("{} (t = {} m)", r.name, r.thickness))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            outln!(
                "  supports:  {}",
                m.supports
                    .iter()
                    .enumerate()
                    .map(|(i, s)| {
                        let one_way = m
                            .staging
                            .push(i)
                            .map_or(String::new(), |p| format!(", one-way {}", p.name()));
                        match s.dofs.len() {
                            1 => format!("{} (1 dof{one_way})", s.name),
                            n => format!("{} ({n} dofs{one_way})", s.name),
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            outln!(
                "  loads:     {}",
                m.load_cases
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            outln!(
                "  monitors:  {}",
                m.monitors
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            outln!(
                "  steps:     {}",
                m.steps
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            if let Some(t) = segfem::input::stage_table(m) {
                out!("{t}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn example(name: Option<String>, output: Option<PathBuf>) -> ExitCode {
    let Some(name) = name else {
        // Descriptions in one column, after the longest name.
        let w = EXAMPLES.iter().map(|e| e.0.len()).max().unwrap_or(0);
        for (n, d, _) in EXAMPLES {
            outln!("{n:w$}  {d}");
        }
        return ExitCode::SUCCESS;
    };
    let Some((_, _, text)) = EXAMPLES.iter().find(|(n, _, _)| *n == name) else {
        eprintln!(
            "error: no example named '{name}' (available: {})",
            EXAMPLES.iter().map(|e| e.0).collect::<Vec<_>>().join(", ")
        );
        return ExitCode::from(2);
    };
    let companions = COMPANIONS.iter().filter(|(n, _, _)| *n == name);
    match output {
        Some(p) => {
            let dir = p.parent().unwrap_or(std::path::Path::new(""));
            let files = std::iter::once((p.clone(), *text))
                .chain(companions.map(|(_, f, t)| (dir.join(f), *t)));
            for (path, text) in files {
                if let Err(e) = std::fs::write(&path, text) {
                    eprintln!("error: {}: {e}", path.display());
                    return ExitCode::from(1);
                }
            }
            ExitCode::SUCCESS
        }
        None => {
            out!("{text}");
            for (_, f, _) in companions {
                eprintln!("note: this example reads {f}; `segfem example {name} -o FILE` writes it beside FILE");
            }
            ExitCode::SUCCESS
        }
    }
}
