//! The step driver: load-controlled increments solved by Newton–Raphson with automatic
//! step cutting; every converged increment is reported to an observer.

use super::driver::{check_stop, implex_retry, note_limit_point};
pub use super::driver::{
    AnalysisError, IdleWork, LineSearchStats, Observer, RunOptions, Snapshot, StepEnd, StopReason,
    Timings,
};
use super::failure::{report, FailedAt, NewtonFailure};
use super::loads::load_vector;
use super::newton::newton;
use super::solver::{SolverError, SparseCholesky};
use super::state::DriverState;
use super::system::System;
use super::time::{Pair, PairStart};
use crate::materials::point::TimeContext;
use crate::model::{Model, Predictor, Step, StepKind, DEFAULT_START_DAY};
use std::time::Instant;

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
    let mut cases: Vec<Vec<f64>> = model
        .load_cases
        .iter()
        .map(|c| load_vector(model, c))
        .collect();
    let mut solver = SparseCholesky::in_background(&sys.asm.pattern, sys.ordering.as_deref())
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
            // The checkpoint leaves the elastic points' outputs out.
            sys.recover_elastic_outputs(&d.factors)
                .map_err(AnalysisError::Restore)?;
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
        if sys.stages.is_some() {
            enter_stage(&mut sys, si, clock, &mut cases, &factors)?;
        }
        sys.stress_tendons(si);
        // Thermal strains of the factors held at the start of the step (path steps keep
        // them; load steps set them again per increment).
        sys.set_thermal(&factors);
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
    // Error-controlled substeps of a time step (`substep_tolerance`): `d_level` is then the
    // length of a pair of substeps, solved once whole (the probe) and then as its two halves,
    // which are kept if they agree with the probe (docs/theory-time.md §9).
    let tolerance = step.time.and_then(|t| t.tolerance);
    let min_pair = d_level / 1024.0;
    let mut pair = Pair::Probe;
    // Path extrapolation ([`Predictor`]) in instantaneous load steps only: time steps keep
    // their error-controlled substeps as they are.
    let extrapolating = step.kind == StepKind::Load
        && step.time.is_none()
        && model.controls.predictor == Predictor::Extrapolated;
    // Whether the last attempt failed: its retry starts from the last converged state.
    let mut retry = false;
    // IMPL-EX error of the last attempt of this increment, if it was cut for it.
    let mut implex_last = None;
    while level < 1.0 - 1e-12 {
        let target = pair.target(level, d_level);
        let lam: Vec<f64> = start
            .iter()
            .zip(&step.factors)
            // At the step's end its factors exactly (a + (b − a) · 1 can differ from b in
            // the last bit).
            .map(|(a, b)| {
                if target == 1.0 {
                    *b
                } else {
                    a + (b - a) * target
                }
            })
            .collect();
        let mut f_ext = vec![0.0; model.n_dofs()];
        for (c, l) in ctx.cases.iter().zip(&lam) {
            if *l != 0.0 {
                f_ext.iter_mut().zip(c).for_each(|(f, v)| *f += l * v);
            }
        }
        ctx.sys.set_thermal(&lam);
        // Reactions of supports removed at the start of the step, released over it.
        if let Some(st) = &ctx.sys.stages {
            st.add_release(&mut f_ext, target);
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
        if let (true, false, true, Some(p)) = (extrapolating, retry, increment > 0, prev_size) {
            ctx.sys.extrapolate(ctx.u, (target - level) / p);
        }
        if let Some(work) = obs.idle_work() {
            ctx.solver.beside_next_factorisation(work);
        }
        match newton(
            ctx.sys,
            ctx.solver,
            ctx.u,
            &f_ext,
            ctx.timings,
            factored_linear,
            step.kind,
        ) {
            Ok((_, iterations)) if tolerance.is_some() && pair.is_probe() => {
                // The whole pair as one substep: keep its displacements, throw its state
                // away, and keep the committed state in case the halves are rejected.
                ctx.timings.iterations += iterations;
                let probe = ctx.u.clone();
                discard_trial(ctx);
                pair = Pair::First(Box::new(PairStart {
                    level,
                    end: target,
                    probe,
                    saved: ctx.sys.snapshot(),
                    prev_size,
                    reached_clock: *reached_clock,
                }));
            }
            Ok((_, iterations)) if matches!(pair, Pair::First(_)) => {
                // The first half: committed, reported with the second.
                ctx.sys.commit(ctx.u);
                ctx.timings.iterations += iterations;
                prev_size = Some(target - level);
                level = target;
                *reached_clock = ctx.sys.time.t_to;
                pair = pair.second();
            }
            Ok((_, iterations)) if pair.rejects(ctx.u, tolerance, d_level > min_pair) => {
                // The halves disagree with the probe beyond the tolerance: back to the
                // start of the pair, with a shorter one.
                ctx.timings.iterations += iterations;
                let Pair::Second(start) = std::mem::replace(&mut pair, Pair::Probe) else {
                    unreachable!("rejects() is true only for a second half")
                };
                d_level = (d_level * start.growth(ctx.u, tolerance)).max(min_pair);
                level = start.level;
                prev_size = start.prev_size;
                *reached_clock = start.reached_clock;
                ctx.sys
                    .restore(start.saved)
                    .map_err(AnalysisError::Mechanism)?;
                discard_trial(ctx);
            }
            Ok((_, iterations))
                if step.kind != StepKind::Linear
                    && implex_retry(
                        ctx.sys,
                        ctx.timings,
                        (target - level, 1.0 / n_inc as f64),
                        &mut implex_last,
                    ) =>
            {
                // The IMPL-EX error is above the tolerance: retried at half the size, as
                // after a failed attempt (not counted against the step's cuts).
                ctx.timings.iterations += iterations;
                discard_trial(ctx);
                retry = true;
                d_level *= 0.5;
                pair = Pair::Probe;
            }
            Ok((f_int, iterations)) => {
                retry = false;
                // With the IMPL-EX error control the increments grow back after cuts, as in
                // displacement control (time steps with substep pairs set their own).
                if model.controls.implex_tolerance.is_some()
                    && tolerance.is_none()
                    && iterations <= 4
                {
                    d_level = (2.0 * d_level).min(1.0 / n_inc as f64);
                }
                if let Pair::Second(start) = std::mem::replace(&mut pair, Pair::Probe) {
                    // An accepted pair: the next one as long as the error allows.
                    d_level = (d_level * start.growth(ctx.u, tolerance)).max(min_pair);
                }
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
                // The run's last increment: no solve follows, and its output is written
                // into the factor's pages ([`SparseCholesky::release`]).
                if end_of_step && si + 1 == model.steps.len() {
                    ctx.solver.release();
                }
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
                // Throw the trial state away and retry with half the increment (a failed
                // half of a substep pair: a new pair from the level reached).
                discard_trial(ctx);
                retry = true;
                if let Some(rep) = rep {
                    return Err(AnalysisError::NotConverged(Box::new(rep)));
                }
                cuts += 1;
                d_level *= 0.5;
                pair = Pair::Probe;
            }
        }
    }
    Ok(())
}

/// Throw the trial state of a failed (or probing) increment away: the displacements back to
/// the committed ones, prescribed values kept, the iteration holds released.
fn discard_trial(ctx: &mut super::path::PathContext) {
    ctx.back_to_committed();
    for &(d, v) in &ctx.sys.dofs.prescribed {
        ctx.u[d] = v;
    }
}

/// Enter the construction stage of step `si` at time `clock` [d]: the external forces of
/// the previous stage (its load vectors `cases` at `factors`) give the reactions of removed
/// supports; then the load vectors are those of the parts active now.
fn enter_stage(
    sys: &mut System,
    si: usize,
    clock: f64,
    cases: &mut [Vec<f64>],
    factors: &[f64],
) -> Result<(), AnalysisError> {
    let model = sys.model;
    let mut f_ext = vec![0.0; model.n_dofs()];
    for (c, l) in cases.iter().zip(factors) {
        f_ext.iter_mut().zip(c).for_each(|(f, v)| *f += l * v);
    }
    sys.begin_time_increment(TimeContext::at(clock));
    sys.enter_stage(si, &f_ext).map_err(|(e, err)| {
        AnalysisError::Mechanism(format!(
            "entering the stage of step '{}': element {} failed at the committed state: {err:?}",
            model.steps[si].name,
            e + 1
        ))
    })?;
    let active = sys.stages.as_ref().map(|s| s.element_active.as_slice());
    for (c, case) in cases.iter_mut().zip(&model.load_cases) {
        *c = super::loads::load_vector_of(model, case, active);
    }
    Ok(())
}

/// A solver failure as the analysis error it is (see [`super::failure::mechanism_message`]).
pub(super) fn mechanism(sys: &System, e: SolverError) -> AnalysisError {
    AnalysisError::Mechanism(super::failure::mechanism_message(sys, e))
}
