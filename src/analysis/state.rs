//! The analysis state saved in a checkpoint: everything a converged step leaves behind that
//! later increments read (displacements; committed material, joint, tendon, bar and time
//! states; the driver's load factors and clock). Restoring it gives the same arithmetic as
//! an uninterrupted run, so the results continue bit for bit.
//!
//! Trial copies, latched cracks and factorisations are not saved: at a step end the trial
//! states equal the committed ones, no crack is latched, and every factorisation is
//! recomputed from the same matrix.

use super::bonded_time::BarPointTime;
use super::system::{BarOutput, BarPhase, System};
use super::time::TendonTime;
use crate::elements::continuum::GaussOutput;
use crate::elements::interface::InterfacePointState;
use crate::elements::tendon::TendonState;
use crate::materials::point::{PointState, TimeContext};
use crate::materials::steel::SteelState;
use serde::{Deserialize, Serialize};

/// Where the step driver stands between two steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriverState {
    /// Index of the next step to run (0-based; = number of steps when done).
    pub next_step: usize,
    /// Load-case factors reached [-].
    pub factors: Vec<f64>,
    /// Analysis clock [d].
    pub clock: f64,
    /// Negative pivots at the last converged increment (limit-point detection) [-].
    pub neg_pivots: usize,
    /// Negative pivots of the solver's last factorisation [-].
    pub solver_negative_pivots: usize,
    /// Converged increments so far.
    pub increments: usize,
    /// Newton iterations so far.
    pub iterations: usize,
    /// Limit points passed so far (messages).
    pub limit_points: Vec<String>,
}

/// A stressed tendon: its nodes' displacements when stressed [m], current initial strains
/// (after relaxation) [-], committed state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedTendon {
    /// Displacements of the tendon nodes at stressing [m].
    pub u0: Vec<[f64; 2]>,
    /// Initial span strains ε0 in force [-].
    pub initial_strains: Vec<f64>,
    /// Committed state.
    pub state: TendonState,
}

/// The committed state of a [`System`] (owned; read from a checkpoint).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct SystemState {
    /// Displacements (all dofs) [m].
    pub u: Vec<f64>,
    /// Material point states.
    pub committed: Vec<PointState>,
    /// Gauss-point outputs.
    pub gauss: Vec<GaussOutput>,
    /// Joint point states per interface element.
    pub iface: Vec<Vec<InterfacePointState>>,
    /// Tendons (None: not stressed yet).
    pub tendons: Vec<Option<SavedTendon>>,
    /// Relaxation and loss records of the tendons.
    pub tendon_time: Vec<Option<TendonTime>>,
    /// Steel states of the bar points.
    pub bar_committed: Vec<SteelState>,
    /// Bar outputs.
    pub bar_out: Vec<BarOutput>,
    /// Stage of each bar or bonded tendon.
    pub bar_phase: Vec<BarPhase>,
    /// Bar-point strain at grouting (bonded post-tensioned tendons) [-].
    pub bar_eps_ref: Vec<f64>,
    /// Time interval of the last increment [d].
    pub time: TimeContext,
    /// Displacements before the last committed increment [m].
    pub u_prev: Vec<f64>,
    /// Relaxation and loss records of the bonded-tendon points.
    pub bar_time: Vec<Option<BarPointTime>>,
}

/// The committed state of a [`System`], borrowed for writing. Same fields in the same order
/// as [`SystemState`], so the encodings agree.
#[derive(Serialize)]
pub struct SystemStateRef<'a> {
    u: &'a [f64],
    committed: &'a [PointState],
    gauss: &'a [GaussOutput],
    iface: &'a [Vec<InterfacePointState>],
    tendons: Vec<Option<SavedTendon>>,
    tendon_time: &'a [Option<TendonTime>],
    bar_committed: &'a [SteelState],
    bar_out: &'a [BarOutput],
    bar_phase: &'a [BarPhase],
    bar_eps_ref: &'a [f64],
    time: TimeContext,
    u_prev: &'a [f64],
    bar_time: &'a [Option<BarPointTime>],
}

impl System<'_> {
    /// The committed state, borrowed (call between increments).
    pub fn state(&self) -> SystemStateRef<'_> {
        SystemStateRef {
            u: &self.u,
            committed: &self.committed,
            gauss: &self.gauss,
            iface: &self.iface_committed,
            tendons: self
                .tendons
                .iter()
                .zip(&self.tendon_u0)
                .zip(&self.tendon_committed)
                .map(|((el, u0), st)| match (el, st) {
                    (Some(el), Some(st)) => Some(SavedTendon {
                        u0: u0.clone(),
                        initial_strains: el.initial_strains().to_vec(),
                        state: st.clone(),
                    }),
                    _ => None,
                })
                .collect(),
            tendon_time: &self.tendon_time,
            bar_committed: &self.bar_committed,
            bar_out: &self.bar_out,
            bar_phase: &self.bar_phase,
            bar_eps_ref: &self.bar_eps_ref,
            time: self.time,
            u_prev: &self.u_prev,
            bar_time: &self.bar_time,
        }
    }

    /// Replace the committed (and trial) states by a saved state of the same model. Errors
    /// name what does not match (the model changed since the state was saved).
    pub fn restore(&mut self, s: SystemState) -> Result<(), String> {
        let check = |what: &str, saved: usize, now: usize| {
            if saved == now {
                Ok(())
            } else {
                Err(format!(
                    "the checkpoint has {saved} {what}, the model {now}: the model changed since the checkpoint was written"
                ))
            }
        };
        check("dofs", s.u.len(), self.u.len())?;
        check("material points", s.committed.len(), self.committed.len())?;
        check("Gauss outputs", s.gauss.len(), self.gauss.len())?;
        check("joint elements", s.iface.len(), self.iface_committed.len())?;
        for (a, b) in s.iface.iter().zip(&self.iface_committed) {
            check("joint points in an element", a.len(), b.len())?;
        }
        check("tendons", s.tendons.len(), self.tendons.len())?;
        check(
            "tendon records",
            s.tendon_time.len(),
            self.tendon_time.len(),
        )?;
        check(
            "bar points",
            s.bar_committed.len(),
            self.bar_committed.len(),
        )?;
        check("bar outputs", s.bar_out.len(), self.bar_out.len())?;
        check("bars", s.bar_phase.len(), self.bar_phase.len())?;
        check("bar strains", s.bar_eps_ref.len(), self.bar_eps_ref.len())?;
        check("bar records", s.bar_time.len(), self.bar_time.len())?;
        if let Some(p) = s
            .committed
            .iter()
            .zip(&self.committed)
            .position(|(a, b)| std::mem::discriminant(a) != std::mem::discriminant(b))
        {
            return Err(format!(
                "material point {} has another kind of state in the checkpoint than in the model: the model changed since the checkpoint was written",
                p + 1
            ));
        }
        for (t, saved) in s.tendons.iter().enumerate() {
            let Some(saved) = saved else { continue };
            let n = self.model.tendons[t].nodes.len();
            check("tendon nodes", saved.u0.len(), n)?;
            check("tendon spans", saved.initial_strains.len(), n - 1)?;
            check("tendon span states", saved.state.spans.len(), n - 1)?;
        }
        self.u = s.u;
        self.u_prev = s.u_prev;
        self.trial.clone_from(&s.committed);
        self.committed = s.committed;
        self.gauss_trial.clone_from(&s.gauss);
        self.gauss = s.gauss;
        self.iface_trial.clone_from(&s.iface);
        self.iface_committed = s.iface;
        for (t, saved) in s.tendons.into_iter().enumerate() {
            match saved {
                Some(saved) => {
                    let mut el = self.build_tendon(t, &saved.u0);
                    el.set_initial_strains(&saved.initial_strains);
                    self.tendons[t] = Some(el);
                    self.tendon_u0[t] = saved.u0;
                    self.tendon_trial[t] = Some(saved.state.clone());
                    self.tendon_committed[t] = Some(saved.state);
                }
                None => {
                    self.tendons[t] = None;
                    self.tendon_u0[t] = Vec::new();
                    self.tendon_trial[t] = None;
                    self.tendon_committed[t] = None;
                }
            }
        }
        self.tendon_time = s.tendon_time;
        self.bar_trial.clone_from(&s.bar_committed);
        self.bar_committed = s.bar_committed;
        self.bar_out_trial.clone_from(&s.bar_out);
        self.bar_out = s.bar_out;
        self.bar_phase = s.bar_phase;
        self.bar_eps_ref = s.bar_eps_ref;
        self.bar_time = s.bar_time;
        self.time = s.time;
        self.latched.clear();
        Ok(())
    }
}
