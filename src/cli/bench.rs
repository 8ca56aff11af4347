//! The `segfem bench` job: build and solve banded plane-stress beams of growing size and
//! print the time of each phase and the peak memory.

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::elements::continuum::Integration;
use segfem::materials::point::Material;
use segfem::mesh::banded::{generate, Band};
use segfem::model::ElementKind;
use segfem::model::*;
use std::time::Instant;

/// A simply supported-free cantilever-like banded beam (three bands: flange, web, flange)
/// with about `target_dofs` degrees of freedom, clamped at x = 0, loaded at the free end.
pub fn banded_beam(kind: ElementKind, target_dofs: usize) -> Model {
    // Mesh with nx = 4 ny: dofs ≈ 2 (nx+1)(ny+1) for Q4, ≈ 6 nx ny for Q8/Q9 (8 for Q9).
    // Dofs per cell: 2 × the nodes per element of a large grid (1 Q4, 3 Q8, 4 Q9).
    let per_cell = 2.0 * kind.grid_nodes(1e4, 1e4).map_or(1.0, |n| (n / 1e8).round());
    let ny = ((target_dofs as f64 / (4.0 * per_cell)).sqrt().round() as usize).max(3);
    let nx = 4 * ny;
    let r1 = ny / 5;
    let r3 = ny / 5;
    let bands = [
        Band {
            depth: 0.2,
            rows: r1.max(1),
            region: 0,
        },
        Band {
            depth: 0.6,
            rows: (ny - r1 - r3).max(1),
            region: 1,
        },
        Band {
            depth: 0.2,
            rows: r3.max(1),
            region: 2,
        },
    ];
    let g = generate([0.0, 0.0], 4.0, nx, &bands, kind);
    let elements = g
        .elements
        .into_iter()
        .map(|(nodes, region)| Element {
            kind,
            nodes,
            region,
            integration: Integration::Full,
        })
        .collect();
    let mut model = Model {
        title: format!("bench {kind:?} {target_dofs}"),
        nodes: g.nodes,
        elements,
        regions: vec![
            Region {
                name: "bottom".into(),
                material: 0,
                thickness: 0.7,
            },
            Region {
                name: "web".into(),
                material: 0,
                thickness: 0.2,
            },
            Region {
                name: "top".into(),
                material: 0,
                thickness: 1.2,
            },
        ],
        materials: vec![NamedMaterial {
            name: "concrete".into(),
            law: Material::Elastic {
                e: 35e9,
                nu: 0.2,
                density: 2500.0,
            },
            strength: None,
        }],
        interfaces: vec![],
        joints: vec![],
        tendons: vec![],
        supports: vec![],
        load_cases: vec![],
        monitors: vec![],
        steps: vec![Step {
            name: "load".into(),
            kind: StepKind::Linear,
            factors: vec![1.0],
            increments: 1,
            field_output: Default::default(),
            path: None,
            time: None,
        }],
        controls: SolverControls::default(),
        geometry: Default::default(),
        bars: Vec::new(),
        staging: Default::default(),
        checks: Vec::new(),
        influence: Vec::new(),
    };
    let wall: Vec<(usize, Dir, f64)> = model
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, p)| p[0] == 0.0)
        .flat_map(|(i, _)| [(i, Dir::X, 0.0), (i, Dir::Y, 0.0)])
        .collect();
    model.supports.push(Support {
        name: "wall".into(),
        dofs: wall,
    });
    let tip = model
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, p)| (p[0] - 4.0).abs() < 1e-9)
        .min_by(|a, b| (a.1[1] - 0.5).abs().total_cmp(&(b.1[1] - 0.5).abs()))
        .map(|(i, _)| i)
        .expect("tip node");
    model.load_cases.push(LoadCase {
        name: "tip".into(),
        point_forces: vec![(tip, [0.0, -1e5])],
        ..Default::default()
    });
    model.monitors.push(Monitor {
        name: "tip_uy".into(),
        kind: MonitorKind::Displacement {
            node: tip,
            dir: Dir::Y,
            since_step: None,
        },
    });
    model
}

struct TipOnly {
    node: usize,
    value: f64,
}

impl Observer for TipOnly {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        self.value = snap.system.displacements()[2 * self.node + 1];
        Ok(())
    }
}

/// One benchmark line.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BenchRow {
    /// Element kind.
    pub kind: String,
    /// Equations.
    pub dofs: usize,
    /// Mesh generation [s].
    pub mesh_s: f64,
    /// Dof map, pattern, states [s].
    pub setup_s: f64,
    /// Element loops and scatter [s].
    pub assembly_s: f64,
    /// Ordering and symbolic factorisation [s].
    pub ordering_s: f64,
    /// Numeric factorisation [s].
    pub factor_s: f64,
    /// Triangular solves [s].
    pub solve_s: f64,
    /// Whole run [s].
    pub total_s: f64,
    /// Peak resident memory so far [bytes].
    pub peak_bytes: u64,
    /// Tip deflection [m] (a check that the run solved something).
    pub tip_uy: f64,
}

/// Run one benchmark case.
pub fn run_case(kind: ElementKind, target_dofs: usize) -> Result<BenchRow, steps::AnalysisError> {
    let t0 = Instant::now();
    let model = banded_beam(kind, target_dofs);
    let mesh_s = t0.elapsed().as_secs_f64();
    let node = match model.monitors[0].kind {
        MonitorKind::Displacement { node, .. } => node,
        _ => unreachable!("bench monitor is a displacement"),
    };
    let mut obs = TipOnly { node, value: 0.0 };
    let t = steps::run(&model, &mut obs)?;
    Ok(BenchRow {
        kind: format!("{kind:?}"),
        dofs: model.n_dofs(),
        mesh_s,
        setup_s: t.setup_s - t.solver.symbolic_s,
        assembly_s: t.assembly_s,
        ordering_s: t.solver.symbolic_s,
        factor_s: t.solver.numeric_s,
        solve_s: t.solver.solve_s,
        total_s: t0.elapsed().as_secs_f64(),
        peak_bytes: segfem::run::peak_memory().unwrap_or(0),
        tip_uy: obs.value,
    })
}

/// Figures of a nonlinear benchmark run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct NonlinearRow {
    /// Case name.
    pub case: String,
    /// Free equations.
    pub equations: usize,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations in all.
    pub iterations: usize,
    /// Numeric factorisations.
    pub factorisations: usize,
    /// Mean time of one numeric factorisation [s].
    pub factor_mean_s: f64,
    /// Element loops in all [s].
    pub assembly_s: f64,
    /// Whole run [s].
    pub total_s: f64,
    /// Final midspan deflection [m] (a check that the run went through).
    pub result: f64,
}

/// Follows the vertical displacement [m] of the soffit node at x = `.0` [m] (the check
/// value of a bench row).
struct DeflectionAt(f64, f64);

impl Observer for DeflectionAt {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let m = snap.system.model;
        if let Some(n) = m
            .nodes
            .iter()
            .position(|p| (p[0] - self.0).abs() < 1e-6 && p[1].abs() < 1e-9)
        {
            self.1 = snap.system.displacements()[2 * n + 1];
        }
        Ok(())
    }
}

/// Parses model text `text` (named `file` in errors), runs all its steps and times them,
/// following the soffit deflection at x = `x` [m]: the row `case` of a nonlinear bench.
fn timed_row(text: &str, file: &str, case: String, x: f64) -> Result<NonlinearRow, String> {
    let t0 = Instant::now();
    let model = segfem::input::parse(text, file)
        .map_err(|e| e.to_string())?
        .model;
    let mut obs = DeflectionAt(x, 0.0);
    let t = steps::run(&model, &mut obs).map_err(|e| e.to_string())?;
    let equations = segfem::analysis::system::System::new(&model).dofs.n_eq;
    Ok(NonlinearRow {
        case,
        equations,
        increments: t.increments,
        iterations: t.iterations,
        factorisations: t.solver.factorisations,
        factor_mean_s: t.solver.numeric_s / t.solver.factorisations.max(1) as f64,
        assembly_s: t.assembly_s,
        total_s: t0.elapsed().as_secs_f64(),
        result: obs.1,
    })
}

/// Midspan of the seed beam and of the examples built on its mesh [m].
const SEED_MIDSPAN: f64 = 3.6;

/// `text` (the seed beam's mesh keys: 6 columns a segment, rows of 0.10 m and 0.40 m) with
/// its mesh refined `r` times in both directions.
pub fn refine_seed_mesh(text: &str, r: usize) -> String {
    text.replace(
        "nx_per_segment = 6 ",
        &format!("nx_per_segment = {} ", 6 * r),
    )
    .replace(
        "depth = 0.10, rows = 1 ",
        &format!("depth = 0.10, rows = {r} "),
    )
    .replace(
        "depth = 0.40, rows = 4 ",
        &format!("depth = 0.40, rows = {} ", 4 * r),
    )
}

/// The seed beam's model file (bundled example) with its mesh refined `refine` times in both
/// directions (1: the seed's coarse mesh, 6 rows through the depth).
fn seed_text(refine: usize) -> String {
    let r = refine.max(1);
    seed_text_to_failure(r)
        .split("[[steps]]\nname = \"failure\"")
        .next()
        .unwrap_or_default()
        .to_string()
}

/// The bundled seed beam, refined as in [`seed_text`], with its last step on to failure.
fn seed_text_to_failure(refine: usize) -> String {
    refine_seed_mesh(
        include_str!("../../examples/seed-beam-elastic.toml"),
        refine.max(1),
    )
}

/// The seed beam (bundled example) with its mesh refined `refine` times in both directions
/// (refine = 1: the seed's coarse mesh, 6 rows through the depth), self weight, prestress and
/// Q up to 140 kN, joints opening on the way.
pub fn seed_case(refine: usize) -> Result<NonlinearRow, String> {
    let r = refine.max(1);
    let text = seed_text(r);
    timed_row(
        &text,
        "seed-beam.toml",
        format!("seed beam, {} rows", 6 * r),
        SEED_MIDSPAN,
    )
}

/// The seed beam (bundled example, mesh refined `refine` times as in [`seed_case`]) held
/// for 10⁴ days (issue #6 item 8): its elastic concrete replaced by MC90 creep and shrinkage
/// (ageing Maxwell chain, f_cm 45 MPa, RH 70 %, h0 0.2 m), tendon relaxation class 2;
/// self weight and prestress on day 28, then one time step of 50 log-spaced substeps to
/// day 10 028. Reports the final midspan deflection.
pub fn seed_long_term_case(refine: usize) -> Result<NonlinearRow, String> {
    let r = refine.max(1);
    let seed = seed_text(r);
    let head = &seed[..seed
        .find("[[steps]]")
        .ok_or("seed-beam.toml has no steps")?];
    let text = head
        .replace(
            "kind = \"elastic\"\nE = 35.5e9          # MC90 Eci for fcm = 45 MPa",
            "kind = \"elastic_creep\"\nrh = 0.70\nh0 = 0.200\ncement = \"N\"",
        )
        .replace(
            "deviators = \"held\"",
            "deviators = \"held\"\nrelaxation_class = 2",
        );
    if !text.contains("elastic_creep") || !text.contains("relaxation_class") {
        return Err("seed-beam.toml changed: cannot build the long-term case".into());
    }
    let text = format!(
        "{text}\n[[steps]]\nname = \"prestress\"\nkind = \"load\"\nloads = {{ self_weight = 1.0 }}\n\n[[steps]]\nname = \"long_term\"\nkind = \"time\"\nfrom = 28.0\nduration = 1e4\nsubsteps = 50\n"
    );
    timed_row(
        &text,
        "seed-beam-long-term.toml",
        format!("seed 1e4 d, {} rows", 6 * r),
        SEED_MIDSPAN,
    )
}

/// Soffit point under the tandem of the viaduct example's traffic pattern [m].
const VIADUCT_TANDEM_X: f64 = 15.375;

/// The bundled three-span viaduct (examples/viaduct.toml, issue #20 item 8) with its mesh
/// refined `refine` times in both directions (1: the example's 2 columns a segment and 6
/// rows): erection span by span (11 stages), 30 years of creep, shrinkage and relaxation,
/// the heating gradient and the traffic pattern to failure. Reports the final deflection
/// under the tandem [m].
pub fn viaduct_case(refine: usize) -> Result<NonlinearRow, String> {
    refined_viaduct(
        include_str!("../../examples/viaduct.toml"),
        "viaduct",
        refine,
    )
}

/// The same on cracking, crushing, creeping concrete (examples/viaduct-concrete.toml,
/// issue 38 items 2 and 8): every stage, 30 years, the gradient and the traffic to tendon
/// yield and L/100. Reports the final deflection under the tandem [m].
pub fn viaduct_concrete_case(refine: usize) -> Result<NonlinearRow, String> {
    refined_viaduct(
        include_str!("../../examples/viaduct-concrete.toml"),
        "viaduct-concrete",
        refine,
    )
}

/// The balanced-cantilever viaduct (examples/viaduct-cantilever.toml, issue 39 item 6):
/// erection in 36 stages, 30 years, LM1 influence lines over 253 positions, the governing
/// position to L/100. The example's mesh only (`refine` 1). Reports the final deflection at
/// mid-span of the main span [m].
pub fn viaduct_cantilever_case(refine: usize) -> Result<NonlinearRow, String> {
    if refine > 1 {
        return Err("viaduct-cantilever: --refine 1 only (the example's mesh)".into());
    }
    timed_row(
        include_str!("../../examples/viaduct-cantilever.toml"),
        "viaduct-cantilever.toml",
        "viaduct-cantilever, 6 rows".into(),
        110.0,
    )
}

/// A viaduct example's text `example` (file name `name`.toml) with its mesh refined
/// `refine` times, timed.
fn refined_viaduct(example: &str, name: &str, refine: usize) -> Result<NonlinearRow, String> {
    let r = refine.max(1);
    let text = example
        .replace(
            "nx_per_segment = 2 ",
            &format!("nx_per_segment = {} ", 2 * r),
        )
        .replace(
            "depth = 0.25, rows = 1 }",
            &format!("depth = 0.25, rows = {r} }}"),
        )
        .replace(
            "depth = 1.90, rows = 4 }",
            &format!("depth = 1.90, rows = {} }}", 4 * r),
        );
    if r > 1 && !text.contains(&format!("depth = 1.90, rows = {} }}", 4 * r)) {
        return Err(format!("{name}.toml changed: cannot refine its mesh"));
    }
    timed_row(
        &text,
        &format!("{name}.toml"),
        format!("{name}, {} rows", 6 * r),
        VIADUCT_TANDEM_X,
    )
}

/// `examples/creep-beam.toml` (the seed beam's seven segments cast 30–90 days before
/// erection, prestress and self weight on day 0, 50 log-spaced substeps to 10⁴ d, then the
/// service load Q = 56 kN in 4 increments) with its `elastic_creep` concrete replaced by the
/// cracking, creeping concrete (`kind = "concrete"`, `creep = "mc90"`, same MC90 keys), mesh
/// refined `refine` times as in [`seed_case`] (issue 19 item 7). Reports the final midspan
/// deflection [m].
pub fn creep_beam_concrete_case(refine: usize) -> Result<NonlinearRow, String> {
    let r = refine.max(1);
    let example = include_str!("../../examples/creep-beam.toml");
    let text = refine_seed_mesh(example, r).replace(
        "kind = \"elastic_creep\"",
        "kind = \"concrete\"\ncreep = \"mc90\"",
    );
    if !text.contains("creep = \"mc90\"") || (r > 1 && text.contains("rows = 4 ")) {
        return Err("creep-beam.toml changed: cannot build the cracking-concrete case".into());
    }
    timed_row(
        &text,
        "creep-beam-concrete.toml",
        format!("creep concrete, {} rows", 6 * r),
        SEED_MIDSPAN,
    )
}

/// CPU time of this process so far, user + system, all threads [s] (Linux /proc/self/stat,
/// in clock ticks of 1/100 s, the kernel's USER_HZ); 0 where unknown. Less sensitive than
/// wall time to other work on a shared machine.
pub fn process_cpu_s() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which may hold spaces) in parentheses: utime and
    // stime are the 12th and 13th of them.
    let rest = s.rsplit_once(')').map_or("", |x| x.1);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// Figures of a run of the seed beam to failure.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FailureRow {
    /// Case name.
    pub case: String,
    /// Free equations.
    pub equations: usize,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations of the converged increments.
    pub iterations: usize,
    /// Whole run, including any failed last increment [s].
    pub total_s: f64,
    /// CPU time of the whole run, user + system, all threads [s].
    pub cpu_s: f64,
    /// Largest load Q reached [kN].
    pub q_max: f64,
    /// Midspan deflection at the last converged increment [m] (downward negative).
    pub deflection: f64,
    /// Largest tendon span stress at the last converged increment [Pa].
    pub tendon_stress: f64,
    /// Largest joint opening at the last converged increment [m].
    pub max_opening: f64,
    /// Crushed concrete integration points at the last converged increment [-].
    pub crushed: usize,
    /// How the run ended.
    pub end: String,
    /// The first failure met (see [`segfem::results::ultimate`]).
    pub mode: String,
    /// The IMPL-EX path error around the peak (None without IMPL-EX concrete).
    #[serde(skip)]
    pub path_error: Option<segfem::results::ultimate::PathError>,
    /// Solver and assembly figures (up to the last converged increment when the run stopped early).
    pub timings: steps::Timings,
}

/// Records what a failure run reaches.
/// Run `model` reporting to `obs`; besides the result, the timings of the run, up to the
/// last converged state if it stopped early (not zeros: `Observer::step_stopped`).
fn run_keeping_timings(
    model: &segfem::model::Model,
    obs: &mut dyn Observer,
) -> (Result<steps::Timings, steps::AnalysisError>, steps::Timings) {
    struct KeepTimings<'a> {
        inner: &'a mut dyn Observer,
        stopped: steps::Timings,
    }
    impl Observer for KeepTimings<'_> {
        fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
            self.inner.increment(snap)
        }
        fn step_stopped(
            &mut self,
            system: &segfem::analysis::system::System,
            timings: &steps::Timings,
        ) -> std::io::Result<()> {
            self.stopped = timings.clone();
            self.inner.step_stopped(system, timings)
        }
    }
    let mut keep = KeepTimings {
        inner: obs,
        stopped: steps::Timings::default(),
    };
    let result = steps::run(model, &mut keep);
    let timings = match &result {
        Ok(t) => t.clone(),
        Err(_) => keep.stopped,
    };
    (result, timings)
}

#[derive(Default)]
struct Reach {
    watch: segfem::results::ultimate::UltimateWatch,
    increments: usize,
    iterations: usize,
    q_max: f64,
    deflection: f64,
    tendon_stress: f64,
    max_opening: f64,
    crushed: usize,
}

impl Observer for Reach {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let sys = snap.system;
        let m = sys.model;
        self.watch.increment(snap);
        self.increments += 1;
        self.iterations += snap.iterations;
        self.q_max = self.q_max.max(snap.factors[1]);
        if let Some(n) = m
            .nodes
            .iter()
            .position(|p| (p[0] - 3.6).abs() < 1e-9 && p[1].abs() < 1e-9)
        {
            self.deflection = sys.displacements()[2 * n + 1];
        }
        self.tendon_stress =
            (sys.tendon_state(0)).map_or(0.0, |t| t.stresses().into_iter().fold(0.0, f64::max));
        self.max_opening = (0..m.joints.len())
            .map(|j| segfem::results::joints::summarise(sys, j).max_opening)
            .fold(0.0, f64::max);
        self.crushed = sys.point_states().iter().filter(|p| p.is_crushed()).count();
        Ok(())
    }
}

/// The seed beam taken to failure: a bundled example (self weight, prestress, Q to 140 kN,
/// then its arc-length step on Q until the midspan deflection reaches 0.12 m, L/60) refined
/// `refine` times; the run ends there, where Newton gives up (the furthest point the model
/// reaches), or after 400 increments. `concrete`: the `seed-beam` example (MC90/Ottosen
/// concrete, fcm = 45 MPa, IMPL-EX cracking, anchor plates and loading bearings with their
/// local zones, docs/validation.md "The seed beam"); else `seed-beam-elastic`.
pub fn seed_failure_case(refine: usize, concrete: bool) -> Result<FailureRow, String> {
    let r = refine.max(1);
    let text = if concrete {
        // The bundled `seed-beam` example as it stands: MC90 concrete with IMPL-EX
        // cracking, the tendon's anchors on their default anchor plates and local zones,
        // the loads on 0.2 m bearings (docs/theory-prestress.md, "Anchor plates, bearings
        // and local zones"), program solver defaults; its own step on to failure.
        refine_seed_mesh(include_str!("../../examples/seed-beam.toml"), r)
    } else {
        // The elastic example's own step on to failure (arc length to L/60).
        seed_text_to_failure(r)
    };
    seed_failure_of(&text, r, concrete)
}

/// The seed beam's run to failure from its model text `text` (already refined `refine` ×,
/// on MC90 `concrete` or elastic: the case's name), as [`seed_failure_case`] runs it: the
/// text of a variant (other increments, `[solver]` keys) run and measured the same way.
pub fn seed_failure_of(text: &str, refine: usize, concrete: bool) -> Result<FailureRow, String> {
    let r = refine.max(1);
    if !text.contains("[[steps]]\nname = \"failure\"") {
        return Err("seed-beam.toml has no failure step".into());
    }
    let t0 = Instant::now();
    let cpu0 = process_cpu_s();
    let model = segfem::input::parse(text, "seed-beam.toml")
        .map_err(|e| e.to_string())?
        .model;
    let mut obs = Reach::default();
    let (result, timings) = run_keeping_timings(&model, &mut obs);
    let ultimate = obs.watch.finish(&model, result.is_ok());
    let path_error = ultimate.as_ref().and_then(|u| u.path_error.clone());
    let mode = ultimate.map_or_else(String::new, |u| u.mode);
    let end = match result {
        Ok(_) => {
            if obs.deflection <= -0.12 + 1e-9 {
                "deflection L/60 reached".to_string()
            } else {
                "increment limit".to_string()
            }
        }
        Err(steps::AnalysisError::NotConverged(rep)) => format!(
            "no convergence beyond this point (step '{}', increment {})",
            rep.step, rep.increment
        ),
        Err(e) => return Err(e.to_string()),
    };
    let equations = segfem::analysis::system::System::new(&model).dofs.n_eq;
    Ok(FailureRow {
        case: format!(
            "seed beam {}, {} rows",
            if concrete { "concrete" } else { "elastic" },
            6 * r
        ),
        equations,
        increments: obs.increments,
        iterations: obs.iterations,
        total_s: t0.elapsed().as_secs_f64(),
        cpu_s: process_cpu_s() - cpu0,
        q_max: obs.q_max,
        deflection: obs.deflection,
        tendon_stress: obs.tendon_stress,
        max_opening: obs.max_opening,
        crushed: obs.crushed,
        end,
        mode,
        path_error,
        timings,
    })
}

/// faer's bare factorisation of a model's stiffness matrix: the baseline that the
/// whole-process time of `segfem run` is measured against (docs/performance.md).
#[derive(Debug, Clone, serde::Serialize)]
pub struct BareRow {
    /// Free equations.
    pub equations: usize,
    /// faer's AMD ordering and symbolic analysis [s].
    pub amd_symbolic_s: f64,
    /// Numeric LLᵀ after AMD [s].
    pub amd_numeric_s: f64,
    /// Stored factor values after AMD.
    pub amd_factor_nnz: usize,
    /// Floating-point operations of one numeric LLᵀ after AMD (Σ c² over the factor's
    /// columns).
    pub amd_factor_flops: f64,
    /// segfem's ordering (nested dissection above its size threshold) and faer's symbolic
    /// analysis with it [s].
    pub own_symbolic_s: f64,
    /// Numeric LLᵀ after segfem's ordering [s].
    pub own_numeric_s: f64,
    /// Stored factor values after segfem's ordering.
    pub own_factor_nnz: usize,
    /// Floating-point operations of one numeric LLᵀ after segfem's ordering.
    pub own_factor_flops: f64,
    /// Whether segfem's ordering factorises the LLᵀ by halves on two threads (large systems
    /// ordered by nested dissection, [`segfem::linalg::solver::SPLIT_MIN_EQUATIONS`]).
    pub own_split: bool,
    /// Medians of [`BARE_ROUNDS`] numeric LLᵀ (and solves of one right-hand side) after
    /// segfem's ordering, the whole matrix on one core and by halves, alternated [s] (both
    /// the whole matrix's when not split).
    pub own_numeric_whole_s: f64,
    pub own_numeric_split_s: f64,
    pub own_solve_whole_s: f64,
    pub own_solve_split_s: f64,
    /// Largest difference of the two solutions of K x = K·1 relative to the largest entry.
    pub split_rel_diff: f64,
    /// An indefinite matrix of the same pattern, K − σ diag(K) with σ = [`LDLT_SHIFT`]: its
    /// negative pivots (by halves and whole, the same) and medians of [`BARE_ROUNDS`]
    /// factorisations [s] as `factorize_indefinite` runs them: the whole matrix's LLᵀ
    /// attempt then LDLᵀ (after a definite tangent), its LLᵀ and LDLᵀ at once on two cores
    /// (after an indefinite one), by halves after a definite tangent (LLᵀ per half, LDLᵀ
    /// where it fails) and after an indefinite one (LDLᵀ at once where it was needed); the
    /// largest difference of the whole and split solutions relative to the largest entry.
    /// Zero when the system does not go by halves.
    pub ldlt_negative_pivots: usize,
    pub ldlt_whole_sequential_s: f64,
    pub ldlt_whole_concurrent_s: f64,
    pub ldlt_split_s: f64,
    pub ldlt_split_next_s: f64,
    pub ldlt_rel_diff: f64,
    /// Medians of [`BARE_ROUNDS`]: fresh memory of the factor's size (segfem's ordering,
    /// 8 bytes a value) faulted in on two threads, and given back [s]
    /// ([`segfem::linalg::solver::fresh_pages_s`]): with the numeric factorisation by halves,
    /// the least a whole run's factorisation costs on this machine.
    pub factor_pages_fault_s: f64,
    pub factor_pages_free_s: f64,
}

/// Shift σ of the indefinite matrix K − σ diag(K) of [`BareRow`]: a few negative
/// eigenvalues of K φ = λ diag(K) φ for the beams and squares measured (its smallest ones
/// are 1e-6–1e-4).
pub const LDLT_SHIFT: f64 = 1e-3;

/// Rounds of [`BareRow::own_numeric_whole_s`] and [`BareRow::own_numeric_split_s`].
const BARE_ROUNDS: usize = 5;

/// Assemble the initial stiffness of the model in `path` and time faer's sequential
/// Cholesky on it: AMD (faer's default) and segfem's own ordering, each symbolic + numeric.
pub fn bare_factorisation(path: &std::path::Path) -> Result<BareRow, String> {
    use segfem::analysis::system::System;
    use segfem::linalg::solver::SparseCholesky;
    let model = segfem::input::load(path).map_err(|e| e.to_string())?.model;
    let mut sys = System::new(&model);
    let u = vec![0.0; model.n_dofs()];
    let k = sys
        .assemble(&u, true)
        .map_err(|(e, err)| format!("element {}: {err}", e + 1))?
        .k_values
        .expect("tangent requested");
    let pattern = &sys.asm.pattern;
    type Figures = (f64, f64, usize, f64);
    let time = |order: Option<&[usize]>, extra: f64| -> Result<Figures, String> {
        let t = Instant::now();
        let mut s = SparseCholesky::with_ordering(pattern, order).map_err(|e| e.to_string())?;
        let sym = t.elapsed().as_secs_f64() + extra;
        let t = Instant::now();
        s.factorize(pattern, &k).map_err(|e| e.to_string())?;
        Ok((
            sym,
            t.elapsed().as_secs_f64(),
            s.stats.factor_nnz,
            s.factor_flops(),
        ))
    };
    let (amd_symbolic_s, amd_numeric_s, amd_factor_nnz, amd_factor_flops) = time(None, 0.0)?;
    let (own_symbolic_s, own_numeric_s, _, _) = time(sys.ordering.as_deref(), sys.ordering_s)?;
    // The whole-matrix and the split factorisation of the same matrix, alternated.
    let order = sys.ordering.as_deref();
    let mut split = SparseCholesky::with_ordering(pattern, order).map_err(|e| e.to_string())?;
    let own_split = split.is_split();
    let mut whole = SparseCholesky::with_ordering(pattern, order)
        .map_err(|e| e.to_string())?
        .without_split(pattern)
        .map_err(|e| e.to_string())?;
    let ones = vec![1.0; pattern.n];
    let mut b = vec![0.0; pattern.n];
    pattern.sym_mul(&k, &ones, &mut b);
    let (mut tw, mut ts, mut sw, mut ss) = (vec![], vec![], vec![], vec![]);
    let (mut xw, mut xs) = (b.clone(), b.clone());
    for _ in 0..BARE_ROUNDS {
        for (s, tf, tsol, x) in [
            (&mut whole, &mut tw, &mut sw, &mut xw),
            (&mut split, &mut ts, &mut ss, &mut xs),
        ] {
            let t = Instant::now();
            s.factorize(pattern, &k).map_err(|e| e.to_string())?;
            tf.push(t.elapsed().as_secs_f64());
            x.copy_from_slice(&b);
            let t = Instant::now();
            s.solve_in_place(x);
            tsol.push(t.elapsed().as_secs_f64());
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let rel_diff = |xw: &[f64], xs: &[f64]| {
        let scale = xw.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        xw.iter()
            .zip(xs)
            .fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()))
            / scale
    };
    let split_rel_diff = rel_diff(&xw, &xs);
    // The indefinite matrix K − σ diag(K), factorised the three ways, alternated.
    let (mut lw1, mut lw2, mut ls, mut ls2) = (vec![0.0], vec![0.0], vec![0.0], vec![0.0]);
    let (mut ldlt_negative_pivots, mut ldlt_rel_diff) = (0, 0.0);
    if own_split {
        let mut kd = k.clone();
        for i in 0..pattern.n {
            if let Some(q) = pattern.position(i, i) {
                kd[q] -= LDLT_SHIFT * k[q];
            }
        }
        let err = |e: segfem::linalg::solver::SolverError| e.to_string();
        (lw1, lw2, ls, ls2) = (vec![], vec![], vec![], vec![]);
        for _ in 0..BARE_ROUNDS {
            // After a definite tangent: the LLᵀ attempt, then the LDLᵀ.
            whole.factorize_indefinite(pattern, &k).map_err(err)?;
            let t = Instant::now();
            let nw = whole.factorize_indefinite(pattern, &kd).map_err(err)?;
            lw1.push(t.elapsed().as_secs_f64());
            // After an indefinite one: both at once.
            let t = Instant::now();
            whole.factorize_indefinite(pattern, &kd).map_err(err)?;
            lw2.push(t.elapsed().as_secs_f64());
            // By halves after a definite tangent (LLᵀ attempts), then after an indefinite
            // one (LDLᵀ at once in the halves that were indefinite).
            split.factorize_indefinite(pattern, &k).map_err(err)?;
            let t = Instant::now();
            let ns = split.factorize_indefinite(pattern, &kd).map_err(err)?;
            ls.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            split.factorize_indefinite(pattern, &kd).map_err(err)?;
            ls2.push(t.elapsed().as_secs_f64());
            if nw != ns {
                return Err(format!("negative pivots: {nw} whole, {ns} by halves"));
            }
            ldlt_negative_pivots = ns;
        }
        let (mut xw, mut xs) = (b.clone(), b.clone());
        whole.solve_in_place(&mut xw);
        split.solve_in_place(&mut xs);
        ldlt_rel_diff = rel_diff(&xw, &xs);
    }
    let (mut pf, mut pu) = (vec![], vec![]);
    for _ in 0..BARE_ROUNDS {
        let (f, u) = segfem::linalg::solver::fresh_pages_s(8 * whole.stats.factor_nnz);
        pf.push(f);
        pu.push(u);
    }
    Ok(BareRow {
        factor_pages_fault_s: median(&mut pf),
        factor_pages_free_s: median(&mut pu),
        equations: pattern.n,
        amd_symbolic_s,
        amd_numeric_s,
        amd_factor_nnz,
        amd_factor_flops,
        own_symbolic_s,
        own_numeric_s,
        own_factor_nnz: whole.stats.factor_nnz,
        own_factor_flops: whole.factor_flops(),
        own_split,
        own_numeric_whole_s: median(&mut tw),
        own_numeric_split_s: median(&mut ts),
        own_solve_whole_s: median(&mut sw),
        own_solve_split_s: median(&mut ss),
        split_rel_diff,
        ldlt_negative_pivots,
        ldlt_whole_sequential_s: median(&mut lw1),
        ldlt_whole_concurrent_s: median(&mut lw2),
        ldlt_split_s: median(&mut ls),
        ldlt_split_next_s: median(&mut ls2),
        ldlt_rel_diff,
    })
}

/// Figures of the RC-beam benchmark (issue #4 item 8).
#[derive(Debug, Clone, serde::Serialize)]
pub struct RcRow {
    /// Case name.
    pub case: String,
    /// Free equations.
    pub equations: usize,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations of the converged increments.
    pub iterations: usize,
    /// Whole run, including a failed last increment [s].
    pub total_s: f64,
    /// CPU time of the whole run, user + system, all threads [s].
    pub cpu_s: f64,
    /// Largest load per load point reached [N].
    pub p_max: f64,
    /// Midspan deflection at the last converged increment [m].
    pub deflection: f64,
    /// How the run ended ("completed" or the first line of the error).
    pub end: String,
    /// Solver and assembly figures (up to the last converged increment when the run stopped early).
    pub timings: steps::Timings,
}

/// Counts increments and iterations, follows the control force and the midspan deflection.
#[derive(Default)]
struct RcWatch {
    equations: usize,
    increments: usize,
    iterations: usize,
    p_max: f64,
    deflection: f64,
}

impl Observer for RcWatch {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        self.equations = snap.system.dofs.n_eq;
        self.increments += 1;
        self.iterations += snap.iterations;
        self.p_max = self.p_max.max(-snap.control_force.unwrap_or(0.0));
        let m = snap.system.model;
        if let Some(n) = m
            .nodes
            .iter()
            .position(|p| (p[0] - 1.6).abs() < 1e-9 && p[1].abs() < 1e-9)
        {
            self.deflection = -snap.system.displacements()[2 * n + 1];
        }
        Ok(())
    }
}

/// The bundled RC beam (examples/rc-beam.toml) with its mesh refined `refine` times in both
/// directions (1: 32 × 10 Q8; 5: 160 × 50 Q8, about 5e4 equations), taken to failure.
pub fn rc_case(refine: usize) -> Result<RcRow, String> {
    let r = refine.max(1);
    let text = include_str!("../../examples/rc-beam.toml")
        .replace("nx = 32\n", &format!("nx = {}\n", 32 * r))
        .replace("rows = 10 }", &format!("rows = {} }}", 10 * r));
    if r > 1 && !text.contains(&format!("nx = {}\n", 32 * r)) {
        return Err("rc-beam.toml changed: cannot refine its mesh".into());
    }
    let t0 = Instant::now();
    let cpu0 = process_cpu_s();
    let model = segfem::input::parse(&text, "rc-beam.toml")
        .map_err(|e| e.to_string())?
        .model;
    let mut obs = RcWatch::default();
    let (result, timings) = run_keeping_timings(&model, &mut obs);
    let end = match result {
        Ok(_) => "completed".to_string(),
        Err(e) => e.to_string().lines().next().unwrap_or("").to_string(),
    };
    // From the run itself, not from a second system built inside the timed span (pattern,
    // ordering, geometry cache, states); a run with no converged increment builds it.
    let equations = match obs.equations {
        0 => segfem::analysis::system::System::new(&model).dofs.n_eq,
        n => n,
    };
    Ok(RcRow {
        case: format!("RC beam, {} rows", 10 * r),
        equations,
        increments: obs.increments,
        iterations: obs.iterations,
        total_s: t0.elapsed().as_secs_f64(),
        cpu_s: process_cpu_s() - cpu0,
        p_max: obs.p_max,
        deflection: obs.deflection,
        end,
        timings,
    })
}

/// Concrete material-point updates per second (issue #4 item 8), single thread: a cracked
/// point (one crack opened to 4 ε0, strains around it, implicit and IMPL-EX laws) and a
/// plastic point (biaxial compression past initial yield). Returns (label, updates/s).
pub fn material_point_rates(n: usize) -> Vec<(String, f64)> {
    use segfem::materials::concrete::{update, update_extrapolated, ConcreteParams, ConcreteState};
    use std::hint::black_box;
    let mut p = ConcreteParams::from_mc90(38e6, 0.2);
    p.initial_yield_ratio = 0.3;
    let e0 = p.eps0();
    let virgin = ConcreteState::new();
    let cracked = update(&p, &virgin, &[4.0 * e0, 0.0, 0.0], 0.1)
        .expect("cracking update")
        .0;
    let ec = -0.6 * p.fcm / p.ec;
    let plastic = update(&p, &virgin, &[ec, 0.3 * ec, 0.0], 0.1)
        .expect("plastic update")
        .0;
    let mut implex = p.clone();
    implex.implex = true;
    let rate = |f: &dyn Fn(f64) -> f64| {
        let t = Instant::now();
        let mut acc = 0.0;
        for i in 0..n {
            acc += f((i % 1000) as f64 / 1000.0);
        }
        black_box(acc);
        n as f64 / t.elapsed().as_secs_f64()
    };
    vec![
        (
            "cracked (implicit)".into(),
            rate(&|s| {
                let e = [(4.0 + s) * e0, -0.2 * e0, 0.5 * s * e0];
                black_box(update(&p, &cracked, black_box(&e), 0.1).map_or(0.0, |r| r.1[0]))
            }),
        ),
        (
            "cracked (IMPL-EX)".into(),
            rate(&|s| {
                let e = [(4.0 + s) * e0, -0.2 * e0, 0.5 * s * e0];
                black_box(
                    update_extrapolated(&implex, &cracked, black_box(&e), 0.1, 1.0)
                        .map_or(0.0, |r| r.1[0]),
                )
            }),
        ),
        (
            "plastic (return mapping)".into(),
            rate(&|s| {
                let e = [ec * (1.0 + 0.1 * s), 0.3 * ec, 0.1 * s * ec];
                black_box(update(&p, &plastic, black_box(&e), 0.1).map_or(0.0, |r| r.1[0]))
            }),
        ),
        (
            "elastic (uncracked)".into(),
            rate(&|s| {
                let e = [0.2 * e0 * s, -0.1 * e0, 0.0];
                black_box(update(&p, &virgin, black_box(&e), 0.1).map_or(0.0, |r| r.1[0]))
            }),
        ),
    ]
    .into_iter()
    .chain(shear_model_rates(rate))
    .collect()
}

/// Material-point update rates of the shear options (for `segfem bench --case
/// material-point`), measured by `rate` (updates/s of a closure of s ∈ [0, 1)): rotating cracks and fixed cracks with compression softening, from a point
/// cracked at 4 ε0, at the fixed model's benchmark strains and at a compressed state
/// (ε1 = 10 ε0, ε2 = −5 ε0) where the reduction is active.
pub fn shear_model_rates(rate: impl Fn(&dyn Fn(f64) -> f64) -> f64) -> Vec<(String, f64)> {
    use segfem::materials::concrete::{
        update, CompressionReduction, ConcreteParams, ConcreteState, CrackModel,
    };
    use std::hint::black_box;
    let fixed = ConcreteParams::from_mc90(38e6, 0.2);
    let mut fixed_vc = fixed.clone();
    fixed_vc.compression_reduction = CompressionReduction::VecchioCollins1993 {
        beta_min: 0.4,
        spacing: 0.0,
    };
    let mut rot = fixed.clone();
    rot.crack_model = CrackModel::Rotating;
    let mut rot_vc = fixed_vc.clone();
    rot_vc.crack_model = CrackModel::Rotating;
    let mut fixed_lim = fixed_vc.clone();
    fixed_lim.crack_shear_limit =
        segfem::materials::concrete::cracking::CrackShearLimit::VecchioCollins1986 { d_agg: 0.016 };
    let e0 = fixed.eps0();
    let crack = |p: &ConcreteParams| {
        update(p, &ConcreteState::new(), &[4.0 * e0, 0.0, 0.0], 0.1)
            .expect("cracking update")
            .0
    };
    let run = |p: &ConcreteParams, c: &ConcreteState, comp: bool| {
        rate(&|s| {
            let e = if comp {
                [(10.0 + s) * e0, -5.0 * e0, s * e0]
            } else {
                [(4.0 + s) * e0, -0.2 * e0, 0.5 * s * e0]
            };
            black_box(update(p, c, black_box(&e), 0.1).map_or(0.0, |r| r.1[0]))
        })
    };
    let (cr, crv, cfv) = (crack(&rot), crack(&rot_vc), crack(&fixed_vc));
    vec![
        ("cracked (rotating)".into(), run(&rot, &cr, false)),
        ("rotating, compressed".into(), run(&rot, &cr, true)),
        ("rotating+VC93, compressed".into(), run(&rot_vc, &crv, true)),
        (
            "fixed, compressed".into(),
            run(&fixed, &crack(&fixed), true),
        ),
        ("fixed+VC93, compressed".into(), run(&fixed_vc, &cfv, true)),
        (
            "fixed+VC86 limit+VC93, compressed".into(),
            run(&fixed_lim, &crack(&fixed_lim), true),
        ),
    ]
}
