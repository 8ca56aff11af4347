//! What the step drivers (`steps`, `path`) share with each other and with observers: the
//! converged-increment snapshot, the observer interface, the run options, the analysis error,
//! the timings, and the two bookkeeping calls after a converged increment (`check_stop`,
//! `note_limit_point`). The drivers point down to this module; it calls neither of them.

use super::failure::FailureReport;
use super::state::{DriverState, SystemState};
use super::system::System;
use crate::linalg::solver::SolverStats;

/// A converged increment, as observers see it.
pub struct Snapshot<'a, 's> {
    /// The system (displacements, committed states and Gauss outputs).
    pub system: &'a System<'s>,
    /// Step index.
    pub step: usize,
    /// Increment number within the step (1-based).
    pub increment: usize,
    /// True at the last increment of the step.
    pub end_of_step: bool,
    /// Current load-case factors.
    pub factors: &'a [f64],
    /// Internal force vector over all dofs [N] (reactions at constrained dofs).
    pub f_int: &'a [f64],
    /// External force vector over all dofs [N].
    pub f_ext: &'a [f64],
    /// Newton iterations used.
    pub iterations: usize,
    /// Negative pivots of the last tangent factorised (0 if positive definite; > 0 past a
    /// limit point or bifurcation).
    pub negative_pivots: usize,
    /// Arc-length load factor λ of the step's reference load (arc-length steps).
    pub arc_length_factor: Option<f64>,
    /// Force [N] the displacement control applies at its dof (displacement steps).
    pub control_force: Option<f64>,
    /// The increment's IMPL-EX path error in the energy norm [-]
    /// ([`implex_energy_error`], docs/theory-concrete.md §5.2 "How sure the peak is"):
    /// measured at every converged increment of a load, displacement or arc-length step
    /// of a model with IMPL-EX concrete; None where it is not measured.
    pub implex_error: Option<f64>,
}

/// Receives converged increments (history, field output, progress), step ends
/// (checkpoints) and failures; may ask the analysis to stop.
pub trait Observer {
    /// Called after every converged increment.
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()>;

    /// Called before the first step and after every step (also a failed step the run goes
    /// on from), with the state a restart needs. Default: nothing.
    fn step_end(&mut self, _end: &StepEnd) -> std::io::Result<()> {
        Ok(())
    }

    /// Called when a step failed and the run goes on with the next one. Default: nothing.
    fn step_failed(&mut self, _report: &FailureReport) {}

    /// Called with the influence lines of an `[[influence]]` table after the step it is
    /// taken at (or why they could not be taken). Default: nothing.
    fn influence(
        &mut self,
        _lines: &Result<super::influence::InfluenceLines, (usize, String)>,
    ) -> std::io::Result<()> {
        Ok(())
    }

    /// Called when a step ends early (an increment failed after all cuts, a stop was asked,
    /// an error), with the system at its last converged state and the timings so far.
    /// Default: nothing.
    fn step_stopped(&mut self, _system: &System, _timings: &Timings) -> std::io::Result<()> {
        Ok(())
    }

    /// Asked after every converged increment and every step end: `Some` stops the analysis
    /// there. Default: never.
    fn stop_requested(&self) -> Option<StopReason> {
        None
    }

    /// Asked before each increment: work that does not depend on the coming solution (e.g.
    /// preparing the memory of the next field output), run on a thread of its own while
    /// the next numeric factorisation runs, which is sequential and leaves the other cores
    /// idle. It may never run (no factorisation follows); the observer must not wait for
    /// it without a way to call it off. `step`: the index of the step the increment
    /// belongs to. Default: none.
    fn idle_work(&mut self, _step: usize) -> Option<IdleWork> {
        None
    }
}

/// Work run beside the next factorisation (defined with the solver, which runs it).
pub use crate::linalg::solver::IdleWork;

/// The state at a step end, as observers see it (for checkpoints).
pub struct StepEnd<'a, 's> {
    /// The system (committed states).
    pub system: &'a System<'s>,
    /// The driver's state (next step, factors, clock, counters).
    pub driver: &'a DriverState,
}

/// Why an observer stopped the analysis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum StopReason {
    /// A termination signal arrived (its number: 2 SIGINT, 15 SIGTERM).
    Signal(i32),
    /// The run was asked to stop after this step (1-based).
    AfterStep(usize),
    /// The program running the analysis asked it to stop (an exception in a Python
    /// progress callback): not a signal.
    Caller,
}

/// Options of an analysis.
#[derive(Debug, Default)]
pub struct RunOptions {
    /// When a step fails after all cuts, report it and go on with the next step from the
    /// last converged state (load factors and time as reached) instead of stopping.
    pub continue_on_failure: bool,
    /// Start from this saved state instead of the beginning.
    pub resume: Option<(DriverState, SystemState)>,
}

/// Why an analysis stopped early.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// An increment failed after all allowed cuts.
    #[error("{0}")]
    NotConverged(Box<FailureReport>),
    /// The stiffness matrix is singular: a mechanism.
    #[error("{0}")]
    Mechanism(String),
    /// Writing results failed.
    #[error("writing results: {0}")]
    Output(#[from] std::io::Error),
    /// An observer asked to stop (signal, or stop after a step).
    #[error("{}", stopped_message(*reason, *step, *increment, *resume_step))]
    Stopped {
        /// Why.
        reason: StopReason,
        /// Step index where the analysis stopped.
        step: usize,
        /// Last converged increment of that step (0 at a step end).
        increment: usize,
        /// Index of the step a restart from the last checkpoint begins with.
        resume_step: usize,
    },
    /// The saved state does not fit the model.
    #[error("{0}")]
    Restore(String),
}

/// "interrupted by SIGINT at step 3 increment 5; a restart continues with step 3".
fn stopped_message(reason: StopReason, step: usize, increment: usize, resume: usize) -> String {
    let why = match reason {
        StopReason::Signal(2) => "interrupted by SIGINT".to_string(),
        StopReason::Signal(15) => "interrupted by SIGTERM".to_string(),
        StopReason::Signal(n) => format!("interrupted by signal {n}"),
        StopReason::AfterStep(_) => "stopped as asked".to_string(),
        StopReason::Caller => "stopped by the program running it".to_string(),
    };
    let at = if increment == 0 {
        format!("after step {}", step + 1)
    } else {
        format!("at step {} increment {increment}", step + 1)
    };
    format!("{why} {at}; a restart continues with step {}", resume + 1)
}

/// Timings of the analysis phases [s].
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Timings {
    /// Pattern, dof map and state set-up.
    pub setup_s: f64,
    /// Element loops and scatter.
    pub assembly_s: f64,
    /// Element loops of the displacement driver's line searches (residual checks along a
    /// correction; not in `assembly_s`).
    pub line_search_s: f64,
    /// What the line searches did (counts; empty in a run without any).
    #[serde(skip_serializing_if = "LineSearchStats::is_empty")]
    pub line_searches: LineSearchStats,
    /// Linear solver figures.
    pub solver: SolverStats,
    /// Observers (output writing).
    pub output_s: f64,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations in all.
    pub iterations: usize,
    /// Limit points or bifurcations passed (the number of negative pivots changed), one
    /// message each.
    pub limit_points: Vec<String>,
    /// One-way supports: converged attempts solved again because a support point lifted
    /// off or touched down in them (docs/theory-stages.md, "One-way supports").
    #[serde(skip_serializing_if = "is_zero")]
    pub support_switches: usize,
    /// Increments kept with the support statuses of their last round after
    /// [`super::one_way::MAX_ROUNDS`] rounds of switching (the statuses chatter).
    #[serde(skip_serializing_if = "is_zero")]
    pub support_chatter: usize,
    /// IMPL-EX error control (`[solver] implex_tolerance`): increments retried at half the
    /// size because their IMPL-EX error exceeded the tolerance.
    #[serde(skip_serializing_if = "is_zero")]
    pub implex_cuts: usize,
    /// Increments accepted with their IMPL-EX error above the tolerance (at the smallest
    /// size `max_cuts` allows).
    #[serde(skip_serializing_if = "is_zero")]
    pub implex_over_tolerance: usize,
    /// The largest IMPL-EX error of an accepted increment [-] (fraction of f_tm; 0 when the
    /// control is off).
    #[serde(skip_serializing_if = "is_zero_f")]
    pub implex_max_error: f64,
    /// Global IMPL-EX error control (`[solver] implex_force_tolerance`): increments retried
    /// at half the size because the out-of-balance force of their IMPL-EX crack stresses
    /// exceeded the tolerance.
    #[serde(skip_serializing_if = "is_zero")]
    pub implex_force_cuts: usize,
    /// Increments accepted with that force error above the tolerance (at the smallest size,
    /// or not reduced by a halving).
    #[serde(skip_serializing_if = "is_zero")]
    pub implex_force_over_tolerance: usize,
    /// The largest global IMPL-EX error of an accepted increment [-] (fraction of the
    /// Newton test's force scale; 0 when the control is off).
    #[serde(skip_serializing_if = "is_zero_f")]
    pub implex_force_max_error: f64,
    /// Error-controlled increments (`[solver] increment_tolerance`, time steps'
    /// `substep_tolerance`): pairs of increments rejected because the halves missed the
    /// whole by more than the tolerance.
    #[serde(skip_serializing_if = "is_zero")]
    pub increments_rejected: usize,
    /// The largest estimated path error of a kept pair of increments [-]:
    /// max|u_whole − u_halves| / max|Δu over the pair| (0 without error control).
    #[serde(skip_serializing_if = "is_zero_f")]
    pub increment_max_error: f64,
    /// Pairs of increments kept with their estimated error above the tolerance: the
    /// shortest pair allowed, or one whose error a shorter pair did not lower (a crack or
    /// a joint jumping open inside it). Where these occur, `increment_max_error` measures
    /// such jumps, not a path error the increment size controls.
    #[serde(skip_serializing_if = "is_zero")]
    pub increments_over_tolerance: usize,
}

/// Counts of the displacement driver's line searches ([`Timings::line_searches`]).
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct LineSearchStats {
    /// Searches that evaluated a trial point (the work of the residual along the
    /// correction positive at s = 0).
    pub searches: usize,
    /// Of these, those after an overshooting correction (the others on a stagnating
    /// residual).
    pub after_overshoot: usize,
    /// Searches that stopped at s = 1 (the work kept its sign: no trial point inside).
    pub full_step: usize,
    /// Trial points assembled without the tangent (s = 1).
    pub residual_trials: usize,
    /// Of these, full steps that were the iterate just assembled (after an overshoot),
    /// computed again only in the elements of the points latched since
    /// (`System::reassemble_after_latch`).
    pub full_step_again: usize,
    /// Trial points assembled with the tangent (inside (0, 1)).
    pub tangent_trials: usize,
    /// Tangent trial assemblies the next Newton iteration took over.
    pub reused: usize,
    /// Element-loop time of the trial points without the tangent [s].
    pub residual_s: f64,
    /// Element-loop time of the trial points with the tangent [s].
    pub tangent_s: f64,
}

impl LineSearchStats {
    fn is_empty(&self) -> bool {
        self.searches == 0
    }
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

fn is_zero_f(v: &f64) -> bool {
    *v == 0.0
}

/// After a converged increment inside a step: stop if an observer asks (the step end
/// asks separately, after its checkpoint).
pub(super) fn check_stop(
    obs: &dyn Observer,
    step: usize,
    increment: usize,
    end_of_step: bool,
) -> Result<(), AnalysisError> {
    if end_of_step {
        return Ok(());
    }
    match obs.stop_requested() {
        Some(reason) => Err(AnalysisError::Stopped {
            reason,
            step,
            increment,
            resume_step: step,
        }),
        None => Ok(()),
    }
}

/// Record a change of the number of negative pivots between converged increments.
pub(super) fn note_limit_point(
    timings: &mut Timings,
    last: &mut usize,
    now: usize,
    step: &str,
    increment: usize,
) {
    if now != *last {
        timings.limit_points.push(format!(
            "step '{step}' increment {increment}: negative pivots {last} -> {now} ({})",
            if now > *last {
                "limit point or bifurcation passed"
            } else {
                "stiffness regained"
            }
        ));
        *last = now;
    }
}

/// A halving must bring the IMPL-EX error of an increment below this fraction of the last
/// attempt's, or the increment is kept as it is (the error is not controlled by the size).
const IMPLEX_MIN_REDUCTION: f64 = 0.9;

/// IMPL-EX error control after a converged increment (`[solver] implex_tolerance` and
/// `implex_force_tolerance`, docs/theory-concrete.md §5.2): true if the increment is to be
/// thrown away and retried at half its size — one of its IMPL-EX errors exceeds its
/// tolerance, it is larger than the smallest size (the step's nominal increment halved
/// `max_cuts` times; `size` and `nominal` in any common unit), and the error fell with the
/// last halving (the larger ratio of error to tolerance below 0.9 of the previous attempt's
/// of this increment, `last`, which this updates; a crack that jumps open at fixed load
/// keeps its error whatever the size). An increment kept above a tolerance is counted in
/// `timings`. `energy` is the attempt's error in the energy norm ([`implex_energy_error`],
/// measured by the caller at every kept increment), the measure of
/// `implex_force_norm = "energy"`. Always false without the options.
pub(super) fn implex_retry(
    sys: &super::system::System,
    energy: f64,
    timings: &mut Timings,
    (size, nominal): (f64, f64),
    last: &mut Option<f64>,
) -> bool {
    let controls = &sys.model.controls;
    let (point_tol, force_tol) = (controls.implex_tolerance, controls.implex_force_tolerance);
    if point_tol.is_none() && force_tol.is_none() {
        return false;
    }
    let point = point_tol.map(|tol| (sys.implex_error(), tol));
    let force = force_tol.map(|tol| {
        let e = match controls.implex_force_norm {
            crate::model::ImplexForceNorm::Force => sys.implex_force_error(),
            crate::model::ImplexForceNorm::Energy => energy,
        };
        (e, tol)
    });
    // The point measure's compression part (IMPL-EX compression) is over f_cm.
    let compression = sys.model.materials.iter().any(|m| {
        matches!(&m.law, crate::materials::point::Material::Concrete { params, .. }
            if params.compression_implex)
    });
    let point_unit = if compression {
        "of f_tm (cracks) or f_cm (compression)"
    } else {
        "of f_tm"
    };
    let force_unit = match controls.implex_force_norm {
        crate::model::ImplexForceNorm::Force => "of the force scale",
        crate::model::ImplexForceNorm::Energy => "in the energy norm",
    };
    // The decisive measure: the larger ratio of error to tolerance.
    let ratio = [point, force]
        .iter()
        .flatten()
        .map(|&(e, t)| e / t)
        .fold(0.0, f64::max);
    let over = |m: Option<(f64, f64)>| m.is_some_and(|(e, t)| e > t);
    let smallest = nominal * 0.5_f64.powi(controls.max_cuts as i32);
    let falls = last.is_none_or(|l| ratio < IMPLEX_MIN_REDUCTION * l);
    if ratio > 1.0 && falls && 0.5 * size >= smallest * (1.0 - 1e-9) {
        timings.implex_cuts += usize::from(over(point));
        timings.implex_force_cuts += usize::from(over(force));
        *last = Some(ratio);
        if controls.verbose {
            eprintln!(
                "    IMPL-EX error {} {}: increment halved",
                describe(point, point_unit),
                describe(force, force_unit)
            );
        }
        return true;
    }
    *last = None;
    timings.implex_over_tolerance += usize::from(over(point));
    timings.implex_force_over_tolerance += usize::from(over(force));
    if ratio > 1.0 && controls.verbose {
        eprintln!(
            "    IMPL-EX error {} {} kept (smallest increment, or not reduced by halving)",
            describe(point, point_unit),
            describe(force, force_unit)
        );
    }
    if let Some((e, _)) = point {
        timings.implex_max_error = timings.implex_max_error.max(e);
    }
    if let Some((e, _)) = force {
        timings.implex_force_max_error = timings.implex_force_max_error.max(e);
    }
    false
}

/// The global IMPL-EX error in the energy norm [-] (`[solver] implex_force_norm =
/// "energy"`, docs/theory-concrete.md §5.2): with r the out-of-balance force of
/// [`super::system::System::implex_force_error`] (free equations) and δu = K⁻¹ r one
/// back-substitution with the factor `solver` holds (the tangent of the increment's last
/// Newton iteration), √|r·δu| / √|u·f_int|: the energy of the correction the crack
/// stresses' error calls for against the work of the internal forces `f_int` [N] on the
/// displacements `u` [m] (all dofs, so that the prescribed displacements' reactions
/// count). Absolute values: an indefinite (LDLᵀ) tangent past a limit point
/// can make r·δu negative. 0 without IMPL-EX points, without a factor (an increment
/// that converged before any factorisation) or with no work done.
pub(super) fn implex_energy_error(
    sys: &super::system::System,
    solver: &mut crate::linalg::solver::SparseCholesky,
    u: &[f64],
    f_int: &[f64],
) -> f64 {
    let Some(r) = sys.implex_residual() else {
        return 0.0;
    };
    if !solver.has_factor() {
        return 0.0;
    }
    let mut du = r.clone();
    solver.solve_in_place(&mut du);
    let correction = r.iter().zip(&du).map(|(a, b)| a * b).sum::<f64>().abs();
    let state = u.iter().zip(f_int).map(|(a, b)| a * b).sum::<f64>().abs();
    if state > 0.0 && correction.is_finite() {
        (correction / state).sqrt()
    } else {
        0.0
    }
}

/// An IMPL-EX error and its tolerance for the verbose log, in `unit` (empty when the
/// measure is off).
fn describe(m: Option<(f64, f64)>, unit: &str) -> String {
    m.map_or(String::new(), |(e, t)| {
        format!("{e:.3e} (tolerance {t} {unit})")
    })
}
