//! `segfem._segfem`: the native half of the Python package (the pure-Python half is
//! `python/segfem/`). It calls the segfem library as the command line does
//! (`segfem::run::run_file_opts`, `segfem::input`), with the GIL released during a run, and
//! hands back plain values (JSON text, bytes of little-endian f64) that the Python side turns
//! into dicts, pandas and numpy objects. docs/python.md describes the package.

use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use segfem::analysis::steps::Snapshot;
use segfem::run::{RunError, RunOptions};
use segfem::view::data::{read_pvd, Array, Grid};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// SIGINT: the stop a Ctrl-C (KeyboardInterrupt) asks for, as the command line's handler.
const SIGINT: usize = 2;

/// What a run ended with: (exit status as the command line's, kind, message, summary.json
/// text of a successful run). Kinds: "ok", "input", "mechanism", "restart",
/// "not_converged", "interrupted", "stopped", "implausible", "io", "busy" (another run
/// writes into the output directory).
type Outcome = (i32, &'static str, Option<String>, Option<String>);

fn outcome(res: Result<segfem::run::Summary, RunError>) -> Outcome {
    match res {
        Ok(s) => (
            0,
            "ok",
            None,
            Some(serde_json::to_string(&s).expect("summary serialises")),
        ),
        Err(e) => {
            let kind = match &e {
                RunError::Input(_) => "input",
                RunError::Mechanism { .. } => "mechanism",
                RunError::Restart(_) => "restart",
                RunError::NotConverged(_) => "not_converged",
                RunError::Interrupted { .. } => "interrupted",
                RunError::Stopped(_) => "stopped",
                RunError::Implausible(_) => "implausible",
                RunError::Io(_) => "io",
                RunError::Busy(_) => "busy",
            };
            (e.exit_code(), kind, Some(e.to_string()), None)
        }
    }
}

/// The progress record handed to a Python callback: one converged increment.
fn snapshot_dict<'py>(py: Python<'py>, s: &Snapshot) -> PyResult<Bound<'py, PyDict>> {
    let model = s.system.model;
    let d = PyDict::new(py);
    d.set_item("step", s.step + 1)?;
    d.set_item(
        "step_name",
        model.steps.get(s.step).map(|st| st.name.as_str()),
    )?;
    d.set_item("increment", s.increment)?;
    d.set_item("end_of_step", s.end_of_step)?;
    d.set_item("steps", model.steps.len())?;
    d.set_item("iterations", s.iterations)?;
    let factors = PyDict::new(py);
    for (c, f) in model.load_cases.iter().zip(s.factors) {
        factors.set_item(c.name.as_str(), *f)?;
    }
    d.set_item("factors", factors)?;
    d.set_item("arc_length_factor", s.arc_length_factor)?;
    d.set_item("negative_pivots", s.negative_pivots)?;
    Ok(d)
}

/// Run a model file into `out_dir` (or continue the run there with `restart`), as
/// `segfem run`. `progress(dict)` is called after every converged increment; pending
/// signals (Ctrl-C) are checked there too: a KeyboardInterrupt, or an exception raised by
/// `progress`, stops the run after the current increment (results so far are written) and
/// is returned as the second item. Returns (outcome, that exception or None).
// The keyword arguments of the Python call, one per `segfem run` option.
#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (model, out_dir, progress=None, verbose=false, continue_on_failure=false, stop_after_step=None, restart=false, no_fields=false))]
fn run(
    py: Python<'_>,
    model: Option<PathBuf>,
    out_dir: PathBuf,
    progress: Option<Py<PyAny>>,
    verbose: bool,
    continue_on_failure: bool,
    stop_after_step: Option<usize>,
    restart: bool,
    no_fields: bool,
) -> (Outcome, Option<PyErr>) {
    let flag = Arc::new(AtomicUsize::new(0));
    let stop = Arc::new(std::sync::Mutex::new(None));
    let opts = RunOptions {
        verbose,
        continue_on_failure,
        stop_after_step,
        signal: Some(flag.clone()),
        restart,
        caller_stop: Some(stop.clone()),
        no_fields,
    };
    let mut raised: Option<PyErr> = None;
    let res = {
        let mut on_increment = |s: &Snapshot| {
            if raised.is_some() {
                return;
            }
            // Python's own SIGINT handler only sets a flag; run it here, between
            // increments, and turn a KeyboardInterrupt into the driver's stop request.
            let err = Python::attach(|py| {
                py.check_signals()?;
                if let Some(cb) = &progress {
                    cb.call1(py, (snapshot_dict(py, s)?,))?;
                }
                Ok::<(), PyErr>(())
            })
            .err();
            if let Some(e) = err {
                // Ctrl-C is the signal it is; any other exception stops the run as the
                // caller's request, recorded as that exception (not as SIGINT).
                let ctrl_c = Python::attach(|py| e.is_instance_of::<PyKeyboardInterrupt>(py));
                if ctrl_c {
                    flag.store(SIGINT, Ordering::SeqCst);
                } else {
                    let what = Python::attach(|py| {
                        let name = e
                            .get_type(py)
                            .name()
                            .map(|n| n.to_string())
                            .unwrap_or_else(|_| "exception".into());
                        format!("the progress callback raised {name}: {}", e.value(py))
                    });
                    *stop.lock().unwrap_or_else(|p| p.into_inner()) = Some(what);
                }
                raised = Some(e);
            }
        };
        py.detach(|| {
            segfem::run::run_file_opts(model.as_deref(), &out_dir, &mut on_increment, &opts)
        })
    };
    (outcome(res), raised)
}

/// Read and validate a model file as `segfem check` does. Returns (model facts as JSON,
/// warnings); raises ValueError with the command line's message on bad input.
#[pyfunction]
fn check(py: Python<'_>, path: PathBuf) -> PyResult<(String, Vec<String>)> {
    let built = py
        .detach(|| segfem::input::load(&path))
        .map_err(input_error)?;
    Ok((facts(&built.model), built.warnings))
}

/// As [`check`], for model text; `label` names the model in messages and is the base of
/// relative file names in it (a Gmsh mesh).
#[pyfunction]
fn check_text(py: Python<'_>, text: String, label: String) -> PyResult<(String, Vec<String>)> {
    let built = py
        .detach(|| segfem::input::parse(&text, &label))
        .map_err(input_error)?;
    Ok((facts(&built.model), built.warnings))
}

/// ValueError(message, file, line, key, problem): the Python side raises its InputError
/// from these.
fn input_error(e: segfem::input::InputError) -> PyErr {
    PyValueError::new_err((e.to_string(), e.file, e.line, e.key, e.message))
}

/// What Python needs to know of a model without running it, as JSON.
fn facts(m: &segfem::model::Model) -> String {
    let v = serde_json::json!({
        "title": m.title,
        "nodes": m.nodes.len(),
        "elements": m.elements.len(),
        "dofs": m.n_dofs(),
        "load_cases": m.load_cases.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(),
        "steps": m.steps.iter().map(|s| s.name.as_str()).collect::<Vec<_>>(),
        "monitors": segfem::run::monitor_info(m),
    });
    v.to_string()
}

/// TOML text to JSON text (the model file as Python data; TOML dates become strings).
#[pyfunction]
fn toml_to_json(text: &str, label: &str) -> PyResult<String> {
    let v: toml::Value = toml::from_str(text)
        .map_err(|e| PyValueError::new_err(format!("{label}: {}", e.message().trim())))?;
    serde_json::to_string(&v).map_err(|e| PyValueError::new_err(format!("{label}: {e}")))
}

/// JSON text (a model as Python data) to TOML text, the model-file form the library reads.
#[pyfunction]
fn json_to_toml(text: &str) -> PyResult<String> {
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let t = toml::Value::try_from(v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    toml::to_string(&t).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// One field output: (time, continuum .vtu, tendons and joints .vtu or None, joint
/// integration points .vtu or None).
type FieldFiles = (f64, PathBuf, Option<PathBuf>, Option<PathBuf>);

/// The field outputs listed in `out_dir/results.pvd`, in output order.
#[pyfunction]
fn field_outputs(out_dir: PathBuf) -> PyResult<Vec<FieldFiles>> {
    let outs = read_pvd(&out_dir).map_err(|e| PyOSError::new_err(e.to_string()))?;
    Ok(outs
        .into_iter()
        .map(|o| (o.time, o.file, o.lines, o.joint_points))
        .collect())
}

fn f64_bytes<'py>(py: Python<'py>, v: impl Iterator<Item = f64>) -> Bound<'py, PyBytes> {
    let b: Vec<u8> = v.flat_map(f64::to_le_bytes).collect();
    PyBytes::new(py, &b)
}

fn arrays<'py>(py: Python<'py>, a: &[Array]) -> PyResult<Bound<'py, PyList>> {
    let l = PyList::empty(py);
    for x in a {
        l.append((
            x.name.as_str(),
            x.components,
            f64_bytes(py, x.values.iter().copied()),
        ))?;
    }
    Ok(l)
}

/// Read a .vtu file the run wrote: a dict of points (bytes, f64 x y), connectivity
/// (bytes, f64 point indices), offsets (cell ends), types and the point and cell arrays
/// as (name, components, bytes).
#[pyfunction]
fn read_vtu<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let g = py
        .detach(|| Grid::read(&path))
        .map_err(|e| PyOSError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item(
        "points",
        f64_bytes(py, g.points.iter().flat_map(|p| [p[0], p[1]])),
    )?;
    d.set_item(
        "connectivity",
        f64_bytes(py, g.cells.iter().flatten().map(|&i| i as f64)),
    )?;
    let mut end = 0usize;
    let offsets: Vec<f64> = g
        .cells
        .iter()
        .map(|c| {
            end += c.len();
            end as f64
        })
        .collect();
    d.set_item("offsets", f64_bytes(py, offsets.into_iter()))?;
    d.set_item("types", PyBytes::new(py, &g.types))?;
    d.set_item("point_data", arrays(py, &g.point_data)?)?;
    d.set_item("cell_data", arrays(py, &g.cell_data)?)?;
    Ok(d)
}

/// The native module.
#[pymodule]
fn _segfem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(check_text, m)?)?;
    m.add_function(wrap_pyfunction!(toml_to_json, m)?)?;
    m.add_function(wrap_pyfunction!(json_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(field_outputs, m)?)?;
    m.add_function(wrap_pyfunction!(read_vtu, m)?)?;
    Ok(())
}
