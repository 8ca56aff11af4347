//! The main job: read a model file, run its steps, write history, fields and a summary.

use crate::analysis::steps::{self, AnalysisError, Observer, Snapshot, Timings};
use crate::input::{self, InputError};
use crate::model::Model;
use crate::results::atomic::write_atomic;
use crate::results::recorder::Recorder;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a run failed; each maps to an exit status.
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
    /// An increment did not converge (exit 3); results so far are written.
    #[error("{0}")]
    NotConverged(String),
    /// Files could not be written (exit 1).
    #[error("{0}")]
    Io(String),
}

impl RunError {
    /// Process exit status for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            RunError::Input(_) | RunError::Mechanism { .. } => 2,
            RunError::NotConverged(_) => 3,
            RunError::Io(_) => 1,
        }
    }
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
    /// "completed" or "failed".
    pub status: String,
    /// Failure message, if any.
    pub error: Option<String>,
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
    /// Warnings met in the input.
    pub warnings: Vec<String>,
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
    on_increment: &'a mut dyn FnMut(&Snapshot),
}

impl Observer for Progress<'_, '_> {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        self.rec.increment(snap)?;
        (self.on_increment)(snap);
        Ok(())
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
    let t0 = Instant::now();
    let mut built = input::load(path)?;
    built.model.controls.verbose = verbose;
    let input_s = t0.elapsed().as_secs_f64();
    let model = built.model;
    let rec = Recorder::new(&model, PathBuf::from(out), true).map_err(|e| {
        RunError::Io(format!(
            "{}: cannot create the output directory: {e}",
            out.display()
        ))
    })?;
    let mut obs = Progress { rec, on_increment };
    let result = steps::run(&model, &mut obs);
    let rec = obs.rec;
    let (timings, error) = match result {
        Ok(t) => (t, None),
        Err(e) => (Timings::default(), Some(e)),
    };
    // History is written whatever happened: every converged increment is kept.
    rec.write_history()
        .map_err(|e| RunError::Io(format!("{}: {e}", out.join("history.csv").display())))?;
    let final_monitors = rec
        .rows
        .last()
        .map(|r| {
            model
                .monitors
                .iter()
                .map(|m| m.name.clone())
                .zip(r.monitors.iter().copied())
                .collect()
        })
        .unwrap_or_default();
    let equations = crate::fem::dofs::DofMap::new(
        model.nodes.len(),
        &model
            .supports
            .iter()
            .flat_map(|s| s.dofs.iter().map(|(n, d, v)| (2 * n + d.index(), *v)))
            .collect::<Vec<_>>(),
    )
    .n_eq;
    let summary = Summary {
        title: model.title.clone(),
        status: if error.is_none() {
            "completed".into()
        } else {
            "failed".into()
        },
        error: error.as_ref().map(|e| e.to_string()),
        size: size_of(&model, equations),
        wall_s: t0.elapsed().as_secs_f64(),
        input_s,
        timings,
        peak_memory_bytes: peak_memory(),
        final_monitors,
        warnings: built.warnings,
    };
    let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
    write_atomic(&out.join("summary.json"), json.as_bytes())
        .map_err(|e| RunError::Io(format!("{}: {e}", out.join("summary.json").display())))?;
    match error {
        None => Ok(summary),
        Some(AnalysisError::Mechanism(m)) => Err(RunError::Mechanism {
            file: path.display().to_string(),
            message: m,
        }),
        Some(AnalysisError::NotConverged { .. }) => Err(RunError::NotConverged(format!(
            "{}: {}",
            path.display(),
            error.expect("matched")
        ))),
        Some(AnalysisError::Output(e)) => Err(RunError::Io(format!("{}: {e}", out.display()))),
    }
}
