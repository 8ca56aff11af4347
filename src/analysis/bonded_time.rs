//! Relaxation and loss records of bonded tendons (post-tensioned once stressed,
//! pre-tensioned from the start), one per tendon integration point: the bonded counterpart of
//! the external tendons' [`super::tendon_time::TendonTime`] (docs/theory-prestress.md, "Losses and
//! relaxation of bonded tendons").
//!
//! Relaxation is a stress-free strain R per point, subtracted from the bond strain
//! (`System::assemble`): at the start of each increment of length Δt the point's non-ageing
//! steel chain (fitted to the MC90 loss at the point's bonding stress ratio σ_0/f_ptk) gives
//! the stress drop at constant strain Σ_μ (1 − e^{−Δt/τ_μ}) σ_μ, and R grows by that drop over
//! E_p (plus the difference between the point's committed stress and the chain stress, so the
//! two never drift apart). After convergence the chain takes the point's actual steel-strain
//! increment: relaxation follows the strain the tendon sees as the concrete creeps and
//! shrinks. Each converged stress change is booked as elastic (load increments: elastic
//! shortening at transfer, later tendons, loads), relaxation (the chain's drop) or creep and
//! shrinkage (the rest of a time increment), so the parts add up to σ_0 − σ exactly.
//!
//! Units: days, Pa, strains dimensionless.

use super::system::{BarPhase, System};
use super::tendon_time::BarPointTime;
use crate::model::{Bar, LossPart};

/// True for the bars that are tendons (post-tensioned, or pre-tensioned with an initial
/// stress or a relaxation class): they get loss records.
pub fn is_tendon(bar: &Bar) -> bool {
    bar.post_tension.is_some() || bar.initial_stress != 0.0 || bar.relaxation.is_some()
}

impl System<'_> {
    /// Create the records of the tendon points that are present (bonded or locked off) and
    /// have none yet.
    fn ensure_bar_records(&mut self) {
        let model = self.model;
        for (i, &(b, p)) in self.bar_gps.iter().enumerate() {
            let bar = &model.bars[b];
            if self.families.bars.time[i].is_none()
                && self.families.bars.phase[b] != BarPhase::Inactive
                && is_tendon(bar)
            {
                self.families.bars.time[i] = Some(BarPointTime::new(bar, bar.bonding_stress(p)));
            }
        }
    }

    /// Trial relaxation strains of the bonded-tendon points for an increment of `dt` [d]
    /// (from the committed chain states, so a cut increment calls this again).
    pub(crate) fn begin_bonded_time(&mut self, dt: f64) {
        self.ensure_bar_records();
        for rec in self.families.bars.time.iter_mut().flatten() {
            rec.relax_drop = 0.0;
            rec.relax_strain.revert();
            let (Some(c), true) = (&rec.chain, dt > 0.0) else {
                continue;
            };
            let drop: f64 = c
                .taus
                .iter()
                .zip(&rec.hidden)
                .map(|(&tau, &h)| -(-dt / tau).exp_m1() * h)
                .sum();
            let mismatch = rec.stress - rec.hidden.iter().sum::<f64>();
            rec.relax_drop = drop;
            rec.relax_strain.trial = rec.relax_strain.committed + (drop + mismatch) / c.ep;
        }
    }

    /// Book-keeping of a converged increment (before the trial bar outputs replace the
    /// committed ones): the loss split and the relaxation chains (the trial relaxation
    /// strains are committed with the block, `BarBlock::commit`).
    pub(crate) fn commit_bonded_time(&mut self, dt: f64) {
        self.ensure_bar_records();
        for (rec, out) in self
            .families
            .bars
            .time
            .iter_mut()
            .zip(&self.families.bars.out.trial)
        {
            let Some(rec) = rec else { continue };
            let d_sigma = out.stress - rec.stress;
            if dt > 0.0 {
                rec.loss_relax += rec.relax_drop;
                rec.loss_creep += -d_sigma - rec.relax_drop;
            } else {
                rec.loss_elastic += -d_sigma;
            }
            let steel = out.strain + rec.relax_strain.trial;
            if let Some(c) = &rec.chain {
                rec.hidden = c.step(&rec.hidden, dt, steel - rec.steel_strain).new_hidden;
            }
            rec.steel_strain = steel;
            rec.stress = out.stress;
            rec.relax_drop = 0.0;
        }
    }

    /// Loss of bonded tendon `bar` since σ_0 [Pa]: at its point `point`, or the mean over its
    /// points weighted by their length (points not yet stressed count as no loss).
    pub fn bar_loss(&self, bar: usize, point: Option<usize>, part: LossPart) -> f64 {
        let model = self.model;
        let (mut sum, mut w) = (0.0, 0.0);
        for (i, &(b, p)) in self.bar_gps.iter().enumerate() {
            if b != bar {
                continue;
            }
            let v = self.families.bars.time[i]
                .as_ref()
                .map_or(0.0, |r| r.loss(part));
            match point {
                Some(q) if q == p => return v,
                Some(_) => {}
                None => {
                    let wl = model.bars[b].points[p].point.weight_length;
                    sum += wl * v;
                    w += wl;
                }
            }
        }
        if w > 0.0 {
            sum / w
        } else {
            0.0
        }
    }
}
