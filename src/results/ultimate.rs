//! Which failure a run to failure reached, and at what load: the first of tendon yield,
//! concrete crushing (at an opened joint or elsewhere) and loss of equilibrium (a limit
//! point) met along the converged increments, with the peak load. First yield of the
//! reinforcement is listed among the events but is not a failure. Written to
//! `summary.json` (`ultimate`) and printed by `segfem run` (docs/running.md, "Runs to
//! failure").
//!
//! Yield and crushing are read from the committed states at each converged increment (one
//! pass over the tendons, bars, concrete points and joints per increment); the limit point
//! is found at the end, from the whole load history.

use super::strength::{fmt_measure, StrengthFinding, StrengthWatch};
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

/// Name of the load measure when it is the force of a displacement control.
pub const CONTROL_FORCE: &str = "control force";

/// How a run to failure ended (summary.json `ultimate`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ultimate {
    /// The first failure met: "tendon yield", "crushing at an opened joint", "concrete
    /// crushing", "loss of equilibrium", or "none reached".
    pub mode: String,
    /// What and where (tendon and its stress, crushed points and joint, …).
    pub detail: String,
    /// The load measure: the load case whose factor varied most in the displacement and
    /// arc-length steps (over the whole run if there are none), or [`CONTROL_FORCE`] when
    /// only displacement controls move the structure there.
    pub load_case: String,
    /// The load measure when the failure was first met (the peak if none): a load factor
    /// [-], or the magnitude of the control force [N].
    pub at_factor: f64,
    /// Largest value of the load measure reached (factor [-] or force [N]).
    pub peak_factor: f64,
    /// Step and increment (1-based) of the peak.
    pub peak_step: String,
    /// Increment of the peak within its step (1-based).
    pub peak_increment: usize,
    /// Every event met, in order: (mode, load measure when first met). Besides the failure
    /// modes it lists "reinforcement yield" (first yield of a bar that is not a tendon).
    pub events: Vec<(String, f64)>,
    /// How the run ended: "completed", "completed, but ... increments used up before
    /// stop_displacement" or "stopped: no convergence beyond the last increment".
    pub ended: String,
    /// Arc-length steps that used up their increments before their `stop_displacement`
    /// (one sentence each: step, displacement reached and aimed at).
    #[serde(default)]
    pub unfinished: Vec<String>,
    /// When no failure was reached: what the run did reach (first yield of the
    /// reinforcement and whether the load then kept rising or levelled off into a
    /// plateau); empty otherwise.
    #[serde(default)]
    pub reached: String,
    /// When concrete modelled as elastic passed its compressive strength at or before the
    /// failure (the peak, if none was reached): what, where and from which load, and the
    /// verdict's loads are upper bounds (`results::strength`); empty otherwise.
    #[serde(default)]
    pub upper_bound: String,
    /// How sure the peak is: the IMPL-EX path error of the increments at the peak (None
    /// without IMPL-EX concrete).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path_error: Option<PathError>,
}

/// The IMPL-EX path error in the energy norm ([`crate::analysis::steps::Snapshot::implex_error`],
/// docs/theory-concrete.md §5.2 "How sure the peak is") around the peak of a run to
/// failure (summary.json `ultimate.path_error`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PathError {
    /// The largest error of the increments of the peak's step up to the peak whose load
    /// measure is within [`PEAK_BAND`] of the peak [-].
    pub at_peak: f64,
    /// The largest error of all measured increments [-].
    pub largest: f64,
    /// The level above which the peak is flagged as depending on the increment size
    /// ([`PATH_ERROR_FLAG`]) [-].
    pub limit: f64,
}

impl PathError {
    /// True if the peak is flagged: its increments' path error exceeds the limit.
    pub fn flagged(&self) -> bool {
        self.at_peak > self.limit
    }

    /// The flag in words (summary.json `warnings`, the verdict), None when not flagged.
    pub fn warning(&self) -> Option<String> {
        self.flagged().then(|| {
            format!(
                "the peak may depend on the increment size: IMPL-EX path error {:.1e} at the peak (> {:.0e}; smaller increments, or [solver] implex_force_tolerance = 3e-3 with implex_force_norm = \"energy\", bound it)",
                self.at_peak, self.limit
            )
        })
    }
}

/// Increments whose load measure is within this fraction of the peak's, up to the peak in
/// its step, are the peak's increments for [`PathError::at_peak`] [-].
pub const PEAK_BAND: f64 = 0.02;

/// IMPL-EX path error (energy norm) at the peak above which the peak is flagged [-]. Set
/// on the runs of docs/validation.md ("How sure the peak is"): at fixed increments the
/// flexural runs (seed beam coarse and 2×, RC example at 1× and 8×) have at most 6.1e-3
/// at their peak and peaks 0.1–2.3 % apart over a factor 8 of increments; the shear beams
/// B1 and OA1 3.8e-3–9.1e-3 where their peaks are within 2 % of the finest run's, and
/// 1.0e-2–2.4e-2 where they are 3.3–28 % above it (and OA1 at 0.05 mm, 1.3e-2 at −1 %).
pub const PATH_ERROR_FLAG: f64 = 1e-2;

impl fmt::Display for Ultimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.verdict(f)?;
        if !self.upper_bound.is_empty() {
            write!(f, "; upper bound: {}", self.upper_bound)?;
        }
        if let Some(w) = self.path_error.as_ref().and_then(PathError::warning) {
            write!(f, "; {w}")?;
        }
        Ok(())
    }
}

impl Ultimate {
    /// The verdict's warnings (summary.json `warnings`): the arc-length steps that used up
    /// their increments, and the path error's flag.
    pub fn warnings(&self) -> impl Iterator<Item = String> + '_ {
        (self.unfinished.iter().cloned())
            .chain(self.path_error.as_ref().and_then(PathError::warning))
    }

    /// The verdict without its upper-bound note.
    fn verdict(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let value = |v: f64| {
            if self.load_case == CONTROL_FORCE {
                format!("{:.4} kN", v / 1e3)
            } else {
                format!("{v:.4}")
            }
        };
        if self.mode == "none reached" && !self.reached.is_empty() {
            write!(
                f,
                "ultimate: no collapse within the run; it reached {}; peak {} = {} (step '{}', increment {}); run {}",
                self.reached,
                self.load_case,
                value(self.peak_factor),
                self.peak_step,
                self.peak_increment,
                self.ended
            )
        } else if self.mode == "none reached" {
            write!(
                f,
                "ultimate: no failure reached; peak {} = {} (step '{}', increment {}); run {}",
                self.load_case,
                value(self.peak_factor),
                self.peak_step,
                self.peak_increment,
                self.ended
            )
        } else {
            write!(
                f,
                "ultimate: {} at {} = {} ({}); peak {} = {} (step '{}', increment {}); run {}",
                self.mode,
                self.load_case,
                value(self.at_factor),
                self.detail,
                self.load_case,
                value(self.peak_factor),
                self.peak_step,
                self.peak_increment,
                self.ended
            )
        }
    }
}

/// One converged increment as the watch keeps it.
#[derive(Debug, Clone)]
struct Row {
    step: usize,
    increment: usize,
    factors: Vec<f64>,
    /// Force of the displacement control [N] (displacement steps).
    control_force: Option<f64>,
    /// The increment belongs to a displacement or arc-length step.
    path: bool,
    negative_pivots: usize,
    /// The increment's IMPL-EX path error (energy norm) [-], where measured.
    implex_error: Option<f64>,
}

/// Mode of a peak that is the first cracking of the concrete (the load falls as the first
/// crack opens).
pub const CRACKING_PEAK: &str = "first cracking";
/// Mode of a run that stopped with the load still rising (Newton stalled, no limit point).
pub const NO_CONVERGENCE: &str = "no convergence";

/// Follows the converged increments of a run and tells which failure it reached.
#[derive(Debug, Default)]
pub struct UltimateWatch {
    rows: Vec<Row>,
    tendon_yield: Option<Event>,
    bar_yield: Option<Event>,
    /// First crushing in an element touching an opened joint.
    joint_crushing: Option<Event>,
    /// First crushing elsewhere (or before the joint it touches opened).
    crushing: Option<Event>,
    /// First cracked concrete point (the element named).
    first_crack: Option<Event>,
    /// Start value [m] of the stop_displacement dof of the arc-length step in hand.
    arc_start: Option<f64>,
    /// Arc-length steps that used up their increments before their stop_displacement.
    unfinished: Vec<String>,
    /// Stresses of elastic concrete past its strength.
    strength: StrengthWatch,
}

/// Relative drop of the load below its peak at the end of the same step, taken as a limit
/// point [-]: well above the Newton tolerance and above the wiggles of a ductile plateau
/// (cracks forming one by one: up to ≈ 0.3 % on the RC beam example; a crack localising can
/// dip it by 3 % for a few increments, but the load climbs back).
const LIMIT_DROP: f64 = 1e-2;

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
        self.rows.push(Row {
            step: snap.step,
            increment: snap.increment,
            factors: snap.factors.to_vec(),
            control_force: snap.control_force,
            path: model.steps[snap.step].path.is_some(),
            negative_pivots: snap.negative_pivots,
            implex_error: snap.implex_error,
        });
        if self.tendon_yield.is_none() {
            for (t, st) in model.tendons.iter().zip(sys.tendon_states()) {
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
        if self.tendon_yield.is_none() || self.bar_yield.is_none() {
            self.bar_events(snap, k);
        }
        if self.first_crack.is_none() {
            if let Some(e) = (0..model.elements.len())
                .find(|&e| (sys.element_points(e).iter()).any(|p| p.n_cracks() > 0))
            {
                self.first_crack = Some(Event {
                    mode: CRACKING_PEAK,
                    detail: format!("element {}", e + 1),
                    at: k,
                });
            }
        }
        self.arc_length_end(snap);
        self.strength.increment(snap, k);
        if self.crushing.is_none() || self.joint_crushing.is_none() {
            for e in crushing(model, snap, k) {
                let slot = if e.mode == "concrete crushing" {
                    &mut self.crushing
                } else {
                    &mut self.joint_crushing
                };
                if slot.is_none() {
                    *slot = Some(e);
                }
            }
        }
    }

    /// An arc-length step with a stop_displacement: note it when its last increment stops
    /// short of that displacement (and of its target_factor).
    fn arc_length_end(&mut self, snap: &Snapshot) {
        use crate::model::PathControl;
        let sys = snap.system;
        let step = &sys.model.steps[snap.step];
        let Some(PathControl::ArcLength(a)) = &step.path else {
            return;
        };
        let Some((n, d, v)) = a.target_displacement else {
            return;
        };
        let k = 2 * n + d.index();
        if snap.increment == 1 {
            self.arc_start = Some(sys.previous_displacements()[k]);
        }
        if !snap.end_of_step {
            return;
        }
        let x = sys.displacements()[k];
        let start = self.arc_start.unwrap_or(0.0);
        let reached_u = (x - v) * (v - start).signum() >= 0.0;
        let reached_f = match (a.target_factor, snap.arc_length_factor) {
            (Some(t), Some(l)) => l >= t,
            _ => false,
        };
        if !reached_u && !reached_f && snap.increment >= a.max_increments {
            self.unfinished.push(format!(
                "step '{}' used all its {} increments before its stop_displacement: node {} moved {:.3} mm of the {:.3} mm asked (raise `increments` or `max_growth`)",
                step.name,
                a.max_increments,
                n + 1,
                1e3 * (x - start),
                1e3 * (v - start)
            ));
        }
    }

    /// First yield of a bonded or pre-tensioned tendon ("tendon yield") and of a plain bar
    /// ("reinforcement yield") at increment `k`.
    fn bar_events(&mut self, snap: &Snapshot, k: usize) {
        let sys = snap.system;
        let model = sys.model;
        for ((b, _), out) in sys.bar_outputs() {
            if out.plastic_strain == 0.0 {
                continue;
            }
            let bar = &model.bars[b];
            let tendon =
                bar.post_tension.is_some() || bar.initial_stress != 0.0 || bar.relaxation.is_some();
            let (slot, mode, what) = if tendon {
                (&mut self.tendon_yield, "tendon yield", "tendon")
            } else {
                (&mut self.bar_yield, "reinforcement yield", "bar")
            };
            if slot.is_none() {
                *slot = Some(Event {
                    mode,
                    detail: format!("{what} {} at {:.0} MPa", bar.name, out.stress.abs() / 1e6),
                    at: k,
                });
            }
        }
    }

    /// The load measure at each watched increment, and its name: the load case whose factor
    /// varied most over the path steps (the whole run if none), or the magnitude of the
    /// displacement control's force when no load factor moves in the path steps.
    fn measure(&self, model: &Model) -> (String, Vec<f64>) {
        let n_cases = self.rows.iter().map(|r| r.factors.len()).max().unwrap_or(0);
        let path: Vec<&Row> = self.rows.iter().filter(|r| r.path).collect();
        let factor = |r: &Row, c: usize| r.factors.get(c).copied().unwrap_or(0.0);
        let variation = |rows: &[&Row], c: usize| {
            let (lo, hi) = rows
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
                    (a.min(factor(r, c)), b.max(factor(r, c)))
                });
            hi - lo
        };
        let name = |c: usize| {
            model
                .load_cases
                .get(c)
                .map(|lc| lc.name.clone())
                .unwrap_or_default()
        };
        if !path.is_empty() {
            let best =
                (0..n_cases).max_by(|&a, &b| variation(&path, a).total_cmp(&variation(&path, b)));
            let moves = best.is_some_and(|c| variation(&path, c) > 0.0);
            if !moves && path.iter().any(|r| r.control_force.is_some()) {
                let v = self
                    .rows
                    .iter()
                    .map(|r| r.control_force.map_or(0.0, f64::abs))
                    .collect();
                return (CONTROL_FORCE.into(), v);
            }
            if let (Some(c), true) = (best, moves) {
                return (name(c), self.rows.iter().map(|r| factor(r, c)).collect());
            }
        }
        // No path step (or nothing moves in it): the case whose factor grew most from the
        // first increment.
        let (first, last) = (&self.rows[0], &self.rows[self.rows.len() - 1]);
        let c = (0..n_cases)
            .max_by(|&a, &b| {
                (factor(last, a) - factor(first, a))
                    .abs()
                    .total_cmp(&(factor(last, b) - factor(first, b)).abs())
            })
            .unwrap_or(0);
        (name(c), self.rows.iter().map(|r| factor(r, c)).collect())
    }

    /// The limit point: the peak `p` of the load measure `v` in a path step, if the step's
    /// last converged load lies LIMIT_DROP below it (a fall that a ductile plateau recovers
    /// from, a crack localising and the load climbing back, is not one) or the tangent
    /// shows negative pivots after it.
    fn limit_point(&self, v: &[f64], p: usize) -> Option<Event> {
        let row = &self.rows[p];
        if !row.path {
            return None;
        }
        let later = || (p..self.rows.len()).filter(|&j| self.rows[j].step == row.step);
        let drop = v[p] - LIMIT_DROP * v[p].abs().max(1e-300);
        let detail = if later().next_back().is_some_and(|j| v[j] < drop) {
            "the load falls past its peak".to_string()
        } else if let Some(j) = later().find(|&j| self.rows[j].negative_pivots > 0) {
            format!(
                "{} negative pivots in the tangent at the peak or after it (limit point)",
                self.rows[j].negative_pivots
            )
        } else {
            return None;
        };
        // The load falls as the first crack opens: the peak is the cracking load of an
        // element, which reinforcement or prestress may carry past.
        // An implicit crack is met at the increment after the peak; an IMPL-EX crack up to
        // two increments before it (its stress follows the crack law one increment late,
        // so the load still rises while the crack opens: the plain beam of tests/probes.rs
        // cracks at increment 24 and peaks at 26).
        if let Some(c) = self
            .first_crack
            .as_ref()
            .filter(|c| c.at <= p + 1 && c.at + 2 >= p)
        {
            return Some(Event {
                mode: CRACKING_PEAK,
                detail: format!(
                    "the load falls as {} cracks, the first crack of the model: this peak is a cracking load, not a collapse",
                    c.detail
                ),
                at: p,
            });
        }
        Some(Event {
            mode: "loss of equilibrium",
            detail,
            at: p,
        })
    }

    /// The IMPL-EX path error around the peak (row `peak` of the load measure `v`); None
    /// where no increment measured it.
    fn path_error(&self, v: &[f64], peak: usize) -> Option<PathError> {
        let largest = self
            .rows
            .iter()
            .filter_map(|r| r.implex_error)
            .reduce(f64::max)?;
        let step = self.rows[peak].step;
        let band = (1.0 - PEAK_BAND) * v[peak];
        let at_peak = (0..=peak)
            .filter(|&k| self.rows[k].step == step && v[k] >= band)
            .filter_map(|k| self.rows[k].implex_error)
            .fold(0.0, f64::max);
        Some(PathError {
            at_peak,
            largest,
            limit: PATH_ERROR_FLAG,
        })
    }

    /// Stresses of elastic concrete past its strength, first met first; their load is the
    /// verdict's load measure in runs to failure.
    pub fn strength_findings(&self, model: &Model) -> Vec<StrengthFinding> {
        let failures = [&self.tendon_yield, &self.joint_crushing, &self.crushing];
        let to_failure = self.rows.iter().any(|r| r.path) || failures.iter().any(|e| e.is_some());
        if self.rows.is_empty() || !to_failure {
            return self.strength.findings(model, None);
        }
        let (name, v) = self.measure(model);
        self.strength.findings(model, Some((&name, &v)))
    }

    /// The verdict, for runs that go to failure: those with a displacement or arc-length
    /// step, or any run in which a failure event was met. `converged`: the run ended
    /// without a failed increment.
    pub fn finish(&self, model: &Model, converged: bool) -> Option<Ultimate> {
        let path = self.rows.iter().any(|r| r.path);
        let failures = [&self.tendon_yield, &self.joint_crushing, &self.crushing];
        if self.rows.is_empty() || (failures.iter().all(|e| e.is_none()) && !path) {
            return None;
        }
        let (load_case, v) = self.measure(model);
        let peak = (0..v.len())
            .max_by(|&a, &b| v[a].total_cmp(&v[b]).then(b.cmp(&a)))
            .unwrap_or(0);
        // Newton stalled with the load still rising (the peak is the last converged
        // increment): no convergence, not a limit point.
        let stalled = !converged && peak + 1 == self.rows.len();
        let equilibrium = if stalled {
            Some(Event {
                mode: NO_CONVERGENCE,
                detail: "Newton stalled after the last converged increment while the load was still rising: the peak is a lower bound of the capacity, not a limit point".into(),
                at: peak,
            })
        } else {
            self.limit_point(&v, peak)
        };
        // Failure modes in the order met (ties: yield, crushing, equilibrium).
        let mut modes: Vec<&Event> = [
            &self.tendon_yield,
            &self.joint_crushing,
            &self.crushing,
            &equilibrium,
        ]
        .into_iter()
        .flatten()
        .collect();
        modes.sort_by_key(|e| e.at);
        let mut events: Vec<&Event> = modes
            .iter()
            .copied()
            .chain(self.bar_yield.as_ref())
            .collect();
        events.sort_by_key(|e| e.at);
        let (mode, detail, at) = match modes.first() {
            Some(e) => (e.mode.to_string(), e.detail.clone(), v[e.at]),
            None => ("none reached".into(), String::new(), v[peak]),
        };
        let reached = match (&self.bar_yield, modes.is_empty()) {
            (Some(y), true) => after_yield(y, &v, &load_case),
            _ => String::new(),
        };
        // Elastic concrete past f_cm at or before the failure (or the peak): the verdict's
        // loads are upper bounds.
        let upper_bound = match self.strength.first_crushing() {
            Some((kind, h)) if h.k <= modes.first().map_or(peak, |e| e.at) => format!(
                "concrete {} {:.1} MPa > fcm {:.1} MPa at {} from {} = {}",
                kind.words(),
                h.value / 1e6,
                h.limit / 1e6,
                h.place,
                load_case,
                fmt_measure(&load_case, v[h.k])
            ),
            _ => String::new(),
        };
        Some(Ultimate {
            path_error: self.path_error(&v, peak),
            reached,
            upper_bound,
            mode,
            detail,
            load_case,
            at_factor: at,
            peak_factor: v[peak],
            peak_step: model.steps[self.rows[peak].step].name.clone(),
            peak_increment: self.rows[peak].increment,
            events: events
                .iter()
                .map(|e| (e.mode.to_string(), v[e.at]))
                .collect(),
            unfinished: self.unfinished.clone(),
            ended: if converged && !self.unfinished.is_empty() {
                format!(
                    "completed, but {} arc-length step(s) used up their increments before stop_displacement",
                    self.unfinished.len()
                )
            } else if converged {
                "completed".into()
            } else {
                "stopped: no convergence beyond the last increment".into()
            },
        })
    }
}

/// Relative change of the load over the last quarter of the increments after first yield
/// below which the response is called a plateau [-]: the RC beam example's load grows
/// ≈ 0.5 % there while cracks form one by one; a still hardening member grows several %.
const PLATEAU: f64 = 2e-2;

/// What a run without failure reached after the first yield `y` of its reinforcement,
/// from the load measure `v` (named `load`): "reinforcement yield (bar B at … MPa) at
/// load = …, then a plateau (the load rose … % to its peak, … % over the last quarter)"
/// or "…, then the load still rising …".
fn after_yield(y: &Event, v: &[f64], load: &str) -> String {
    let fmt = |x: f64| {
        if load == CONTROL_FORCE {
            format!("{:.4} kN", x / 1e3)
        } else {
            format!("{x:.4}")
        }
    };
    let at = v[y.at];
    let peak = v[y.at..].iter().copied().fold(at, f64::max);
    let n = v.len() - y.at;
    let tail = &v[v.len() - (n / 4).max(2).min(n)..];
    let change = (tail[tail.len() - 1] - tail[0]) / peak.abs().max(1e-300);
    let rise = 100.0 * (peak - at) / at.abs().max(1e-300);
    let how = if change.abs() < PLATEAU {
        format!(
            "then a plateau (the load rose {rise:.1} % to its peak, {:.1} % over the last quarter of the increments after yield)",
            100.0 * change
        )
    } else {
        format!(
            "then the load still rising ({rise:.1} % above the yield load at the peak, {:.1} % over the last quarter of the increments after yield)",
            100.0 * change
        )
    };
    format!(
        "reinforcement yield ({}) at {load} = {}, {how}",
        y.detail,
        fmt(at)
    )
}

/// Crushed concrete points at increment `k`: "crushing at an opened joint" for crushed
/// elements touching a joint that is open, "concrete crushing" for the others (both events
/// may be met at once).
fn crushing(model: &Model, snap: &Snapshot, k: usize) -> Vec<Event> {
    let sys = snap.system;
    let crushed_points = |e: usize| {
        (sys.element_points(e).iter())
            .filter(|p| p.is_crushed())
            .count()
    };
    let crushed: Vec<usize> = (0..model.elements.len())
        .filter(|&e| crushed_points(e) > 0)
        .collect();
    if crushed.is_empty() {
        return Vec::new();
    }
    let mut at_joint = vec![false; crushed.len()];
    let mut events = Vec::new();
    for (j, joint) in model.joints.iter().enumerate() {
        let touches = |e: usize| {
            joint.interfaces.iter().any(|&i| {
                model.interfaces[i]
                    .nodes
                    .iter()
                    .any(|n| model.elements[e].nodes.contains(n))
            })
        };
        let here: Vec<usize> = (0..crushed.len())
            .filter(|&c| touches(crushed[c]))
            .collect();
        if here.is_empty() || super::joints::summarise(sys, j).max_opening <= 0.0 {
            continue;
        }
        let points: usize = here.iter().map(|&c| crushed_points(crushed[c])).sum();
        if events.is_empty() {
            events.push(Event {
                mode: "crushing at an opened joint",
                detail: format!(
                    "joint {}, {points} crushed points in {} elements",
                    joint.name,
                    here.len()
                ),
                at: k,
            });
        }
        for c in here {
            at_joint[c] = true;
        }
    }
    let elsewhere: Vec<usize> = (0..crushed.len())
        .filter(|&c| !at_joint[c])
        .map(|c| crushed[c])
        .collect();
    if let Some(&first) = elsewhere.first() {
        let points: usize = elsewhere.iter().map(|&e| crushed_points(e)).sum();
        events.push(Event {
            mode: "concrete crushing",
            detail: format!(
                "{points} crushed points in {} elements (first element {})",
                elsewhere.len(),
                first + 1
            ),
            at: k,
        });
    }
    events
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A watch over one displacement step whose control forces are `loads` [N].
    fn watch(loads: &[f64]) -> (UltimateWatch, Vec<f64>) {
        let rows = loads
            .iter()
            .enumerate()
            .map(|(i, &f)| Row {
                step: 0,
                increment: i + 1,
                factors: vec![],
                control_force: Some(f),
                path: true,
                negative_pivots: 0,
                implex_error: None,
            })
            .collect();
        let w = UltimateWatch {
            rows,
            ..Default::default()
        };
        (w, loads.to_vec())
    }

    /// A plateau that dips 3 % when a crack localises and climbs back to within 0.4 % of its
    /// peak is not a limit point; the same dip at the end of the step, or a fall that stays,
    /// is one (reported at the peak).
    #[test]
    fn a_dip_that_recovers_is_not_a_limit_point() {
        let (w, v) = watch(&[100.0, 130.0, 140.4, 136.4, 138.6, 139.8]);
        assert!(w.limit_point(&v, 2).is_none());
        let (w, v) = watch(&[100.0, 130.0, 140.4, 139.8, 136.4]);
        assert_eq!(w.limit_point(&v, 2).map(|e| e.at), Some(2));
        let (w, v) = watch(&[100.0, 130.0, 140.4, 120.0, 110.0, 115.0]);
        assert_eq!(
            w.limit_point(&v, 2).map(|e| e.mode),
            Some("loss of equilibrium")
        );
    }

    /// The peak's path error is the largest of the increments up to the peak, in its step,
    /// within 2 % of its load: a large error early in the path (first cracking) or after
    /// the peak does not flag it, one in the band does; none measured gives None.
    #[test]
    fn the_path_error_at_the_peak_is_taken_over_the_increments_leading_to_it() {
        let (mut w, v) = watch(&[50.0, 90.0, 98.5, 99.0, 100.0, 60.0]);
        assert_eq!(w.path_error(&v, 4), None);
        let errors = [0.2, 5e-3, 3e-3, 4e-3, 2e-3, 0.5];
        for (r, e) in w.rows.iter_mut().zip(errors) {
            r.implex_error = Some(e);
        }
        let p = w.path_error(&v, 4).unwrap();
        assert_eq!((p.at_peak, p.largest), (4e-3, 0.5));
        assert!(!p.flagged() && p.warning().is_none());
        // 1.5e-2 at 98.5 (1.5 % below the peak): inside the band, flagged.
        w.rows[2].implex_error = Some(1.5e-2);
        let p = w.path_error(&v, 4).unwrap();
        assert!(p.flagged());
        assert!(p.warning().unwrap().contains("1.5e-2"));
        // The same increment in another step is not the peak's.
        w.rows[2].step = 1;
        assert_eq!(w.path_error(&v, 4).unwrap().at_peak, 4e-3);
    }
}

#[cfg(test)]
mod reached_tests {
    use super::*;

    fn yield_at(k: usize) -> Event {
        Event {
            mode: "reinforcement yield",
            detail: "bar B at 500 MPa".into(),
            at: k,
        }
    }

    /// After yield at 100 the load creeps to 110 and stays within 1 % over the last
    /// quarter: a plateau, 10 % above the yield load; a member still gaining 10 % over the
    /// last quarter is "still rising".
    #[test]
    fn plateau_or_rising_after_yield() {
        let v = [50.0, 100.0, 105.0, 108.0, 109.0, 109.5, 110.0, 110.0, 109.8];
        let s = after_yield(&yield_at(1), &v, "P");
        assert!(s.contains("then a plateau"), "{s}");
        assert!(s.contains("rose 10.0 %"), "{s}");
        let v = [50.0, 100.0, 110.0, 120.0, 130.0, 140.0, 150.0, 160.0, 170.0];
        let s = after_yield(&yield_at(1), &v, "P");
        assert!(s.contains("still rising"), "{s}");
    }
}
