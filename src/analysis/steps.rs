//! The step driver: load-controlled increments solved by Newton–Raphson with automatic
//! step cutting; every converged increment is reported to an observer.

use super::loads::load_vector;
use super::solver::{SolverError, SolverStats, SparseCholesky};
use super::system::System;
use crate::fem::dofs::CONSTRAINED;
use crate::materials::point::TimeContext;
use crate::model::{Model, StepKind, DEFAULT_START_DAY};
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

/// Receives converged increments (history, field output, progress).
pub trait Observer {
    /// Called after every converged increment.
    fn increment(&mut self, snap: &Snapshot) -> std::io::Result<()>;
}

/// Why an analysis stopped early.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// An increment failed after all allowed cuts.
    #[error("step '{step}' did not converge at load level {level:.6} (increment {increment}, after {cuts} cuts): {reason}")]
    NotConverged {
        /// Step name.
        step: String,
        /// Increment number.
        increment: usize,
        /// Fraction of the step reached (0..1).
        level: f64,
        /// Cuts tried.
        cuts: usize,
        /// Last reason (residual history, material failure, ...).
        reason: String,
    },
    /// The stiffness matrix is singular: a mechanism.
    #[error("{0}")]
    Mechanism(String),
    /// Writing results failed.
    #[error("writing results: {0}")]
    Output(#[from] std::io::Error),
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
    let mut timings = Timings {
        setup_s: t0.elapsed().as_secs_f64(),
        ..Default::default()
    };
    let mut factors = vec![0.0; model.load_cases.len()];
    // Prescribed displacements apply from the first increment on.
    let mut u = sys.u.clone();
    for &(d, v) in &sys.dofs.prescribed {
        u[d] = v;
    }
    let mut factored_linear = false;
    let mut neg_pivots = 0;
    // Analysis clock [d]: steps before the first time step act at its start.
    let mut clock = model
        .steps
        .iter()
        .find_map(|s| s.time.map(|t| t.from))
        .unwrap_or(DEFAULT_START_DAY);
    for (si, step) in model.steps.iter().enumerate() {
        sys.stress_tendons(si);
        if matches!(step.kind, StepKind::Displacement | StepKind::ArcLength) {
            let mut ctx = super::path::PathContext {
                sys: &mut sys,
                solver: &mut solver,
                cases: &cases,
                factors: &mut factors,
                u: &mut u,
                timings: &mut timings,
                neg_pivots: &mut neg_pivots,
            };
            super::path::run_step(&mut ctx, si, step, obs)?;
            continue;
        }
        let start = factors.clone();
        let n_inc = step.increments.max(1);
        let mut level = 0.0; // fraction of the step reached
        let mut d_level = 1.0 / n_inc as f64;
        let mut increment = 0;
        let mut cuts = 0;
        while level < 1.0 - 1e-12 {
            let target = (level + d_level).min(1.0);
            let lam: Vec<f64> = start
                .iter()
                .zip(&step.factors)
                .map(|(a, b)| a + (b - a) * target)
                .collect();
            let mut f_ext = vec![0.0; model.n_dofs()];
            for (c, l) in cases.iter().zip(&lam) {
                if *l != 0.0 {
                    f_ext.iter_mut().zip(c).for_each(|(f, v)| *f += l * v);
                }
            }
            sys.begin_time_increment(match &step.time {
                Some(span) => TimeContext {
                    t_from: span.time_at(level),
                    t_to: span.time_at(target),
                },
                None => TimeContext::at(clock),
            });
            match newton(
                &mut sys,
                &mut solver,
                &mut u,
                &f_ext,
                &mut timings,
                &mut factored_linear,
                step.kind,
            ) {
                Ok((f_int, iterations)) => {
                    sys.commit(&u);
                    level = target;
                    increment += 1;
                    factors = lam;
                    timings.increments += 1;
                    timings.iterations += iterations;
                    note_limit_point(
                        &mut timings,
                        &mut neg_pivots,
                        solver.negative_pivots,
                        &step.name,
                        increment,
                    );
                    let t = Instant::now();
                    obs.increment(&Snapshot {
                        system: &sys,
                        step: si,
                        increment,
                        end_of_step: level >= 1.0 - 1e-12,
                        factors: &factors,
                        f_int: &f_int,
                        f_ext: &f_ext,
                        iterations,
                        negative_pivots: solver.negative_pivots,
                        arc_length_factor: None,
                        control_force: None,
                    })?;
                    timings.output_s += t.elapsed().as_secs_f64();
                }
                Err(NewtonFailure::Singular(e)) if cuts == 0 && sys.linear => {
                    return Err(mechanism(&sys, e));
                }
                Err(failure) => {
                    // Throw the trial state away and retry with half the increment.
                    u.copy_from_slice(&sys.u);
                    for &(d, v) in &sys.dofs.prescribed {
                        u[d] = v;
                    }
                    sys.unlatch();
                    if cuts >= model.controls.max_cuts || step.kind == StepKind::Linear {
                        return Err(AnalysisError::NotConverged {
                            step: step.name.clone(),
                            increment: increment + 1,
                            level: target,
                            cuts,
                            reason: failure.describe(&sys),
                        });
                    }
                    cuts += 1;
                    d_level *= 0.5;
                }
            }
        }
        if let Some(span) = &step.time {
            clock = span.to;
        }
    }
    timings.solver = solver.stats.clone();
    Ok(timings)
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

pub(super) enum NewtonFailure {
    Singular(SolverError),
    Material(usize, String),
    Diverged(Vec<f64>),
}

impl NewtonFailure {
    pub(super) fn describe(&self, sys: &System) -> String {
        match self {
            NewtonFailure::Singular(e) => mechanism(sys, e.clone()).to_string(),
            NewtonFailure::Material(e, m) => format!("element {} material: {m}", e + 1),
            NewtonFailure::Diverged(h) => format!(
                "relative residual history {}",
                h.iter()
                    .map(|r| format!("{r:.2e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
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
    for it in 0..=max_it {
        let need_k = !(sys.linear && *factored_linear);
        let t = Instant::now();
        let a = sys
            .assemble(u, need_k)
            .map_err(|(e, err)| NewtonFailure::Material(e, err.to_string()))?;
        sys.latch_cracks();
        timings.assembly_s += t.elapsed().as_secs_f64();
        let r: Vec<f64> = f_ext.iter().zip(&a.f_int).map(|(e, i)| e - i).collect();
        let rf = sys.to_free(&r);
        let rnorm = norm(&rf);
        // Reference: the larger of the external force norm and the scale of the element
        // forces (which stays finite under self-equilibrated prestress).
        let reference = norm(f_ext).max(a.force_scale).max(f64::MIN_POSITIVE);
        let rel = rnorm / reference;
        if !rel.is_finite() {
            history.push(rel);
            return Err(NewtonFailure::Diverged(history));
        }
        history.push(rel);
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
            break;
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
        // material response); see `path::damping`.
        let damp = super::path::damping(&history);
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
    }
    Err(NewtonFailure::Diverged(history))
}

pub(super) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Turn a solver failure into a message naming the node and dof.
pub(super) fn mechanism(sys: &System, e: SolverError) -> AnalysisError {
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
            AnalysisError::Mechanism(format!(
                "the structure is a mechanism or has lost stiffness: zero pivot at node {} ({x}, {y}), dof u{dir}, region(s) {:?} — check supports and connections",
                node + 1,
                regions
            ))
        }
        SolverError::Internal(m) => AnalysisError::Mechanism(m),
        SolverError::Singular => AnalysisError::Mechanism(
            "the tangent stiffness is singular (zero pivot): a mechanism, or exactly at a limit point"
                .into(),
        ),
    }
}
