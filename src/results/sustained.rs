//! Watch for sustained compressive stresses beyond MC90's linear-creep range in creeping
//! concrete (`creep = "mc90"` without `nonlinear_creep`): MC90's creep function is linear in
//! the stress only up to |σ_c| = 0.4 f_cm; above it creep grows faster and a linear
//! analysis underestimates it (docs/theory-time.md §9, docs/running.md "Warnings").
//!
//! The check reads the committed Gauss-point stresses after each converged time increment
//! (Δt > 0: the stress is held over the increment); load increments (Δt = 0) are not
//! sustained and are not checked. The material update is untouched.

use crate::analysis::steps::Snapshot;
use crate::materials::point::Material;

/// Largest compressive stress over f_cm [-] of MC90's linear creep range (MC90 2.1.6.4.3).
pub const LINEAR_CREEP_LIMIT: f64 = 0.4;

/// The worst sustained stress seen: |σ_c|/f_cm [-], region index, analysis time [d].
#[derive(Debug, Clone, Copy)]
struct Worst {
    ratio: f64,
    region: usize,
    time: f64,
}

/// Watches converged time increments; keeps the largest |σ_c|/f_cm above the limit.
#[derive(Debug, Default)]
pub struct SustainedStress {
    /// f_cm [Pa] of each region whose material is a linearly creeping concrete (None: not
    /// watched); empty until the first increment.
    fcm: Vec<Option<f64>>,
    /// The first time [d] the limit was passed.
    first: Option<f64>,
    worst: Option<Worst>,
}

impl SustainedStress {
    /// A watch with nothing seen.
    pub fn new() -> Self {
        Self::default()
    }

    /// Check one converged increment.
    pub fn increment(&mut self, snap: &Snapshot) {
        let sys = snap.system;
        let model = sys.model;
        if sys.time_interval().t_to <= sys.time_interval().t_from {
            return;
        }
        if self.fcm.is_empty() {
            self.fcm = model
                .regions
                .iter()
                .map(|r| match &model.materials[r.material].law {
                    Material::Concrete { params, .. } => params
                        .creep
                        .as_ref()
                        .filter(|c| !c.nonlinear)
                        .map(|c| c.chain.params().fcm),
                    _ => None,
                })
                .collect();
        }
        if self.fcm.iter().all(Option::is_none) {
            return;
        }
        for (e, el) in model.elements.iter().enumerate() {
            let Some(fcm) = self.fcm[el.region] else {
                continue;
            };
            for g in sys.element_gauss(e) {
                let s = g.stress;
                let c = 0.5 * (s[0] + s[1]);
                let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
                let ratio = -(c - r) / fcm;
                if ratio > LINEAR_CREEP_LIMIT {
                    self.first.get_or_insert(sys.time_interval().t_to);
                    if self.worst.is_none_or(|w| ratio > w.ratio) {
                        self.worst = Some(Worst {
                            ratio,
                            region: el.region,
                            time: sys.time_interval().t_to,
                        });
                    }
                }
            }
        }
    }

    /// The warning, if the limit was passed (one for the run, at its worst point).
    pub fn warning(&self, model: &crate::model::Model) -> Option<String> {
        let w = self.worst?;
        let region = &model.regions[w.region];
        Some(format!(
            "sustained compressive stress beyond MC90's linear creep range: region '{}' (material '{}', creep = \"mc90\") reached |σ_c| = {:.2} f_cm at t = {} d (above {} f_cm from t = {} d on); creep there is underestimated: set nonlinear_creep = true on the material for MC90's stress-dependent creep",
            region.name,
            model.materials[region.material].name,
            w.ratio,
            fmt_day(w.time),
            LINEAR_CREEP_LIMIT,
            fmt_day(self.first.unwrap_or(w.time)),
        ))
    }
}

/// A day count rounded to 1e-3 d (no trailing zeros).
fn fmt_day(t: f64) -> String {
    format!("{}", (t * 1e3).round() / 1e3)
}
