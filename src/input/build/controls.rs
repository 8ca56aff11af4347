//! `[analysis]` (geometry) and `[solver]` (tolerances and limits of the Newton iterations).

use super::R;
use crate::elements::continuum::Integration;
use crate::input::error::Ctx;
use crate::input::limits;
use crate::input::schema::{AnalysisIn, SolverIn};
use crate::model::{Geometry, ImplexForceNorm, Model, Predictor};

/// `[analysis] geometry`: linear (default) or nonlinear (total Lagrangian).
pub(super) fn geometry(ctx: &Ctx, analysis: Option<&AnalysisIn>, model: &mut Model) -> R<()> {
    if let Some(a) = analysis {
        model.geometry = match a.geometry.as_deref() {
            None | Some("linear") => Geometry::Linear,
            Some("nonlinear") => Geometry::Nonlinear,
            Some(o) => {
                return Err(ctx.err(
                    "analysis.geometry",
                    format!("unknown geometry '{o}' (expected linear or nonlinear)"),
                ))
            }
        };
        if model.geometry == Geometry::Nonlinear
            && model
                .elements
                .iter()
                .any(|e| e.integration == Integration::Incompatible)
        {
            return Err(ctx.err(
                "analysis.geometry",
                "'nonlinear' is not available with incompatible-mode Q4 elements (mesh integration = \"incompatible\"): use Q8 or Q9",
            ));
        }
    }
    Ok(())
}

/// Range of `solver.force_tolerance` [-]: a relative residual of 1e-14 is at round-off of
/// the sums (double precision over thousands of terms); 0.1 leaves a tenth of the forces
/// unbalanced.
const FORCE_TOLERANCE: (f64, f64) = (1e-14, 0.1);
/// Range of `solver.energy_tolerance` [-]: a ratio of energies, quadratic in the
/// correction (1e-2: the last correction a tenth of the first).
const ENERGY_TOLERANCE: (f64, f64) = (1e-30, 1e-2);
/// Range of `solver.implex_tolerance` [-], a fraction of f_tm: an error above f_tm is no
/// control.
const IMPLEX_TOLERANCE: (f64, f64) = (1e-6, 1.0);
/// Range of `solver.implex_force_tolerance` [-], a fraction of the Newton test's force
/// scale: below 1e-8 round-off in the crack laws alone exceeds it; above 0.5 the crack
/// stresses' out-of-balance force would be of the order of the structure's forces.
const IMPLEX_FORCE_TOLERANCE: (f64, f64) = (1e-8, 0.5);

/// `v` if it lies in `range` (inclusive), else an error naming the range and `what` the
/// tolerance bounds.
fn in_range(ctx: &Ctx, key: &str, v: f64, range: (f64, f64), what: &str) -> R<f64> {
    if v >= range.0 && v <= range.1 {
        Ok(v)
    } else {
        Err(ctx.err(
            key,
            format!(
                "must lie between {:e} and {:e} (got {}): the bound {what}; outside it every increment converges at once or none can",
                range.0,
                range.1,
                if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
                    v.to_string()
                } else {
                    format!("{v:e}")
                }
            ),
        ))
    }
}

/// `[solver]`: override the default convergence tolerances and limits.
pub(super) fn solver(ctx: &Ctx, solver: Option<&SolverIn>, model: &mut Model) -> R<()> {
    if let Some(sv) = solver {
        let c = &mut model.controls;
        // Tolerances outside these ranges cannot be meant: above them every increment
        // "converges" with residuals of the order of the forces (a verdict that means
        // nothing); below them the residual is under round-off and no increment converges.
        if let Some(v) = sv.force_tolerance {
            c.force_tolerance = in_range(
                ctx,
                "solver.force_tolerance",
                v,
                FORCE_TOLERANCE,
                "of the residual relative to the forces",
            )?;
        }
        if let Some(v) = sv.absolute_force_tolerance {
            if !(v.is_finite() && v > 0.0) {
                return Err(ctx.err(
                    "solver.absolute_force_tolerance",
                    format!("must be a positive force in N (got {v}): the norm of the residual that converges an iteration"),
                ));
            }
            if sv.force_tolerance.is_some() {
                // Only one force test applies; both given would leave one silently unused.
                return Err(ctx.err(
                    "solver.absolute_force_tolerance",
                    "replaces solver.force_tolerance (the relative test): give one of the two",
                ));
            }
            c.absolute_force_tolerance = Some(v);
        }
        if let Some(v) = sv.energy_tolerance {
            c.energy_tolerance = in_range(
                ctx,
                "solver.energy_tolerance",
                v,
                ENERGY_TOLERANCE,
                "of the last correction's energy relative to the first's",
            )?;
        }
        if let Some(v) = sv.max_iterations {
            if v > limits::MAX_ITERATIONS {
                return Err(ctx.err(
                    "solver.max_iterations",
                    format!("{v} is above the limit of {}", limits::MAX_ITERATIONS),
                ));
            }
            c.max_iterations = v.max(1);
        }
        if let Some(v) = sv.max_cuts {
            if v > limits::MAX_CUTS {
                return Err(ctx.err(
                    "solver.max_cuts",
                    format!(
                        "{v} is above the limit of {} (2^-{} of an increment is below double precision)",
                        limits::MAX_CUTS,
                        limits::MAX_CUTS
                    ),
                ));
            }
            c.max_cuts = v;
        }
        if let Some(v) = sv.implex_tolerance {
            c.implex_tolerance = Some(in_range(
                ctx,
                "solver.implex_tolerance",
                v,
                IMPLEX_TOLERANCE,
                "of the crack stress error relative to f_tm",
            )?);
        }
        if let Some(v) = sv.implex_force_tolerance {
            c.implex_force_tolerance = Some(in_range(
                ctx,
                "solver.implex_force_tolerance",
                v,
                IMPLEX_FORCE_TOLERANCE,
                "of the crack stresses' out-of-balance force relative to the force scale",
            )?);
        }
        if let Some(v) = sv.implex_force_norm.as_deref() {
            c.implex_force_norm = match v {
                "force" => ImplexForceNorm::Force,
                "energy" => ImplexForceNorm::Energy,
                o => {
                    return Err(ctx.err(
                        "solver.implex_force_norm",
                        format!("unknown norm '{o}' (expected force or energy)"),
                    ))
                }
            };
            // A norm for a control that is off would be silently ignored.
            if c.implex_force_tolerance.is_none() {
                return Err(ctx.err(
                    "solver.implex_force_norm",
                    "used by solver.implex_force_tolerance only (give the tolerance too)",
                ));
            }
        }
        if let Some(v) = sv.increment_tolerance {
            c.increment_tolerance = Some(super::time::error_tolerance(
                ctx,
                "solver.increment_tolerance",
                v,
            )?);
        }
        if let Some(v) = sv.predictor.as_deref() {
            c.predictor = match v {
                "extrapolated" => Predictor::Extrapolated,
                "last_converged" => Predictor::LastConverged,
                o => {
                    return Err(ctx.err(
                        "solver.predictor",
                        format!(
                            "unknown predictor '{o}' (expected extrapolated or last_converged)"
                        ),
                    ))
                }
            };
        }
    }
    Ok(())
}
