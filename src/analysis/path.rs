//! Path following: displacement control of one dof and Crisfield's cylindrical arc-length
//! method. Both go past limit points of the load; arc length also past snap-backs. The
//! tangent may then be indefinite: it is factorised by LLᵀ with an LDLᵀ fallback that
//! reports the number of negative pivots.

use super::context::PathContext;
use super::driver::{check_stop, note_limit_point, AnalysisError, Observer, Snapshot};
use super::failure::{report, FailedAt, NewtonFailure};
use super::increments::{
    self, external_forces, external_forces_along, ArcSizing, Controller, Growth, PairNorm, Sizing,
};
use super::newton::{cycling, damping, hold_consistent, newton, norm, overshot};
use super::system::{Assembled, At, System};
use crate::fem::dofs::CONSTRAINED;
use crate::model::{ArcLengthControl, PathControl, Predictor, Step, StepKind};
use std::time::Instant;

impl PathContext<'_, '_> {
    /// Internal forces, tangent values and the element-force scale (the residual reference
    /// that stays finite under self-equilibrated loading) at the displacements `at`.
    fn tangent(&mut self, at: At<'_>) -> Result<(Vec<f64>, Vec<f64>, f64), NewtonFailure> {
        self.tangent_reusing(at, None)
    }

    /// As [`PathContext::tangent`], taking the assembly the line search made at its last
    /// trial point (`kept`, with the tangent) instead of assembling again when that point
    /// is the displacements `at` to the bit: the system's trial states are still that
    /// assembly's, and the same displacements, committed and latched states give the same
    /// forces, tangent and trial states, so only the repetition is saved.
    fn tangent_reusing(
        &mut self,
        at: At<'_>,
        kept: Option<Kept>,
    ) -> Result<(Vec<f64>, Vec<f64>, f64), NewtonFailure> {
        let t = Instant::now();
        let a = match kept.filter(|k| same_bits(&k.u, at.of(&self.sys.disp))) {
            Some(k) => {
                self.timings.line_searches.reused += 1;
                k.assembled
            }
            None => self
                .sys
                .assemble_at(at, true)
                .map_err(NewtonFailure::material)?,
        };
        self.sys.latch_cracks();
        self.timings.assembly_s += t.elapsed().as_secs_f64();
        Ok((
            a.f_int,
            a.k_values.expect("tangent requested"),
            a.force_scale,
        ))
    }

    /// Add a free-equation correction to the full displacement vector.
    fn add_free(&self, u: &mut [f64], du: &[f64], scale: f64) {
        for (d, &q) in self.sys.dofs.eq.iter().enumerate() {
            if q != CONSTRAINED {
                u[d] += scale * du[q];
            }
        }
    }

    /// Add `scale` × a free-equation correction to the trial displacements (the same
    /// arithmetic as [`PathContext::add_free`]).
    fn add_to_trial(&mut self, du: &[f64], scale: f64) {
        self.sys.disp.add_free(&self.sys.dofs.eq, du, scale);
    }

    /// Report a converged increment to the observer.
    #[allow(clippy::too_many_arguments)]
    fn report(
        &mut self,
        obs: &mut dyn Observer,
        step: usize,
        increment: usize,
        end_of_step: bool,
        f_int: &[f64],
        f_ext: &[f64],
        iterations: usize,
        arc_length_factor: Option<f64>,
        control_force: Option<f64>,
    ) -> Result<(), AnalysisError> {
        self.timings.increments += 1;
        self.timings.iterations += iterations;
        let name = &self.sys.model.steps[step].name;
        note_limit_point(
            self.timings,
            self.neg_pivots,
            self.solver.negative_pivots,
            name,
            increment,
        );
        let t = Instant::now();
        obs.increment(&Snapshot {
            system: self.sys,
            step,
            increment,
            end_of_step,
            factors: self.factors,
            f_int,
            f_ext,
            iterations,
            negative_pivots: self.solver.negative_pivots,
            arc_length_factor,
            control_force,
            implex_error: self.implex_error,
        })?;
        self.timings.output_s += t.elapsed().as_secs_f64();
        check_stop(obs, step, increment, end_of_step)
    }
}

/// A tangent assembly the line search made at its last trial point, kept for the Newton
/// iteration that goes on from there ([`PathContext::tangent_reusing`]).
struct Kept {
    /// The trial point (all dofs) [m].
    u: Vec<f64>,
    /// Its assembly, with the tangent.
    assembled: Assembled,
}

/// What a line search gives: the step length (None: the full step) and, when the search
/// ended on its last trial point, that point's assembly with the tangent.
type Searched = (Option<f64>, Option<Kept>);

/// Whether two vectors hold the same bits.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Run one displacement or arc-length step.
pub(super) fn run_step(
    ctx: &mut PathContext,
    si: usize,
    step: &Step,
    obs: &mut dyn Observer,
) -> Result<(), AnalysisError> {
    match (&step.path, step.kind) {
        (Some(PathControl::Displacement { nodes, dir, value }), StepKind::Displacement) => {
            let dofs: Vec<usize> = nodes.iter().map(|n| 2 * n + dir.index()).collect();
            displacement_step(ctx, si, step, &dofs, *value, obs)
        }
        (Some(PathControl::ArcLength(a)), StepKind::ArcLength) => arc_length_step(ctx, si, a, obs),
        _ => Err(AnalysisError::Mechanism(format!(
            "step '{}': path control missing (input error)",
            step.name
        ))),
    }
}

/// The error of a step that failed after all cuts, with its report (built from the trial
/// states of the failed attempt: call before anything is reassembled).
fn not_converged(
    ctx: &PathContext,
    si: usize,
    increment: usize,
    level: f64,
    cuts: usize,
    f: &NewtonFailure,
) -> AnalysisError {
    AnalysisError::NotConverged(Box::new(report(
        ctx.sys,
        FailedAt {
            step: si,
            increment,
            level,
            cuts,
            factors: ctx.factors,
            negative_pivots: ctx.solver.negative_pivots,
        },
        f,
    )))
}

// ------------------------------------------------------------------------------------------
// Displacement control
// ------------------------------------------------------------------------------------------

/// Positions in the lower-triangle value array of the off-diagonal entries of row and
/// column `q`: (other index, position). Found once per step.
fn row_positions(sys: &System, q: usize) -> Vec<(usize, usize)> {
    let p = &sys.asm.pattern;
    let mut v: Vec<(usize, usize)> = (0..q)
        .filter_map(|j| p.position(q, j).map(|pos| (j, pos)))
        .collect();
    v.extend((p.col_ptr[q] + 1..p.col_ptr[q + 1]).map(|pos| (p.row_idx[pos], pos)));
    v
}

/// Run one displacement step: the controlled dofs driven to `value` in increments sized by
/// the increment controller ([`increments::run`]).
fn displacement_step(
    ctx: &mut PathContext,
    si: usize,
    step: &Step,
    dofs: &[usize],
    value: f64,
    obs: &mut dyn Observer,
) -> Result<(), AnalysisError> {
    let mut ctl = Vec::new();
    for &c in dofs {
        let q = ctx.sys.dofs.eq[c];
        if q == CONSTRAINED {
            return Err(AnalysisError::Mechanism(format!(
                "step '{}': the controlled dof is constrained",
                step.name
            )));
        }
        // All controlled dofs move by the same increment from their own start values.
        ctl.push(Controlled {
            c,
            q,
            v0: ctx.sys.disp.committed[c],
            row_pos: row_positions(ctx.sys, q),
        });
    }
    let f_ext = external_forces(ctx.sys.model.n_dofs(), ctx.cases, ctx.factors);
    // The step drives the first controlled dof to `value`; the others follow with the same
    // increment (equal to it when they start equal).
    let v0 = ctl[0].v0;
    let controls = &ctx.sys.model.controls;
    // Nonlinear materials: pairs of increments with `[solver] increment_tolerance`, never
    // longer than the user's increment (pairs set their own growth).
    let tolerance = (!ctx.sys.linear)
        .then_some(controls.increment_tolerance)
        .flatten();
    let growth = if tolerance.is_some() {
        Growth::Kept
    } else {
        Growth::WhenEasy
    };
    let mut sizing = Controller::new(step.increments, controls.max_cuts, growth, tolerance);
    sizing.max_size = sizing.nominal;
    sizing.norm = PairNorm::Rms;
    // The last increment's move of the first controlled dof (whatever step it belonged to)
    // scales the first extrapolation; then the increments of this step.
    let c0 = ctl[0].c;
    let last_move = (ctx.sys.disp.committed[c0] - ctx.sys.disp.previous[c0]).abs();
    let full = (value - v0).abs();
    sizing.prev_size = (last_move > 0.0 && full > 0.0).then(|| last_move / full);
    let mut stepper = DisplacementStepper {
        si,
        ctl,
        f_ext,
        value,
        v0,
    };
    increments::run(&mut sizing, &mut stepper, ctx, obs)
}

/// What a displacement step supplies to the increment controller.
struct DisplacementStepper {
    /// Step index.
    si: usize,
    /// The controlled dofs.
    ctl: Vec<Controlled>,
    /// External forces held over the step [N].
    f_ext: Vec<f64>,
    /// Value the first controlled dof is driven to [m].
    value: f64,
    /// Its value at the step's start [m].
    v0: f64,
}

impl increments::Stepper<Controller> for DisplacementStepper {
    fn attempt(
        &mut self,
        ctx: &mut PathContext,
        _obs: &mut dyn Observer,
        sizing: &mut Controller,
    ) -> Result<(Vec<f64>, usize), NewtonFailure> {
        let target = sizing.target();
        let shift = (self.value - self.v0) * target;
        // History extrapolation (IMPL-EX cracking) relative to the last increment of this step.
        ctx.sys.time.extrapolation = sizing.extrapolation(target);
        // Path extrapolation from the last increment of this step ([`Predictor`]).
        let extrapolate = (ctx.sys.model.controls.predictor == Predictor::Extrapolated
            && sizing.increment > 0
            && !sizing.retry)
            .then(|| sizing.prev_size.map(|p| (target - sizing.level) / p))
            .flatten();
        newton_controlled(ctx, &self.f_ext, &self.ctl, shift, extrapolate)
    }

    fn external(&self) -> &[f64] {
        &self.f_ext
    }

    fn discard(&mut self, ctx: &mut PathContext) {
        ctx.back_to_committed();
    }

    fn commit_half(&mut self, ctx: &mut PathContext) {
        ctx.sys.commit();
    }

    fn accept(
        &mut self,
        ctx: &mut PathContext,
        obs: &mut dyn Observer,
        sizing: &mut Controller,
        f_int: Vec<f64>,
        iterations: usize,
    ) -> Result<bool, AnalysisError> {
        ctx.sys.commit();
        let force: f64 = self.ctl.iter().map(|k| f_int[k.c] - self.f_ext[k.c]).sum();
        ctx.report(
            obs,
            self.si,
            sizing.increment,
            sizing.finished(),
            &f_int,
            &self.f_ext,
            iterations,
            None,
            Some(force),
        )?;
        Ok(false)
    }

    fn failed(
        &mut self,
        ctx: &mut PathContext,
        sizing: &Controller,
        failure: NewtonFailure,
        give_up: bool,
    ) -> Option<AnalysisError> {
        ctx.back_to_committed();
        give_up.then(|| {
            not_converged(
                ctx,
                self.si,
                sizing.increment + 1,
                sizing.target(),
                sizing.cuts,
                &failure,
            )
        })
    }
}

/// A controlled dof: full index, free equation, value at the start of the step [m], and
/// the off-diagonal positions of its row/column in the tangent.
struct Controlled {
    c: usize,
    q: usize,
    v0: f64,
    row_pos: Vec<(usize, usize)>,
}

/// Newton with the controlled dofs driven to v0 + `shift`: their equations are removed from
/// the system (rows and columns zeroed, diagonals kept) and their increments imposed; the
/// first iteration moves the other dofs by −K_fq Δ (tangent predictor), so the controlled
/// nodes are not pushed alone. With `extrapolate = Some(r)` the iterations start from the
/// last converged displacements plus r × the last increment (Δ is then what remains of the
/// controlled move). The iterate is the trial displacements (`ctx.sys.disp.trial`), left at
/// the converged ones. Returns the converged internal forces and the iterations.
fn newton_controlled(
    ctx: &mut PathContext,
    f_ext: &[f64],
    ctl: &[Controlled],
    shift: f64,
    extrapolate: Option<f64>,
) -> Result<(Vec<f64>, usize), NewtonFailure> {
    let controls = ctx.sys.model.controls.clone();
    let mut history = Vec::new();
    let (mut first_energy, mut last_energy): (Option<f64>, Option<f64>) = (None, None);
    if let Some(r) = extrapolate {
        ctx.sys.extrapolate(r);
    }
    let mut last: Option<Correction> = None;
    // The line search's last assembly, when the iterations go on from its trial point.
    let mut kept: Option<Kept> = None;
    for it in 0..=controls.max_iterations {
        let Residual {
            mut f_int,
            mut k,
            mut rf,
            mut rel,
        } = controlled_residual(ctx, f_ext, ctl, kept.take())?;
        if let Some(c) = last.take() {
            if overshot(rel, c.rel) {
                // The correction overshot (a band of open cracks or yielded bars is nearly a
                // mechanism: the linearised step closes cracks into compression at E): back
                // along it to where the residual's work vanishes, or half-way.
                ctx.sys.disp.trial = c.u;
                let (s, at) = line_search(ctx, &c.du, &c.rf, f_ext, ctl, true)?;
                let s = s.unwrap_or(0.5);
                ctx.add_to_trial(&c.du, s);
                Residual { f_int, k, rf, rel } = controlled_residual(ctx, f_ext, ctl, at)?;
                if controls.verbose {
                    eprintln!(
                        "    residual grew: back to {s:.3} of the last correction, relative residual {rel:.3e}"
                    );
                }
            }
        }
        history.push(rel);
        if cycling(&history) {
            ctx.sys.freeze_cracks();
            ctx.sys.hold_contacts();
        }
        if controls.verbose {
            eprintln!(
                "    iteration {it:2}: relative residual {rel:.3e}, {} negative pivots; {}",
                ctx.solver.negative_pivots,
                super::failure::census(ctx.sys, &rf)
            );
        }
        if !rel.is_finite() {
            return Err(NewtonFailure::diverged(history, rf));
        }
        if it > 0 {
            let energy_ok = it > 1
                && matches!((first_energy, last_energy), (Some(e0), Some(e)) if e <= controls.energy_tolerance * e0);
            let tol = controls.relative_force_tolerance(rel, norm(&rf));
            if rel <= tol || energy_ok {
                if ctx.sys.release_contacts() {
                    // Converged on held contact statuses: checked under the free law.
                    let free = controlled_residual(ctx, f_ext, ctl, None)?;
                    history.push(free.rel);
                    if !hold_consistent(free.rel, rel, tol, controls.verbose) {
                        return Err(NewtonFailure::diverged(history, free.rf));
                    }
                    return Ok((free.f_int, it));
                }
                return Ok((f_int, it));
            }
        }
        if it == controls.max_iterations {
            return Err(NewtonFailure::diverged(history, rf));
        }
        let p = &ctx.sys.asm.pattern;
        if it == 0 {
            // rhs_i = r_i − Σ_q K_iq Δ_q for the free i; rhs_q = K_qq Δ_q.
            for k_ in ctl {
                let delta = k_.v0 + shift - ctx.sys.disp.trial[k_.c];
                for &(j, pos) in &k_.row_pos {
                    rf[j] -= k[pos] * delta;
                }
            }
            for k_ in ctl {
                let delta = k_.v0 + shift - ctx.sys.disp.trial[k_.c];
                rf[k_.q] = k[p.col_ptr[k_.q]] * delta;
            }
        }
        for k_ in ctl {
            for &(_, pos) in &k_.row_pos {
                k[pos] = 0.0;
            }
        }
        ctx.solver
            .factorize_indefinite(&ctx.sys.asm.pattern, &k)
            .map_err(NewtonFailure::Singular)?;
        let mut du = rf.clone();
        ctx.solver.solve_in_place(&mut du);
        // Damping when the residual stagnates over two iterations: Newton cycles between
        // two sides of a kink of the material response (a crack closing/reopening, a point
        // switching between elastic and plastic); a shorter step lands between them.
        let damp = damping(&history);
        if damp < 1.0 && it > 0 {
            // Stagnating iterations: a line search on the work of the residual along the
            // correction, g(s) = δu·r(u + s δu), which has a zero in (0, 1] when the
            // correction overshoots a kink of the material response; fall back to the
            // plain halving when g does not change sign.
            let (s, at) = line_search(ctx, &du, &rf, f_ext, ctl, false)?;
            kept = at;
            let s = s.unwrap_or(damp);
            du.iter_mut().for_each(|v| *v *= s);
        } else if damp < 1.0 {
            du.iter_mut().for_each(|v| *v *= damp);
        }
        if it > 0 {
            let energy = du.iter().zip(&rf).map(|(a, b)| a * b).sum::<f64>().abs();
            first_energy.get_or_insert(energy);
            last_energy = Some(energy);
            last = Some(Correction {
                u: ctx.sys.disp.trial.clone(),
                du: du.clone(),
                rf,
                rel,
            });
        }
        ctx.add_to_trial(&du, 1.0);
    }
    // The loop returns at its last iteration; this is for max_iterations = usize::MAX only.
    Err(NewtonFailure::diverged(history, Vec::new()))
}

/// One Newton correction of the displacement driver, kept to backtrack along it.
struct Correction {
    /// Iterate the correction started from (all dofs) [m].
    u: Vec<f64>,
    /// The correction (free equations) [m].
    du: Vec<f64>,
    /// Free residual at `u` [N].
    rf: Vec<f64>,
    /// Relative residual norm at `u` [-].
    rel: f64,
}

/// Out-of-balance state of the displacement driver at one iterate.
struct Residual {
    /// Internal forces (all dofs) [N].
    f_int: Vec<f64>,
    /// Tangent matrix values in the assembly pattern [N/m].
    k: Vec<f64>,
    /// Free residual, the controlled dofs' rows zeroed (their reactions) [N].
    rf: Vec<f64>,
    /// ‖rf‖ over the force scale [-].
    rel: f64,
}

/// Internal forces, tangent, free residual and relative residual norm at the trial
/// displacements (the line search's assembly `kept` taken when it was made there).
fn controlled_residual(
    ctx: &mut PathContext,
    f_ext: &[f64],
    ctl: &[Controlled],
    kept: Option<Kept>,
) -> Result<Residual, NewtonFailure> {
    let (f_int, k, scale) = ctx.tangent_reusing(At::Trial, kept)?;
    let r: Vec<f64> = f_ext.iter().zip(&f_int).map(|(e, i)| e - i).collect();
    let mut rf = ctx.sys.to_free(&r);
    for k in ctl {
        rf[k.q] = 0.0; // the reaction of the control
    }
    let rel = norm(&rf)
        / norm(f_ext)
            .max(norm(&f_int))
            .max(scale)
            .max(f64::MIN_POSITIVE);
    Ok(Residual { f_int, k, rf, rel })
}

/// Step length s ∈ (0, 1] along the correction `du` (free equations) from the trial
/// displacements (left as they are) where the
/// work of the residual g(s) = du·r(u + s du) vanishes (regula falsi with the Illinois
/// modification, at most 6 evaluations, |g| ≤ ½ |g(0)| accepted). None when g(1) keeps the
/// sign of g(0) (no overshoot: the full step is as good as any shorter one).
///
/// The trial points after s = 1 are assembled with the tangent (the forces, and so the
/// search, are the same without it); when the search stops at its last trial point, that
/// assembly comes back with it ([`Kept`]) for the Newton iteration that continues from
/// there. On the RC beam 8 of 10 searches that pass s = 1 end on their last point, and a
/// tangent assembly costs about 1.4 residual-only ones.
fn line_search(
    ctx: &mut PathContext,
    du: &[f64],
    r0: &[f64],
    f_ext: &[f64],
    ctl: &[Controlled],
    overshoot: bool,
) -> Result<Searched, NewtonFailure> {
    let g0 = dot(du, r0);
    if g0.is_nan() || g0 <= 0.0 {
        return Ok((None, None));
    }
    let t = Instant::now();
    let g_at = |s: f64,
                tangent: bool,
                ctx: &mut PathContext|
     -> Result<(f64, Option<Kept>), NewtonFailure> {
        let mut ut = ctx.sys.disp.trial.clone();
        ctx.add_free(&mut ut, du, s);
        let t = Instant::now();
        // The full step after an overshoot is the iterate just assembled (and latched):
        // only the elements of the latched points are computed again.
        let again = if tangent {
            None
        } else {
            ctx.sys.reassemble_after_latch(&ut)
        };
        let ls = &mut ctx.timings.line_searches;
        ls.full_step_again += usize::from(again.is_some());
        let a = match again {
            Some(a) => a,
            None => ctx.sys.assemble(&ut, tangent),
        }
        .map_err(NewtonFailure::material)?;
        let ls = &mut ctx.timings.line_searches;
        if tangent {
            ls.tangent_trials += 1;
            ls.tangent_s += t.elapsed().as_secs_f64();
        } else {
            ls.residual_trials += 1;
            ls.residual_s += t.elapsed().as_secs_f64();
        }
        let r: Vec<f64> = f_ext.iter().zip(&a.f_int).map(|(e, i)| e - i).collect();
        let mut rf = ctx.sys.to_free(&r);
        for k in ctl {
            rf[k.q] = 0.0;
        }
        let kept = tangent.then_some(Kept {
            u: ut,
            assembled: a,
        });
        Ok((dot(du, &rf), kept))
    };
    ctx.timings.line_searches.searches += 1;
    ctx.timings.line_searches.after_overshoot += usize::from(overshoot);
    let searched = (|| {
        let (g1, _) = g_at(1.0, false, ctx)?;
        if g1 >= 0.0 {
            ctx.timings.line_searches.full_step += 1;
            return Ok((None, None));
        }
        let (mut a, mut ga, mut b, mut gb) = (0.0, g0, 1.0, g1);
        let mut best = (1.0, g1.abs());
        let mut last = None;
        for _ in 0..6 {
            let s = (a * gb - b * ga) / (gb - ga);
            let (g, kept) = g_at(s, true, ctx)?;
            last = kept;
            if g.abs() < best.1 {
                best = (s, g.abs());
            }
            if g.abs() <= 0.5 * g0 {
                return Ok((Some(s), last));
            }
            if g > 0.0 {
                (a, ga) = (s, g);
                gb *= 0.5;
            } else {
                (b, gb) = (s, g);
                ga *= 0.5;
            }
        }
        // The best point is the last one only by chance; the kept assembly is checked
        // against the point the iterations go on from.
        Ok((Some(best.0), last))
    })();
    ctx.timings.line_search_s += t.elapsed().as_secs_f64();
    searched
}

// ------------------------------------------------------------------------------------------
// Arc length
// ------------------------------------------------------------------------------------------

/// A converged arc-length increment.
struct ArcIncrement {
    f_int: Vec<f64>,
    d_lambda: f64,
    du: Vec<f64>,
    iterations: usize,
}

/// Run one arc-length step: arcs sized by [`ArcSizing`] and driven by the increment
/// controller ([`increments::run`]), each solved by [`arc_increment`].
fn arc_length_step(
    ctx: &mut PathContext,
    si: usize,
    a: &ArcLengthControl,
    obs: &mut dyn Observer,
) -> Result<(), AnalysisError> {
    let held = ctx.factors.clone();
    let n_dofs = ctx.sys.model.n_dofs();
    let f_base = external_forces(n_dofs, ctx.cases, &held);
    let q_full = external_forces(n_dofs, ctx.cases, &a.reference);
    // Nonlinear materials: pairs of arcs with `[solver] increment_tolerance`.
    let tolerance = (!ctx.sys.linear)
        .then_some(ctx.sys.model.controls.increment_tolerance)
        .flatten();
    let mut sizing = ArcSizing::new(a.max_increments, ctx.sys.model.controls.max_cuts, tolerance);
    let start_disp = a
        .target_displacement
        .map(|(n, d, _)| ctx.sys.disp.committed[2 * n + d.index()]);
    let mut stepper = ArcStepper {
        si,
        a,
        held,
        f_base,
        q_full,
        lambda: 0.0,
        reported_lambda: 0.0,
        du_prev: None,
        pair_start_du: None,
        start_disp,
        last: None,
        f_try: Vec::new(),
    };
    increments::run(&mut sizing, &mut stepper, ctx, obs)
}

/// What an arc-length step supplies to the increment controller: the arc solved from the
/// committed load factor, and the end found on the way (a target factor or displacement).
struct ArcStepper<'a> {
    /// Step index.
    si: usize,
    /// The step's control.
    a: &'a ArcLengthControl,
    /// The load-case factors held at the step's start [-].
    held: Vec<f64>,
    /// External forces held over the step [N].
    f_base: Vec<f64>,
    /// The reference load at factor 1 (all dofs) [N].
    q_full: Vec<f64>,
    /// Committed load factor of the step [-].
    lambda: f64,
    /// Load factor at the last reported increment (where a target factor is crossed
    /// from) [-].
    reported_lambda: f64,
    /// The last committed increment's displacement change (free equations) [m].
    du_prev: Option<Vec<f64>>,
    /// `du_prev` at the start of the current pair (restored when its halves are rejected).
    pair_start_du: Option<Vec<f64>>,
    /// The start value of the target displacement's dof [m].
    start_disp: Option<f64>,
    /// The last converged arc: load factor change [-] and displacement change [m].
    last: Option<(f64, Vec<f64>)>,
    /// External forces at the last converged arc's end (all dofs) [N].
    f_try: Vec<f64>,
}

impl ArcStepper<'_> {
    /// The load-case factors at the step's load factor `lambda` [-].
    fn factors_at(&self, lambda: f64) -> Vec<f64> {
        self.held
            .iter()
            .zip(&self.a.reference)
            .map(|(h, r)| h + lambda * r)
            .collect()
    }
}

impl increments::Stepper<ArcSizing> for ArcStepper<'_> {
    fn attempt(
        &mut self,
        ctx: &mut PathContext,
        _obs: &mut dyn Observer,
        sizing: &mut ArcSizing,
    ) -> Result<(Vec<f64>, usize), NewtonFailure> {
        // History extrapolation (IMPL-EX cracking): ratio of arc lengths.
        ctx.sys.time.extrapolation = sizing.extrapolation();
        let mut dl_try = sizing.attempt_length();
        // On the equations free now (one-way supports hold and let go of theirs).
        let q_free = ctx.sys.to_free(&self.q_full);
        let loads = (
            self.f_base.as_slice(),
            self.q_full.as_slice(),
            q_free.as_slice(),
        );
        let solved = arc_increment(ctx, loads, self.lambda, &mut dl_try, self.a, &self.du_prev);
        // The first attempt sets the arc length, converged or not (a failed first arc is
        // cut from it).
        sizing.attempted(dl_try);
        let inc = solved?;
        self.f_try = external_forces_along(&self.f_base, &self.q_full, self.lambda + inc.d_lambda);
        self.last = Some((inc.d_lambda, inc.du));
        Ok((inc.f_int, inc.iterations))
    }

    fn external(&self) -> &[f64] {
        &self.f_try
    }

    fn discard(&mut self, ctx: &mut PathContext) {
        ctx.back_to_committed();
    }

    fn mark(&mut self) -> f64 {
        self.pair_start_du = self.du_prev.clone();
        self.lambda
    }

    fn restore_mark(&mut self, ctx: &mut PathContext, mark: f64) {
        self.lambda = mark;
        self.du_prev = self.pair_start_du.take();
        *ctx.factors = self.factors_at(mark);
    }

    fn commit_half(&mut self, ctx: &mut PathContext) {
        ctx.sys.commit();
        let (d_lambda, du) = self.last.take().expect("a converged arc");
        self.lambda += d_lambda;
        *ctx.factors = self.factors_at(self.lambda);
        self.du_prev = Some(du);
    }

    fn accept(
        &mut self,
        ctx: &mut PathContext,
        obs: &mut dyn Observer,
        sizing: &mut ArcSizing,
        f_int: Vec<f64>,
        iterations: usize,
    ) -> Result<bool, AnalysisError> {
        let (d_lambda, du) = self.last.take().expect("a converged arc");
        let a = self.a;
        let mut lam_new = self.lambda + d_lambda;
        let mut f_int = f_int;
        let mut reported_iterations = iterations;
        // Land on the target factor by a load-controlled correction if this increment
        // crossed it on the way up (the arc-length point is kept if that fails).
        let mut reached = false;
        if let Some(t) = a.target_factor {
            if self.reported_lambda < t && lam_new >= t {
                reached = true;
                if let Some((fi, it)) = land_on_factor(ctx, &self.f_base, &self.q_full, t)? {
                    f_int = fi;
                    reported_iterations += it;
                    lam_new = t;
                }
            }
        }
        ctx.sys.commit();
        self.lambda = lam_new;
        self.reported_lambda = lam_new;
        *ctx.factors = self.factors_at(lam_new);
        if let (Some((n, d, v)), Some(u0)) = (a.target_displacement, self.start_disp) {
            let x = ctx.sys.disp.committed[2 * n + d.index()];
            if (x - v) * (v - u0).signum() >= 0.0 {
                reached = true;
            }
        }
        let end = reached || sizing.finished();
        let f_ext = external_forces_along(&self.f_base, &self.q_full, lam_new);
        ctx.report(
            obs,
            self.si,
            sizing.increment,
            end,
            &f_int,
            &f_ext,
            reported_iterations,
            Some(lam_new),
            None,
        )?;
        sizing.grow(a.desired_iterations, iterations, a.max_growth);
        self.du_prev = Some(du);
        Ok(end)
    }

    fn failed(
        &mut self,
        ctx: &mut PathContext,
        sizing: &ArcSizing,
        failure: NewtonFailure,
        give_up: bool,
    ) -> Option<AnalysisError> {
        ctx.back_to_committed();
        give_up.then(|| {
            not_converged(
                ctx,
                self.si,
                sizing.increment + 1,
                self.lambda,
                sizing.cuts,
                &failure,
            )
        })
    }
}

/// Load-controlled correction from the arc-length point in the trial displacements onto
/// the load factor `t` (forces `f_base + t q_full` [N]), starting from the committed
/// displacements: Some((internal forces, iterations)) with the trial there, or None with
/// the arc-length point and its trial states restored if Newton fails.
fn land_on_factor(
    ctx: &mut PathContext,
    f_base: &[f64],
    q_full: &[f64],
    t: f64,
) -> Result<Option<(Vec<f64>, usize)>, AnalysisError> {
    let disp = &mut ctx.sys.disp;
    let arc_point = std::mem::replace(&mut disp.trial, disp.committed.clone());
    let f_t = external_forces_along(f_base, q_full, t);
    let mut factored = false;
    if let Ok((fi, it)) = newton(
        ctx.sys,
        ctx.solver,
        &f_t,
        ctx.timings,
        &mut factored,
        StepKind::Load,
    ) {
        return Ok(Some((fi, it)));
    }
    // Restore the arc-length point and its trial states.
    ctx.sys.disp.trial = arc_point;
    ctx.sys
        .assemble_trial(false)
        .map_err(|(e, err)| AnalysisError::Mechanism(format!("element {}: {err}", e + 1)))?;
    Ok(None)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// One arc-length increment from the committed state at load factor `lambda_n`, with
/// arc length `dl` (set from the initial load-factor increment if None): cylindrical
/// constraint ‖Δu‖ = Δl over the free equations (Crisfield 1981).
fn arc_increment(
    ctx: &mut PathContext,
    (f_base, q_full, q_free): (&[f64], &[f64], &[f64]),
    lambda_n: f64,
    dl: &mut Option<f64>,
    a: &ArcLengthControl,
    du_prev: &Option<Vec<f64>>,
) -> Result<ArcIncrement, NewtonFailure> {
    let controls = ctx.sys.model.controls.clone();
    // Predictor: tangent at the committed state.
    let (_, k, _) = ctx.tangent(At::Committed)?;
    ctx.solver
        .factorize_indefinite(&ctx.sys.asm.pattern, &k)
        .map_err(NewtonFailure::Singular)?;
    let mut dut = q_free.to_vec();
    ctx.solver.solve_in_place(&mut dut);
    let nt = norm(&dut);
    if !(nt.is_finite() && nt > 0.0) {
        return Err(NewtonFailure::diverged(vec![nt], Vec::new()));
    }
    let l = *dl.get_or_insert(a.initial_increment * nt);
    // Direction: keep going the way the previous increment went (Feng's criterion
    // Δu_prev · δu_t > 0), which follows snap-backs where the load must decrease.
    // With a positive-definite tangent the load must grow (sign of det K); past a limit
    // point (negative pivots) the previous direction decides.
    let sign = match du_prev {
        Some(p) if ctx.solver.negative_pivots > 0 && dot(p, &dut) < 0.0 => -1.0,
        _ => 1.0,
    };
    let mut d_lambda = sign * l / nt;
    let mut du: Vec<f64> = dut.iter().map(|v| v * d_lambda).collect();
    // The iterate is the trial displacements, from the committed ones.
    let disp = &mut ctx.sys.disp;
    disp.trial.copy_from_slice(&disp.committed);
    ctx.add_to_trial(&du, 1.0);
    let mut history = Vec::new();
    let (mut first_energy, mut last_energy): (Option<f64>, Option<f64>) = (None, None);
    // The last correction (iterate, Δu and Δλ it started from, δu, δλ, relative residual).
    let mut last: Option<ArcCorrection> = None;
    for it in 1..=controls.max_iterations + 1 {
        let mut eval = arc_residual(ctx, lambda_n + d_lambda, f_base, q_full);
        if let Some(c) = last.take() {
            // An overshooting correction (the residual grows more than BACKTRACK_GROWTH×, or
            // a material update fails at its wild strains) is halved, up to three times; the
            // iterations after pull the iterate back onto the constraint.
            let mut s = 1.0;
            while s > 0.2 && eval.as_ref().map_or(true, |e| overshot(e.rel, c.rel)) {
                s *= 0.5;
                ctx.sys.disp.trial.copy_from_slice(&c.u);
                ctx.add_to_trial(&c.corr, s);
                du.iter_mut()
                    .zip(c.du.iter().zip(&c.corr))
                    .for_each(|(d, (d0, k))| *d = d0 + s * k);
                d_lambda = c.d_lambda + s * c.dlam;
                eval = arc_residual(ctx, lambda_n + d_lambda, f_base, q_full);
                if controls.verbose {
                    let r = eval.as_ref().map_or(f64::NAN, |e| e.rel);
                    eprintln!(
                        "    residual grew: back to {s:.3} of the last correction, relative residual {r:.3e}"
                    );
                }
            }
        }
        let Residual { f_int, k, rf, rel } = eval?;
        history.push(rel);
        if cycling(&history) {
            ctx.sys.freeze_cracks();
            ctx.sys.hold_contacts();
        }
        if controls.verbose {
            eprintln!(
                "    iteration {it:2}: relative residual {rel:.3e}, load factor increment {d_lambda:.4e}, {} negative pivots; {}",
                ctx.solver.negative_pivots,
                super::failure::census(ctx.sys, &rf)
            );
        }
        if !rel.is_finite() {
            return Err(NewtonFailure::diverged(history, rf));
        }
        let energy_ok = it > 2
            && matches!((first_energy, last_energy), (Some(e0), Some(e)) if e <= controls.energy_tolerance * e0);
        let tol = controls.relative_force_tolerance(rel, norm(&rf));
        if rel <= tol || energy_ok {
            let f_int = if ctx.sys.release_contacts() {
                // Converged on held contact statuses: checked under the free law.
                let free = arc_residual(ctx, lambda_n + d_lambda, f_base, q_full)?;
                history.push(free.rel);
                if !hold_consistent(free.rel, rel, tol, controls.verbose) {
                    return Err(NewtonFailure::diverged(history, free.rf));
                }
                free.f_int
            } else {
                f_int
            };
            return Ok(ArcIncrement {
                f_int,
                d_lambda,
                du,
                iterations: it,
            });
        }
        if it > controls.max_iterations {
            return Err(NewtonFailure::diverged(history, rf));
        }
        ctx.solver
            .factorize_indefinite(&ctx.sys.asm.pattern, &k)
            .map_err(NewtonFailure::Singular)?;
        let mut dur = rf.clone();
        ctx.solver.solve_in_place(&mut dur);
        let mut dut = q_free.to_vec();
        ctx.solver.solve_in_place(&mut dut);
        // The far root may turn the path back only past a limit point of this tangent.
        let limit_point = ctx.solver.negative_pivots > 0;
        let dlam = constraint_root(&du, &dur, &dut, l, &history, limit_point);
        let corr: Vec<f64> = dur.iter().zip(&dut).map(|(r, t)| r + dlam * t).collect();
        let energy = dot(&corr, &rf).abs();
        first_energy.get_or_insert(energy);
        last_energy = Some(energy);
        last = Some(ArcCorrection {
            u: ctx.sys.disp.trial.clone(),
            du: du.clone(),
            d_lambda,
            corr: corr.clone(),
            dlam,
            rel,
        });
        for (d, c) in du.iter_mut().zip(&corr) {
            *d += c;
        }
        d_lambda += dlam;
        ctx.add_to_trial(&corr, 1.0);
    }
    // The loop returns at its last iteration; this is for max_iterations = usize::MAX only.
    Err(NewtonFailure::diverged(history, Vec::new()))
}

/// The load-factor correction δλ of an arc-length iteration: the root of the cylindrical
/// constraint ‖Δu + δu_r + δλ δu_t‖ = Δl (increment `du`, residual and load corrections
/// `dur`, `dut` over the free equations [m], arc length `l`), given the relative residuals
/// of the iterations so far (`history`) and whether the tangent the corrections were solved
/// with has a negative pivot (`limit_point`: Sylvester's inertia, a limit point passed).
fn constraint_root(
    du: &[f64],
    dur: &[f64],
    dut: &[f64],
    l: f64,
    history: &[f64],
    limit_point: bool,
) -> f64 {
    // ‖Δu + δu_r + δλ δu_t‖² = Δl²  →  a1 δλ² + a2 δλ + a3 = 0.
    let w: Vec<f64> = du.iter().zip(dur).map(|(a, b)| a + b).collect();
    let a1 = dot(dut, dut);
    let a2 = 2.0 * dot(dut, &w);
    let a3 = dot(&w, &w) - l * l;
    let disc = a2 * a2 - 4.0 * a1 * a3;
    if disc < 0.0 {
        // No intersection with the cylinder: take the closest point (the minimum of the
        // quadratic); the next iterations pull back onto the constraint.
        -a2 / (2.0 * a1)
    } else {
        // Of the two roots take the one whose new Δu makes the smaller angle with the
        // current one (no backtracking along the path).
        let sq = disc.sqrt();
        let r1 = (-a2 + sq) / (2.0 * a1);
        let r2 = (-a2 - sq) / (2.0 * a1);
        let cosang = |r: f64| {
            w.iter()
                .zip(dut)
                .zip(du)
                .map(|((wi, ti), di)| (wi + r * ti) * di)
                .sum::<f64>()
        };
        let (near, far) = if cosang(r1) >= cosang(r2) {
            (r1, r2)
        } else {
            (r2, r1)
        };
        // Stagnation (the residual not falling over two iterations) means Newton cycles
        // across a kink of the response. At a crack that snaps back with its implicit
        // softening law the root nearest the predictor lies on the wrong side of the peak,
        // and the tangent shows it by a negative pivot: take the other root then. With a
        // positive-definite tangent no limit point lies on the way (IMPL-EX cracks are
        // secant in the increment, plasticity and joints harden or kink): the other root
        // is the path just travelled, run backwards, and taking it made the viaduct on
        // concrete shuttle between two points 0.003 × LM1 apart for 240 increments
        // (docs/theory.md, "Arc length past a peak"). The near root is kept there; if
        // Newton does not converge on it, the arc is cut.
        let n = history.len();
        let stagnating = n >= 3 && history[n - 1] >= 0.9 * history[n - 3];
        if stagnating && limit_point {
            far
        } else {
            near
        }
    }
}

/// One corrective iteration of the arc-length driver, kept to backtrack along it.
struct ArcCorrection {
    /// Iterate it started from (all dofs) [m].
    u: Vec<f64>,
    /// Increment Δu of the step at that iterate (free equations) [m].
    du: Vec<f64>,
    /// Load-factor increment Δλ at that iterate [-].
    d_lambda: f64,
    /// The correction δu (free equations) [m].
    corr: Vec<f64>,
    /// The load-factor correction δλ [-].
    dlam: f64,
    /// Relative residual norm at that iterate [-].
    rel: f64,
}

/// Internal forces, tangent, free residual and relative residual norm at the trial
/// displacements under the loads `f_base + lam q_full` (all dofs) [N].
fn arc_residual(
    ctx: &mut PathContext,
    lam: f64,
    f_base: &[f64],
    q_full: &[f64],
) -> Result<Residual, NewtonFailure> {
    let (f_int, k, scale) = ctx.tangent(At::Trial)?;
    let f_ext = external_forces_along(f_base, q_full, lam);
    let r: Vec<f64> = f_ext.iter().zip(&f_int).map(|(e, i)| e - i).collect();
    let rf = ctx.sys.to_free(&r);
    let rel = norm(&rf)
        / norm(&f_ext)
            .max(norm(&f_int))
            .max(scale)
            .max(f64::MIN_POSITIVE);
    Ok(Residual { f_int, k, rf, rel })
}

#[cfg(test)]
mod tests {
    use super::constraint_root;

    /// The constraint ‖w + δλ δu_t‖ = Δl with Δu = (1, 0), δu_r = (0, ½), δu_t = (1, 0),
    /// Δl = 1: (1 + δλ)² + ¼ = 1, roots δλ = −1 ± √¾. The near root keeps Δu pointing
    /// forward, (√¾, ½); the far root turns it back, (−√¾, ½).
    #[test]
    fn the_far_root_is_taken_only_on_stagnation_past_a_limit_point() {
        let (du, dur, dut) = ([1.0, 0.0], [0.0, 0.5], [1.0, 0.0]);
        let near = -1.0 + 0.75_f64.sqrt();
        let far = -1.0 - 0.75_f64.sqrt();
        let falling = [1e-2, 1e-3, 1e-4];
        let stagnating = [1e-3, 1e-3, 1e-3];
        // Round-off of the quadratic's coefficients only.
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        let root = |h: &[f64], limit| constraint_root(&du, &dur, &dut, 1.0, h, limit);
        assert!(close(root(&falling, false), near));
        assert!(close(root(&falling, true), near));
        // Stagnating on a positive-definite tangent: no limit point on the way, the far
        // root would retrace the path.
        assert!(close(root(&stagnating, false), near));
        // Stagnating with a negative pivot: past the peak, the far root.
        assert!(close(root(&stagnating, true), far));
    }
}
