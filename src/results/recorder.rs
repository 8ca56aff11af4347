//! The observer that records monitors into a history and writes field files (.vtu/.pvd)
//! as increments converge. Files are rewritten whole (atomically) so that a run stopped at
//! any point leaves complete files of everything computed so far.

use super::atomic::write_atomic;
use super::fields::{principal, recover};
use super::joints::summarise;
use super::vtu::{render, render_pvd, Array, Grid};
use crate::analysis::steps::{Observer, Snapshot};
use crate::model::{Model, MonitorKind};
use std::path::PathBuf;

/// One row of the history: step, increment, iterations, load factors, monitor values.
#[derive(Debug, Clone, serde::Serialize)]
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
}

/// Records history and writes outputs into a directory.
pub struct Recorder<'m> {
    model: &'m Model,
    dir: PathBuf,
    /// Recorded rows.
    pub rows: Vec<Row>,
    pvd: Vec<(f64, String)>,
    write_fields: bool,
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
            pvd: Vec::new(),
            write_fields,
        })
    }

    /// The CSV text of the history (header with units).
    pub fn history_csv(&self) -> String {
        let mut s = String::from("step,increment,iterations,time [d]");
        for c in &self.model.load_cases {
            s.push_str(&format!(",factor:{} [-]", c.name));
        }
        for m in &self.model.monitors {
            s.push_str(&format!(",{} [{}]", m.name, m.unit()));
        }
        s.push('\n');
        for r in &self.rows {
            s.push_str(&format!(
                "{},{},{},{:e}",
                r.step + 1,
                r.increment,
                r.iterations,
                r.time
            ));
            for v in r.factors.iter().chain(&r.monitors) {
                s.push_str(&format!(",{v:e}"));
            }
            s.push('\n');
        }
        s
    }

    /// Write history.csv (atomically).
    pub fn write_history(&self) -> std::io::Result<()> {
        write_atomic(&self.dir.join("history.csv"), self.history_csv().as_bytes())
    }

    fn monitor_values(&self, snap: &Snapshot) -> Vec<f64> {
        let u = &snap.system.u;
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
                MonitorKind::Displacement { node, dir } => u[2 * node + dir.index()],
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
                MonitorKind::TendonStress { tendon } => snap.system.tendon_committed[*tendon]
                    .as_ref()
                    .map(|st| st.stresses().into_iter().fold(0.0, f64::max))
                    .unwrap_or(0.0),
                MonitorKind::TendonForce { tendon } => snap.system.tendon_committed[*tendon]
                    .as_ref()
                    .map(|st| st.forces().into_iter().fold(0.0, f64::max))
                    .unwrap_or(0.0),
                MonitorKind::TendonLoss { tendon, part } => snap.system.tendon_time[*tendon]
                    .as_ref()
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
            })
            .collect()
    }

    fn write_vtu(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let model = self.model;
        let f = recover(snap.system);
        let cells: Vec<Vec<usize>> = model.elements.iter().map(|e| e.nodes.clone()).collect();
        let types: Vec<u8> = model
            .elements
            .iter()
            .map(|e| e.kind.vtk_cell_type())
            .collect();
        let disp: Vec<f64> = snap
            .system
            .u
            .chunks(2)
            .flat_map(|d| [d[0], d[1], 0.0])
            .collect();
        let flat = |v: &[[f64; 3]]| -> Vec<f64> { v.iter().flatten().copied().collect() };
        let ns = flat(&f.node_stress);
        let ne = flat(&f.node_strain);
        let np: Vec<f64> = f
            .node_stress
            .iter()
            .flat_map(|s| {
                let (a, b) = principal(s);
                [a, b]
            })
            .collect();
        let cs = flat(&f.cell_stress);
        let ce = flat(&f.cell_strain);
        let region: Vec<i32> = model.elements.iter().map(|e| e.region as i32).collect();
        let mut reaction = vec![0.0; 3 * model.nodes.len()];
        for s in &model.supports {
            for &(n, d, _) in &s.dofs {
                let k = 2 * n + d.index();
                reaction[3 * n + d.index()] = snap.f_int[k] - snap.f_ext[k];
            }
        }
        let doc = render(
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
                    values: &ns,
                },
                Array::F64 {
                    name: "principal_stress",
                    components: 2,
                    values: &np,
                },
                Array::F64 {
                    name: "strain",
                    components: 3,
                    values: &ne,
                },
            ],
            &[
                Array::I32 {
                    name: "region",
                    values: &region,
                },
                Array::F64 {
                    name: "stress",
                    components: 3,
                    values: &cs,
                },
                Array::F64 {
                    name: "strain",
                    components: 3,
                    values: &ce,
                },
            ],
        );
        let name = format!("step{:03}_inc{:04}.vtu", snap.step + 1, snap.increment);
        write_atomic(&self.dir.join(&name), doc.as_bytes())?;
        self.pvd.push((self.rows.len() as f64, name));
        write_atomic(
            &self.dir.join("results.pvd"),
            render_pvd(&self.pvd).as_bytes(),
        )
    }
}

impl Observer for Recorder<'_> {
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let monitors = self.monitor_values(snap);
        self.rows.push(Row {
            step: snap.step,
            increment: snap.increment,
            iterations: snap.iterations,
            time: snap.system.time.t_to,
            factors: snap.factors.to_vec(),
            monitors,
        });
        let step = &self.model.steps[snap.step];
        if self.write_fields && (snap.end_of_step || step.output_every_increment) {
            self.write_vtu(snap)?;
        }
        if snap.end_of_step {
            self.write_history()?;
        }
        Ok(())
    }
}
