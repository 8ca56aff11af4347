//! Time steps: the interval and log-spaced substeps of a `kind = "time"` step.

use super::fields::positive;
use super::R;
use crate::input::error::Ctx;
use crate::input::schema::StepIn;
use crate::model::{TimeSpan, DEFAULT_START_DAY};

/// Default number of substeps per decade of a time step's duration. The exponential
/// algorithm with 1 substep per decade under-estimates creep at 1e4 d by ≈ 4 %, 2 by 1.6 %,
/// 5 by < 0.1 % of the converged value (docs/theory-time.md, step-size table).
pub const SUBSTEPS_PER_DECADE: f64 = 5.0;

/// Default first substep of a time step [d].
pub const DEFAULT_FIRST_SUBSTEP: f64 = 0.1;

/// Smallest `substep_tolerance` accepted: below it the error estimate is at the level of
/// the Newton tolerance and the substeps would shrink without end.
const MIN_TOLERANCE: f64 = 1e-5;

/// Largest `substep_tolerance` accepted (an error of half the change is no control).
const MAX_TOLERANCE: f64 = 0.5;

/// Latest analysis day accepted [d].
const MAX_DAY: f64 = 1e6;

/// A step-doubling tolerance (`substep_tolerance`, `[solver] increment_tolerance`) at
/// `key`, checked to lie between [`MIN_TOLERANCE`] and [`MAX_TOLERANCE`].
pub(super) fn error_tolerance(ctx: &Ctx, key: &str, v: f64) -> R<f64> {
    if (MIN_TOLERANCE..=MAX_TOLERANCE).contains(&v) {
        return Ok(v);
    }
    Err(ctx.err(
        key,
        format!(
            "must be a fraction between {MIN_TOLERANCE:e} and {MAX_TOLERANCE} (got {v}): \
             the error allowed per pair of increments relative to its displacement change"
        ),
    ))
}

/// The interval and substeps of a time step; `clock` = end of the previous time step.
pub(super) fn time_span(ctx: &Ctx, key: &str, s: &StepIn, clock: Option<f64>) -> R<TimeSpan> {
    if !s.loads.is_empty() {
        return Err(ctx.err(
            format!("{key}.loads"),
            "a time step holds the loads at their previous factors; change loads in a load step",
        ));
    }
    if s.increments.is_some() {
        return Err(ctx.err(
            format!("{key}.increments"),
            "a time step takes substeps (log-spaced), not increments",
        ));
    }
    let from = match (s.from, clock) {
        (Some(f), None) => {
            if !f.is_finite() {
                return Err(ctx.err(format!("{key}.from"), "must be a finite number of days"));
            }
            f
        }
        (Some(f), Some(c)) => {
            if (f - c).abs() > 1e-9 * c.abs().max(1.0) {
                return Err(ctx.err(
                    format!("{key}.from"),
                    format!("time steps follow each other: from must be {c} d (the end of the previous time step) or be left out"),
                ));
            }
            c
        }
        (None, Some(c)) => c,
        (None, None) => DEFAULT_START_DAY,
    };
    let to = match (s.to, s.duration) {
        (Some(t), None) => t,
        (None, Some(d)) => from + positive(ctx, &format!("{key}.duration"), d)?,
        _ => {
            return Err(ctx.err(
                format!("{key}.to"),
                "a time step needs exactly one of to (end day) or duration [d]",
            ))
        }
    };
    if !(to.is_finite() && to > from) {
        return Err(ctx.err(
            format!("{key}.to"),
            format!("must be later than from = {from} d (got {to})"),
        ));
    }
    // MC90 creep and shrinkage are at their final values within 1e5 d; a later day is a
    // typing or unit slip (seconds for days), and the power laws lose precision there.
    if to > MAX_DAY {
        return Err(ctx.err(
            format!("{key}.to"),
            format!("{to:e} d is beyond {MAX_DAY:e} d (2700 years; creep and shrinkage end long before): times are in days"),
        ));
    }
    let d = to - from;
    let first = match s.first_substep {
        Some(v) => {
            let v = positive(ctx, &format!("{key}.first_substep"), v)?;
            if v > d {
                return Err(ctx.err(
                    format!("{key}.first_substep"),
                    format!("{v} d is longer than the step ({d} d)"),
                ));
            }
            v
        }
        None => DEFAULT_FIRST_SUBSTEP.min(d),
    };
    let substeps = match s.substeps {
        Some(0) => return Err(ctx.err(format!("{key}.substeps"), "must be at least 1")),
        Some(n) => n,
        None => (SUBSTEPS_PER_DECADE * (d / first).log10()).ceil().max(0.0) as usize + 1,
    };
    let tolerance = match s.substep_tolerance {
        None => None,
        Some(v) => Some(error_tolerance(
            ctx,
            &format!("{key}.substep_tolerance"),
            v,
        )?),
    };
    Ok(TimeSpan {
        from,
        to,
        first,
        substeps,
        tolerance,
    })
}
