//! The time records of tendons that the state blocks keep ([`super::families`]): per span
//! of an external tendon (`SpanTime`, `TendonTime`) and per integration point of a bonded
//! tendon (`BarPointTime`), with their committed relaxation strains, relaxation chains and
//! the split of the losses. The engine that advances them is `System`'s, in
//! [`super::time`] (external tendons) and [`super::bonded_time`] (bonded tendons); the
//! records sit below the state so that the state does not import the engine.
//!
//! Units: days, Pa, strains dimensionless.

use super::staged::Staged;
use crate::materials::chain::SteelRelaxationChain;
use crate::model::{Bar, LossPart};

/// Time-dependent record of one tendon span.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpanTime {
    /// Span stress just after stressing [Pa].
    pub sigma_initial: f64,
    /// Initial (prestress) strain at stressing, before relaxation [-].
    pub eps0: f64,
    /// Accumulated relaxation strain R [-]: committed, and of the current (trial)
    /// increment (both saved: the layout of checkpoint format 10).
    #[serde(with = "super::staged::both")]
    pub relax_strain: Staged<f64>,
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

/// Time-dependent record of one bonded-tendon integration point.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BarPointTime {
    /// Stress when the tendon was bonded or locked off (σ_0, the losses' origin) [Pa].
    pub sigma_initial: f64,
    /// Committed stress [Pa].
    pub stress: f64,
    /// Accumulated relaxation strain R [-]: committed, and of the current (trial)
    /// increment (both saved: the layout of checkpoint format 10).
    #[serde(with = "super::staged::both")]
    pub relax_strain: Staged<f64>,
    /// Committed total steel strain (bond strain + R) the chain has seen [-].
    pub steel_strain: f64,
    /// Relaxation chain (None: no `relaxation_class`, or σ_0 ≤ 0.5 f_ptk).
    pub chain: Option<SteelRelaxationChain>,
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

impl BarPointTime {
    /// Record of a point bonded (or locked off) at stress `sigma0` [Pa].
    pub(super) fn new(bar: &Bar, sigma0: f64) -> Self {
        let ep = bar.steel.es;
        let chain = bar.relaxation.and_then(|(class, fptk)| {
            SteelRelaxationChain::fit(class, sigma0 / fptk, ep)
                .ok()
                .filter(|c| c.n_units() > 1)
        });
        let hidden = chain
            .as_ref()
            .map(|c| c.fractions.iter().map(|a| a * sigma0).collect())
            .unwrap_or_default();
        Self {
            sigma_initial: sigma0,
            stress: sigma0,
            relax_strain: Staged::new(0.0),
            steel_strain: sigma0 / ep,
            chain,
            hidden,
            relax_drop: 0.0,
            loss_elastic: 0.0,
            loss_creep: 0.0,
            loss_relax: 0.0,
        }
    }

    /// One part of the loss since σ_0 [Pa] (positive = loss).
    pub fn loss(&self, part: LossPart) -> f64 {
        match part {
            LossPart::Total => self.loss_elastic + self.loss_creep + self.loss_relax,
            LossPart::Elastic => self.loss_elastic,
            LossPart::CreepShrinkage => self.loss_creep,
            LossPart::Relaxation => self.loss_relax,
        }
    }
}
