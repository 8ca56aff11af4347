//! The step driver: load-controlled increments solved by Newton–Raphson with automatic
//! step cutting; every converged increment is reported to an observer.

use super::driver::{check_stop, note_limit_point};
pub use super::driver::{
    AnalysisError, IdleWork, LineSearchStats, Observer, RunOptions, Snapshot, StepEnd, StopReason,
    Timings,
};
use super::failure::{report, FailedAt, NewtonFailure};
use super::increments::{self, external_forces, Controller, Growth, PairNorm};
use super::loads::load_vector;
use super::newton::newton;
use super::state::{DriverState, SystemState};
use super::system::System;
use crate::linalg::solver::{SolverError, SparseCholesky};
use crate::materials::point::TimeContext;
use crate::model::{Model, Predictor, Step, StepKind, DEFAULT_START_DAY};
use std::time::Instant;

/// Run all steps of the model, reporting to `obs`. Returns the timings.
pub fn run(model: &Model, obs: &mut dyn Observer) -> Result<Timings, AnalysisError> {
    run_with(model, obs, RunOptions::default())
}

/// Run the steps of the model with `options` (continue on failure, resume from a saved
/// state), reporting to `obs`. Returns the timings.
// long: the run loop threads the system, solver, load vectors, factors, clock and placed loads through every step, stage and influence table
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
    let mut driver = start(
        model,
        &mut sys,
        &mut solver,
        &mut timings,
        obs,
        options.resume,
    )?;
    timings.setup_s = t0.elapsed().as_secs_f64();
    let mut factors = driver.factors.clone();
    let mut neg_pivots = driver.neg_pivots;
    let mut clock = driver.clock;
    // Prescribed displacements apply from the first increment on.
    for &(d, v) in &sys.dofs.prescribed {
        sys.disp.trial[d] = v;
    }
    let mut factored_linear = false;
    // Load cases given their loads by influence lines (`[[influence.place]]`).
    let mut placed: Vec<(usize, Vec<f64>)> = Vec::new();
    for si in driver.next_step..model.steps.len() {
        let step = &model.steps[si];
        if sys.stages.is_some() {
            enter_stage(&mut sys, si, clock, &mut cases, &factors)?;
            // Load cases placed by influence lines keep their loads across stages.
            for (c, f) in &placed {
                cases[*c].copy_from_slice(f);
            }
        }
        sys.stress_tendons(si);
        // Thermal strains of the factors held at the start of the step (path steps keep
        // them; load steps set them again per increment).
        sys.thermal.impose(&factors, &mut sys.tendons);
        // Every step starts as an instantaneous increment at the current clock: path steps
        // keep this context for all their increments (no creep, shrinkage or relaxation
        // while they run; their time is the clock), load steps set it again per increment,
        // and time steps replace it with their substeps.
        sys.begin_time_increment(TimeContext::at(clock));
        let mut reached_clock = clock;
        let mut ctx = super::context::PathContext {
            sys: &mut sys,
            solver: &mut solver,
            cases: &cases,
            factors: &mut factors,
            timings: &mut timings,
            neg_pivots: &mut neg_pivots,
            implex_error: None,
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
        // Influence lines taken at this step's end (they leave the state as it is; the
        // next step factorises its own tangent).
        for table in (0..model.influence.len()).filter(|&t| model.influence[t].after_step == si) {
            let f_ext = external_forces(model.n_dofs(), &cases, &factors);
            let lines = super::influence::compute(&mut sys, &mut solver, &f_ext, clock, table)
                .map_err(|e| (table, e));
            obs.influence(&lines)?;
            factored_linear = false;
            let inf = &model.influence[table];
            match &lines {
                Ok(l) => {
                    for p in &inf.place {
                        let f = super::influence::placed_load(model, l, p);
                        cases[p.case].copy_from_slice(&f);
                        placed.push((p.case, f));
                    }
                }
                // A later step would run a placed case without its loads.
                Err((_, e)) if !inf.place.is_empty() => {
                    timings.solver = solver.stats.clone();
                    obs.step_stopped(&sys, &timings)?;
                    return Err(AnalysisError::Mechanism(format!(
                        "influence '{}' after step '{}': {e}; load case '{}' takes its loads from these lines",
                        inf.name, step.name, model.load_cases[inf.place[0].case].name
                    )));
                }
                Err(_) => {}
            }
        }
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

/// The driver state the run starts from: the model's initial state (reported to `obs` as
/// the end of "step 0"), or a checkpoint's (`resume`: its driver state and system state,
/// restored into `sys`, `solver` and `timings`). A checkpoint past an influence table that
/// places load cases is refused: the placed loads are not saved.
fn start(
    model: &Model,
    sys: &mut System,
    solver: &mut SparseCholesky,
    timings: &mut Timings,
    obs: &mut dyn Observer,
    resume: Option<(DriverState, SystemState)>,
) -> Result<DriverState, AnalysisError> {
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
    match resume {
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
            system: sys,
            driver: &driver,
        })?,
    }
    if let Some(inf) = model
        .influence
        .iter()
        .find(|i| !i.place.is_empty() && i.after_step < driver.next_step)
    {
        return Err(AnalysisError::Restore(format!(
            "influence '{}' placed load case '{}' after step '{}', which the checkpoint has done; restart from a checkpoint before it",
            inf.name, model.load_cases[inf.place[0].case].name, model.steps[inf.after_step].name
        )));
    }
    Ok(driver)
}

/// Run one load, linear or time step: increments of the load-case factors (and of the clock
/// over a time span), each solved by Newton, sized by the increment controller
/// ([`increments::run`]). `reached_clock` follows the time of the last converged increment.
#[allow(clippy::too_many_arguments)]
fn load_step(
    ctx: &mut super::context::PathContext,
    si: usize,
    step: &Step,
    clock: f64,
    reached_clock: &mut f64,
    factored_linear: &mut bool,
    obs: &mut dyn Observer,
) -> Result<(), AnalysisError> {
    let model = ctx.sys.model;
    // Error-controlled substeps of a time step (`substep_tolerance`): the controller's size
    // is then the length of a pair of substeps, solved once whole (the probe) and then as
    // its two halves, which are kept if they agree with the probe (docs/theory-time.md §9).
    // Instantaneous load steps on nonlinear materials: pairs of increments with
    // `[solver] increment_tolerance`, never longer than the user's increment.
    let path_tolerance = (step.kind == StepKind::Load && step.time.is_none() && !ctx.sys.linear)
        .then_some(model.controls.increment_tolerance)
        .flatten();
    let tolerance = step.time.and_then(|t| t.tolerance).or(path_tolerance);
    // With the IMPL-EX error control the increments grow back after cuts, as in
    // displacement control (time steps with substep pairs set their own).
    let implex_control = model.controls.implex_tolerance.is_some()
        || model.controls.implex_force_tolerance.is_some();
    let growth = if implex_control && tolerance.is_none() {
        Growth::WhenEasy
    } else {
        Growth::Kept
    };
    let mut ctl = Controller::new(step.increments, model.controls.max_cuts, growth, tolerance);
    if path_tolerance.is_some() {
        ctl.max_size = ctl.nominal;
        ctl.norm = PairNorm::Rms;
    }
    let mut stepper = LoadStepper {
        si,
        step,
        start: ctx.factors.clone(),
        clock,
        reached_clock: *reached_clock,
        factored_linear: *factored_linear,
        // Path extrapolation ([`Predictor`]) in instantaneous load steps only: time steps
        // keep their error-controlled substeps as they are.
        extrapolating: step.kind == StepKind::Load
            && step.time.is_none()
            && model.controls.predictor == Predictor::Extrapolated,
        lam: Vec::new(),
        f_ext: Vec::new(),
    };
    let result = increments::run(&mut ctl, &mut stepper, ctx, obs);
    *reached_clock = stepper.reached_clock;
    *factored_linear = stepper.factored_linear;
    result
}

/// What a load, linear or time step supplies to the increment controller.
struct LoadStepper<'a> {
    /// Step index.
    si: usize,
    /// The step.
    step: &'a Step,
    /// Load-case factors at the step's start.
    start: Vec<f64>,
    /// Clock of an instantaneous step [d].
    clock: f64,
    /// Time of the last converged increment [d].
    reached_clock: f64,
    /// Whether the linear system is factorised (linear steps).
    factored_linear: bool,
    /// Whether attempts start from the extrapolated path.
    extrapolating: bool,
    /// Factors of the current attempt.
    lam: Vec<f64>,
    /// External forces of the current attempt [N].
    f_ext: Vec<f64>,
}

impl increments::Stepper<Controller> for LoadStepper<'_> {
    fn attempt(
        &mut self,
        ctx: &mut super::context::PathContext,
        obs: &mut dyn Observer,
        ctl: &mut Controller,
    ) -> Result<(Vec<f64>, usize), NewtonFailure> {
        let target = ctl.target();
        let step = self.step;
        self.lam = self
            .start
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
        // Parts placed at the start of a load step: their out-of-balance force, found once
        // an attempt stops short of the step's end (an attempt to the end needs none, so
        // steps that converge at once are not touched), comes in over the step.
        if target < 1.0 && self.step.kind == StepKind::Load && ctx.sys.stage_jump_pending() {
            let f0 = external_forces(ctx.sys.model.n_dofs(), ctx.cases, &self.start);
            ctx.sys.thermal.impose(&self.start, &mut ctx.sys.tendons);
            ctx.sys.begin_time_increment(TimeContext::at(self.clock));
            // A committed state that no longer assembles is left to the attempt to report.
            let _ = ctx.sys.ramp_stage_jump(&f0);
        }
        self.f_ext = external_forces(ctx.sys.model.n_dofs(), ctx.cases, &self.lam);
        ctx.sys.thermal.impose(&self.lam, &mut ctx.sys.tendons);
        // Reactions of supports removed at the start of the step, released over it.
        if let Some(st) = &ctx.sys.stages {
            st.add_release(&mut self.f_ext, target);
        }
        // The out-of-balance of parts placed at the start of the step, brought in over it.
        let rest = 1.0 - target;
        if rest > 0.0 {
            for (f, j) in self.f_ext.iter_mut().zip(&ctx.sys.stage_jump) {
                *f -= rest * j;
            }
        }
        ctx.sys.begin_time_increment(match &step.time {
            Some(span) => TimeContext {
                t_from: span.time_at(ctl.level),
                t_to: span.time_at(target),
                extrapolation: 0.0,
            },
            None => TimeContext::at(self.clock),
        });
        // History extrapolation (IMPL-EX cracking) relative to the last increment of this step.
        ctx.sys.time.extrapolation = ctl.extrapolation(target);
        if let (true, false, true, Some(p)) = (
            self.extrapolating,
            ctl.retry,
            ctl.increment > 0,
            ctl.prev_size,
        ) {
            ctx.sys.extrapolate((target - ctl.level) / p);
        }
        if let Some(work) = obs.idle_work(self.si) {
            ctx.solver.beside_next_factorisation(work);
        }
        newton(
            ctx.sys,
            ctx.solver,
            &self.f_ext,
            ctx.timings,
            &mut self.factored_linear,
            step.kind,
        )
    }

    fn external(&self) -> &[f64] {
        &self.f_ext
    }

    fn implex_controlled(&self) -> bool {
        self.step.kind != StepKind::Linear
    }

    fn discard(&mut self, ctx: &mut super::context::PathContext) {
        discard_trial(ctx);
    }

    fn mark(&mut self) -> f64 {
        self.reached_clock
    }

    fn restore_mark(&mut self, _ctx: &mut super::context::PathContext, mark: f64) {
        self.reached_clock = mark;
    }

    fn commit_half(&mut self, ctx: &mut super::context::PathContext) {
        ctx.sys.commit();
        self.reached_clock = ctx.sys.time.t_to;
    }

    fn accept(
        &mut self,
        ctx: &mut super::context::PathContext,
        obs: &mut dyn Observer,
        ctl: &mut Controller,
        f_int: Vec<f64>,
        iterations: usize,
    ) -> Result<bool, AnalysisError> {
        let si = self.si;
        ctx.sys.commit();
        *ctx.factors = std::mem::take(&mut self.lam);
        self.reached_clock = ctx.sys.time.t_to;
        let end_of_step = ctl.finished();
        ctx.timings.increments += 1;
        ctx.timings.iterations += iterations;
        note_limit_point(
            ctx.timings,
            ctx.neg_pivots,
            ctx.solver.negative_pivots,
            &self.step.name,
            ctl.increment,
        );
        // The run's last increment: no solve follows, and its output is written
        // into the factor's pages ([`SparseCholesky::release`]).
        if end_of_step && si + 1 == ctx.sys.model.steps.len() {
            ctx.solver.release();
        }
        let t = Instant::now();
        obs.increment(&Snapshot {
            system: ctx.sys,
            step: si,
            increment: ctl.increment,
            end_of_step,
            factors: ctx.factors,
            f_int: &f_int,
            f_ext: &self.f_ext,
            iterations,
            negative_pivots: ctx.solver.negative_pivots,
            arc_length_factor: None,
            control_force: None,
            implex_error: ctx.implex_error,
        })?;
        ctx.timings.output_s += t.elapsed().as_secs_f64();
        check_stop(obs, si, ctl.increment, end_of_step)?;
        Ok(false)
    }

    fn failed(
        &mut self,
        ctx: &mut super::context::PathContext,
        ctl: &Controller,
        failure: NewtonFailure,
        give_up: bool,
    ) -> Option<AnalysisError> {
        if let NewtonFailure::Singular(e) = &failure {
            if ctl.cuts == 0 && ctx.sys.linear {
                return Some(mechanism(ctx.sys, e.clone()));
            }
        }
        let give_up = give_up || self.step.kind == StepKind::Linear;
        // The report reads the trial states of the failed attempt: build it first.
        let rep = give_up.then(|| {
            report(
                ctx.sys,
                FailedAt {
                    step: self.si,
                    increment: ctl.increment + 1,
                    level: ctl.target(),
                    cuts: ctl.cuts,
                    factors: ctx.factors,
                    negative_pivots: ctx.solver.negative_pivots,
                },
                &failure,
            )
        });
        // Throw the trial state away; the controller retries with half the increment.
        discard_trial(ctx);
        rep.map(|rep| AnalysisError::NotConverged(Box::new(rep)))
    }
}

/// Throw the trial state of a failed (or probing) increment away: the displacements back to
/// the committed ones, prescribed values kept, the iteration holds released.
fn discard_trial(ctx: &mut super::context::PathContext) {
    ctx.back_to_committed();
    for &(d, v) in &ctx.sys.dofs.prescribed {
        ctx.sys.disp.trial[d] = v;
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
    let f_ext = external_forces(model.n_dofs(), cases, factors);
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
