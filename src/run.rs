//! The main job: read a model file, run its steps, write history, fields and a summary.

use crate::analysis::failure::FailureReport;
use crate::analysis::state::{DriverState, SystemState};
use crate::analysis::steps::{
    self, AnalysisError, Observer, Snapshot, StepEnd, StopReason, Timings,
};
use crate::analysis::system::System;
use crate::input::{self, InputError};
use crate::model::Model;
use crate::results::atomic::write_atomic;
use crate::results::checkpoint::{self, Origin};
use crate::results::lock;
use crate::results::plausibility::Plausibility;
use crate::results::recorder::Recorder;
use crate::results::stages::{self as stage_results, StageResult};
use crate::results::sustained::SustainedStress;
use crate::results::ultimate::{Ultimate, UltimateWatch};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Why a run failed; each maps to an exit status (docs/running.md).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Bad input (exit 2).
    #[error("{0}")]
    Input(#[from] InputError),
    /// The model is a mechanism (exit 2).
    #[error("{file}: {message}")]
    Mechanism {
        /// Model file.
        file: String,
        /// What is singular.
        message: String,
    },
    /// A restart is impossible: no or a damaged checkpoint, or the model changed (exit 2).
    #[error("cannot restart: {0}")]
    Restart(String),
    /// An increment did not converge (exit 3); results so far are written. With
    /// continue-on-failure: one or more steps failed, the others ran.
    #[error("{0}")]
    NotConverged(String),
    /// Stopped by a signal after finishing the current increment (exit 128 + signal:
    /// 130 for SIGINT, 143 for SIGTERM); results so far are written.
    #[error("{message}")]
    Interrupted {
        /// Signal number.
        signal: i32,
        /// What was done and how to go on.
        message: String,
    },
    /// Stopped as asked after a step (`--stop-after-step`, exit 4).
    #[error("{0}")]
    Stopped(String),
    /// Every step converged but the result is not physically meaningful (exit 5):
    /// `results::plausibility` (a model held by numerical stiffness).
    #[error("{0}")]
    Implausible(String),
    /// Files could not be written (exit 1).
    #[error("{0}")]
    Io(String),
    /// Another run is writing into the output directory (exit 2): `results::lock`.
    #[error("{0}")]
    Busy(String),
}

impl RunError {
    /// Process exit status for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            RunError::Input(_)
            | RunError::Mechanism { .. }
            | RunError::Restart(_)
            | RunError::Busy(_) => 2,
            RunError::NotConverged(_) => 3,
            RunError::Stopped(_) => 4,
            RunError::Implausible(_) => 5,
            RunError::Interrupted { signal, .. } => 128 + signal,
            RunError::Io(_) => 1,
        }
    }
}

/// Options of [`run_file_opts`].
#[derive(Debug, Default, Clone)]
pub struct RunOptions {
    /// Print every Newton iteration's norms to standard error.
    pub verbose: bool,
    /// Report a step that fails and go on with the next one (docs/running.md).
    pub continue_on_failure: bool,
    /// Stop after this step (1-based) once its checkpoint is written.
    pub stop_after_step: Option<usize>,
    /// Set to a signal number (non-zero) to stop after the current increment.
    pub signal: Option<Arc<AtomicUsize>>,
    /// Continue the run whose output directory is `out` from its checkpoint.
    pub restart: bool,
    /// Set to why (e.g. "the progress callback raised ValueError: ...") to stop after the
    /// current increment at the request of the program running the analysis: status
    /// "stopped", exit 4, that reason in the message.
    pub caller_stop: Option<Arc<std::sync::Mutex<Option<String>>>>,
    /// Write no field files (.vtu, results.pvd): history.csv, summary.json and the
    /// checkpoint only, with the same numbers, as if every step had `output = "none"`
    /// (sweeps keeping only their summaries; `segfem run --no-fields`).
    pub no_fields: bool,
}

/// The reason a caller asked to stop with, if it did ([`RunOptions::caller_stop`]).
fn caller_reason(stop: &Option<Arc<std::sync::Mutex<Option<String>>>>) -> Option<String> {
    stop.as_ref()
        .and_then(|m| m.lock().unwrap_or_else(|p| p.into_inner()).clone())
}

/// Model size figures.
#[derive(Debug, Clone, Serialize)]
pub struct Size {
    /// Nodes.
    pub nodes: usize,
    /// Continuum elements.
    pub elements: usize,
    /// Degrees of freedom.
    pub dofs: usize,
    /// Free equations.
    pub equations: usize,
}

/// Contents of summary.json.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Model title.
    pub title: String,
    /// "completed", "implausible" (every step converged but the result is held by
    /// numerical stiffness: `plausibility`), "failed" (a step did not converge),
    /// "interrupted" (signal) or "stopped" (`--stop-after-step`).
    pub status: String,
    /// Failure message, if any.
    pub error: Option<String>,
    /// Reports of the steps that failed (where, why), in order.
    pub failures: Vec<FailureReport>,
    /// Step (1-based) a `--restart` of this directory begins with, when the run stopped
    /// early and can be continued.
    pub resume_step: Option<usize>,
    /// Step (1-based) this run restarted from, if it was a restart.
    pub restarted_from_step: Option<usize>,
    /// Size.
    pub size: Size,
    /// Wall time of the whole run [s].
    pub wall_s: f64,
    /// Wall time reading and validating input [s].
    pub input_s: f64,
    /// Phase timings.
    pub timings: Timings,
    /// Peak resident memory [bytes], where the platform reports it.
    pub peak_memory_bytes: Option<u64>,
    /// Final monitor values (name → value).
    pub final_monitors: Vec<(String, f64)>,
    /// The load cases: name, whether forces only, resultant at factor 1 [N].
    pub load_cases: Vec<LoadCaseInfo>,
    /// The monitors as history.csv holds them: name, input kind, component and unit (the
    /// plots choose display units and signs by kind).
    pub monitors: Vec<MonitorInfo>,
    /// Region names, by the index the .vtu `region` cell array holds.
    pub regions: Vec<String>,
    /// Joint names, in model order (the .vtu `joint` arrays count from 1 in this order).
    pub joints: Vec<String>,
    /// Construction stages of a staged model, as in stages.csv (absent without stages).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<StageResult>,
    /// Runs to failure (a displacement or arc-length step, or a failure met): which
    /// failure was reached first and at what load, and the peak load.
    pub ultimate: Option<Ultimate>,
    /// Why the result is not physically meaningful (empty when it is): load carried
    /// through open joints' residual stiffness, displacements beyond a tenth of the model
    /// size (docs/running.md, "Implausible results").
    pub plausibility: Vec<String>,
    /// Stresses of concrete modelled as elastic past its strength (f_cm, f_tm, joint
    /// contact), first met first (docs/running.md, "Concrete past its strength"); each also
    /// in `warnings`.
    pub strength_exceeded: Vec<crate::results::strength::StrengthFinding>,
    /// Design checks (`[[checks]]`), in model order: verdict, utilisation, clause and every
    /// item checked (docs/theory-design.md).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub design_checks: Vec<crate::results::design::CheckResult>,
    /// Influence lines, traffic envelopes and combinations (`[[influence]]`; absent
    /// without).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub influence: Vec<crate::results::envelopes::InfluenceSummary>,
    /// Warnings met in the input and in the results.
    pub warnings: Vec<String>,
}

/// One monitor column of history.csv, described (summary.json `monitors`).
#[derive(Debug, Clone, Serialize)]
pub struct MonitorInfo {
    /// Monitor name (the column name).
    pub name: String,
    /// Input kind (`displacement`, `reaction`, `stress`, …).
    pub kind: String,
    /// Component where the kind has one: `x`/`y` (displacements, reactions) or
    /// `sx`…`s2` (stresses).
    pub component: Option<String>,
    /// Unit of the column (SI).
    pub unit: String,
    /// The load case of a `load_factor` monitor (its name), so a viewer can give the
    /// factor its load case's unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub case: Option<String>,
}

/// One load case described for summary.json (`load_cases`): what a unit factor of it is.
#[derive(Debug, Clone, Serialize)]
pub struct LoadCaseInfo {
    /// Load case name (the `factor:<name>` column of history.csv).
    pub name: String,
    /// True when the case holds forces only (point and edge loads: no gravity, no
    /// temperature), so that its factor measures a force.
    pub forces_only: bool,
    /// Resultant (x, y) of the case's loads at factor 1 [N] (gravity included).
    pub resultant: [f64; 2],
}

/// The load cases of a model described for summary.json.
pub fn load_case_info(model: &Model) -> Vec<LoadCaseInfo> {
    model
        .load_cases
        .iter()
        .map(|c| {
            let f = crate::analysis::loads::load_vector(model, c);
            let mut r = [0.0; 2];
            for n in 0..model.nodes.len() {
                r[0] += f[2 * n];
                r[1] += f[2 * n + 1];
            }
            LoadCaseInfo {
                name: c.name.clone(),
                forces_only: c.gravity.is_none() && c.thermal.is_none(),
                resultant: r,
            }
        })
        .collect()
}

/// The monitors of a model described for summary.json.
pub fn monitor_info(model: &Model) -> Vec<MonitorInfo> {
    use crate::model::{MonitorKind, StressComponent};
    model
        .monitors
        .iter()
        .map(|m| {
            let stress = |c: &StressComponent| {
                match c {
                    StressComponent::Sx => "sx",
                    StressComponent::Sy => "sy",
                    StressComponent::Txy => "txy",
                    StressComponent::S1 => "s1",
                    StressComponent::S2 => "s2",
                }
                .to_string()
            };
            let component = match &m.kind {
                MonitorKind::Displacement { dir, .. } | MonitorKind::Reaction { dir, .. } => {
                    Some(if dir.index() == 0 { "x" } else { "y" }.to_string())
                }
                MonitorKind::StressAtPoint { component, .. }
                | MonitorKind::StressExtreme { component, .. } => Some(stress(component)),
                _ => None,
            };
            let case = match &m.kind {
                MonitorKind::LoadFactor { case } => {
                    model.load_cases.get(*case).map(|c| c.name.clone())
                }
                _ => None,
            };
            MonitorInfo {
                name: m.name.clone(),
                kind: crate::results::recorder::kind_name(&m.kind).into(),
                component,
                unit: m.unit().into(),
                case,
            }
        })
        .collect()
}

/// Names of the files a run writes into its output directory: history.csv, stages.csv,
/// results.pvd, summary.json, the checkpoint, report.html and the field files
/// `[lines_|bars_|gauss_|joints_]stepNNN[_<stage name>]_incNNNN.vtu`.
pub fn is_run_file(name: &str) -> bool {
    if matches!(
        name,
        "history.csv" | "stages.csv" | "results.pvd" | "summary.json" | "report.html"
    ) || name == crate::results::checkpoint::FILE
    {
        return true;
    }
    // Influence tables' files: influence_, envelopes_, combinations_<name>.csv.
    if name.ends_with(".csv")
        && ["influence_", "envelopes_", "combinations_"]
            .iter()
            .any(|p| name.starts_with(p))
    {
        return true;
    }
    let Some(stem) = name.strip_suffix(".vtu") else {
        return false;
    };
    let stem = ["lines_", "bars_", "gauss_", "joints_"]
        .iter()
        .find_map(|p| stem.strip_prefix(p))
        .unwrap_or(stem);
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    // The stage name of a staged run (file-safe: letters, digits, `-`, `_`) may follow
    // the step number.
    let slug = |s: &str| {
        s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
    };
    stem.strip_prefix("step")
        .and_then(|r| r.rsplit_once("_inc"))
        .is_some_and(|(a, b)| {
            let (n, name) = a.split_once('_').unwrap_or((a, ""));
            digits(n) && slug(name) && digits(b)
        })
}

/// Remove the files an earlier run left in `out` (only the names of [`is_run_file`]; other
/// files are kept), so that results.pvd and the .vtu files cannot mix two runs. Returns
/// how many were removed.
fn clear_stale(out: &Path) -> Result<usize, RunError> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(0);
    };
    let mut n = 0;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if e.file_type().is_ok_and(|t| t.is_file()) && is_run_file(&name) {
            std::fs::remove_file(e.path()).map_err(|err| {
                RunError::Io(format!(
                    "{}: cannot remove a file of an earlier run: {err}",
                    e.path().display()
                ))
            })?;
            n += 1;
        }
    }
    Ok(n)
}

/// Remove the field files (.vtu names of [`is_run_file`]) in `out` that results.pvd of
/// `rec` does not list. Returns how many were removed.
fn remove_unlisted_fields(out: &Path, rec: &Recorder) -> Result<usize, RunError> {
    let listed: std::collections::HashSet<&str> = rec.field_files().collect();
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(0);
    };
    let mut n = 0;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if name.ends_with(".vtu")
            && is_run_file(&name)
            && !listed.contains(name.as_str())
            && e.file_type().is_ok_and(|t| t.is_file())
        {
            std::fs::remove_file(e.path()).map_err(|err| {
                RunError::Io(format!(
                    "{}: cannot remove a field file of the stopped run: {err}",
                    e.path().display()
                ))
            })?;
            n += 1;
        }
    }
    Ok(n)
}

/// Peak resident set size of this process [bytes] (Linux: VmHWM), if known.
pub fn peak_memory() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Size figures of a model.
pub fn size_of(model: &Model, equations: usize) -> Size {
    Size {
        nodes: model.nodes.len(),
        elements: model.elements.len(),
        dofs: model.n_dofs(),
        equations,
    }
}

struct Progress<'a, 'm> {
    rec: Recorder<'m>,
    watch: UltimateWatch,
    design: crate::results::design::DesignWatch,
    plausible: Plausibility,
    sustained: SustainedStress,
    on_increment: &'a mut dyn FnMut(&Snapshot),
    dir: PathBuf,
    origin: Origin,
    failures: Vec<FailureReport>,
    stop_after_step: Option<usize>,
    stop_now: bool,
    signal: Option<Arc<AtomicUsize>>,
    caller_stop: Option<Arc<std::sync::Mutex<Option<String>>>>,
    /// Timings when a step stopped early (the analysis returns none with its error).
    timings: Option<Timings>,
    /// The last checkpoint, still being written (waited for before the next and at the end).
    checkpoint: Option<checkpoint::Pending>,
    /// Influence tables written so far.
    influence: Vec<crate::results::envelopes::InfluenceSummary>,
    /// The model (influence tables).
    model: &'m Model,
}

impl Observer for Progress<'_, '_> {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        self.rec.increment(snap)?;
        self.watch.increment(snap);
        self.design.increment(snap);
        self.plausible.increment(snap);
        self.sustained.increment(snap);
        (self.on_increment)(snap);
        Ok(())
    }

    fn step_end(&mut self, end: &StepEnd) -> std::io::Result<()> {
        if let Some(p) = self.checkpoint.take() {
            p.wait()?;
        }
        // Before the first step the state is the model's initial one, which a restart
        // rebuilds from the model: not saved.
        let initial = end.driver.next_step == 0;
        self.checkpoint = Some(checkpoint::start(
            &self.dir,
            &self.origin,
            end.driver,
            &self.failures,
            &self.rec.state(),
            (!initial).then(|| end.system.state()),
            self.rec.writing(),
        )?);
        if self.stop_after_step == Some(end.driver.next_step) {
            self.stop_now = true;
        }
        Ok(())
    }

    fn step_failed(&mut self, report: &FailureReport) {
        self.failures.push(report.clone());
    }

    fn influence(
        &mut self,
        lines: &Result<crate::analysis::influence::InfluenceLines, (usize, String)>,
    ) -> std::io::Result<()> {
        let model = self.model;
        let written = crate::results::envelopes::write(&self.dir, model, lines)?;
        self.influence.push(written);
        Ok(())
    }

    fn step_stopped(&mut self, system: &System, timings: &Timings) -> std::io::Result<()> {
        self.timings = Some(timings.clone());
        // A failed or stopped run still shows its last converged state.
        self.rec.write_last_fields(system)
    }

    fn idle_work(&mut self, step: usize) -> Option<crate::analysis::steps::IdleWork> {
        self.rec.idle_work(step)
    }

    fn stop_requested(&self) -> Option<StopReason> {
        let sig = self.signal.as_ref().map_or(0, |s| s.load(Ordering::SeqCst));
        if sig != 0 {
            Some(StopReason::Signal(sig as i32))
        } else if caller_reason(&self.caller_stop).is_some() {
            Some(StopReason::Caller)
        } else if self.stop_now {
            self.stop_after_step.map(StopReason::AfterStep)
        } else {
            None
        }
    }
}

/// Run a model file, writing into `out`. `on_increment` sees every converged increment
/// (progress display). Warnings are returned in the summary.
pub fn run_file(
    path: &Path,
    out: &Path,
    on_increment: &mut dyn FnMut(&Snapshot),
) -> Result<Summary, RunError> {
    run_file_with(path, out, on_increment, false)
}

/// As [`run_file`]; `verbose` prints every Newton iteration's norms to standard error.
pub fn run_file_with(
    path: &Path,
    out: &Path,
    on_increment: &mut dyn FnMut(&Snapshot),
    verbose: bool,
) -> Result<Summary, RunError> {
    let opts = RunOptions {
        verbose,
        ..Default::default()
    };
    run_file_opts(Some(path), out, on_increment, &opts)
}

/// Run a model file (or, with `opts.restart`, continue the run in `out`; the model file is
/// then the one given or else the one the checkpoint names), writing into `out`.
pub fn run_file_opts(
    path: Option<&Path>,
    out: &Path,
    on_increment: &mut dyn FnMut(&Snapshot),
    opts: &RunOptions,
) -> Result<Summary, RunError> {
    let t0 = Instant::now();
    let Opened {
        path,
        built,
        saved,
        lock: _lock, // held until the run returns
        digest,
        input_s,
    } = open(path, out, opts, t0)?;
    let path = path.as_path();
    let model = built.model;
    let mut rec = Recorder::new(&model, PathBuf::from(out), !opts.no_fields).map_err(|e| {
        RunError::Io(format!(
            "{}: cannot create the output directory: {e}",
            out.display()
        ))
    })?;
    let (resume, failures, restarted_from_step) = resume_from(saved, &mut rec, &model, path)?;
    let model_file = std::fs::canonicalize(path)
        .unwrap_or_else(|_| path.to_path_buf())
        .display()
        .to_string();
    let mut obs = Progress {
        rec,
        watch: UltimateWatch::new(),
        design: crate::results::design::DesignWatch::new(&model),
        plausible: Plausibility::new(),
        sustained: SustainedStress::new(),
        on_increment,
        dir: PathBuf::from(out),
        origin: Origin {
            model_file,
            model_digest: digest,
        },
        failures,
        stop_after_step: opts.stop_after_step,
        stop_now: false,
        signal: opts.signal.clone(),
        caller_stop: opts.caller_stop.clone(),
        timings: None,
        checkpoint: None,
        influence: Vec::new(),
        model: &model,
    };
    let result = steps::run_with(
        &model,
        &mut obs,
        steps::RunOptions {
            continue_on_failure: opts.continue_on_failure,
            resume,
        },
    );
    // The last checkpoint's write, and the last field files', fail the run as they did
    // when written in place.
    let result = match (obs.checkpoint.take().map(checkpoint::Pending::wait), result) {
        (Some(Err(e)), Ok(_)) => Err(AnalysisError::Output(e)),
        (_, r) => r,
    };
    let result = match (obs.rec.wait_fields(), result) {
        (Err(e), Ok(_)) => Err(AnalysisError::Output(e)),
        (_, r) => r,
    };
    // A refused restart (the saved state does not fit the model) leaves the directory as it
    // was: nothing was computed, and the checkpoint still continues the stopped run.
    if let Err(AnalysisError::Restore(m)) = &result {
        return Err(RunError::Restart(format!("{}: {m}", path.display())));
    }
    let mut rec = obs.rec;
    let mut warnings = built.warnings;
    if restarted_from_step.is_some() {
        // Field files of the increments the stopped run did after its checkpoint and this
        // run did not write again: results.pvd no longer lists them.
        let n = remove_unlisted_fields(out, &rec)?;
        if n > 0 {
            warnings.push(format!(
                "{}: removed {n} field files (.vtu) of the increments the stopped run did after its last checkpoint, which results.pvd no longer lists",
                out.display()
            ));
        }
    }
    let watch = obs.watch;
    let design_checks = obs.design.results(&model);
    let plausibility = obs.plausible.findings();
    let sustained = obs.sustained.warning(&model);
    let mut failures = obs.failures;
    let influence = obs.influence;
    let (timings, error) = match result {
        Ok(t) => (t, None),
        Err(e) => (obs.timings.unwrap_or_default(), Some(e)),
    };
    if let Some(AnalysisError::NotConverged(r)) = &error {
        failures.push((**r).clone());
    }
    // History is written whatever happened: every converged increment is kept.
    rec.write_history()
        .map_err(|e| RunError::Io(format!("{}: {e}", out.join("history.csv").display())))?;
    let stages = stage_outputs(&model, &rec, &timings, out, &mut warnings)?;
    let (status, resume_step, error_text) =
        status_of(&error, &failures, &plausibility, &opts.caller_stop);
    let ultimate = watch.finish(
        &model,
        !matches!(error, Some(AnalysisError::NotConverged(_))) && failures.is_empty(),
    );
    let strength_exceeded = watch.strength_findings(&model);
    warnings.extend(ultimate.iter().flat_map(|u| u.warnings()));
    warnings.extend(strength_exceeded.iter().map(|f| f.text.clone()));
    warnings.extend(sustained);
    if error.is_some() || !failures.is_empty() {
        // A failed or stopped run says why it failed; the findings still go with it.
        warnings.extend(plausibility.iter().cloned());
    }
    let summary = Summary {
        title: model.title.clone(),
        status: status.into(),
        error: error_text.clone(),
        failures,
        resume_step,
        restarted_from_step,
        size: size_of(&model, equation_count(&model)),
        wall_s: t0.elapsed().as_secs_f64(),
        input_s,
        timings,
        peak_memory_bytes: peak_memory(),
        final_monitors: final_monitors(&model, &rec.rows),
        monitors: monitor_info(&model),
        load_cases: load_case_info(&model),
        regions: model.regions.iter().map(|r| r.name.clone()).collect(),
        joints: model.joints.iter().map(|j| j.name.clone()).collect(),
        stages,
        ultimate,
        plausibility,
        strength_exceeded,
        design_checks,
        influence,
        warnings,
    };
    let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
    write_atomic(&out.join("summary.json"), json.as_bytes())
        .map_err(|e| RunError::Io(format!("{}: {e}", out.join("summary.json").display())))?;
    outcome(error, summary, error_text, path, out, opts)
}

/// The run's status word (summary.json `status`), the step a restart continues with, and
/// the error text of summary.json, from how the analysis ended (`error`), the steps that
/// did not converge (`failures`) and the plausibility findings.
fn status_of(
    error: &Option<AnalysisError>,
    failures: &[FailureReport],
    plausibility: &[String],
    caller_stop: &Option<Arc<std::sync::Mutex<Option<String>>>>,
) -> (&'static str, Option<usize>, Option<String>) {
    let (status, resume_step) = match error {
        None if failures.is_empty() && !plausibility.is_empty() => ("implausible", None),
        None if failures.is_empty() => ("completed", None),
        None | Some(AnalysisError::NotConverged(_)) => ("failed", None),
        Some(AnalysisError::Stopped {
            reason,
            resume_step,
            ..
        }) => (
            match reason {
                StopReason::Signal(_) => "interrupted",
                StopReason::AfterStep(_) | StopReason::Caller => "stopped",
            },
            Some(resume_step + 1),
        ),
        Some(_) => ("failed", None),
    };
    let error_text = match (error, failures.len()) {
        (
            Some(
                e @ AnalysisError::Stopped {
                    reason: StopReason::Caller,
                    ..
                },
            ),
            _,
        ) => Some(format!(
            "{e}: {}",
            caller_reason(caller_stop).unwrap_or_default()
        )),
        (Some(e), _) => Some(e.to_string()),
        (None, 0) if !plausibility.is_empty() => Some(format!(
            "every step converged but the result is not physically meaningful:\n{}",
            plausibility.join("\n")
        )),
        (None, 0) => None,
        (None, n) => Some(format!(
            "{n} step(s) did not converge (the run went on): {}\n{}",
            failures
                .iter()
                .map(|f| format!("'{}'", f.step))
                .collect::<Vec<_>>()
                .join(", "),
            failures
                .iter()
                .map(|f| f.to_string())
                .collect::<Vec<_>>()
                .join("\n")
        )),
    };
    (status, resume_step, error_text)
}

/// What `run_file_opts` returns once summary.json is written: the summary, or the error
/// that says how the run ended (model file `path`, output directory `out`).
fn outcome(
    error: Option<AnalysisError>,
    summary: Summary,
    error_text: Option<String>,
    path: &Path,
    out: &Path,
    opts: &RunOptions,
) -> Result<Summary, RunError> {
    let file = path.display();
    match error {
        None if summary.failures.is_empty() && !summary.plausibility.is_empty() => {
            Err(RunError::Implausible(format!(
                "{file}: {}",
                error_text.expect("set with findings")
            )))
        }
        None if summary.failures.is_empty() => Ok(summary),
        None => Err(RunError::NotConverged(format!(
            "{file}: {}",
            error_text.expect("set with failures")
        ))),
        Some(AnalysisError::Mechanism(m)) => Err(RunError::Mechanism {
            file: file.to_string(),
            message: m,
        }),
        Some(e @ AnalysisError::NotConverged(_)) => {
            Err(RunError::NotConverged(match &summary.ultimate {
                Some(u) => format!("{file}: {e}\n{u}"),
                None => format!("{file}: {e}"),
            }))
        }
        Some(AnalysisError::Stopped {
            reason,
            step,
            increment,
            resume_step,
        }) => {
            let done = if increment == 0 {
                format!("after step {}", step + 1)
            } else {
                format!("at step {} increment {increment}", step + 1)
            };
            let how = format!(
                "results so far are in {0}; `segfem run --restart {0}` continues with step {1}",
                out.display(),
                resume_step + 1
            );
            match reason {
                StopReason::Signal(signal) => Err(RunError::Interrupted {
                    signal,
                    message: format!(
                        "{file}: interrupted by {} {done}; {how}",
                        signal_name(signal)
                    ),
                }),
                StopReason::AfterStep(_) => Err(RunError::Stopped(format!(
                    "{file}: stopped {done} as asked; {how}"
                ))),
                StopReason::Caller => Err(RunError::Stopped(format!(
                    "{file}: stopped {done}: {}; {how}",
                    caller_reason(&opts.caller_stop).unwrap_or_default()
                ))),
            }
        }
        Some(AnalysisError::Restore(m)) => Err(RunError::Restart(format!("{file}: {m}"))),
        Some(AnalysisError::Output(e)) => Err(RunError::Io(format!("{}: {e}", out.display()))),
    }
}

/// A run's start: the model file read and checked, a restart's checkpoint, the output
/// directory locked and, for a fresh run, cleared of an earlier run's files.
struct Opened {
    /// The model file (given, or the one the checkpoint names).
    path: PathBuf,
    /// The built model and its warnings.
    built: input::Built,
    /// A restart's checkpoint.
    saved: Option<(Origin, checkpoint::Checkpoint)>,
    /// The output directory's lock, held until the run returns.
    lock: Option<lock::DirLock>,
    /// Digest of the model file's bytes (0 if unreadable).
    digest: u64,
    /// Time to read and check the input [s].
    input_s: f64,
}

/// Open a run as [`run_file_opts`] does (`t0`: when the run started).
fn open(
    path: Option<&Path>,
    out: &Path,
    opts: &RunOptions,
    t0: Instant,
) -> Result<Opened, RunError> {
    // A restart's directory holds the checkpoint: locked before it is read. A fresh run's
    // is locked once its input is valid (bad input writes nothing, not even a directory).
    let mut lock = None;
    if opts.restart && out.is_dir() {
        lock = Some(lock::acquire(out, path.unwrap_or(Path::new("?"))).map_err(RunError::Busy)?);
    }
    let saved = if opts.restart {
        Some(checkpoint::read(out).map_err(RunError::Restart)?)
    } else {
        None
    };
    let path_buf: PathBuf = match (path, &saved) {
        (Some(p), _) => p.to_path_buf(),
        (None, Some((o, _))) => PathBuf::from(&o.model_file),
        (None, None) => {
            return Err(RunError::Restart(
                "no model file given and no checkpoint to take it from".into(),
            ))
        }
    };
    let mut built = input::load(&path_buf)?;
    built.model.controls.verbose = opts.verbose;
    let digest = std::fs::read(&path_buf)
        .map(|b| checkpoint::digest(&b))
        .unwrap_or(0);
    if let Some((o, _)) = &saved {
        if o.model_digest != digest {
            built.warnings.push(format!(
                "{}: the model file changed since the checkpoint was written; the restarted run equals an uninterrupted one only if the steps already done are unchanged",
                path_buf.display()
            ));
        }
    }
    let input_s = t0.elapsed().as_secs_f64();
    if lock.is_none() {
        std::fs::create_dir_all(out).map_err(|e| {
            RunError::Io(format!(
                "{}: cannot create the output directory: {e}",
                out.display()
            ))
        })?;
        lock = Some(lock::acquire(out, &path_buf).map_err(RunError::Busy)?);
    }
    if saved.is_none() {
        let n = clear_stale(out)?;
        if n > 0 {
            built.warnings.push(format!(
                "{}: removed {n} files of an earlier run (history.csv, stages.csv, results.pvd, .vtu fields, summary.json, checkpoint, report.html); other files are kept",
                out.display()
            ));
        }
    }
    Ok(Opened {
        path: path_buf,
        built,
        saved,
        lock,
        digest,
        input_s,
    })
}

/// What a restart goes on from (`saved`: the checkpoint, whose history `rec` takes up):
/// the driver and system state (None: from the model's initial state), the failures so
/// far and the step it restarts from (1-based); all None and empty for a fresh run.
#[allow(clippy::type_complexity)]
fn resume_from(
    saved: Option<(Origin, checkpoint::Checkpoint)>,
    rec: &mut Recorder,
    model: &Model,
    path: &Path,
) -> Result<
    (
        Option<(DriverState, SystemState)>,
        Vec<FailureReport>,
        Option<usize>,
    ),
    RunError,
> {
    Ok(match saved {
        Some((_, cp)) => {
            // The history goes on with the same columns, or not at all.
            if let Some(r) = cp.recorder.rows.first() {
                if r.monitors.len() != model.monitors.len()
                    || r.factors.len() != model.load_cases.len()
                {
                    return Err(RunError::Restart(format!(
                        "{}: the checkpoint's history has {} load cases and {} monitors, the model {} and {}: the model changed since the checkpoint was written",
                        path.display(),
                        r.factors.len(),
                        r.monitors.len(),
                        model.load_cases.len(),
                        model.monitors.len()
                    )));
                }
            }
            rec.restore(cp.recorder);
            let from = cp.driver.next_step + 1;
            // Without a saved state (the checkpoint before the first step) the run starts
            // from the model's initial state, as a fresh run does.
            (cp.system.map(|s| (cp.driver, s)), cp.failures, Some(from))
        }
        None => (None, Vec::new(), None),
    })
}

/// Every monitor's name and value at the last history row (empty without rows).
fn final_monitors(model: &Model, rows: &[crate::results::recorder::Row]) -> Vec<(String, f64)> {
    rows.last()
        .map(|r| {
            model
                .monitors
                .iter()
                .map(|m| m.name.clone())
                .zip(r.monitors.iter().copied())
                .collect()
        })
        .unwrap_or_default()
}

/// The number of equations of `model` (dofs less those its supports hold).
fn equation_count(model: &Model) -> usize {
    // The dofs less the distinct supported ones (what `DofMap::new` numbers, without
    // building the map: 24 MB at 5e5 dofs).
    let mut held = vec![false; 2 * model.nodes.len()];
    for s in &model.supports {
        for (n, d, _) in &s.dofs {
            held[2 * n + d.index()] = true;
        }
    }
    held.iter().filter(|&&h| !h).count()
}

/// The per-stage results of the run (written to `out`/stages.csv when there are any), and
/// the warnings of one-way supports: every lift-off and touch-down, and increments kept with
/// statuses still changing.
fn stage_outputs(
    model: &Model,
    rec: &Recorder,
    timings: &Timings,
    out: &Path,
    warnings: &mut Vec<String>,
) -> Result<Vec<StageResult>, RunError> {
    let stages = stage_results::stage_results(model, &rec.rows, &rec.openings, &rec.lifted);
    // Every lift-off and touch-down of a one-way support, staged model or not.
    warnings.extend(
        stage_results::support_events(model, &rec.rows, &rec.lifted)
            .into_iter()
            .map(|(i, e)| format!("step '{}': {e}", model.steps[i].name)),
    );
    if timings.support_chatter > 0 {
        warnings.push(format!(
            "{} increments kept with one-way support statuses that still changed after {} rounds (a support point lifting off and touching down in turn): smaller increments settle them",
            timings.support_chatter,
            crate::analysis::one_way::MAX_ROUNDS
        ));
    }
    if !stages.is_empty() {
        let p = out.join("stages.csv");
        write_atomic(&p, stage_results::render_csv(&stages).as_bytes())
            .map_err(|e| RunError::Io(format!("{}: {e}", p.display())))?;
    }
    Ok(stages)
}

fn signal_name(s: i32) -> String {
    match s {
        2 => "SIGINT".into(),
        15 => "SIGTERM".into(),
        n => format!("signal {n}"),
    }
}
