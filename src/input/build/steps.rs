//! `[[steps]]`: load, displacement, arc-length, linear and time steps in order; load
//! factors are totals carried from step to step.

use super::fields::{dir, index_by_name, locate_nodes, positive, unique_names};

/// Longest step name accepted [characters]: 4 bytes per character at most, 4 × 50 = 200
/// bytes, leaves room in a 255-byte file name for the prefix and suffix of field files.
const MAX_NAME_CHARS: usize = 50;
use super::time::time_span;
use super::R;
use crate::input::error::Ctx;
use crate::input::limits;
use crate::input::schema::{ControlIn, StepIn};
use crate::model::{
    ArcLengthControl, Dir, FieldOutput, Geometry, Model, PathControl, Step, StepKind, TimeSpan,
};

/// The steps, with the load factors of each (totals) and their path controls.
pub(super) fn build(ctx: &Ctx, list: &[StepIn], model: &mut Model, used: &[bool]) -> R<()> {
    if list.is_empty() {
        return Err(ctx.err("steps", "no steps given: add at least one [[steps]] table"));
    }
    unique_names(ctx, "steps", list.iter().map(|s| s.name.as_str()))?;
    // The name becomes part of the field files' names in a staged run (limit 255 bytes on
    // most file systems, with about 40 of prefix and suffix) and a report's headings.
    if let Some((i, s)) = list
        .iter()
        .enumerate()
        .find(|(_, s)| s.name.chars().count() > MAX_NAME_CHARS)
    {
        return Err(ctx.err(
            format!("steps[{i}].name"),
            format!(
                "{} characters, more than {MAX_NAME_CHARS}: the name goes into file names and headings; shorten it",
                s.name.chars().count()
            ),
        ));
    }
    let linear = model.materials.iter().all(|m| m.law.is_linear());
    let mut factors = vec![0.0; model.load_cases.len()];
    // End of the last time step [d] (None before the first one).
    let mut clock: Option<f64> = None;
    for (i, s) in list.iter().enumerate() {
        let step = step(ctx, i, s, linear, &mut factors, &mut clock, model, used)?;
        model.steps.push(step);
    }
    Ok(())
}

/// Step `s` (`steps[i]`); `factors` are the load factors so far (updated), `clock` the end
/// of the last time step [d] (updated).
#[allow(clippy::too_many_arguments)]
fn step(
    ctx: &Ctx,
    i: usize,
    s: &StepIn,
    linear: bool,
    factors: &mut Vec<f64>,
    clock: &mut Option<f64>,
    model: &Model,
    used: &[bool],
) -> R<Step> {
    let key = format!("steps[{i}]");
    let kind = step_kind(ctx, &key, s, linear, model)?;
    let path = path_control(ctx, &key, s, kind, model, used)?;
    if kind == StepKind::Displacement && !s.loads.is_empty() {
        return Err(ctx.err(
            format!("{key}.loads"),
            "a displacement step holds the loads of the previous steps; give no loads",
        ));
    }
    let time = time_of(ctx, &key, s, kind, clock)?;
    let held = factors.clone();
    for (name, f) in &s.loads {
        let c = index_by_name(
            ctx,
            &format!("{key}.loads.{name}"),
            "load case",
            model.load_cases.iter().map(|c| c.name.as_str()),
            name,
        )?;
        if !f.is_finite() {
            return Err(ctx.err(format!("{key}.loads.{name}"), "must be a finite number"));
        }
        factors[c] = *f;
    }
    let increments = increments_of(ctx, &key, s, kind, time.as_ref())?;
    let field_output = match s.output.as_deref() {
        None | Some("end") => FieldOutput::End,
        Some("increments") => FieldOutput::Increments,
        Some("none") => FieldOutput::None,
        Some(o) => {
            return Err(ctx.err(
                format!("{key}.output"),
                format!("unknown value '{o}' (expected end, increments or none)"),
            ))
        }
    };
    let path = match path {
        Some(PathControl::ArcLength(mut a)) => {
            // `loads` of an arc-length step is the reference pattern, not a total.
            a.reference = factors.iter().zip(&held).map(|(f, h)| f - h).collect();
            for (name, f) in &s.loads {
                if let Some(c) = model.load_cases.iter().position(|c| &c.name == name) {
                    a.reference[c] = *f;
                }
            }
            factors.clone_from(&held);
            if a.reference.iter().all(|r| *r == 0.0) {
                return Err(ctx.err(
                    format!("{key}.loads"),
                    "an arc-length step needs a reference load: give loads = { case = factor }",
                ));
            }
            Some(PathControl::ArcLength(a))
        }
        p => p,
    };
    Ok(Step {
        name: s.name.clone(),
        kind,
        factors: factors.clone(),
        increments,
        field_output,
        path,
        time,
    })
}

/// The kind of step `s` (`key` = "steps[i]"); a linear step needs linear materials and
/// geometry.
fn step_kind(ctx: &Ctx, key: &str, s: &StepIn, linear: bool, model: &Model) -> R<StepKind> {
    let kind = match s.kind.as_str() {
        "linear" => {
            if !linear {
                return Err(ctx.err(
                    format!("{key}.kind"),
                    "a linear step needs linear materials; use kind = \"load\"",
                ));
            }
            // One solve with the initial stiffness cannot follow nonlinear geometry.
            if model.geometry == Geometry::Nonlinear {
                return Err(ctx.err(
                    format!("{key}.kind"),
                    "a linear step needs analysis.geometry = \"linear\"; use kind = \"load\"",
                ));
            }
            StepKind::Linear
        }
        "load" => StepKind::Load,
        "displacement" => StepKind::Displacement,
        "arc_length" => StepKind::ArcLength,
        "time" => StepKind::Time,
        o => {
            return Err(ctx.err(
                format!("{key}.kind"),
                format!(
                "unknown step kind '{o}' (expected linear, load, displacement, arc_length or time)"
            ),
            ))
        }
    };
    Ok(kind)
}

/// The interval of a time step (None for the other kinds, which must not take its keys).
fn time_of(
    ctx: &Ctx,
    key: &str,
    s: &StepIn,
    kind: StepKind,
    clock: &mut Option<f64>,
) -> R<Option<TimeSpan>> {
    let time = if kind == StepKind::Time {
        let span = time_span(ctx, key, s, *clock)?;
        *clock = Some(span.to);
        Some(span)
    } else {
        for (name, given) in [
            ("from", s.from.is_some()),
            ("to", s.to.is_some()),
            ("duration", s.duration.is_some()),
            ("substeps", s.substeps.is_some()),
            ("first_substep", s.first_substep.is_some()),
            ("substep_tolerance", s.substep_tolerance.is_some()),
        ] {
            if given {
                return Err(ctx.err(
                    format!("{key}.{name}"),
                    "belongs to a time step (kind = \"time\")",
                ));
            }
        }
        None
    };
    Ok(time)
}

/// The increments of a step (the substeps of a time step), within the limits.
fn increments_of(
    ctx: &Ctx,
    key: &str,
    s: &StepIn,
    kind: StepKind,
    time: Option<&TimeSpan>,
) -> R<usize> {
    let increments = match time {
        Some(t) => t.substeps,
        None => s.increments.unwrap_or(1),
    };
    if increments == 0 || (kind == StepKind::Linear && increments != 1) {
        return Err(ctx.err(
            format!("{key}.increments"),
            "must be at least 1 (and exactly 1 for a linear step)",
        ));
    }
    if increments > limits::MAX_INCREMENTS {
        let k = if time.is_some() {
            "substeps"
        } else {
            "increments"
        };
        return Err(ctx.err(
            format!("{key}.{k}"),
            format!(
                "{increments} is above the limit of {} per step (a typing error?)",
                limits::MAX_INCREMENTS
            ),
        ));
    }
    Ok(increments)
}

/// A node/point + component + value table → (node, direction, value).
pub(super) fn control_dof(
    ctx: &Ctx,
    key: &str,
    c: &ControlIn,
    model: &Model,
    used: &[bool],
) -> R<(Vec<usize>, Dir, f64)> {
    let nodes = locate_nodes(
        ctx,
        key,
        model,
        used,
        c.node,
        c.point,
        c.line.as_ref().map(|l| &l[..]),
    )?;
    let d = dir(ctx, &format!("{key}.component"), c.component.as_deref())?;
    if !c.value.is_finite() {
        return Err(ctx.err(format!("{key}.value"), "must be a finite number [m]"));
    }
    Ok((nodes, d, c.value))
}

/// Control of displacement and arc-length steps; keys of the wrong step kind are errors.
pub(super) fn path_control(
    ctx: &Ctx,
    key: &str,
    s: &StepIn,
    kind: StepKind,
    model: &Model,
    used: &[bool],
) -> R<Option<PathControl>> {
    let arc_keys = [
        (s.initial_increment.is_some(), "initial_increment"),
        (s.desired_iterations.is_some(), "desired_iterations"),
        (s.max_growth.is_some(), "max_growth"),
        (s.target_factor.is_some(), "target_factor"),
        (s.stop_displacement.is_some(), "stop_displacement"),
    ];
    if kind != StepKind::ArcLength {
        if let Some((_, k)) = arc_keys.iter().find(|(g, _)| *g) {
            return Err(ctx.err(format!("{key}.{k}"), "only arc_length steps take this key"));
        }
    }
    if kind != StepKind::Displacement && s.control.is_some() {
        return Err(ctx.err(
            format!("{key}.control"),
            "only displacement steps take a control",
        ));
    }
    match kind {
        StepKind::Displacement => {
            let c = s.control.as_ref().ok_or_else(|| {
                ctx.err(
                    format!("{key}.control"),
                    "missing: give control = { point = [x, y], component = \"y\", value = -0.01 }",
                )
            })?;
            let (nodes, dir, value) = control_dof(ctx, &format!("{key}.control"), c, model, used)?;
            for &node in &nodes {
                let k = 2 * node + dir.index();
                if model
                    .supports
                    .iter()
                    .any(|sp| sp.dofs.iter().any(|(n, d, _)| 2 * n + d.index() == k))
                {
                    return Err(ctx.err(
                        format!("{key}.control"),
                        format!(
                            "node {} ({:?}) is supported in that direction; control a free dof",
                            node + 1,
                            model.nodes[node]
                        ),
                    ));
                }
            }
            Ok(Some(PathControl::Displacement { nodes, dir, value }))
        }
        StepKind::ArcLength => {
            let initial_increment = s.initial_increment.ok_or_else(|| {
                ctx.err(
                    format!("{key}.initial_increment"),
                    "missing: the load-factor increment of the first increment",
                )
            })?;
            let initial_increment =
                positive(ctx, &format!("{key}.initial_increment"), initial_increment)?;
            let target_displacement = s
                .stop_displacement
                .as_ref()
                .map(|c| {
                    let k = format!("{key}.stop_displacement");
                    if c.line.is_some() {
                        return Err(ctx.err(&k, "give a node or point, not a line"));
                    }
                    control_dof(ctx, &k, c, model, used).map(|(n, d, v)| (n[0], d, v))
                })
                .transpose()?;
            if let Some(t) = s.target_factor {
                positive(ctx, &format!("{key}.target_factor"), t)?;
            }
            let desired_iterations = s.desired_iterations.unwrap_or(6).max(1);
            let max_growth = positive(
                ctx,
                &format!("{key}.max_growth"),
                s.max_growth.unwrap_or(10.0),
            )?;
            Ok(Some(PathControl::ArcLength(ArcLengthControl {
                initial_increment,
                desired_iterations,
                max_growth,
                target_factor: s.target_factor,
                target_displacement,
                max_increments: s.increments.unwrap_or(100),
                reference: Vec::new(),
            })))
        }
        _ => Ok(None),
    }
}
