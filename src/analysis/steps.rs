//! The step driver: load-controlled increments solved by Newton–Raphson with automatic
//! step cutting; every converged increment is reported to an observer.

pub(crate) use super::failure::NewtonFailure;
use super::failure::{report, FailedAt, FailureReport};
use super::loads::load_vector;
use super::newton::{cycling, damping, norm};
use super::solver::{SolverError, SolverStats, SparseCholesky};
use super::state::{DriverState, SystemState};
use super::system::System;
use crate::fem::dofs::CONSTRAINED;
use crate::materials::point::TimeContext;
use crate::model::{Model, Step, StepKind, DEFAULT_START_DAY};
use std::time::Instant;

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
}

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
}

/// Run all steps of the model, reporting to `obs`. Returns the timings.
pub fn run(model: &Model, obs: &mut dyn Observer) -> Result<Timings, AnalysisError> {
    run_with(model, obs, RunOptions::default())
}

/// Run the steps of the model with `options` (continue on failure, resume from a saved
/// state), reporting to `obs`. Returns the timings.
pub fn run_with(
    model: &Model,
    obs: &mut dyn Observer,
    options: RunOptions,
) -> Result<Timings, AnalysisError> {
    let t0 = Instant::now();
    let mut sys = System::new(model);
    let cases: Vec<Vec<f64>> = model
        .load_cases
        .iter()
        .map(|c| load_vector(model, c))
        .collect();
    let mut solver = SparseCholesky::with_ordering(&sys.asm.pattern, sys.ordering.as_deref())
        .map_err(|e| mechanism(&sys, e))?;
    // The ordering is part of the symbolic analysis, wherever it is computed.
    solver.stats.symbolic_s += sys.ordering_s;
    let mut timings = Timings::default();
    // Analysis clock [d]: steps before the first time step act at its start.
    let mut driver = DriverState {
        next_step: 0,
        factors: vec![0.0; model.load_cases.len()],
        clock: model
            .steps
            .iter()
            .find_map(|s| s.time.map(|t| t.from))
            .unwrap_or(DEFAULT_START_DAY),
        neg_pivots: 0,
        solver_negative_pivots: 0,
        increments: 0,
        iterations: 0,
        limit_points: Vec::new(),
    };
    match options.resume {
        Some((d, s)) => {
            if d.factors.len() != driver.factors.len() || d.next_step > model.steps.len() {
                return Err(AnalysisError::Restore(format!(
                    "the checkpoint has {} load cases and {} steps done, the model {} load cases and {} steps: the model changed since the checkpoint was written",
                    d.factors.len(),
                    d.next_step,
                    driver.factors.len(),
                    model.steps.len()
                )));
            }
            sys.restore(s).map_err(AnalysisError::Restore)?;
            solver.negative_pivots = d.solver_negative_pivots;
            timings.increments = d.increments;
            timings.iterations = d.iterations;
            timings.limit_points = d.limit_points.clone();
            driver = d;
        }
        None => obs.step_end(&StepEnd {
            system: &sys,
            driver: &driver,
        })?,
    }
    timings.setup_s = t0.elapsed().as_secs_f64();
    let mut factors = driver.factors.clone();
    let mut neg_pivots = driver.neg_pivots;
    let mut clock = driver.clock;
    // Prescribed displacements apply from the first increment on.
    let mut u = sys.u.clone();
    for &(d, v) in &sys.dofs.prescribed {
        u[d] = v;
    }
    let mut factored_linear = false;
    for si in driver.next_step..model.steps.len() {
        let step = &model.steps[si];
        sys.stress_tendons(si);
        // Every step starts as an instantaneous increment at the current clock: path steps
        // keep this context for all their increments (no creep, shrinkage or relaxation
        // while they run; their time is the clock), load steps set it again per increment,
        // and time steps replace it with their substeps.
        sys.begin_time_increment(TimeContext::at(clock));
        let mut reached_clock = clock;
        let mut ctx = super::path::PathContext {
            sys: &mut sys,
            solver: &mut solver,
            cases: &cases,
            factors: &mut factors,
            u: &mut u,
            timings: &mut timings,
            neg_pivots: &mut neg_pivots,
        };
        let result = if matches!(step.kind, StepKind::Displacement | StepKind::ArcLength) {
            super::path::run_step(&mut ctx, si, step, obs)
        } else {
            load_step(
                &mut ctx,
                si,
                step,
                clock,
                &mut reached_clock,
                &mut factored_linear,
                obs,
            )
        };
        match result {
            Ok(()) => {
                if let Some(span) = &step.time {
                    clock = span.to;
                }
            }
            Err(AnalysisError::NotConverged(r)) if options.continue_on_failure => {
                obs.step_stopped(&sys, &timings)?;
                obs.step_failed(&r);
                // Go on from the last converged state. A load or time step set the clock of
                // its failed attempt: back to the time reached, and the tendons' initial
                // strains back to their committed relaxation (path steps leave both alone).
                if step.kind != StepKind::Displacement && step.kind != StepKind::ArcLength {
                    clock = reached_clock;
                    sys.begin_time_increment(TimeContext::at(clock));
                }
            }
            Err(e) => {
                timings.solver = solver.stats.clone();
                obs.step_stopped(&sys, &timings)?;
                return Err(e);
            }
        }
        driver = DriverState {
            next_step: si + 1,
            factors: factors.clone(),
            clock,
            neg_pivots,
            solver_negative_pivots: solver.negative_pivots,
            increments: timings.increments,
            iterations: timings.iterations,
            limit_points: timings.limit_points.clone(),
        };
        obs.step_end(&StepEnd {
            system: &sys,
            driver: &driver,
        })?;
        if si + 1 < model.steps.len() {
            if let Some(reason) = obs.stop_requested() {
                return Err(AnalysisError::Stopped {
                    reason,
                    step: si,
                    increment: 0,
                    resume_step: si + 1,
                });
            }
        }
    }
    timings.solver = solver.stats.clone();
    Ok(timings)
}

/// Run one load, linear or time step: increments of the load-case factors (and of the clock
/// over a time span), each solved by Newton, halved on failure up to `max_cuts` times.
/// `reached_clock` follows the time of the last converged increment.
#[allow(clippy::too_many_arguments)]
fn load_step(
    ctx: &mut super::path::PathContext,
    si: usize,
    step: &Step,
    clock: f64,
    reached_clock: &mut f64,
    factored_linear: &mut bool,
    obs: &mut dyn Observer,
) -> Result<(), AnalysisError> {
    let model = ctx.sys.model;
    let start = ctx.factors.clone();
    let n_inc = step.increments.max(1);
    let mut level = 0.0; // fraction of the step reached
    let mut d_level = 1.0 / n_inc as f64;
    let mut increment = 0;
    let mut cuts = 0;
    let mut prev_size: Option<f64> = None;
    while level < 1.0 - 1e-12 {
        let target = (level + d_level).min(1.0);
        let lam: Vec<f64> = start
            .iter()
            .zip(&step.factors)
            .map(|(a, b)| a + (b - a) * target)
            .collect();
        let mut f_ext = vec![0.0; model.n_dofs()];
        for (c, l) in ctx.cases.iter().zip(&lam) {
            if *l != 0.0 {
                f_ext.iter_mut().zip(c).for_each(|(f, v)| *f += l * v);
            }
        }
        ctx.sys.begin_time_increment(match &step.time {
            Some(span) => TimeContext {
                t_from: span.time_at(level),
                t_to: span.time_at(target),
                extrapolation: 0.0,
            },
            None => TimeContext::at(clock),
        });
        // History extrapolation (IMPL-EX cracking) relative to the last increment of this step.
        ctx.sys.time.extrapolation = prev_size.map_or(0.0, |p| (target - level) / p);
        match newton(
            ctx.sys,
            ctx.solver,
            ctx.u,
            &f_ext,
            ctx.timings,
            factored_linear,
            step.kind,
        ) {
            Ok((f_int, iterations)) => {
                ctx.sys.commit(ctx.u);
                prev_size = Some(target - level);
                level = target;
                increment += 1;
                *ctx.factors = lam;
                *reached_clock = ctx.sys.time.t_to;
                let end_of_step = level >= 1.0 - 1e-12;
                ctx.timings.increments += 1;
                ctx.timings.iterations += iterations;
                note_limit_point(
                    ctx.timings,
                    ctx.neg_pivots,
                    ctx.solver.negative_pivots,
                    &step.name,
                    increment,
                );
                let t = Instant::now();
                obs.increment(&Snapshot {
                    system: ctx.sys,
                    step: si,
                    increment,
                    end_of_step,
                    factors: ctx.factors,
                    f_int: &f_int,
                    f_ext: &f_ext,
                    iterations,
                    negative_pivots: ctx.solver.negative_pivots,
                    arc_length_factor: None,
                    control_force: None,
                })?;
                ctx.timings.output_s += t.elapsed().as_secs_f64();
                check_stop(obs, si, increment, end_of_step)?;
            }
            Err(NewtonFailure::Singular(e)) if cuts == 0 && ctx.sys.linear => {
                return Err(mechanism(ctx.sys, e));
            }
            Err(failure) => {
                let give_up = cuts >= model.controls.max_cuts || step.kind == StepKind::Linear;
                // The report reads the trial states of the failed attempt: build it first.
                let rep = give_up.then(|| {
                    report(
                        ctx.sys,
                        FailedAt {
                            step: si,
                            increment: increment + 1,
                            level: target,
                            cuts,
                            factors: ctx.factors,
                            negative_pivots: ctx.solver.negative_pivots,
                        },
                        &failure,
                    )
                });
                // Throw the trial state away and retry with half the increment.
                ctx.u.copy_from_slice(&ctx.sys.u);
                for &(d, v) in &ctx.sys.dofs.prescribed {
                    ctx.u[d] = v;
                }
                ctx.sys.unlatch();
                if let Some(rep) = rep {
                    return Err(AnalysisError::NotConverged(Box::new(rep)));
                }
                cuts += 1;
                d_level *= 0.5;
            }
        }
    }
    Ok(())
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

/// Newton–Raphson for one increment: returns the converged internal forces and iterations.
pub(super) fn newton(
    sys: &mut System,
    solver: &mut SparseCholesky,
    u: &mut [f64],
    f_ext: &[f64],
    timings: &mut Timings,
    factored_linear: &mut bool,
    kind: StepKind,
) -> Result<(Vec<f64>, usize), NewtonFailure> {
    let c = &sys.model.controls;
    let max_it = if kind == StepKind::Linear {
        2
    } else {
        c.max_iterations
    };
    let mut history = Vec::new();
    let mut first_energy: Option<f64> = None;
    let mut last_energy: Option<f64> = None;
    // The last correction (free equations) and the relative residual before it.
    let mut last: Option<(Vec<f64>, f64)> = None;
    for it in 0..=max_it {
        let need_k = !(sys.linear && *factored_linear);
        let mut eval = residual_at(sys, u, f_ext, need_k, timings);
        if let Some((du, rel0)) = last.take() {
            // An overshooting correction (residual grown more than 2×, or a material update
            // failing at its strains) is halved, up to three times (`path::overshot`).
            let mut s = 1.0;
            while s > 0.2
                && eval
                    .as_ref()
                    .map_or(true, |e| super::path::overshot(e.3, rel0))
            {
                s *= 0.5;
                for (d, &q) in sys.dofs.eq.iter().enumerate() {
                    if q != CONSTRAINED {
                        u[d] -= s * du[q];
                    }
                }
                eval = residual_at(sys, u, f_ext, need_k, timings);
                if c.verbose {
                    let r = eval.as_ref().map_or(f64::NAN, |e| e.3);
                    eprintln!(
                        "    residual grew: back to {s:.3} of the last correction, relative residual {r:.3e}"
                    );
                }
            }
        }
        let (a, r, rf, rel) = eval?;
        let rnorm = norm(&rf);
        if !rel.is_finite() {
            history.push(rel);
            return Err(NewtonFailure::diverged(history, rf));
        }
        history.push(rel);
        if cycling(&history) {
            sys.freeze_cracks();
        }
        if c.verbose {
            eprintln!(
                "    iteration {it:2}: relative residual {rel:.3e}, last energy {:.3e}",
                last_energy.unwrap_or(0.0)
            );
        }
        // Converged on force, or on energy (|Δu·r| of the last correction small against the
        // first one) once at least one correction has been made.
        let energy_ok = it > 1
            && matches!((first_energy, last_energy), (Some(e0), Some(e)) if e <= c.energy_tolerance * e0);
        if rnorm == 0.0 || (it > 0 && (rel <= c.force_tolerance || energy_ok)) {
            return Ok((a.f_int, it));
        }
        if it == max_it {
            return Err(NewtonFailure::diverged(history, rf));
        }
        if let Some(k) = a.k_values {
            if sys.linear {
                solver
                    .factorize(&sys.asm.pattern, &k)
                    .map_err(NewtonFailure::Singular)?;
            } else {
                // Nonlinear tangents may be indefinite (softening): LDLᵀ fallback.
                solver
                    .factorize_indefinite(&sys.asm.pattern, &k)
                    .map_err(NewtonFailure::Singular)?;
            }
            *factored_linear = sys.linear;
        }
        let mut du = rf;
        solver.solve_in_place(&mut du);
        // Damped correction while the residual stagnates (cycling across a kink of the
        // material response); see `newton::damping`.
        let damp = damping(&history);
        if damp < 1.0 {
            du.iter_mut().for_each(|v| *v *= damp);
        }
        let energy = du
            .iter()
            .zip(&sys.to_free(&r))
            .map(|(a, b)| a * b)
            .sum::<f64>()
            .abs();
        first_energy.get_or_insert(energy);
        last_energy = Some(energy);
        for (d, &q) in sys.dofs.eq.iter().enumerate() {
            if q != CONSTRAINED {
                u[d] += du[q];
            }
        }
        if it > 0 && !sys.linear {
            last = Some((du, rel));
        }
    }
    // The loop returns at its last iteration; this is for max_it = usize::MAX only.
    Err(NewtonFailure::diverged(history, Vec::new()))
}

/// An assembly, the full and free residuals [N] and the relative residual norm [-].
type Evaluated = (crate::analysis::system::Assembled, Vec<f64>, Vec<f64>, f64);

/// Assembly at `u` (with the tangent if `need_k`), crack latching, and the residual; the
/// relative norm is taken against the larger of the external force norm and the
/// element-force scale (which stays finite under self-equilibrated prestress).
fn residual_at(
    sys: &mut System,
    u: &[f64],
    f_ext: &[f64],
    need_k: bool,
    timings: &mut Timings,
) -> Result<Evaluated, NewtonFailure> {
    let t = Instant::now();
    let a = sys.assemble(u, need_k).map_err(NewtonFailure::material)?;
    sys.latch_cracks();
    timings.assembly_s += t.elapsed().as_secs_f64();
    let r: Vec<f64> = f_ext.iter().zip(&a.f_int).map(|(e, i)| e - i).collect();
    let rf = sys.to_free(&r);
    let reference = norm(f_ext).max(a.force_scale).max(f64::MIN_POSITIVE);
    let rel = norm(&rf) / reference;
    Ok((a, r, rf, rel))
}

/// A solver failure as the analysis error it is (see [`super::failure::mechanism_message`]).
pub(super) fn mechanism(sys: &System, e: SolverError) -> AnalysisError {
    AnalysisError::Mechanism(super::failure::mechanism_message(sys, e))
}
