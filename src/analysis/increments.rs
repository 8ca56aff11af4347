//! The increment controller of the load, time and displacement steps: the size of the next
//! increment, attempt → accept / cut on failure (`max_cuts`) / IMPL-EX retry / growth after
//! easy increments / step-doubling pairs with error control, and the one place where the
//! external forces are formed from the load-case factors. A step kind supplies only what is
//! its own through [`Stepper`]: how an attempt is solved (Newton at a load level, Newton with
//! a driven dof) and what it does with a converged increment. The arc-length step, whose
//! size is an arc length rather than a fraction of the step, uses the same cut, retry and
//! force pieces ([`ArcSizing`], [`external_forces_along`]).

use super::context::PathContext;
use super::driver::{implex_energy_error, implex_retry, AnalysisError, Observer};
use super::failure::NewtonFailure;
use super::state::SystemState;

/// Σ_c λ_c f_c over the `n_dofs` dofs [N]: the external forces of the load cases `cases`
/// (each over all dofs, at factor 1) at the factors `factors` [-]. Cases at factor 0 are
/// skipped.
pub(super) fn external_forces(n_dofs: usize, cases: &[Vec<f64>], factors: &[f64]) -> Vec<f64> {
    let mut f: Option<Vec<f64>> = None;
    for (c, l) in cases.iter().zip(factors).filter(|(_, l)| **l != 0.0) {
        match &mut f {
            // The first case written, not added into zeros: a fresh zeroed vector read
            // before it is written is faulted in twice per page, the second time with a TLB
            // flush on every core (10 ms of a 5e5-dof linear run). `0.0 +` keeps the sum's
            // bits (a −0.0 term gives +0.0).
            None if c.len() == n_dofs => f = Some(c.iter().map(|v| 0.0 + l * v).collect()),
            None => {
                let mut z = vec![0.0; n_dofs];
                z.iter_mut().zip(c).for_each(|(a, v)| *a += l * v);
                f = Some(z);
            }
            Some(f) => f.iter_mut().zip(c).for_each(|(a, v)| *a += l * v),
        }
    }
    f.unwrap_or_else(|| vec![0.0; n_dofs])
}

/// `base + λ reference` over all dofs [N]: the external forces of an arc-length step at its
/// load factor λ [-] (held forces `base`, reference load `reference`).
pub(super) fn external_forces_along(base: &[f64], reference: &[f64], lambda: f64) -> Vec<f64> {
    base.iter()
        .zip(reference)
        .map(|(b, q)| b + lambda * q)
        .collect()
}

/// Phase of an error-controlled pair of increments (`substep_tolerance` of a time step,
/// `[solver] increment_tolerance` of load, displacement and arc-length steps;
/// docs/theory-time.md §9, docs/theory.md).
/// The pair over the levels [a, b] of the step is solved once as one increment (the probe,
/// not kept) and then as its two halves; the halves are kept if
/// max|u_probe − u| ≤ tol · max|u − u_a| (step doubling: the difference estimates the
/// probe's error and bounds the halves' own, about 1/(2^p − 1) of it for a method of order
/// p ≥ 1), else the state goes back to a and a shorter pair is tried.
#[derive(Debug, Clone, Default)]
pub enum Pair {
    /// Next: the whole pair as one increment.
    #[default]
    Probe,
    /// Next: the first half.
    First(Box<PairStart>),
    /// Next: the second half.
    Second(Box<PairStart>),
}

/// What a pair of increments keeps from its start.
#[derive(Debug, Clone)]
pub struct PairStart {
    /// Level (fraction of the step) at the pair's start.
    pub level: f64,
    /// Level at the pair's end.
    pub end: f64,
    /// Displacements of the probe [m].
    pub probe: Vec<f64>,
    /// Committed displacements at the pair's start [m].
    pub start_u: Vec<f64>,
    /// Committed state at the pair's start (restored if the halves are rejected; set by
    /// [`run`] after the probe).
    pub saved: Option<SystemState>,
    /// Size of the increment before the pair (IMPL-EX extrapolation).
    pub prev_size: Option<f64>,
    /// What the step kind keeps of the pair's start (a time step: the clock reached [d]).
    pub mark: f64,
    /// The norm the error is measured in.
    pub norm: PairNorm,
}

/// The norm of a pair's error and of its displacement change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairNorm {
    /// The largest component (time steps: every point creeps smoothly).
    Max,
    /// The root mean square over all dofs (load and displacement steps: a crack opening
    /// inside a pair is a local jump whose size no increment length controls; the rms
    /// weighs it by the part of the structure it moves).
    Rms,
}

/// `level` [-], or exactly 1 (the end of the step) when it is within the step loop's 1e-12
/// of it or beyond: ten increments of 0.1 sum to 0.9999999999999999, and the last would
/// otherwise end short of the step's factors (a load factor of 100 recorded as
/// 99.999999999999986).
pub fn end_level(level: f64) -> f64 {
    if level >= 1.0 - 1e-12 {
        1.0
    } else {
        level
    }
}

impl Pair {
    /// Level the next increment ends at, from the level reached and the pair length.
    pub fn target(&self, level: f64, pair_length: f64) -> f64 {
        match self {
            Pair::Probe => end_level(level + pair_length),
            Pair::First(s) => 0.5 * (s.level + s.end),
            Pair::Second(s) => s.end,
        }
    }

    /// True before the probe of a pair.
    pub fn is_probe(&self) -> bool {
        matches!(self, Pair::Probe)
    }

    /// The phase after the first half.
    pub fn second(self) -> Pair {
        match self {
            Pair::First(s) => Pair::Second(s),
            p => p,
        }
    }

    /// True when this is a second half whose end displacements `u` [m] miss the probe's by
    /// more than `tol` times the change over the pair, and the pair may still be shortened.
    pub fn rejects(&self, u: &[f64], tol: Option<f64>, may_shorten: bool) -> bool {
        match (self, tol) {
            (Pair::Second(s), Some(tol)) if may_shorten => {
                let (err, change) = pair_error(&s.probe, &s.start_u, u, s.norm);
                err > tol * change
            }
            _ => false,
        }
    }
}

impl PairStart {
    /// Factor on the pair length after a pair ending at `u` [m]: the probe's error grows
    /// as h² for a first-order integration, so 0.9 (tol·change/err)^½, between ¼ and 2 (2
    /// where nothing moved).
    pub fn growth(&self, u: &[f64], tol: Option<f64>) -> f64 {
        let Some(tol) = tol else { return 1.0 };
        let (err, change) = pair_error(&self.probe, &self.start_u, u, self.norm);
        if err <= 0.0 || !err.is_finite() {
            return 2.0;
        }
        (0.9 * (tol * change / err).sqrt()).clamp(0.25, 2.0)
    }

    /// The pair's relative error max|probe − u| / max|u − u_a| [-] (0 where nothing moved).
    pub fn relative_error(&self, u: &[f64]) -> f64 {
        let (err, change) = pair_error(&self.probe, &self.start_u, u, self.norm);
        if change > 0.0 {
            err / change
        } else {
            0.0
        }
    }
}

/// Step-doubling error of a pair and the displacement change over it: (‖probe − u‖,
/// ‖u − start‖) [m] in the norm `norm`.
pub fn pair_error(probe: &[f64], start: &[f64], u: &[f64], norm: PairNorm) -> (f64, f64) {
    if norm == PairNorm::Rms {
        let rms = |a: &[f64], b: &[f64]| {
            (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len().max(1) as f64)
                .sqrt()
        };
        return (rms(probe, u), rms(start, u));
    }
    let err = probe
        .iter()
        .zip(u)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    let change = start
        .iter()
        .zip(u)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    (err, change)
}

/// How increments grow back after cuts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Growth {
    /// They keep the size they have (pairs set their own).
    Kept,
    /// ×2 after an increment of at most [`EASY_ITERATIONS`] iterations, up to the nominal
    /// size.
    WhenEasy,
}

/// An increment converged in at most this many iterations is easy: the next may be larger.
const EASY_ITERATIONS: usize = 4;

/// The sizing state of a step whose level runs from 0 to 1 (a fraction of the step).
#[derive(Debug)]
pub(super) struct Controller {
    /// Fraction of the step reached [-].
    pub level: f64,
    /// Length of the next increment (of the next pair, with pairs) [-].
    pub size: f64,
    /// The user's increment, 1 / increments [-].
    pub nominal: f64,
    /// Cuts after failed attempts so far in this step.
    pub cuts: usize,
    /// Cuts allowed before the step fails.
    pub max_cuts: usize,
    /// Converged (reported) increments of this step.
    pub increment: usize,
    /// Size of the last converged increment of this step (the extrapolations' scale).
    pub prev_size: Option<f64>,
    /// Whether the last attempt was thrown away: its retry starts from the committed state.
    pub retry: bool,
    /// IMPL-EX error of the last attempt of this increment, if it was cut for it.
    pub implex_last: Option<f64>,
    /// Growth after cuts.
    pub growth: Growth,
    /// Step-doubling tolerance (None: single increments).
    pub tolerance: Option<f64>,
    /// Shortest pair [-]: the tolerance is given up below it.
    pub min_pair: f64,
    /// Longest pair [-] (unbounded for time steps; the user's increment for load and
    /// displacement steps, so their output is never sparser than asked).
    pub max_size: f64,
    /// Phase of the current pair.
    pub pair: Pair,
    /// The norm of the pairs' errors.
    pub norm: PairNorm,
    /// Path pairs: the relative error of the last rejected pair at this level, if any (a
    /// shorter pair whose error did not fall below [`MIN_REDUCTION`] of it is kept: the
    /// error is not controlled by the size there).
    pub last_rejected: Option<f64>,
}

/// A shorter pair must bring the relative error below this fraction of the rejected one's,
/// or it is kept as it is (load and displacement steps).
const MIN_REDUCTION: f64 = 0.9;

impl Controller {
    /// A step of `increments` increments with `max_cuts` cuts allowed.
    pub fn new(increments: usize, max_cuts: usize, growth: Growth, tolerance: Option<f64>) -> Self {
        let nominal = 1.0 / increments.max(1) as f64;
        Controller {
            level: 0.0,
            size: nominal,
            nominal,
            cuts: 0,
            max_cuts,
            increment: 0,
            prev_size: None,
            retry: false,
            implex_last: None,
            growth,
            tolerance,
            min_pair: nominal / 1024.0,
            max_size: f64::INFINITY,
            pair: Pair::Probe,
            norm: PairNorm::Max,
            last_rejected: None,
        }
    }

    /// True once the step's end is reached.
    pub fn finished(&self) -> bool {
        self.level >= 1.0 - 1e-12
    }

    /// Level the next attempt ends at.
    pub fn target(&self) -> f64 {
        self.pair.target(self.level, self.size)
    }

    /// History extrapolation factor of an attempt ending at `target` (IMPL-EX cracking):
    /// its size over the last converged increment's, 0 at a step's first increment.
    pub fn extrapolation(&self, target: f64) -> f64 {
        self.prev_size.map_or(0.0, |p| (target - self.level) / p)
    }

    /// Throw the attempt away after a failure: false if no cut is left (the step fails),
    /// else the size is halved (a failed half of a pair: a new pair from the level
    /// reached).
    pub fn cut(&mut self) -> bool {
        self.retry = true;
        if self.cuts >= self.max_cuts {
            return false;
        }
        self.cuts += 1;
        self.size *= 0.5;
        self.pair = Pair::Probe;
        true
    }

    /// A converged attempt (ending at [`Controller::target`]) after `iterations`, with
    /// displacements `u` [m] from the committed `committed_u` [m]: what becomes of it, and
    /// the size and level that follow. `implex_over` is asked (once, and only for an
    /// attempt that would otherwise be kept) whether its IMPL-EX error calls for a retry.
    pub fn converged(
        &mut self,
        iterations: usize,
        u: &[f64],
        committed_u: &[f64],
        implex_over: impl FnOnce(&mut Controller) -> bool,
    ) -> Verdict {
        let target = self.target();
        if self.tolerance.is_some() && self.pair.is_probe() {
            // The whole pair as one increment: kept to compare with its halves.
            self.pair = Pair::First(Box::new(PairStart {
                level: self.level,
                end: target,
                probe: u.to_vec(),
                start_u: committed_u.to_vec(),
                saved: None,
                prev_size: self.prev_size,
                mark: 0.0,
                norm: self.norm,
            }));
            return Verdict::Probed;
        }
        if matches!(self.pair, Pair::First(_)) {
            // The first half: committed, reported with the second.
            self.prev_size = Some(target - self.level);
            self.level = target;
            self.pair = std::mem::replace(&mut self.pair, Pair::Probe).second();
            return Verdict::FirstHalf;
        }
        if self
            .pair
            .rejects(u, self.tolerance, self.size > self.min_pair)
            && self.error_falls(u)
        {
            // The halves disagree with the probe beyond the tolerance: back to the start
            // of the pair, with a shorter one.
            let Pair::Second(start) = std::mem::replace(&mut self.pair, Pair::Probe) else {
                unreachable!("rejects() is true only for a second half")
            };
            self.size = (self.size * start.growth(u, self.tolerance)).max(self.min_pair);
            self.level = start.level;
            self.prev_size = start.prev_size;
            if self.norm == PairNorm::Rms {
                self.last_rejected = Some(start.relative_error(u));
            }
            return Verdict::Rejected(start);
        }
        if implex_over(self) {
            // Retried at half the size, as after a failed attempt (not counted against the
            // step's cuts).
            self.retry = true;
            self.size *= 0.5;
            self.pair = Pair::Probe;
            return Verdict::ImplexRetry;
        }
        self.retry = false;
        if self.growth == Growth::WhenEasy && iterations <= EASY_ITERATIONS {
            self.size = (2.0 * self.size).min(self.nominal);
        }
        let mut error = None;
        if let Pair::Second(start) = std::mem::replace(&mut self.pair, Pair::Probe) {
            // An accepted pair: the next one as long as the error allows.
            self.size = (self.size * start.growth(u, self.tolerance))
                .max(self.min_pair)
                .min(self.max_size);
            error = Some(start.relative_error(u));
        }
        self.prev_size = Some(target - self.level);
        self.level = target;
        self.increment += 1;
        self.last_rejected = None;
        Verdict::Accepted { pair_error: error }
    }

    /// Whether a second half ending at `u` has an error that fell enough since the last
    /// rejected pair at this level (always true for time steps and at a first rejection).
    fn error_falls(&self, u: &[f64]) -> bool {
        match (&self.pair, self.last_rejected) {
            (Pair::Second(s), Some(last)) if self.norm == PairNorm::Rms => {
                s.relative_error(u) < MIN_REDUCTION * last
            }
            _ => true,
        }
    }
}

/// What becomes of a converged attempt ([`Controller::converged`]).
#[derive(Debug)]
pub(super) enum Verdict {
    /// The probe of a pair: its state thrown away, the committed state kept.
    Probed,
    /// The first half of a pair: committed, not reported.
    FirstHalf,
    /// The halves missed the probe: back to the pair's start (its state).
    Rejected(Box<PairStart>),
    /// Thrown away for its IMPL-EX error; retried at half the size.
    ImplexRetry,
    /// Kept and reported, with the relative error of the pair it completes (None outside
    /// pairs) [-].
    Accepted {
        /// max|u_probe − u| / max|u − u_a| of the pair [-].
        pair_error: Option<f64>,
    },
}

/// The sizing rules of a step kind, driven by [`run`]: where the step ends, how a failed
/// attempt is cut, and what becomes of a converged one (pairs of increments with their error
/// control, the IMPL-EX retry, growth). [`Controller`] sizes load, displacement and time
/// steps by a fraction of the step; [`ArcSizing`] sizes arc-length steps by an arc length.
pub(super) trait Sizing {
    /// True once the step's end is reached.
    fn finished(&self) -> bool;

    /// Whether a failed attempt may still be cut (otherwise the step fails).
    fn can_cut(&self) -> bool;

    /// Throw a failed attempt away: false if no cut is left, else the next attempt's size.
    fn cut(&mut self) -> bool;

    /// The attempt is solved again from its start at the same size (a one-way support
    /// switched in it).
    fn again(&mut self);

    /// A converged attempt after `iterations`, with displacements `u` [m] from the
    /// committed `committed_u` [m]: what becomes of it. `implex_over` is asked (once, and
    /// only for an attempt that would otherwise be kept) whether its IMPL-EX error calls
    /// for a retry at half the size.
    fn converged(
        &mut self,
        iterations: usize,
        u: &[f64],
        committed_u: &[f64],
        implex_over: impl FnOnce(&mut Self) -> bool,
    ) -> Verdict;

    /// The IMPL-EX control's sizes of the current attempt: (its size, the smallest size's
    /// reference), in the sizing's own unit.
    fn implex_sizes(&self) -> (f64, f64);

    /// The IMPL-EX error of the last attempt of this increment, if it was retried for it.
    fn implex_last(&mut self) -> &mut Option<f64>;

    /// The phase of the current pair of increments.
    fn pair_mut(&mut self) -> &mut Pair;

    /// Step-doubling tolerance (None: single increments).
    fn tolerance(&self) -> Option<f64>;
}

impl Sizing for Controller {
    fn finished(&self) -> bool {
        Controller::finished(self)
    }

    fn can_cut(&self) -> bool {
        self.cuts < self.max_cuts
    }

    fn cut(&mut self) -> bool {
        Controller::cut(self)
    }

    fn again(&mut self) {
        self.retry = true;
    }

    fn converged(
        &mut self,
        iterations: usize,
        u: &[f64],
        committed_u: &[f64],
        implex_over: impl FnOnce(&mut Self) -> bool,
    ) -> Verdict {
        Controller::converged(self, iterations, u, committed_u, implex_over)
    }

    fn implex_sizes(&self) -> (f64, f64) {
        (self.target() - self.level, self.nominal)
    }

    fn implex_last(&mut self) -> &mut Option<f64> {
        &mut self.implex_last
    }

    fn pair_mut(&mut self) -> &mut Pair {
        &mut self.pair
    }

    fn tolerance(&self) -> Option<f64> {
        self.tolerance
    }
}

/// What a step kind supplies to [`run`]: how an attempt is solved and what a converged
/// increment does. The sizing `S` is the step kind's ([`Controller`] or [`ArcSizing`]).
pub(super) trait Stepper<S> {
    /// Solve the next increment (its size from `ctl`), starting from the trial displacements
    /// (`ctx.sys.disp.trial`, left at the attempt's end). Returns the internal forces [N] and
    /// the Newton iterations.
    fn attempt(
        &mut self,
        ctx: &mut PathContext,
        obs: &mut dyn Observer,
        ctl: &mut S,
    ) -> Result<(Vec<f64>, usize), NewtonFailure>;

    /// The external forces of the last attempt (all dofs) [N].
    fn external(&self) -> &[f64];

    /// Whether the IMPL-EX error control applies to this step's increments.
    fn implex_controlled(&self) -> bool {
        true
    }

    /// Throw the trial state of an attempt away (back to the committed state).
    fn discard(&mut self, ctx: &mut PathContext);

    /// Keep the step kind's own record of the state committed now (restored with a
    /// rejected pair, [`Stepper::restore_mark`]); returns what the pair keeps of it.
    fn mark(&mut self) -> f64 {
        0.0
    }

    /// Restore the record [`Stepper::mark`] gave at a rejected pair's start.
    fn restore_mark(&mut self, _ctx: &mut PathContext, _mark: f64) {}

    /// Commit the first half of a pair (not reported: it is reported with the second).
    fn commit_half(&mut self, ctx: &mut PathContext);

    /// Commit and report a kept increment (`ctl` already past it) with internal forces
    /// `f_int` [N] after `iterations`. Returns true if the step ends with it (a step whose
    /// end is found on the way, as an arc-length step's).
    fn accept(
        &mut self,
        ctx: &mut PathContext,
        obs: &mut dyn Observer,
        ctl: &mut S,
        f_int: Vec<f64>,
        iterations: usize,
    ) -> Result<bool, AnalysisError>;

    /// The attempt failed with `failure`: throw its trial state away and, when `give_up`
    /// (no cut left), return the step's error. A step kind may also return an error
    /// without `give_up` (a singular linear system is a mechanism, not a cut).
    fn failed(
        &mut self,
        ctx: &mut PathContext,
        ctl: &S,
        failure: NewtonFailure,
        give_up: bool,
    ) -> Option<AnalysisError>;
}

/// Run a step: attempts sized by `ctl` until it is finished or the stepper ends the step,
/// each solved by `stepper`; failed attempts cut, one-way support switches solved again,
/// pairs probed, kept or rejected, IMPL-EX errors retried.
pub(super) fn run<S: Sizing>(
    ctl: &mut S,
    stepper: &mut dyn Stepper<S>,
    ctx: &mut PathContext,
    obs: &mut dyn Observer,
) -> Result<(), AnalysisError> {
    // Rounds of one-way support switches in the current increment.
    let mut rounds = 0;
    while !ctl.finished() {
        let (f_int, iterations) = match stepper.attempt(ctx, obs, ctl) {
            Ok(solved) => solved,
            Err(failure) => {
                rounds = 0;
                let give_up = !ctl.can_cut();
                if let Some(e) = stepper.failed(ctx, ctl, failure, give_up) {
                    return Err(e);
                }
                ctl.cut();
                continue;
            }
        };
        // A one-way support lifted off or touched down: the same increment again, from
        // its start, with the new statuses.
        if let Some(trial) = ctx.one_way_check(&f_int, stepper.external(), &mut rounds) {
            ctx.timings.iterations += iterations;
            stepper.discard(ctx);
            ctx.one_way_resume(&trial);
            ctl.again();
            continue;
        }
        // The IMPL-EX path error is measured at every increment that would be kept (the
        // report's "how sure"), and decides a retry where a tolerance is set.
        let measure = stepper.implex_controlled() && ctx.sys.has_implex();
        let mut measured = None;
        let disp = &ctx.sys.disp;
        let verdict = ctl.converged(iterations, &disp.trial, &disp.committed, |c| {
            measure && {
                let e = implex_energy_error(&*ctx.sys, &mut *ctx.solver, &disp.trial, &f_int);
                measured = Some(e);
                let sizes = c.implex_sizes();
                implex_retry(&*ctx.sys, e, ctx.timings, sizes, c.implex_last())
            }
        });
        ctx.implex_error = measured;
        match verdict {
            Verdict::Probed => {
                // Throw the probe's state away; keep the committed state in case the
                // halves are rejected.
                ctx.timings.iterations += iterations;
                stepper.discard(ctx);
                let mark = stepper.mark();
                if let Pair::First(start) = ctl.pair_mut() {
                    start.saved = Some(ctx.sys.snapshot());
                    start.mark = mark;
                }
            }
            Verdict::FirstHalf => {
                ctx.timings.iterations += iterations;
                stepper.commit_half(ctx);
            }
            Verdict::Rejected(start) => {
                ctx.timings.iterations += iterations;
                ctx.timings.increments_rejected += 1;
                stepper.restore_mark(ctx, start.mark);
                let saved = start.saved.expect("saved after the probe");
                ctx.sys.restore(saved).map_err(AnalysisError::Mechanism)?;
                stepper.discard(ctx);
            }
            Verdict::ImplexRetry => {
                ctx.timings.iterations += iterations;
                stepper.discard(ctx);
            }
            Verdict::Accepted { pair_error } => {
                if let Some(e) = pair_error {
                    ctx.timings.increment_max_error = ctx.timings.increment_max_error.max(e);
                    if ctl.tolerance().is_some_and(|tol| e > tol) {
                        ctx.timings.increments_over_tolerance += 1;
                    }
                }
                if stepper.accept(ctx, obs, ctl, f_int, iterations)? {
                    break;
                }
            }
        }
    }
    Ok(())
}

/// Sizing of an arc-length step: its arc length Δl, set by the first increment, cut after
/// failures to ½, 2, ¼, 4, … of the failed length, halved for the IMPL-EX error, and grown
/// by the iterations an increment took. With a step-doubling tolerance
/// (`[solver] increment_tolerance`) Δl is the length of a pair of arcs: solved once whole
/// (the probe) and then as two arcs of Δl/2, kept if the rms difference of the
/// displacements is within the tolerance of the rms change over the pair
/// ([`ArcSizing::converged`]), and sized by that error as well as by the iterations. The
/// step ends after `max_increments` kept increments, or earlier where its stepper finds
/// its end (a target load factor or displacement reached).
#[derive(Debug, Default)]
pub(super) struct ArcSizing {
    /// Arc length of the next increment (None before the first sets it).
    pub dl: Option<f64>,
    /// The first increment's arc length (0 before it).
    pub dl0: f64,
    /// Cuts since the last converged increment.
    pub cuts: usize,
    /// Cuts allowed before the step fails.
    max_cuts: usize,
    /// The arc length that failed first (the cuts' reference).
    failed_dl: Option<f64>,
    /// Arc length of the last converged increment.
    pub prev_dl: Option<f64>,
    /// The arc length the current attempt was made with.
    tried: Option<f64>,
    /// IMPL-EX error of the last attempt of this increment, if it was cut for it.
    pub implex_last: Option<f64>,
    /// Step-doubling tolerance (None: single arcs).
    pub tolerance: Option<f64>,
    /// Phase of the current pair of arcs (with a tolerance).
    pub pair: Pair,
    /// Relative error of the last rejected pair at this point, if any (a shorter pair whose
    /// error did not fall below [`MIN_REDUCTION`] of it is kept, as in [`Controller`]).
    last_rejected: Option<f64>,
    /// Growth factor the last kept pair's error allows (applied with the iterations' one).
    pair_growth: Option<f64>,
    /// Kept (reported) increments of this step.
    pub increment: usize,
    /// Kept increments after which the step ends.
    max_increments: usize,
}

impl ArcSizing {
    /// Arc-length sizing of a step of at most `max_increments` increments with `max_cuts`
    /// cuts allowed and the step-doubling tolerance `tolerance` (None: single arcs).
    pub fn new(max_increments: usize, max_cuts: usize, tolerance: Option<f64>) -> Self {
        ArcSizing {
            tolerance,
            max_cuts,
            max_increments,
            ..ArcSizing::default()
        }
    }

    /// Arc length of the next attempt (None before the first sets it): the pair's length
    /// for its probe, half of it for its halves.
    pub fn attempt_length(&self) -> Option<f64> {
        match self.pair {
            Pair::Probe => self.dl,
            _ => self.dl.map(|l| 0.5 * l),
        }
    }

    /// The attempt was made with the arc length `tried` (converged or not): it sets the
    /// pair's (or single arc's) length if none is set yet.
    pub fn attempted(&mut self, tried: Option<f64>) {
        self.tried = tried;
        if self.dl.is_none() {
            self.dl = tried;
        }
    }

    /// History extrapolation factor (IMPL-EX cracking): ratio of the arc lengths.
    pub fn extrapolation(&self) -> f64 {
        match (self.prev_dl, self.attempt_length()) {
            (Some(p), Some(l)) if p > 0.0 => l / p,
            _ => 0.0,
        }
    }

    /// A converged attempt is kept; `tried` is the arc length it was attempted with.
    fn accept(&mut self, tried: Option<f64>) {
        self.prev_dl = tried.or(self.dl);
        if self.dl0 == 0.0 {
            self.dl0 = self.dl.expect("set by the first increment");
        }
        self.cuts = 0;
    }

    /// A kept increment (a single arc, or the second half of a pair) that `implex_over`
    /// does not send back: accepted with the pair's relative error `pair_error`; else the
    /// arc is halved (not counted against the cuts) and a pair starts again from the point
    /// reached (its first half stays committed).
    fn implex_or_accept(
        &mut self,
        implex_over: impl FnOnce(&mut Self) -> bool,
        pair_error: Option<f64>,
    ) -> Verdict {
        if implex_over(self) {
            if self.dl0 == 0.0 {
                self.dl0 = self.dl.expect("set by the first increment");
            }
            self.dl = self.dl.map(|l| 0.5 * l);
            self.pair = Pair::Probe;
            return Verdict::ImplexRetry;
        }
        self.accept(self.tried);
        self.increment += 1;
        Verdict::Accepted { pair_error }
    }

    /// Step-size adaptation after a kept increment of `iterations`:
    /// Δl ← Δl √(desired/N), bounded to [½, 2] per increment and to `max_growth` × the
    /// first arc length; after a kept pair, by the smaller of that and the factor its error
    /// allows ([`PairStart::growth`]).
    pub fn grow(&mut self, desired: usize, iterations: usize, max_growth: f64) {
        let ratio = (desired as f64 / iterations.max(1) as f64)
            .sqrt()
            .clamp(0.5, 2.0);
        let ratio = self.pair_growth.take().map_or(ratio, |g| ratio.min(g));
        let dl0 = self.dl0;
        self.dl = self.dl.map(|l| (l * ratio).min(max_growth * dl0));
    }
}

impl Sizing for ArcSizing {
    fn finished(&self) -> bool {
        self.increment >= self.max_increments
    }

    fn can_cut(&self) -> bool {
        self.cuts < self.max_cuts && self.dl.is_some()
    }

    /// After a failed attempt: false if the step fails (no cut left, or no arc length yet),
    /// else the next arc length. A material jump (a crack forming, the stress dropping at
    /// fixed strain) leaves a gap in the path that a shorter arc cannot cross when the last
    /// point sits just before it; a longer one steps over it: ½, 2, ¼, 4, … of the failed
    /// length.
    fn cut(&mut self) -> bool {
        if !self.can_cut() {
            return false;
        }
        // A failed arc of a pair: a new pair from the point reached.
        self.pair = Pair::Probe;
        if self.cuts == 0 {
            self.failed_dl = self.dl;
        }
        self.cuts += 1;
        let k = self.cuts.div_ceil(2) as i32;
        let factor = if self.cuts % 2 == 1 {
            0.5_f64.powi(k)
        } else {
            2.0_f64.powi(k)
        };
        self.dl = self.failed_dl.map(|l| factor * l);
        true
    }

    fn again(&mut self) {}

    /// A converged arc:
    /// - without a tolerance: kept, unless its IMPL-EX error sends it back;
    /// - the probe of a pair: kept to compare with the halves ([`Verdict::Probed`], [`run`]
    ///   throws its state away and sets [`PairStart::saved`]);
    /// - the first half: committed, not reported ([`Verdict::FirstHalf`]);
    /// - the second half: kept if rms|u_probe − u| ≤ tol · rms|u − u_a| (step doubling, as
    ///   [`Controller::converged`]), or if the pair is already the shortest (1/1024 of the
    ///   first) or its error did not fall below [`MIN_REDUCTION`] of the last rejected
    ///   one's; else rejected with the pair length × 0.9 (tol · change/err)^½ (at least ¼).
    ///   A kept second half is still sent back for its IMPL-EX error.
    fn converged(
        &mut self,
        _iterations: usize,
        u: &[f64],
        committed_u: &[f64],
        implex_over: impl FnOnce(&mut Self) -> bool,
    ) -> Verdict {
        let Some(tol) = self.tolerance else {
            return self.implex_or_accept(implex_over, None);
        };
        match std::mem::take(&mut self.pair) {
            Pair::Probe => {
                self.pair = Pair::First(Box::new(PairStart {
                    // Levels are a load or displacement step's; an arc's pair keeps its
                    // start through the stepper's mark.
                    level: 0.0,
                    end: 0.0,
                    probe: u.to_vec(),
                    start_u: committed_u.to_vec(),
                    saved: None,
                    prev_size: self.prev_dl,
                    mark: 0.0,
                    norm: PairNorm::Rms,
                }));
                Verdict::Probed
            }
            Pair::First(s) => {
                self.accept(self.dl.map(|l| 0.5 * l));
                self.pair = Pair::Second(s);
                Verdict::FirstHalf
            }
            Pair::Second(s) => {
                let min_dl = self.dl0 / 1024.0;
                let may_shorten = self.dl.is_some_and(|l| l > min_dl);
                let error = s.relative_error(u);
                let growth = s.growth(u, Some(tol));
                let falls = self
                    .last_rejected
                    .is_none_or(|last| error < MIN_REDUCTION * last);
                if may_shorten && falls && error > tol {
                    self.dl = self.dl.map(|l| (l * growth).max(min_dl));
                    self.prev_dl = s.prev_size;
                    self.last_rejected = Some(error);
                    self.pair_growth = None;
                    return Verdict::Rejected(s);
                }
                // Put back for the IMPL-EX check, which starts a new pair if it sends the
                // half back.
                self.pair = Pair::Second(s);
                let verdict = self.implex_or_accept(implex_over, Some(error));
                if matches!(verdict, Verdict::ImplexRetry) {
                    return verdict;
                }
                self.pair = Pair::Probe;
                if error <= tol {
                    self.last_rejected = None;
                    self.pair_growth = Some(growth);
                } else {
                    // Kept above the tolerance (the shortest pair, or an error that a
                    // shorter pair did not lower: a joint or a crack jumping open inside
                    // it). Its size does not control that error: the next pair keeps the
                    // size, and the rejected error stays the reference, so that a run of
                    // such pairs is not shortened by ¼ at each (measured: the 2× seed beam
                    // at 8× finer arcs crawled to its increment limit, 3,707 increments).
                    self.pair_growth = Some(growth.max(1.0));
                }
                verdict
            }
        }
    }

    fn implex_sizes(&self) -> (f64, f64) {
        let dl = self.dl.unwrap_or(0.0);
        (dl, if self.dl0 == 0.0 { dl } else { self.dl0 })
    }

    fn implex_last(&mut self) -> &mut Option<f64> {
        &mut self.implex_last
    }

    fn pair_mut(&mut self) -> &mut Pair {
        &mut self.pair
    }

    fn tolerance(&self) -> Option<f64> {
        self.tolerance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a scripted attempt gives: displacements and iterations, or a failure.
    type Scripted = Option<(Vec<f64>, usize)>;

    /// Drive `ctl` over a step from the displacement `u0` as [`run`] does, with `attempt(level, target, u_committed)`
    /// in place of a Newton solve and no IMPL-EX control. Returns the committed
    /// displacements at the end (None: the step failed), the kept increments' sizes and
    /// the rejected pairs.
    fn drive(
        ctl: &mut Controller,
        u0: f64,
        mut attempt: impl FnMut(f64, f64, &[f64]) -> Scripted,
    ) -> (Option<Vec<f64>>, Vec<f64>, usize) {
        let mut committed = vec![u0];
        let mut saved: Vec<Vec<f64>> = Vec::new();
        let (mut sizes, mut rejected) = (Vec::new(), 0);
        while !ctl.finished() {
            let (level, target) = (ctl.level, ctl.target());
            let Some((u, iterations)) = attempt(level, target, &committed) else {
                if ctl.cuts >= ctl.max_cuts {
                    return (None, sizes, rejected);
                }
                ctl.cut();
                continue;
            };
            match ctl.converged(iterations, &u, &committed, |_| false) {
                Verdict::Probed => saved.push(committed.clone()),
                Verdict::FirstHalf => {
                    sizes.push(target - level);
                    committed = u;
                }
                Verdict::Rejected(_) => {
                    rejected += 1;
                    sizes.pop(); // the first half, undone
                    committed = saved.pop().expect("saved at the probe");
                }
                Verdict::ImplexRetry => unreachable!("no IMPL-EX control here"),
                Verdict::Accepted { .. } => {
                    sizes.push(target - level);
                    committed = u;
                }
            }
        }
        (Some(committed), sizes, rejected)
    }

    #[test]
    fn a_failed_attempt_is_cut_and_the_increments_grow_back_when_easy() {
        // 4 increments of 0.25; any attempt longer than 0.1 fails. Cuts: 0.25 → 0.125 →
        // 0.0625 (2 cuts), then easy increments double back, but only up to the nominal
        // 0.25, and each failure halves again.
        let mut ctl = Controller::new(4, 20, Growth::WhenEasy, None);
        let (u, sizes, _) = drive(&mut ctl, 0.0, |l, t, _| {
            (t - l <= 0.1).then(|| (vec![t], 2))
        });
        assert_eq!(u, Some(vec![1.0]));
        assert!(sizes.iter().all(|&h| h <= 0.1), "{sizes:?}");
        assert_eq!(sizes[0], 0.0625, "two halvings of 0.25");
        // 0.0625 → doubled to 0.125 fails → 0.0625 again: every kept size is 1/16 and the
        // step takes 16 increments, a failure before each but the last.
        assert_eq!(sizes.len(), 16);
        // The last attempt, from 15/16, is cut short by the step end: no failure.
        assert_eq!(ctl.cuts, 2 + 14);
    }

    #[test]
    fn a_step_fails_after_max_cuts() {
        // Attempts longer than 1/64 fail; 4 increments of 0.25 need 4 halvings, 3 allowed.
        let mut ctl = Controller::new(4, 3, Growth::Kept, None);
        let (u, sizes, _) = drive(&mut ctl, 0.0, |l, t, _| {
            (t - l <= 1.0 / 64.0).then(|| (vec![t], 1))
        });
        assert_eq!(u, None);
        assert!(sizes.is_empty());
        assert_eq!(ctl.cuts, 3);
    }

    #[test]
    fn step_doubling_meets_the_tolerance_on_explicit_euler() {
        // du/dλ = 2u, u(0) = 1 by forward Euler: one increment h multiplies u by 1 + 2h.
        // The exact end is e² = 7.389; 4 plain increments give 1.5⁴ = 5.06 (31 % low).
        // Whole against halves differ by 2h²u, the change over the pair is ~2hu: the
        // relative pair error is ~h, so a tolerance of 1e-3 brings h to ~1e-3 and Euler's
        // global relative error (~h over the path, λ·h·2²/2 / 2 ≈ h) to ~0.1–0.4 %: the end
        // must come within 1 % of e², with some pairs rejected on the way.
        let euler = |l: f64, t: f64, u0: &[f64]| Some((vec![u0[0] * (1.0 + 2.0 * (t - l))], 3));
        let mut fixed = Controller::new(4, 6, Growth::Kept, None);
        let (u_fixed, _, _) = drive(&mut fixed, 1.0, euler);
        let u_fixed = u_fixed.unwrap()[0];
        assert!((u_fixed - 1.5_f64.powi(4)).abs() < 1e-12, "{u_fixed}");

        let mut ctl = Controller::new(4, 6, Growth::Kept, Some(1e-3));
        let (u, sizes, rejected) = drive(&mut ctl, 1.0, euler);
        let u = u.unwrap()[0];
        let exact = 2.0_f64.exp();
        assert!((u - exact).abs() < 0.01 * exact, "u(1) = {u}, e² = {exact}");
        assert!(
            rejected > 0,
            "the first pair (0.25) misses by ~10 %: rejected"
        );
        // Kept increments come in pairs of equal halves.
        assert_eq!(sizes.len() % 2, 0);
        for p in sizes.chunks(2) {
            assert!((p[0] - p[1]).abs() < 1e-12, "{sizes:?}");
        }
    }

    #[test]
    fn a_pair_on_a_linear_path_is_kept_and_grows() {
        // u = λ: the whole and the halves agree exactly, so every pair is kept and the
        // next is twice as long (the largest growth), from 0.25: 0.25, then 0.5 capped
        // at the step's end.
        let mut ctl = Controller::new(4, 6, Growth::Kept, Some(1e-3));
        let (u, sizes, rejected) = drive(&mut ctl, 0.0, |_, t, _| Some((vec![t], 1)));
        assert_eq!(u, Some(vec![1.0]));
        assert_eq!(rejected, 0);
        assert_eq!(sizes, vec![0.125, 0.125, 0.25, 0.25, 0.125, 0.125]);
    }

    #[test]
    fn a_pair_whose_error_does_not_fall_with_its_size_is_kept_on_a_path() {
        // du/dλ = 1 below u = 0.3, 20 above (a crack opening: a jump of the slope). A pair
        // that crosses 0.3 has a relative error of about (20 − 1)/(20 + 1) ≈ 0.9 whatever
        // its length (forward Euler: the probe keeps the slope 1 over the whole pair).
        // With the path rule a shorter pair that does not lower the error below 0.9 of the
        // rejected one's is kept: a few rejections only. The time-step rule (max norm, no
        // such check) halves on to the shortest pair, 1/1024 of the nominal size.
        let jump = |l: f64, t: f64, u0: &[f64]| {
            let slope = if u0[0] < 0.3 { 1.0 } else { 20.0 };
            Some((vec![u0[0] + slope * (t - l)], 3))
        };
        let mut path = Controller::new(4, 6, Growth::Kept, Some(0.05));
        path.norm = PairNorm::Rms;
        path.max_size = path.nominal;
        let (u, _, rejected) = drive(&mut path, 0.0, jump);
        assert!(u.is_some());
        assert!(rejected <= 4, "{rejected} rejected pairs");

        let mut time = Controller::new(4, 6, Growth::Kept, Some(0.05));
        let (_, sizes, rejected_time) = drive(&mut time, 0.0, jump);
        let shortest = sizes.iter().cloned().fold(f64::MAX, f64::min);
        assert!(rejected_time > rejected, "{rejected_time} vs {rejected}");
        assert!(shortest < 0.25 / 100.0, "shortest increment {shortest}");
    }

    /// Drive an [`ArcSizing`] with a tolerance along a scripted path from `u0` as the
    /// arc-length step does: `attempt(u_committed, arc)` gives the displacements an arc of
    /// length `arc` [m] reaches (the first pair is `first` long). Returns the committed
    /// displacements after `reports` reported increments, the lengths of the kept arcs, the
    /// kept pairs' errors and the rejected pairs.
    fn drive_arcs(
        sizing: &mut ArcSizing,
        u0: Vec<f64>,
        first: f64,
        reports: usize,
        attempt: impl Fn(&[f64], f64) -> Vec<f64>,
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>, usize) {
        let mut committed = u0;
        let mut saved = committed.clone();
        let (mut kept, mut errors, mut rejected, mut reported) = (Vec::new(), Vec::new(), 0, 0);
        while reported < reports {
            let arc = sizing.attempt_length().unwrap_or(first);
            sizing.attempted(Some(arc));
            let u = attempt(&committed, arc);
            match Sizing::converged(sizing, 1, &u, &committed, |_| false) {
                Verdict::Probed => saved = committed.clone(),
                Verdict::FirstHalf => {
                    kept.push(arc);
                    committed = u;
                }
                Verdict::Rejected(_) => {
                    rejected += 1;
                    kept.pop();
                    committed = saved.clone();
                }
                Verdict::ImplexRetry => unreachable!("no IMPL-EX control here"),
                Verdict::Accepted { pair_error } => {
                    // One iteration where four are desired: the iterations allow ×2.
                    sizing.grow(4, 1, 1e9);
                    kept.push(arc);
                    errors.push(pair_error.expect("a pair"));
                    committed = u;
                    reported += 1;
                }
            }
        }
        (committed, kept, errors, rejected)
    }

    #[test]
    fn arc_pairs_on_a_straight_path_are_kept_and_grow() {
        // u moves along a straight line: whole and halves end at the same point, the pair
        // error is 0, every pair is kept and the next is twice as long (the iterations
        // allow ×2 too): pairs of 1, 2, 4 → arcs 0.5, 0.5, 1, 1, 2, 2.
        let mut sizing = ArcSizing::new(usize::MAX, 8, Some(0.05));
        let line = |u: &[f64], l: f64| vec![u[0] + 0.6 * l, u[1] + 0.8 * l];
        let (u, kept, errors, rejected) = drive_arcs(&mut sizing, vec![0.0, 0.0], 1.0, 3, line);
        assert_eq!(rejected, 0);
        assert_eq!(kept, vec![0.5, 0.5, 1.0, 1.0, 2.0, 2.0]);
        assert!(errors.iter().all(|&e| e < 1e-12), "{errors:?}");
        // 7 of arc length along the unit direction (0.6, 0.8).
        assert!(
            (u[0] - 4.2).abs() < 1e-12 && (u[1] - 5.6).abs() < 1e-12,
            "{u:?}"
        );
    }

    #[test]
    fn an_arc_pair_off_the_path_is_rejected_and_shortened_to_meet_the_tolerance() {
        // The path is the unit circle, followed by forward Euler: an arc of length l from u
        // goes along the tangent (−u₁, u₀)/|u|. From (1, 0) the probe ends at (1, l), the
        // halves at ≈ (1 − l²/4, l): the pair's relative rms error is ≈ (l²/4)/l = l/4,
        // 0.25 for the first pair of 1. With tol = 0.02 pairs are rejected down to
        // l ≈ 4 tol = 0.08 and every kept pair's error is within the tolerance (the
        // shortest pair, 1/1024 of the first, is not reached).
        let tol = 0.02;
        let mut sizing = ArcSizing::new(usize::MAX, 8, Some(tol));
        let euler = |u: &[f64], l: f64| {
            let r = (u[0] * u[0] + u[1] * u[1]).sqrt();
            vec![u[0] - l * u[1] / r, u[1] + l * u[0] / r]
        };
        let (_, kept, errors, rejected) = drive_arcs(&mut sizing, vec![1.0, 0.0], 1.0, 6, euler);
        assert!(rejected >= 2, "the first pair misses by ~25 %: {rejected}");
        assert!(errors.iter().all(|&e| e <= tol), "{errors:?}");
        // Pairs near 4 tol = 0.08 (between ¼ and 1 of it: the growth factor 0.9 (tol/e)^½
        // keeps them below the size where e = tol): arcs of half that.
        assert!(kept.iter().all(|&k| (0.01..=0.04).contains(&k)), "{kept:?}");
    }
}
