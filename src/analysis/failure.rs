//! The report of an increment that failed after all allowed step cuts: where (step,
//! increment, load level, time), why (residual history of the last attempt, the largest
//! residual components and the elements, joints and tendons at their nodes, negative
//! pivots, points that changed state in that attempt). Everything in it is already at hand
//! when Newton gives up, so building it costs one pass over the states.

use super::system::System;
use crate::fem::dofs::CONSTRAINED;
use crate::linalg::solver::SolverError;
use crate::materials::point::UpdateError;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Why Newton gave up on an increment (one attempt).
pub(crate) enum NewtonFailure {
    /// The tangent could not be factorised.
    Singular(SolverError),
    /// A material update failed at this element (0-based) with this message.
    Material(usize, String),
    /// The residual did not fall below the tolerances (or became non-finite).
    Diverged {
        /// Relative residual norm at each iteration [-].
        history: Vec<f64>,
        /// Free-equation residual at the last iterate [N] (empty if not available).
        residual: Vec<f64>,
    },
}

impl NewtonFailure {
    /// A failed material update at element `e` (0-based): a step cut when it did not
    /// converge; a broken internal contract stops the program as the bug it is (cutting the
    /// step would only hide it).
    pub(crate) fn material((e, err): (usize, UpdateError)) -> Self {
        match err {
            UpdateError::NotConverged(_) => NewtonFailure::Material(e, err.to_string()),
            UpdateError::Internal(_) => panic!("element {}: {err}", e + 1),
        }
    }

    /// A divergence with its residual history and last residual.
    pub(crate) fn diverged(history: Vec<f64>, residual: Vec<f64>) -> Self {
        NewtonFailure::Diverged { history, residual }
    }
}

/// One of the largest residual components of the last attempt.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorstDof {
    /// Node number (1-based, as in the output files).
    pub node: usize,
    /// Node coordinates [m].
    pub x: f64,
    /// Node coordinates [m].
    pub y: f64,
    /// Direction: "x" or "y".
    pub direction: String,
    /// Out-of-balance force [N] (external minus internal).
    pub residual: f64,
}

/// Where and why an increment failed after all cuts (summary.json `failures`, standard error).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailureReport {
    /// Step name.
    pub step: String,
    /// Step number (1-based).
    pub step_number: usize,
    /// Increment number within the step (1-based) that failed.
    pub increment: usize,
    /// Level tried: fraction of the step (load and displacement steps) or the arc-length
    /// load factor λ reached (arc-length steps) [-].
    pub level: f64,
    /// Analysis time at the end of the failed increment [d].
    pub time: f64,
    /// Load-case factors at the last converged increment (name, factor).
    pub load_factors: Vec<(String, f64)>,
    /// Step cuts tried.
    pub cuts: usize,
    /// "diverged", "material" or "singular".
    pub cause: String,
    /// One-line reason.
    pub reason: String,
    /// Relative residual norm at each iteration of the last attempt [-].
    pub residual_history: Vec<f64>,
    /// Largest out-of-balance components of the last attempt, largest first.
    pub worst_dofs: Vec<WorstDof>,
    /// Continuum elements (1-based) at the nodes of the worst dofs, or the failing element.
    pub elements: Vec<usize>,
    /// Joints with an interface element at those nodes.
    pub joints: Vec<String>,
    /// Tendons tied to those nodes.
    pub tendons: Vec<String>,
    /// Negative pivots of the last tangent factorised [-].
    pub negative_pivots: usize,
    /// Material points that cracked in the last attempt (against the committed state) [-].
    pub new_cracks: usize,
    /// Material points that crushed in the last attempt [-].
    pub new_crushed: usize,
    /// Joint integration points that opened or closed in the last attempt [-].
    pub joint_points_switched: usize,
    /// Joint integration points that started sliding in the last attempt [-].
    pub joint_points_sliding: usize,
}

/// The one-way supports off their seats in the last attempt (trial statuses), said so: a
/// structure that lifts off the supports of a direction is a mechanism.
fn lifted_supports(sys: &System) -> Option<String> {
    let st = sys.stages.as_ref()?;
    let mut per = vec![(0, 0); sys.model.supports.len()];
    for p in st.one_way.points.iter().filter(|p| p.acting) {
        per[p.support].1 += 1;
        per[p.support].0 += usize::from(!p.touching.trial);
    }
    let names: Vec<String> = per
        .iter()
        .enumerate()
        .filter(|(_, (off, _))| *off > 0)
        .map(|(s, &(off, n))| {
            let name = &sys.model.supports[s].name;
            if off == n {
                format!("'{name}'")
            } else {
                format!("'{name}' ({off} of {n} points)")
            }
        })
        .collect();
    (!names.is_empty()).then(|| {
        format!(
            "one-way supports lifted off in this attempt: {} (a structure lifted off the supports that held it in a direction is a mechanism)",
            names.join(", ")
        )
    })
}

/// How many of the largest residual components are reported.
const N_WORST: usize = 5;

/// Where the increment was when it failed (filled in by the step drivers).
pub(crate) struct FailedAt<'a> {
    pub step: usize,
    pub increment: usize,
    pub level: f64,
    pub cuts: usize,
    pub factors: &'a [f64],
    pub negative_pivots: usize,
}

/// Build the report of a failure. Call before the trial states are overwritten by another
/// assembly (they tell which points changed state in the last attempt).
pub(crate) fn report(sys: &System, at: FailedAt, failure: &NewtonFailure) -> FailureReport {
    let model = sys.model;
    let step = &model.steps[at.step];
    let (cause, reason, history, worst, mut elements) = match failure {
        NewtonFailure::Singular(e) => (
            "singular",
            mechanism_message(sys, e.clone()),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        ),
        NewtonFailure::Material(e, m) => (
            "material",
            format!("element {} material: {m}", e + 1),
            Vec::new(),
            Vec::new(),
            vec![e + 1],
        ),
        NewtonFailure::Diverged { history, residual } => (
            "diverged",
            format!(
                "relative residual history {}",
                history
                    .iter()
                    .map(|r| format!("{r:.2e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            history.clone(),
            worst_dofs(sys, residual),
            Vec::new(),
        ),
    };
    let reason = match lifted_supports(sys) {
        Some(l) => format!("{reason}; {l}"),
        None => reason,
    };
    let nodes: Vec<usize> = worst.iter().map(|w| w.node - 1).collect();
    for (e, el) in model.elements.iter().enumerate() {
        if el.nodes.iter().any(|n| nodes.contains(n)) && !elements.contains(&(e + 1)) {
            elements.push(e + 1);
        }
    }
    let joints = model
        .joints
        .iter()
        .filter(|j| {
            j.interfaces
                .iter()
                .any(|&i| model.interfaces[i].nodes.iter().any(|n| nodes.contains(n)))
        })
        .map(|j| j.name.clone())
        .collect();
    let tendons = model
        .tendons
        .iter()
        .filter(|t| t.nodes.iter().any(|n| nodes.contains(n)))
        .map(|t| t.name.clone())
        .collect();
    let (mut new_cracks, mut new_crushed) = (0, 0);
    for (c, t) in sys
        .families
        .continuum
        .points
        .committed
        .iter()
        .zip(&sys.families.continuum.points.trial)
    {
        new_cracks += usize::from(t.n_cracks() > c.n_cracks());
        new_crushed += usize::from(t.is_crushed() && !c.is_crushed());
    }
    let (mut switched, mut sliding) = (0, 0);
    for (c, t) in sys
        .families
        .joints
        .points
        .committed
        .iter()
        .zip(&sys.families.joints.points.trial)
    {
        for (a, b) in c.iter().zip(t) {
            switched += usize::from(a.closed != b.closed);
            sliding += usize::from(b.sliding && !a.sliding);
        }
    }
    FailureReport {
        step: step.name.clone(),
        step_number: at.step + 1,
        increment: at.increment,
        level: at.level,
        time: sys.time.t_to,
        load_factors: model
            .load_cases
            .iter()
            .map(|c| c.name.clone())
            .zip(at.factors.iter().copied())
            .collect(),
        cuts: at.cuts,
        cause: cause.into(),
        reason,
        residual_history: history,
        worst_dofs: worst,
        elements,
        joints,
        tendons,
        negative_pivots: at.negative_pivots,
        new_cracks,
        new_crushed,
        joint_points_switched: switched,
        joint_points_sliding: sliding,
    }
}

/// The largest components (by magnitude; non-finite first) of a free-equation residual.
fn worst_dofs(sys: &System, residual: &[f64]) -> Vec<WorstDof> {
    if residual.len() != sys.dofs.n_eq {
        return Vec::new();
    }
    let mut dofs: Vec<(usize, f64)> = sys
        .dofs
        .eq
        .iter()
        .enumerate()
        .filter(|(_, &q)| q != CONSTRAINED)
        .map(|(d, &q)| (d, residual[q]))
        .collect();
    let key = |v: f64| {
        if v.is_finite() {
            v.abs()
        } else {
            f64::INFINITY
        }
    };
    // Stable order for ties (dof number) so the report is reproducible.
    dofs.sort_by(|a, b| key(b.1).total_cmp(&key(a.1)).then(a.0.cmp(&b.0)));
    dofs.into_iter()
        .take(N_WORST)
        .filter(|(_, v)| *v != 0.0)
        .map(|(d, v)| {
            let [x, y] = sys.model.nodes[d / 2];
            WorstDof {
                node: d / 2 + 1,
                x,
                y,
                direction: if d % 2 == 0 { "x" } else { "y" }.into(),
                residual: v,
            }
        })
        .collect()
}

impl fmt::Display for FailureReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // First line as before (scripts and tests match on it), details below.
        write!(
            f,
            "step '{}' did not converge at load level {:.6} (increment {}, after {} cuts): {}",
            self.step, self.level, self.increment, self.cuts, self.reason
        )?;
        write!(
            f,
            "\n  where: step {} '{}', increment {}, level {:.6}, time {} d",
            self.step_number, self.step, self.increment, self.level, self.time,
        )?;
        if !self.load_factors.is_empty() {
            write!(
                f,
                ", load factors reached {}",
                self.load_factors
                    .iter()
                    .map(|(n, v)| format!("{n} = {v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )?;
        }
        if !self.worst_dofs.is_empty() {
            write!(
                f,
                "\n  largest out-of-balance forces: {}",
                self.worst_dofs
                    .iter()
                    .map(|w| format!(
                        "node {} ({:.4}, {:.4}) u{} {:.3e} N",
                        w.node, w.x, w.y, w.direction, w.residual
                    ))
                    .collect::<Vec<_>>()
                    .join("; ")
            )?;
        }
        if !self.elements.is_empty() {
            let shown: Vec<String> = self
                .elements
                .iter()
                .take(12)
                .map(|e| e.to_string())
                .collect();
            let more = self.elements.len().saturating_sub(12);
            write!(f, "\n  elements there: {}", shown.join(", "))?;
            if more > 0 {
                write!(f, " (+{more} more)")?;
            }
        }
        if !self.joints.is_empty() {
            write!(f, "\n  joints there: {}", self.joints.join(", "))?;
        }
        if !self.tendons.is_empty() {
            write!(f, "\n  tendons there: {}", self.tendons.join(", "))?;
        }
        write!(
            f,
            "\n  last attempt: {} negative pivots, {} points newly cracked, {} newly crushed, {} joint points opened or closed, {} started sliding",
            self.negative_pivots,
            self.new_cracks,
            self.new_crushed,
            self.joint_points_switched,
            self.joint_points_sliding
        )
    }
}

/// One line for `--verbose` iterations: how many points the current trial states changed
/// against the committed ones (cracked, crushed, flowed plastically while uncracked) and how
/// many are latched for the rest of the increment.
pub(crate) fn census(sys: &System, residual: &[f64]) -> String {
    let (mut cracked, mut crushed, mut plastic) = (0, 0, 0);
    for (c, t) in sys
        .families
        .continuum
        .points
        .committed
        .iter()
        .zip(&sys.families.continuum.points.trial)
    {
        cracked += usize::from(t.n_cracks() > c.n_cracks());
        crushed += usize::from(t.is_crushed() && !c.is_crushed());
        if let (Some(c), Some(t)) = (c.concrete(), t.concrete()) {
            plastic += usize::from(t.n_cracks() == 0 && t.plastic_strain() != c.plastic_strain());
        }
    }
    let ws = worst_dofs(sys, residual);
    let worst = ws
        .first()
        .map(|w| {
            format!(
                "; largest residual {:.3e} N at node {} ({:.4}, {:.4}) {}",
                w.residual, w.node, w.x, w.y, w.direction
            )
        })
        .unwrap_or_default();
    format!(
        "{cracked} newly cracked, {crushed} newly crushed, {plastic} flowing, {} latched{worst}",
        sys.families.continuum.holds.latched.len()
    )
}

/// A solver failure as a message naming the node and dof (a mechanism or a lost stiffness).
pub(crate) fn mechanism_message(sys: &System, e: SolverError) -> String {
    match e {
        SolverError::NotPositiveDefinite { equation } => {
            let dof = sys.dofs.eq.iter().position(|&q| q == equation).unwrap_or(0);
            let node = dof / 2;
            let dir = if dof % 2 == 0 { "x" } else { "y" };
            let regions: Vec<&str> = sys
                .model
                .elements
                .iter()
                .filter(|el| el.nodes.contains(&node))
                .map(|el| sys.model.regions[el.region].name.as_str())
                .collect();
            let [x, y] = sys.model.nodes[node];
            format!(
                "the structure is a mechanism or has lost stiffness: zero pivot at node {} ({x}, {y}), dof u{dir}, region(s) {:?} — check supports and connections",
                node + 1,
                regions
            )
        }
        SolverError::Internal(m) => m,
        SolverError::Singular => {
            "the tangent stiffness is singular (zero pivot): a mechanism, or exactly at a limit point"
                .into()
        }
    }
}
