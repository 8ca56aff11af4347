//! `[analysis]` (geometry) and `[solver]` (tolerances and limits of the Newton iterations).

use super::fields::positive;
use super::R;
use crate::elements::continuum::Integration;
use crate::input::error::Ctx;
use crate::input::limits;
use crate::input::schema::{AnalysisIn, SolverIn};
use crate::model::{Geometry, Model, Predictor};

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

/// `[solver]`: override the default convergence tolerances and limits.
pub(super) fn solver(ctx: &Ctx, solver: Option<&SolverIn>, model: &mut Model) -> R<()> {
    if let Some(sv) = solver {
        let c = &mut model.controls;
        if let Some(v) = sv.force_tolerance {
            c.force_tolerance = positive(ctx, "solver.force_tolerance", v)?;
        }
        if let Some(v) = sv.energy_tolerance {
            c.energy_tolerance = positive(ctx, "solver.energy_tolerance", v)?;
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
            c.implex_tolerance = Some(positive(ctx, "solver.implex_tolerance", v)?);
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
