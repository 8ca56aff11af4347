//! The observer that records monitors into a history and writes field files (.vtu/.pvd)
//! as increments converge. Field files are rewritten whole (atomically); history.csv gets
//! one appended line per converged increment, written before that increment's fields are
//! listed in results.pvd, so that a run killed at any point leaves a history at least as far
//! as its fields (docs/running.md, "Output files").

use super::atomic::write_atomic;
use super::fields::{principal, recover};
use super::joints::summarise;
use super::prepare::{Prepared, TempFile, PREPARE_MIN_BYTES};
use super::vtu::{render, render_into, render_pvd, Array, Grid};
use crate::analysis::steps::{IdleWork, Observer, Snapshot};
use crate::analysis::system::System;
use crate::model::{FieldOutput, Model, MonitorKind};
use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// One row of the history: step, increment, iterations, load factors, monitor values.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Row {
    /// Step index (0-based).
    pub step: usize,
    /// Increment within the step (1-based).
    pub increment: usize,
    /// Newton iterations.
    pub iterations: usize,
    /// Analysis time at the end of the increment [d].
    pub time: f64,
    /// Load-case factors.
    pub factors: Vec<f64>,
    /// Monitor values, in model order.
    pub monitors: Vec<f64>,
    /// Negative pivots of the last tangent (limit point passed when > 0).
    pub negative_pivots: usize,
    /// Arc-length load factor λ (NaN outside arc-length steps).
    pub arc_length_factor: f64,
    /// Force of the displacement control [N] (NaN outside displacement steps).
    pub control_force: f64,
}

/// The recorder's state saved in a checkpoint.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecorderState {
    /// History rows so far.
    pub rows: Vec<Row>,
    /// Entries of results.pvd: (time, part, file name).
    pub pvd: Vec<(f64, usize, String)>,
    /// Displacements at the end of the steps some monitor measures from (step, u) [m].
    pub step_end_u: Vec<(usize, Vec<f64>)>,
    /// Per row: the largest opening of an open joint point [m] and its joint (staged
    /// models; stages.csv reports it per stage).
    pub openings: Vec<(f64, Option<usize>)>,
    /// Per row: (points lifted off, points acting) of every support (models with one-way
    /// supports; empty otherwise).
    pub lifted: Vec<Vec<(usize, usize)>>,
}

/// Records history and writes outputs into a directory.
pub struct Recorder<'m> {
    model: &'m Model,
    dir: PathBuf,
    /// Recorded rows.
    pub rows: Vec<Row>,
    /// Per row: the largest opening of an open joint point [m] and its joint (staged models
    /// only, else (0, None); not a history.csv column: stages.csv reports it per stage).
    pub openings: Vec<(f64, Option<usize>)>,
    /// Per row: (points lifted off, points acting) of every support (models with one-way
    /// supports; empty otherwise): the lift-offs and touch-downs of stages.csv and
    /// summary.json.
    pub lifted: Vec<Vec<(usize, usize)>>,
    pvd: Vec<(f64, usize, String)>,
    /// Displacements at the end of each step some monitor measures from.
    step_end_u: std::collections::HashMap<usize, Vec<f64>>,
    write_fields: bool,
    /// history.csv opened for appending, and the rows it holds.
    history: Option<(std::fs::File, usize)>,
    /// The last converged increment when its fields were not written (what a failed or
    /// stopped run needs to write them from the committed state).
    unwritten: Option<Unwritten>,
    /// The field files of the last increment and results.pvd, being written in that order
    /// on a thread of their own ([`FieldWrite`]).
    writing: Option<FieldWrite>,
    /// The next continuum .vtu's memory being prepared on an idle core
    /// ([`Recorder::idle_work`]).
    prepared: Option<Arc<Prepared>>,
}

/// Field files being written on a thread of their own, in order, results.pvd last (so that
/// it never lists a file not yet in place): the analysis goes on meanwhile (at 5e5 dofs the
/// 95 MB .vtu took 0.2–0.45 s to write, now overlapping the checkpoint's encoding and the
/// release of the factor). Waited for before the next field files, before the checkpoint
/// that lists them is put in place, and before the run ends. Clones share the one write:
/// whichever waits first joins it, the others see its outcome.
#[derive(Clone)]
pub struct FieldWrite(Arc<Mutex<WriteState>>);

/// The thread until joined, then its outcome (an error kept as kind and text).
struct WriteState {
    thread: Option<std::thread::JoinHandle<std::io::Result<()>>>,
    outcome: Result<(), (std::io::ErrorKind, String)>,
}

impl FieldWrite {
    /// Write `files` (path, contents) in order on another thread, the first through
    /// `first_into` if given (a temporary file prepared for it).
    fn start(files: Vec<(PathBuf, Vec<u8>)>, mut first_into: Option<TempFile>) -> Self {
        let thread = std::thread::spawn(move || {
            files
                .iter()
                .try_for_each(|(path, bytes)| match first_into.take() {
                    Some(t) => t.write_as(path, bytes),
                    None => write_atomic(path, bytes),
                })
        });
        Self(Arc::new(Mutex::new(WriteState {
            thread: Some(thread),
            outcome: Ok(()),
        })))
    }

    /// Wait until every file is in place; the first write's error, if any.
    pub fn wait(&self) -> std::io::Result<()> {
        let mut st = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(t) = st.thread.take() {
            st.outcome = t
                .join()
                .unwrap_or_else(|_| Err(std::io::Error::other("the field writer panicked")))
                .map_err(|e| (e.kind(), e.to_string()));
        }
        st.outcome
            .clone()
            .map_err(|(kind, text)| std::io::Error::new(kind, text))
    }
}

/// What a snapshot holds besides the system, kept for an increment whose fields were not
/// written.
struct Unwritten {
    step: usize,
    increment: usize,
    end_of_step: bool,
    factors: Vec<f64>,
    f_int: Vec<f64>,
    f_ext: Vec<f64>,
    iterations: usize,
    negative_pivots: usize,
    arc_length_factor: Option<f64>,
    control_force: Option<f64>,
}

impl<'m> Recorder<'m> {
    /// A recorder writing into `dir` (created if needed). With `write_fields` false only the
    /// history is kept (benchmarks).
    pub fn new(model: &'m Model, dir: PathBuf, write_fields: bool) -> std::io::Result<Self> {
        std::fs::create_dir_all(&dir)?;
        Ok(Self {
            model,
            dir,
            rows: Vec::new(),
            openings: Vec::new(),
            lifted: Vec::new(),
            pvd: Vec::new(),
            step_end_u: Default::default(),
            // A model whose every step has `output = "none"` prepares no .vtu memory either.
            write_fields: write_fields
                && model
                    .steps
                    .iter()
                    .any(|s| s.field_output != FieldOutput::None),
            history: None,
            unwritten: None,
            writing: None,
            prepared: None,
        })
    }

    /// The field files under way, if any: to wait for before anything that lists them
    /// (a checkpoint) is put in place.
    pub fn writing(&self) -> Option<FieldWrite> {
        self.writing.clone()
    }

    /// Wait until the field files under way, if any, are written.
    pub fn wait_fields(&mut self) -> std::io::Result<()> {
        self.writing.take().map_or(Ok(()), |w| w.wait())
    }

    /// What a restart needs to continue the history and the .pvd collection.
    pub fn state(&self) -> RecorderState {
        let mut step_end_u: Vec<(usize, Vec<f64>)> = self
            .step_end_u
            .iter()
            .map(|(k, v)| (*k, v.clone()))
            .collect();
        step_end_u.sort_by_key(|x| x.0);
        RecorderState {
            rows: self.rows.clone(),
            pvd: self.pvd.clone(),
            step_end_u,
            openings: self.openings.clone(),
            lifted: self.lifted.clone(),
        }
    }

    /// Names of the field files results.pvd lists (in the output directory).
    pub fn field_files(&self) -> impl Iterator<Item = &str> {
        self.pvd.iter().map(|(_, _, name)| name.as_str())
    }

    /// Continue from a saved state (rows and field files recorded before a restart).
    pub fn restore(&mut self, s: RecorderState) {
        self.rows = s.rows;
        self.openings = s.openings;
        self.lifted = s.lifted;
        self.pvd = s.pvd;
        self.step_end_u = s.step_end_u.into_iter().collect();
        self.history = None;
    }

    /// The CSV text of the history (header with units).
    pub fn history_csv(&self) -> String {
        let mut s = self.history_header();
        for r in &self.rows {
            s.push_str(&self.history_line(r));
        }
        s
    }

    /// The header line of history.csv: every column with its unit.
    fn history_header(&self) -> String {
        let mut s = String::from("step,increment,iterations,time [d]");
        for c in &self.model.load_cases {
            s.push_str(&format!(",factor:{} [-]", c.name));
        }
        for m in &self.model.monitors {
            s.push_str(&format!(",{} [{}]", m.name, m.unit()));
        }
        let (nonlinear, disp, arc) = path_columns(self.model);
        if nonlinear {
            s.push_str(",negative_pivots [-]");
        }
        if disp {
            s.push_str(",control_force [N]");
        }
        if arc {
            s.push_str(",arc_length_factor [-]");
        }
        s.push('\n');
        s
    }

    /// One data line of history.csv.
    fn history_line(&self, r: &Row) -> String {
        let (nonlinear, disp, arc) = path_columns(self.model);
        let mut s = format!(
            "{},{},{},{:e}",
            r.step + 1,
            r.increment,
            r.iterations,
            r.time
        );
        for v in r.factors.iter().chain(&r.monitors) {
            s.push_str(&format!(",{v:e}"));
        }
        if nonlinear {
            s.push_str(&format!(",{}", r.negative_pivots));
        }
        if disp {
            s.push_str(&format!(",{:e}", r.control_force));
        }
        if arc {
            s.push_str(&format!(",{:e}", r.arc_length_factor));
        }
        s.push('\n');
        s
    }

    /// Write history.csv whole (atomically).
    pub fn write_history(&mut self) -> std::io::Result<()> {
        self.history = None;
        write_atomic(&self.dir.join("history.csv"), self.history_csv().as_bytes())
    }

    /// Bring history.csv up to the rows recorded: append the new lines in one write (a
    /// kill leaves whole lines; the page cache keeps them after the process dies), or
    /// rewrite the file whole when it is not open yet (first row, after a restart).
    fn flush_history(&mut self) -> std::io::Result<()> {
        let open = self.history.as_ref().map(|h| h.1);
        if let Some(done) = open.filter(|&n| n <= self.rows.len()) {
            let text: String = self.rows[done..]
                .iter()
                .map(|r| self.history_line(r))
                .collect();
            let rows = self.rows.len();
            let (f, n) = self.history.as_mut().expect("open");
            f.write_all(text.as_bytes())?;
            *n = rows;
            return Ok(());
        }
        self.write_history()?;
        let f = std::fs::OpenOptions::new()
            .append(true)
            .open(self.dir.join("history.csv"))?;
        self.history = Some((f, self.rows.len()));
        Ok(())
    }

    /// After a run stopped early (an increment failed, a signal): write the fields of the
    /// last converged increment if they were not written, from `system`, which holds that
    /// increment's committed state.
    pub fn write_last_fields(&mut self, system: &System) -> std::io::Result<()> {
        let Some(w) = self.unwritten.take() else {
            return Ok(());
        };
        if !self.write_fields {
            return Ok(());
        }
        let snap = Snapshot {
            system,
            step: w.step,
            increment: w.increment,
            end_of_step: w.end_of_step,
            factors: &w.factors,
            f_int: &w.f_int,
            f_ext: &w.f_ext,
            iterations: w.iterations,
            negative_pivots: w.negative_pivots,
            arc_length_factor: w.arc_length_factor,
            control_force: w.control_force,
            implex_error: None,
        };
        self.write_vtu(&snap)
    }

    fn monitor_values(&self, snap: &Snapshot) -> Vec<f64> {
        let u = snap.system.displacements();
        let n_joints = self.model.joints.len();
        let joints_of = |j: Option<usize>| -> std::ops::Range<usize> {
            match j {
                Some(j) => j..j + 1,
                None => 0..n_joints,
            }
        };
        self.model
            .monitors
            .iter()
            .map(|m| match &m.kind {
                MonitorKind::Displacement {
                    node,
                    dir,
                    since_step,
                } => {
                    let k = 2 * node + dir.index();
                    let base = since_step
                        .and_then(|s| self.step_end_u.get(&s))
                        .map_or(0.0, |u0| u0[k]);
                    u[k] - base
                }
                MonitorKind::Reaction { support, dir } => self.model.supports[*support]
                    .dofs
                    .iter()
                    .filter(|(_, d, _)| d == dir)
                    .map(|(n, d, _)| {
                        let k = 2 * n + d.index();
                        snap.f_int[k] - snap.f_ext[k]
                    })
                    .sum(),
                MonitorKind::LoadFactor { case } => snap.factors[*case],
                MonitorKind::TendonStress { tendon, span } => (snap.system.tendon_state(*tendon))
                    .map(|st| pick_span(st.stresses(), *span))
                    .unwrap_or(0.0),
                MonitorKind::TendonForce { tendon, span } => (snap.system.tendon_state(*tendon))
                    .map(|st| pick_span(st.forces(), *span))
                    .unwrap_or(0.0),
                MonitorKind::TendonLoss { tendon, part } => (snap.system.tendon_time(*tendon))
                    .map(|tt| tt.loss(*part))
                    .unwrap_or(0.0),
                MonitorKind::JointOpening { joint } => joints_of(*joint)
                    .map(|j| summarise(snap.system, j).max_opening)
                    .fold(0.0, f64::max),
                MonitorKind::JointContactDepth { joint } => {
                    summarise(snap.system, *joint).contact_depth
                }
                MonitorKind::JointSlip { joint } => joints_of(*joint)
                    .map(|j| summarise(snap.system, j).max_slip)
                    .fold(0.0, f64::max),
                MonitorKind::BarStress { bar, point } => bar_stress(snap, *bar, *point),
                MonitorKind::BarForce { bar, point } => {
                    self.model.bars[*bar].area * bar_stress(snap, *bar, *point)
                }
                MonitorKind::BarLoss { bar, point, part } => {
                    snap.system.bar_loss(*bar, *point, *part)
                }
                MonitorKind::MaxCrackStrain { region } => {
                    point_extreme(snap, *region, |p| p.crack_strain())
                }
                MonitorKind::MaxPlasticStrain { region } => {
                    point_extreme(snap, *region, |p| p.equivalent_plastic_strain())
                }
                MonitorKind::CrushedPoints { region } => {
                    point_extreme_sum(snap, *region, |p| p.is_crushed() as u8 as f64)
                }
                MonitorKind::StressAtPoint {
                    component,
                    gauss_point,
                } => component.of(snap.system.gauss_outputs()[*gauss_point].stress),
                MonitorKind::StressExtreme {
                    component,
                    region,
                    extreme,
                } => stress_extreme(snap, *component, *region, *extreme),
                MonitorKind::JointContactStress { joint } => joints_of(*joint)
                    .flat_map(|j| summarise(snap.system, j).profile)
                    .map(|p| p.normal_stress)
                    .fold(0.0, f64::max),
            })
            .collect()
    }

    /// Work preparing the next continuum .vtu's buffer and file beside the factorisation
    /// ([`super::prepare`]), for large documents, one at a time; none in a step (index
    /// `step`) that writes no fields.
    pub fn idle_work(&mut self, step: usize) -> Option<IdleWork> {
        let none = self.model.steps[step].field_output == FieldOutput::None;
        if !self.write_fields || none || self.prepared.is_some() {
            return None;
        }
        let len = vtu_len(self.model);
        (len >= PREPARE_MIN_BYTES).then(|| {
            let (p, work) = Prepared::start(&self.dir, len);
            self.prepared = Some(p);
            work
        })
    }

    fn write_vtu(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        // One increment's files at a time, in order.
        self.wait_fields()?;
        let model = self.model;
        let ready = self.prepared.take().and_then(|p| p.take());
        let (buffer, file) = ready.map_or((Vec::new(), None), |r| (r.buffer, r.file));
        let (doc, disp) = continuum_vtu(model, snap, buffer);
        let tag = field_tag(model, snap.step);
        let name = format!("{tag}_inc{:04}.vtu", snap.increment);
        let mut files = vec![(self.dir.join(&name), doc)];
        let t = self.rows.len() as f64;
        self.pvd.push((t, 0, name));
        if let Some(lines) = render_lines(snap, &disp) {
            let name = format!("lines_{tag}_inc{:04}.vtu", snap.increment);
            files.push((self.dir.join(&name), lines.into_bytes()));
            self.pvd.push((t, 1, name));
        }
        if !model.bars.is_empty() {
            let bname = format!("bars_{tag}_inc{:04}.vtu", snap.increment);
            files.push((self.dir.join(&bname), bars_vtu(snap).into_bytes()));
            self.pvd.push((t, 2, bname));
        }
        if super::gauss_points::wanted(model) {
            let gname = format!("gauss_{tag}_inc{:04}.vtu", snap.increment);
            let doc = super::gauss_points::render_gauss_points(snap);
            files.push((self.dir.join(&gname), doc.into_bytes()));
            self.pvd.push((t, 3, gname));
        }
        if let Some(doc) = super::joints::render_joint_points(snap.system) {
            let jname = format!("joints_{tag}_inc{:04}.vtu", snap.increment);
            files.push((self.dir.join(&jname), doc.into_bytes()));
            self.pvd.push((t, 4, jname));
        }
        files.push((
            self.dir.join("results.pvd"),
            render_pvd(&self.pvd).into_bytes(),
        ));
        self.writing = Some(FieldWrite::start(files, file));
        Ok(())
    }
}

impl Drop for Recorder<'_> {
    /// Field files still being written are finished (their error, if any, is lost here:
    /// [`Recorder::wait_fields`] reports it).
    fn drop(&mut self) {
        let _ = self.wait_fields();
        // A prepared file not used is removed (dropping it).
        drop(self.prepared.take().and_then(|p| p.take()));
    }
}

impl Observer for Recorder<'_> {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let wanted = self.model.monitors.iter().any(|m| {
            matches!(m.kind, MonitorKind::Displacement { since_step: Some(s), .. } if s == snap.step)
        });
        if snap.end_of_step && wanted {
            self.step_end_u
                .insert(snap.step, snap.system.displacements().to_vec());
        }
        let monitors = self.monitor_values(snap);
        let (joint_opening, opening_joint) = if self.model.staging.is_staged() {
            super::stages::largest_opening(snap.system)
        } else {
            (0.0, None)
        };
        self.rows.push(Row {
            step: snap.step,
            increment: snap.increment,
            iterations: snap.iterations,
            time: snap.system.time_interval().t_to,
            factors: snap.factors.to_vec(),
            monitors,
            negative_pivots: snap.negative_pivots,
            arc_length_factor: snap.arc_length_factor.unwrap_or(f64::NAN),
            control_force: snap.control_force.unwrap_or(f64::NAN),
        });
        self.openings.push((joint_opening, opening_joint));
        if self.model.staging.has_one_way() {
            let n = self.model.supports.len();
            self.lifted.push(
                snap.system
                    .stages
                    .as_ref()
                    .map_or_else(|| vec![(0, 0); n], |st| st.one_way.lifted_per_support(n)),
            );
        }
        // The history first: results.pvd never lists an increment history.csv lacks.
        self.flush_history()?;
        let fields = self.model.steps[snap.step].field_output;
        if !self.write_fields || fields == FieldOutput::None {
            self.unwritten = None;
        } else if snap.end_of_step || fields == FieldOutput::Increments {
            self.unwritten = None;
            self.write_vtu(snap)?;
        } else {
            self.unwritten = Some(Unwritten {
                step: snap.step,
                increment: snap.increment,
                end_of_step: snap.end_of_step,
                factors: snap.factors.to_vec(),
                f_int: snap.f_int.to_vec(),
                f_ext: snap.f_ext.to_vec(),
                iterations: snap.iterations,
                negative_pivots: snap.negative_pivots,
                arc_length_factor: snap.arc_length_factor,
                control_force: snap.control_force,
            });
        }
        Ok(())
    }
}

/// Length of the continuum .vtu of `model` [bytes], about (the arrays of
/// [`Recorder::write_vtu`] as base64 blocks, and a margin for the tags).
fn vtu_len(model: &Model) -> usize {
    let b64 = |bytes: usize| (4 + bytes).div_ceil(3) * 4 + 120;
    let (n, e) = (model.nodes.len(), model.elements.len());
    let conn: usize = model.elements.iter().map(|el| el.nodes.len()).sum();
    let index = if n <= i32::MAX as usize && conn <= i32::MAX as usize {
        4
    } else {
        8
    };
    let points = b64(24 * n) + b64(index * conn) + b64(index * e) + b64(e);
    // displacement, reaction, stress, principal stress, strain.
    let point_data = 4 * b64(24 * n) + b64(16 * n);
    // region, stress, strain; the concrete state where written.
    let mut cell_data = b64(4 * e) + 2 * b64(24 * e);
    if super::gauss_points::wanted(model) {
        cell_data += 2 * b64(4 * e) + 3 * b64(8 * e) + b64(24 * e);
    }
    points + point_data + cell_data + 1000
}

/// The step part of the field file names: `stepNNN`, and for a staged model
/// `stepNNN_<step name>` (the name made file-safe by [`super::stages::file_slug`]), so that
/// the files of each construction stage carry its name.
fn field_tag(model: &Model, step: usize) -> String {
    let slug = if model.staging.is_staged() {
        super::stages::file_slug(&model.steps[step].name)
    } else {
        String::new()
    };
    if slug.is_empty() {
        format!("step{:03}", step + 1)
    } else {
        format!("step{:03}_{slug}", step + 1)
    }
}

/// Joints and tendons as line cells in a second piece (part 1 of the .pvd): joint elements
/// as face-A lines with their opening and mean tractions, tendon spans with stress and force.
/// None when the model has neither.
fn render_lines(snap: &Snapshot, disp: &[f64]) -> Option<String> {
    let sys = snap.system;
    let model = sys.model;
    if model.interfaces.is_empty() && model.tendons.is_empty() {
        return None;
    }
    let mut cells = Vec::new();
    let mut types = Vec::new();
    let mut kind = Vec::new();
    let (mut opening, mut sn, mut tau, mut t_stress, mut t_force) =
        (vec![], vec![], vec![], vec![], vec![]);
    for (i, el) in model.interfaces.iter().enumerate() {
        let face: Vec<usize> = el.nodes[..el.n_a].to_vec();
        types.push(if face.len() == 3 { 21u8 } else { 3u8 });
        cells.push(face);
        kind.push(1);
        let st = sys.joint_points(i);
        let n = st.len().max(1) as f64;
        opening.push(st.iter().map(|p| p.opening()).fold(0.0, f64::max));
        sn.push(st.iter().map(|p| p.normal_stress()).sum::<f64>() / n);
        tau.push(st.iter().map(|p| p.shear_stress()).sum::<f64>() / n);
        t_stress.push(0.0);
        t_force.push(0.0);
    }
    for (t, data) in model.tendons.iter().enumerate() {
        let state = sys.tendon_state(t);
        for (k, w) in data.nodes.windows(2).enumerate() {
            cells.push(w.to_vec());
            types.push(3);
            kind.push(2);
            opening.push(0.0);
            sn.push(0.0);
            tau.push(0.0);
            t_stress.push(state.map(|s| s.spans[k].stress).unwrap_or(0.0));
            t_force.push(state.map(|s| s.spans[k].force).unwrap_or(0.0));
        }
    }
    Some(render(
        &Grid {
            points: &model.nodes,
            cells: &cells,
            types: &types,
        },
        &[Array::F64 {
            name: "displacement",
            components: 3,
            values: disp,
        }],
        &[
            Array::I32 {
                name: "cell_kind",
                values: &kind,
            },
            Array::F64 {
                name: "joint_opening",
                components: 1,
                values: &opening,
            },
            Array::F64 {
                name: "joint_normal_stress",
                components: 1,
                values: &sn,
            },
            Array::F64 {
                name: "joint_shear_stress",
                components: 1,
                values: &tau,
            },
            Array::F64 {
                name: "tendon_stress",
                components: 1,
                values: &t_stress,
            },
            Array::F64 {
                name: "tendon_force",
                components: 1,
                values: &t_force,
            },
        ],
    ))
}

/// The value of span `span` of a tendon, or the largest over its spans.
fn pick_span(values: Vec<f64>, span: Option<usize>) -> f64 {
    match span {
        Some(k) => values.get(k).copied().unwrap_or(0.0),
        None => values.into_iter().fold(0.0, f64::max),
    }
}

/// Stress of a bar [Pa] at one of its points, or the value of largest magnitude.
fn bar_stress(snap: &Snapshot, bar: usize, point: Option<usize>) -> f64 {
    let sys = snap.system;
    let mut best: f64 = 0.0;
    for ((b, p), out) in sys.bar_outputs() {
        if b != bar {
            continue;
        }
        let s = out.stress;
        match point {
            Some(q) if q == p => return s,
            Some(_) => {}
            None => {
                if s.abs() > best.abs() {
                    best = s;
                }
            }
        }
    }
    best
}

/// Committed point states of the elements of a region (all if None).
fn region_points<'a>(
    snap: &'a Snapshot,
    region: Option<usize>,
) -> impl Iterator<Item = &'a crate::materials::point::PointState> + 'a {
    let sys = snap.system;
    sys.model
        .elements
        .iter()
        .enumerate()
        .filter(move |(_, e)| region.is_none_or(|r| e.region == r))
        .flat_map(move |(i, _)| sys.element_points(i))
}

fn point_extreme(
    snap: &Snapshot,
    region: Option<usize>,
    f: impl Fn(&crate::materials::point::PointState) -> f64,
) -> f64 {
    region_points(snap, region).map(f).fold(0.0, f64::max)
}

/// The extreme of a stress component over the Gauss points of a region (all if None) [Pa].
fn stress_extreme(
    snap: &Snapshot,
    component: crate::model::StressComponent,
    region: Option<usize>,
    extreme: crate::model::Extreme,
) -> f64 {
    use crate::model::Extreme;
    let sys = snap.system;
    let values = sys
        .model
        .elements
        .iter()
        .enumerate()
        .filter(move |(_, e)| region.is_none_or(|r| e.region == r))
        .flat_map(move |(i, _)| sys.element_gauss(i))
        .map(|g| component.of(g.stress));
    let pick = match extreme {
        Extreme::Max => values.reduce(f64::max),
        Extreme::Min => values.reduce(f64::min),
        Extreme::Abs => values.reduce(|a, b| if b.abs() > a.abs() { b } else { a }),
    };
    pick.unwrap_or(0.0)
}

/// The input `kind` of a monitor (summary.json `monitors`; the plots choose display units
/// and signs by it).
pub fn kind_name(k: &MonitorKind) -> &'static str {
    match k {
        MonitorKind::Displacement { .. } => "displacement",
        MonitorKind::Reaction { .. } => "reaction",
        MonitorKind::LoadFactor { .. } => "load_factor",
        MonitorKind::JointOpening { .. } => "joint_opening",
        MonitorKind::JointContactDepth { .. } => "joint_contact_depth",
        MonitorKind::JointSlip { .. } => "joint_slip",
        MonitorKind::JointContactStress { .. } => "joint_contact_stress",
        MonitorKind::TendonStress { .. } | MonitorKind::BarStress { .. } => "tendon_stress",
        MonitorKind::TendonForce { .. } | MonitorKind::BarForce { .. } => "tendon_force",
        MonitorKind::TendonLoss { .. } | MonitorKind::BarLoss { .. } => "tendon_loss",
        MonitorKind::MaxCrackStrain { .. } => "max_crack_strain",
        MonitorKind::MaxPlasticStrain { .. } => "max_plastic_strain",
        MonitorKind::CrushedPoints { .. } => "crushed_points",
        MonitorKind::StressAtPoint { .. } | MonitorKind::StressExtreme { .. } => "stress",
    }
}

fn point_extreme_sum(
    snap: &Snapshot,
    region: Option<usize>,
    f: impl Fn(&crate::materials::point::PointState) -> f64,
) -> f64 {
    region_points(snap, region).map(f).sum()
}

/// Which extra history columns a model has: negative pivots (nonlinear models), control
/// force (displacement steps), arc-length factor (arc-length steps).
fn path_columns(model: &Model) -> (bool, bool, bool) {
    use crate::model::StepKind;
    let has = |k: StepKind| model.steps.iter().any(|s| s.kind == k);
    let nonlinear = !model.materials.iter().all(|m| m.law.is_linear())
        || !model.bars.is_empty()
        || has(StepKind::Displacement)
        || has(StepKind::ArcLength);
    (
        nonlinear,
        has(StepKind::Displacement),
        has(StepKind::ArcLength),
    )
}

/// Cell values of the concrete states (Gauss points of each element).
struct CellStates {
    /// Largest number of cracks at a point [-].
    cracks: Vec<i32>,
    /// Crack-normal angle from x [deg] at the point with the largest crack strain.
    angle: Vec<f64>,
    /// Largest crack-opening strain [-].
    crack_strain: Vec<f64>,
    /// Largest equivalent plastic strain [-].
    plastic: Vec<f64>,
    /// Number of crushed points [-].
    crushed: Vec<i32>,
}

/// The .vtu document of the continuum of `model` at `snap` (nodal displacements, reactions, recovered
/// stresses and strains; per cell the region, stresses, strains and, where a material can
/// crack or crush, the concrete state), rendered into `buffer`, and the nodal displacements
/// (x, y, 0) [m] the line cells reuse.
fn continuum_vtu(model: &Model, snap: &Snapshot, buffer: Vec<u8>) -> (Vec<u8>, Vec<f64>) {
    let f = recover(snap.system);
    let cells: Vec<&[usize]> = model.elements.iter().map(|e| e.nodes.as_slice()).collect();
    let types: Vec<u8> = model
        .elements
        .iter()
        .map(|e| e.kind.vtk_cell_type())
        .collect();
    let disp: Vec<f64> = snap
        .system
        .displacements()
        .chunks(2)
        .flat_map(|d| [d[0], d[1], 0.0])
        .collect();
    // The recovered fields' own memory, viewed flat (no copies: 24 MB at 5e5 dofs).
    let ns = f.node_stress.as_flattened();
    let ne = f.node_strain.as_flattened();
    let np: Vec<f64> = f
        .node_stress
        .iter()
        .flat_map(|s| {
            let (a, b) = principal(s);
            [a, b]
        })
        .collect();
    let cs = f.cell_stress.as_flattened();
    let ce = f.cell_strain.as_flattened();
    let region: Vec<i32> = model.elements.iter().map(|e| e.region as i32).collect();
    let mut reaction = vec![0.0; 3 * model.nodes.len()];
    for s in &model.supports {
        for &(n, d, _) in &s.dofs {
            let k = 2 * n + d.index();
            reaction[3 * n + d.index()] = snap.f_int[k] - snap.f_ext[k];
        }
    }
    // The concrete state per cell only where a material can crack or crush: an elastic
    // model's zeros would be a fifth of a large .vtu.
    let concrete = (super::gauss_points::wanted(model)).then(|| {
        let st = cell_states(snap);
        // Unit normal of the widest crack of each cell, as a vector for ParaView glyphs
        // (zero for uncracked cells); crack_angle holds the same in degrees from x.
        let crack_normal: Vec<f64> = st
            .angle
            .iter()
            .zip(&st.cracks)
            .flat_map(|(deg, n)| {
                let t = deg.to_radians();
                if *n > 0 {
                    [t.cos(), t.sin(), 0.0]
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        (st, crack_normal)
    });
    let mut cell_data = vec![
        Array::I32 {
            name: "region",
            values: &region,
        },
        Array::F64 {
            name: "stress",
            components: 3,
            values: cs,
        },
        Array::F64 {
            name: "strain",
            components: 3,
            values: ce,
        },
    ];
    if let Some((st, crack_normal)) = &concrete {
        cell_data.extend([
            Array::I32 {
                name: "cracks",
                values: &st.cracks,
            },
            Array::F64 {
                name: "crack_angle",
                components: 1,
                values: &st.angle,
            },
            Array::F64 {
                name: "crack_strain",
                components: 1,
                values: &st.crack_strain,
            },
            Array::F64 {
                name: "crack_normal",
                components: 3,
                values: crack_normal,
            },
            Array::F64 {
                name: "plastic_strain",
                components: 1,
                values: &st.plastic,
            },
            Array::I32 {
                name: "crushed",
                values: &st.crushed,
            },
        ]);
    }
    let doc = render_into(
        buffer,
        &Grid {
            points: &model.nodes,
            cells: &cells,
            types: &types,
        },
        &[
            Array::F64 {
                name: "displacement",
                components: 3,
                values: &disp,
            },
            Array::F64 {
                name: "reaction",
                components: 3,
                values: &reaction,
            },
            Array::F64 {
                name: "stress",
                components: 3,
                values: ns,
            },
            Array::F64 {
                name: "principal_stress",
                components: 2,
                values: &np,
            },
            Array::F64 {
                name: "strain",
                components: 3,
                values: ne,
            },
        ],
        &cell_data,
    );
    (doc, disp)
}

fn cell_states(snap: &Snapshot) -> CellStates {
    let sys = snap.system;
    let n = sys.model.elements.len();
    let mut c = CellStates {
        cracks: Vec::with_capacity(n),
        angle: Vec::with_capacity(n),
        crack_strain: Vec::with_capacity(n),
        plastic: Vec::with_capacity(n),
        crushed: Vec::with_capacity(n),
    };
    for e in 0..n {
        let pts = sys.element_points(e);
        c.cracks
            .push(pts.iter().map(|p| p.n_cracks()).max().unwrap_or(0) as i32);
        let widest = pts
            .iter()
            .filter(|p| p.n_cracks() > 0)
            .max_by(|a, b| a.crack_strain().total_cmp(&b.crack_strain()));
        c.angle
            .push(widest.map_or(0.0, |p| p.crack_angle().to_degrees()));
        c.crack_strain
            .push(pts.iter().map(|p| p.crack_strain()).fold(0.0, f64::max));
        c.plastic.push(
            pts.iter()
                .map(|p| p.equivalent_plastic_strain())
                .fold(0.0, f64::max),
        );
        c.crushed
            .push(pts.iter().filter(|p| p.is_crushed()).count() as i32);
    }
    c
}

/// The bars as a .vtu of poly-lines: one cell per piece (entry, its Gauss points, exit),
/// and one vertex per Gauss point of a smeared layer;
/// point data = stress, strain and plastic strain (the entry/exit points take the values of
/// the nearest Gauss point); cell data = bar index.
fn bars_vtu(snap: &Snapshot) -> String {
    let sys = snap.system;
    let model = sys.model;
    // Output values per (bar, point) from the element-sorted arrays.
    let mut vals: Vec<Vec<crate::analysis::system::BarOutput>> = model
        .bars
        .iter()
        .map(|b| vec![Default::default(); b.points.len()])
        .collect();
    for ((b, p), out) in sys.bar_outputs() {
        vals[b][p] = *out;
    }
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut cells: Vec<Vec<usize>> = Vec::new();
    let mut bar_id: Vec<i32> = Vec::new();
    let (mut stress, mut strain, mut plastic) = (Vec::new(), Vec::new(), Vec::new());
    let mut types: Vec<u8> = Vec::new();
    for (b, bar) in model.bars.iter().enumerate() {
        if bar.layer {
            // A smeared layer has no line: one vertex per Gauss point.
            for (p, gp) in bar.points.iter().enumerate() {
                cells.push(vec![points.len()]);
                points.push(gp.point.x);
                stress.push(vals[b][p].stress);
                strain.push(vals[b][p].strain);
                plastic.push(vals[b][p].plastic_strain);
                bar_id.push(b as i32);
                types.push(1); // VTK_VERTEX
            }
            continue;
        }
        for (k, &(p0, p1)) in bar.piece_points.iter().enumerate() {
            if p1 == p0 {
                continue;
            }
            let mut cell = Vec::with_capacity(p1 - p0 + 2);
            let mut push = |x: [f64; 2], o: &crate::analysis::system::BarOutput| {
                cell.push(points.len());
                points.push(x);
                stress.push(o.stress);
                strain.push(o.strain);
                plastic.push(o.plastic_strain);
            };
            push(bar.piece_ends[k][0], &vals[b][p0]);
            for p in p0..p1 {
                push(bar.points[p].point.x, &vals[b][p]);
            }
            push(bar.piece_ends[k][1], &vals[b][p1 - 1]);
            cells.push(cell);
            bar_id.push(b as i32);
            types.push(4); // VTK_POLY_LINE
        }
    }
    render(
        &Grid {
            points: &points,
            cells: &cells,
            types: &types,
        },
        &[
            Array::F64 {
                name: "bar_stress",
                components: 1,
                values: &stress,
            },
            Array::F64 {
                name: "bar_strain",
                components: 1,
                values: &strain,
            },
            Array::F64 {
                name: "bar_plastic_strain",
                components: 1,
                values: &plastic,
            },
        ],
        &[Array::I32 {
            name: "bar",
            values: &bar_id,
        }],
    )
}
