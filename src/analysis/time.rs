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

use super::staged::Staged;
use super::system::System;
use super::tendon_time::{SpanTime, TendonTime};
use crate::materials::chain::SteelRelaxationChain;
use crate::materials::point::TimeContext;

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
                        relax_strain: Staged::new(0.0),
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
                sp.relax_strain.revert();
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
                    sp.relax_strain.trial = sp.relax_strain.committed + (drop + mismatch) / ep;
                }
                eps0.push(sp.eps0 - sp.relax_strain.trial);
            }
            // The strains in force: the element reads them from the block.
            self.families.tendons.initial_strains[t] = eps0;
        }
    }

    /// Book-keeping of a converged increment, called by [`System::commit`] before the trial
    /// tendon states replace the committed ones: the loss split and the relaxation chains
    /// (the trial relaxation strains are committed with the block, `TendonBlock::commit`).
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
                let steel = new.spans[i].strain + sp.relax_strain.trial;
                if let Some(c) = chain {
                    sp.hidden = c.step(&sp.hidden, dt, steel - sp.steel_strain).new_hidden;
                }
                sp.steel_strain = steel;
                sp.relax_drop = 0.0;
            }
        }
    }
}
