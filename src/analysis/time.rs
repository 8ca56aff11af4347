//! Time-dependent analysis in the engine: the analysis clock of the increments, the
//! relaxation of the external tendons' steel, and the split of the prestress losses
//! (docs/theory-time.md, "In the engine").
//!
//! Relaxation is imposed on the tendon as a stress-free strain R_i per span: at the start of
//! each increment of length Δt the non-ageing steel chain of the span
//! ([`SteelRelaxationChain`], fitted to the MC90 loss at the span's initial stress ratio)
//! gives the stress drop at constant strain, Σ_μ (1 − e^{−Δt/τ_μ}) σ_μ; R grows by that drop
//! over E_p (plus the small difference between the tendon's elastic stress and the chain
//! stress, so the two never drift apart). After convergence the chain is advanced with the
//! span's actual total steel strain increment (exponential algorithm), i.e. relaxation
//! follows the varying strain the tendon sees as concrete creeps and shrinks.
//!
//! Units: days, Pa, strains dimensionless.

use super::state::SystemState;
use super::system::System;
use crate::materials::chain::SteelRelaxationChain;
use crate::materials::point::TimeContext;
use crate::model::LossPart;

/// Time-dependent record of one tendon span.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpanTime {
    /// Span stress just after stressing [Pa].
    pub sigma_initial: f64,
    /// Initial (prestress) strain at stressing, before relaxation [-].
    pub eps0: f64,
    /// Committed accumulated relaxation strain R [-].
    pub relax_strain: f64,
    /// R of the current (trial) increment [-].
    pub relax_strain_trial: f64,
    /// Committed total steel strain the chain has seen [-].
    pub steel_strain: f64,
    /// Chain unit stresses [Pa] (empty without relaxation).
    pub hidden: Vec<f64>,
    /// Stress drop at constant strain of the current increment [Pa].
    pub relax_drop: f64,
    /// Loss from instantaneous increments (load steps) [Pa].
    pub loss_elastic: f64,
    /// Loss during time steps not due to relaxation (concrete creep and shrinkage) [Pa].
    pub loss_creep: f64,
    /// Loss by relaxation of the steel [Pa].
    pub loss_relax: f64,
}

/// Time-dependent record of one external tendon.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TendonTime {
    /// One entry per span.
    pub spans: Vec<SpanTime>,
    /// Relaxation chain per span (None: relaxation off or stress ≤ 0.5 f_ptk).
    pub chains: Vec<Option<SteelRelaxationChain>>,
    /// Reference span lengths [m] (weights of the mean loss).
    pub lengths: Vec<f64>,
}

impl TendonTime {
    /// Length-weighted mean over the spans of a loss part [Pa].
    pub fn loss(&self, part: LossPart) -> f64 {
        let lt: f64 = self.lengths.iter().sum();
        self.spans
            .iter()
            .zip(&self.lengths)
            .map(|(s, l)| {
                l * match part {
                    LossPart::Total => s.loss_elastic + s.loss_creep + s.loss_relax,
                    LossPart::Elastic => s.loss_elastic,
                    LossPart::CreepShrinkage => s.loss_creep,
                    LossPart::Relaxation => s.loss_relax,
                }
            })
            .sum::<f64>()
            / lt
    }
}

impl System<'_> {
    /// Start an increment over `time`: set the clock of the material points and impose the
    /// trial relaxation strains of the tendons (from the committed chain states, so a cut
    /// increment simply calls this again with a shorter interval).
    pub fn begin_time_increment(&mut self, time: TimeContext) {
        self.time = time;
        let dt = time.dt();
        self.begin_bonded_time(dt);
        for t in 0..self.tendons.len() {
            let Some(el) = self.tendons[t].as_ref() else {
                continue;
            };
            if self.families.tendons.time[t].is_none() {
                let data = &self.model.tendons[t];
                let ep = el.modulus();
                let chains: Vec<Option<SteelRelaxationChain>> = el
                    .initial_stresses()
                    .iter()
                    .map(|&s| {
                        data.relaxation.and_then(|class| {
                            SteelRelaxationChain::fit(class, s / data.fptk, ep)
                                .ok()
                                .filter(|c| c.n_units() > 1)
                        })
                    })
                    .collect();
                let spans = el
                    .initial_stresses()
                    .iter()
                    .zip(el.initial_strains())
                    .zip(&chains)
                    .map(|((&s, &e0), c)| SpanTime {
                        sigma_initial: s,
                        eps0: e0,
                        relax_strain: 0.0,
                        relax_strain_trial: 0.0,
                        steel_strain: e0,
                        hidden: c
                            .as_ref()
                            .map(|c| c.fractions.iter().map(|a| a * ep * e0).collect())
                            .unwrap_or_default(),
                        relax_drop: 0.0,
                        loss_elastic: 0.0,
                        loss_creep: 0.0,
                        loss_relax: 0.0,
                    })
                    .collect();
                self.families.tendons.time[t] = Some(TendonTime {
                    spans,
                    chains,
                    lengths: el.reference_lengths().to_vec(),
                });
            }
            let (Some(tt), Some(committed)) = (
                self.families.tendons.time[t].as_mut(),
                self.families.tendons.states.committed[t].as_ref(),
            ) else {
                continue;
            };
            if tt.chains.iter().all(Option::is_none) {
                continue;
            }
            let ep = el.modulus();
            let mut eps0 = Vec::with_capacity(tt.spans.len());
            for (i, (sp, chain)) in tt.spans.iter_mut().zip(&tt.chains).enumerate() {
                sp.relax_drop = 0.0;
                sp.relax_strain_trial = sp.relax_strain;
                if let (Some(c), true) = (chain, dt > 0.0) {
                    let drop: f64 = c
                        .taus
                        .iter()
                        .zip(&sp.hidden)
                        .map(|(&tau, &h)| -(-dt / tau).exp_m1() * h)
                        .sum();
                    let chain_stress: f64 = sp.hidden.iter().sum();
                    let mismatch = committed.spans[i].stress - chain_stress;
                    sp.relax_drop = drop;
                    sp.relax_strain_trial = sp.relax_strain + (drop + mismatch) / ep;
                }
                eps0.push(sp.eps0 - sp.relax_strain_trial);
            }
            // The element computes with its copy; the family block keeps the one saved in
            // checkpoints.
            if let Some(el) = self.tendons[t].as_mut() {
                el.set_initial_strains(&eps0);
            }
            self.families.tendons.initial_strains[t] = eps0;
        }
    }

    /// Book-keeping of a converged increment, called by [`System::commit`] before the trial
    /// tendon states replace the committed ones: the loss split and the relaxation chains.
    pub(crate) fn commit_time_dependent(&mut self) {
        let dt = self.time.dt();
        self.commit_bonded_time(dt);
        for t in 0..self.families.tendons.time.len() {
            let (Some(tt), Some(old), Some(new)) = (
                self.families.tendons.time[t].as_mut(),
                self.families.tendons.states.committed[t].as_ref(),
                self.families.tendons.states.trial[t].as_ref(),
            ) else {
                continue;
            };
            for (i, (sp, chain)) in tt.spans.iter_mut().zip(&tt.chains).enumerate() {
                let d_sigma = new.spans[i].stress - old.spans[i].stress;
                if dt > 0.0 {
                    sp.loss_relax += sp.relax_drop;
                    sp.loss_creep += -d_sigma - sp.relax_drop;
                } else {
                    sp.loss_elastic += -d_sigma;
                }
                let steel = new.spans[i].strain + sp.relax_strain_trial;
                if let Some(c) = chain {
                    sp.hidden = c.step(&sp.hidden, dt, steel - sp.steel_strain).new_hidden;
                }
                sp.steel_strain = steel;
                sp.relax_strain = sp.relax_strain_trial;
                sp.relax_drop = 0.0;
            }
        }
    }
}

/// Phase of an error-controlled pair of time substeps (`substep_tolerance` of a time step,
/// docs/theory-time.md §9). The pair over the levels [a, b] of the step is solved once as
/// one substep (the probe, not kept) and then as its two halves; the halves are kept if
/// max|u_probe − u| ≤ tol · max|u − u_a| (step doubling: the difference estimates the
/// probe's error and bounds the halves' own, about 1/(2^p − 1) of it for a method of order
/// p ≥ 1), else the state goes back to a and a shorter pair is tried.
#[derive(Debug, Clone)]
pub enum Pair {
    /// Next: the whole pair as one substep.
    Probe,
    /// Next: the first half.
    First(Box<PairStart>),
    /// Next: the second half.
    Second(Box<PairStart>),
}

/// What a pair of substeps keeps from its start.
#[derive(Debug, Clone)]
pub struct PairStart {
    /// Level (fraction of the step) at the pair's start.
    pub level: f64,
    /// Level at the pair's end.
    pub end: f64,
    /// Displacements of the probe [m].
    pub probe: Vec<f64>,
    /// Committed state at the pair's start (restored if the halves are rejected).
    pub saved: SystemState,
    /// Size of the increment before the pair (IMPL-EX extrapolation).
    pub prev_size: Option<f64>,
    /// Clock reached before the pair [d].
    pub reached_clock: f64,
}

/// `level` [-], or exactly 1 (the end of the step) when it is within the step loop's 1e-12
/// of it or beyond: ten increments of 0.1 sum to 0.9999999999999999, and the last would
/// otherwise end short of the step's factors (a load factor of 100 recorded as
/// 99.999999999999986).
pub fn end_level(level: f64) -> f64 {
    if level >= 1.0 - 1e-12 {
        1.0
    } else {
        level
    }
}

impl Pair {
    /// Level the next increment ends at, from the level reached and the pair length.
    pub fn target(&self, level: f64, pair_length: f64) -> f64 {
        match self {
            Pair::Probe => end_level(level + pair_length),
            Pair::First(s) => 0.5 * (s.level + s.end),
            Pair::Second(s) => s.end,
        }
    }

    /// True before the probe of a pair.
    pub fn is_probe(&self) -> bool {
        matches!(self, Pair::Probe)
    }

    /// The phase after the first half.
    pub fn second(self) -> Pair {
        match self {
            Pair::First(s) => Pair::Second(s),
            p => p,
        }
    }

    /// True when this is a second half whose end displacements `u` [m] miss the probe's by
    /// more than `tol` times the change over the pair, and the pair may still be shortened.
    pub fn rejects(&self, u: &[f64], tol: Option<f64>, may_shorten: bool) -> bool {
        match (self, tol) {
            (Pair::Second(s), Some(tol)) if may_shorten => {
                let (err, change) = pair_error(&s.probe, &s.saved.u, u);
                err > tol * change
            }
            _ => false,
        }
    }
}

impl PairStart {
    /// Factor on the pair length after a pair ending at `u` [m]: the probe's error grows
    /// as h² for the first-order exponential algorithm, so 0.9 (tol·change/err)^½, between
    /// ¼ and 2 (2 where nothing moved).
    pub fn growth(&self, u: &[f64], tol: Option<f64>) -> f64 {
        let Some(tol) = tol else { return 1.0 };
        let (err, change) = pair_error(&self.probe, &self.saved.u, u);
        if err <= 0.0 || !err.is_finite() {
            return 2.0;
        }
        (0.9 * (tol * change / err).sqrt()).clamp(0.25, 2.0)
    }
}

/// Step-doubling error of a pair and the displacement change over it: (max|probe − u|,
/// max|u − start|) [m].
pub fn pair_error(probe: &[f64], start: &[f64], u: &[f64]) -> (f64, f64) {
    let err = probe
        .iter()
        .zip(u)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    let change = start
        .iter()
        .zip(u)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    (err, change)
}
