//! Which failure a run to failure reached, and at what load: the first of tendon yield,
//! concrete crushing (at an opened joint or elsewhere) and loss of equilibrium met along the
//! converged increments, with the peak load. Written to `summary.json` (`ultimate`) and
//! printed by `segfem run` (docs/running.md, "Runs to failure").
//!
//! The events are read from the committed states at each converged increment, so the
//! verdict costs one pass over the tendons, concrete points and joints per increment.

use crate::analysis::steps::Snapshot;
use crate::model::Model;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A failure event and the increment (index into the watched increments) where it was
/// first met.
#[derive(Debug, Clone, PartialEq)]
struct Event {
    mode: &'static str,
    detail: String,
    at: usize,
}

/// How a run to failure ended (summary.json `ultimate`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ultimate {
    /// The first failure met: "tendon yield", "crushing at an opened joint", "concrete
    /// crushing", "loss of equilibrium", or "none reached".
    pub mode: String,
    /// What and where (tendon and its stress, crushed points and joint, …).
    pub detail: String,
    /// The load measure: the load case whose factor grew most over the run.
    pub load_case: String,
    /// Factor of that load case when the failure was first met (the peak if none) [-].
    pub at_factor: f64,
    /// Largest factor of that load case reached [-].
    pub peak_factor: f64,
    /// Step and increment (1-based) of the peak.
    pub peak_step: String,
    /// Increment of the peak within its step (1-based).
    pub peak_increment: usize,
    /// Every failure event met, in order: (mode, factor of the load case when first met).
    pub events: Vec<(String, f64)>,
    /// How the run ended: "completed" or "no convergence beyond the last increment".
    pub ended: String,
}

impl fmt::Display for Ultimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.mode == "none reached" {
            write!(
                f,
                "ultimate: no failure reached; peak {} = {:.4} (step '{}', increment {}); run {}",
                self.load_case, self.peak_factor, self.peak_step, self.peak_increment, self.ended
            )
        } else {
            write!(
                f,
                "ultimate: {} at {} = {:.4} ({}); peak {} = {:.4} (step '{}', increment {}); run {}",
                self.mode,
                self.load_case,
                self.at_factor,
                self.detail,
                self.load_case,
                self.peak_factor,
                self.peak_step,
                self.peak_increment,
                self.ended
            )
        }
    }
}

/// Follows the converged increments of a run and tells which failure it reached.
#[derive(Debug, Default)]
pub struct UltimateWatch {
    /// (step, increment within it, load factors) of every converged increment.
    rows: Vec<(usize, usize, Vec<f64>)>,
    tendon_yield: Option<Event>,
    crushing: Option<Event>,
    equilibrium: Option<Event>,
    /// Largest arc-length factor so far in the current path step, and its step.
    lambda_peak: Option<(usize, f64)>,
}

/// Relative drop of the arc-length factor below its peak taken as a limit point (well
/// above the Newton tolerance, so that convergence noise on a plateau is not one) [-].
const LIMIT_DROP: f64 = 1e-3;

impl UltimateWatch {
    /// A watch with nothing seen.
    pub fn new() -> Self {
        Self::default()
    }

    /// Record one converged increment.
    pub fn increment(&mut self, snap: &Snapshot) {
        let sys = snap.system;
        let model = sys.model;
        let k = self.rows.len();
        self.rows
            .push((snap.step, snap.increment, snap.factors.to_vec()));
        if self.tendon_yield.is_none() {
            for (t, st) in model.tendons.iter().zip(&sys.tendon_committed) {
                let Some(st) = st else { continue };
                if let Some(s) = st
                    .spans
                    .iter()
                    .filter(|s| s.law.plastic_strain > 0.0)
                    .map(|s| s.stress)
                    .reduce(f64::max)
                {
                    self.tendon_yield = Some(Event {
                        mode: "tendon yield",
                        detail: format!("tendon {} at {:.0} MPa", t.name, s / 1e6),
                        at: k,
                    });
                    break;
                }
            }
        }
        if self.crushing.is_none() {
            self.crushing = crushing(model, snap, k);
        }
        if self.equilibrium.is_none() && model.steps[snap.step].path.is_some() {
            // A limit point: negative pivots in the tangent, or the arc-length factor falling
            // back from its peak.
            let lam = snap.arc_length_factor;
            let fell = match (lam, self.lambda_peak) {
                (Some(l), Some((s, p))) if s == snap.step => {
                    l < p - LIMIT_DROP * p.abs().max(1e-12)
                }
                _ => false,
            };
            if let Some(l) = lam {
                match self.lambda_peak {
                    Some((s, p)) if s == snap.step && p >= l => {}
                    _ => self.lambda_peak = Some((snap.step, l)),
                }
            }
            if fell || snap.negative_pivots > 0 {
                self.equilibrium = Some(Event {
                    mode: "loss of equilibrium",
                    detail: if fell {
                        "the load falls past its peak".into()
                    } else {
                        format!(
                            "{} negative pivots in the tangent (limit point)",
                            snap.negative_pivots
                        )
                    },
                    at: k,
                });
            }
        }
    }

    /// The verdict, for runs that go to failure: those with a displacement or arc-length
    /// step, or any run in which a failure event was met. `converged`: the run ended
    /// without a failed increment.
    pub fn finish(&self, model: &Model, converged: bool) -> Option<Ultimate> {
        let mut events: Vec<&Event> = [&self.tendon_yield, &self.crushing, &self.equilibrium]
            .into_iter()
            .flatten()
            .collect();
        let path = model.steps.iter().any(|s| s.path.is_some());
        if self.rows.is_empty() || (events.is_empty() && !path) {
            return None;
        }
        events.sort_by_key(|e| e.at);
        // The load measure: the load case whose factor grew most from the first increment.
        let first = &self.rows[0].2;
        let last = &self.rows[self.rows.len() - 1].2;
        let case = (0..first.len())
            .max_by(|&a, &b| {
                (last[a] - first[a])
                    .abs()
                    .total_cmp(&(last[b] - first[b]).abs())
            })
            .unwrap_or(0);
        let factor = |k: usize| self.rows[k].2.get(case).copied().unwrap_or(0.0);
        let peak = (0..self.rows.len())
            .max_by(|&a, &b| factor(a).total_cmp(&factor(b)))
            .unwrap_or(0);
        let (mode, detail, at) = match events.first() {
            Some(e) => (e.mode.to_string(), e.detail.clone(), factor(e.at)),
            None => ("none reached".into(), String::new(), factor(peak)),
        };
        Some(Ultimate {
            mode,
            detail,
            load_case: model
                .load_cases
                .get(case)
                .map(|c| c.name.clone())
                .unwrap_or_default(),
            at_factor: at,
            peak_factor: factor(peak),
            peak_step: model.steps[self.rows[peak].0].name.clone(),
            peak_increment: self.rows[peak].1,
            events: events
                .iter()
                .map(|e| (e.mode.to_string(), factor(e.at)))
                .collect(),
            ended: if converged {
                "completed".into()
            } else {
                "stopped: no convergence beyond the last increment".into()
            },
        })
    }
}

/// Crushed concrete points at increment `k`: "crushing at an opened joint" when a crushed
/// element touches a joint that is open, else "concrete crushing".
fn crushing(model: &Model, snap: &Snapshot, k: usize) -> Option<Event> {
    let sys = snap.system;
    let crushed: Vec<usize> = (0..model.elements.len())
        .filter(|&e| {
            sys.committed[sys.gp_offset[e]..sys.gp_offset[e + 1]]
                .iter()
                .any(|p| p.is_crushed())
        })
        .collect();
    if crushed.is_empty() {
        return None;
    }
    let points = sys.committed.iter().filter(|p| p.is_crushed()).count();
    for (j, joint) in model.joints.iter().enumerate() {
        let touches = crushed.iter().any(|&e| {
            joint.interfaces.iter().any(|&i| {
                model.interfaces[i]
                    .nodes
                    .iter()
                    .any(|n| model.elements[e].nodes.contains(n))
            })
        });
        if touches && super::joints::summarise(sys, j).max_opening > 0.0 {
            return Some(Event {
                mode: "crushing at an opened joint",
                detail: format!(
                    "joint {}, {points} crushed points in {} elements",
                    joint.name,
                    crushed.len()
                ),
                at: k,
            });
        }
    }
    Some(Event {
        mode: "concrete crushing",
        detail: format!(
            "{points} crushed points in {} elements (first element {})",
            crushed.len(),
            crushed[0] + 1
        ),
        at: k,
    })
}
