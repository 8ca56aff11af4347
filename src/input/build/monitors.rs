//! `[[monitors]]`: the quantities written to history.csv at every output increment.

use super::fields::{dir, index_by_name, locate_nodes, required_ref, unique_names};
use super::tendons::is_bonded_kind;
use super::R;
use crate::input::error::Ctx;
use crate::input::schema::{File, MonitorIn};
use crate::model::{
    Bar, Extreme, LossPart, Model, Monitor, MonitorKind, StressComponent, TendonEl,
};

/// Columns of history.csv before the monitors, without their units.
const RESERVED: &[&str] = &["step", "increment", "iterations", "time"];

/// The monitors, resolved against the supports, load cases, tendons, joints, bars and steps.
pub(super) fn build(ctx: &Ctx, file: &File, model: &mut Model, used: &[bool]) -> R<()> {
    unique_names(
        ctx,
        "monitors",
        file.monitors.iter().map(|m| m.name.as_str()),
    )?;
    for (i, m) in file.monitors.iter().enumerate() {
        // The history's own columns (`step`, `increment`, `iterations`, `time [d]`,
        // `factor:<case> [-]`) read without their units (`time`, as Python and the plots
        // name them): a monitor of one of these names would head a second column of that
        // name.
        let bare = m.name.split(" [").next().unwrap_or("").trim();
        if RESERVED.contains(&bare) || bare.starts_with("factor:") || m.name.contains('[') {
            return Err(ctx.err(
                format!("monitors[{i}].name"),
                format!(
                    "'{}' is a column history.csv already has (step, increment, iterations, time [d], factor:<case> [-]) or holds '[' (the column's unit follows in brackets); choose another name",
                    m.name
                ),
            ));
        }
        let kind = monitor(ctx, i, m, file, model, used)?;
        model.monitors.push(Monitor {
            name: m.name.clone(),
            kind,
        });
    }
    Ok(())
}

/// The kind of monitor `m` (`monitors[i]`).
fn monitor(
    ctx: &Ctx,
    i: usize,
    m: &MonitorIn,
    file: &File,
    model: &Model,
    used: &[bool],
) -> R<MonitorKind> {
    let key = format!("monitors[{i}]");
    // The bar of a bonded (post- or pre-tensioned) tendon named by `tendon`.
    let bonded_bar = m.tendon.as_deref().and_then(|n| {
        file.tendons
            .iter()
            .any(|t| t.name == n && is_bonded_kind(&t.kind))
            .then(|| model.bars.iter().position(|b| b.name == n))
            .flatten()
    });
    let kind = match m.kind.as_str() {
        "displacement" => {
            let node = locate_nodes(ctx, &key, model, used, m.node, m.point, None)?[0];
            let since_step = match &m.since_step {
                Some(name) => Some(index_by_name(
                    ctx,
                    &format!("{key}.since_step"),
                    "step",
                    file.steps.iter().map(|s| s.name.as_str()),
                    name,
                )?),
                None => None,
            };
            MonitorKind::Displacement {
                node,
                dir: dir(ctx, &format!("{key}.component"), m.component.as_deref())?,
                since_step,
            }
        }
        "reaction" => {
            let support = required_ref(
                ctx,
                &format!("{key}.support"),
                "support",
                m.support.as_deref(),
                model.supports.iter().map(|s| s.name.as_str()),
            )?;
            MonitorKind::Reaction {
                support,
                dir: dir(ctx, &format!("{key}.component"), m.component.as_deref())?,
            }
        }
        "load_factor" => {
            MonitorKind::LoadFactor {
                case: required_ref(
                    ctx,
                    &format!("{key}.case"),
                    "load case",
                    m.case.as_deref(),
                    model.load_cases.iter().map(|c| c.name.as_str()),
                )?,
            }
        }
            "tendon_stress" | "tendon_force" | "tendon_loss" | "tendon_loss_elastic"
            | "tendon_loss_creep" | "tendon_loss_relaxation" => {
                tendon_monitor(ctx, &key, m, bonded_bar, model)?
            }
            "joint_opening" | "joint_slip" | "joint_contact_depth" | "joint_contact_stress" => {
                joint_monitor(ctx, &key, m, model)?
            }
        "stress" => stress_monitor(ctx, &key, m, model)?,
        "bar_stress" | "max_crack_strain" | "max_plastic_strain" | "crushed_points" => {
            material_monitor(ctx, &key, m, model)?
        }
        o => {
            return Err(ctx.err(
                format!("{key}.kind"),
                format!("unknown monitor kind '{o}' (expected displacement, reaction, load_factor, joint_opening, joint_slip, joint_contact_depth, joint_contact_stress, stress, tendon_stress, tendon_force, tendon_loss, tendon_loss_elastic, tendon_loss_creep, tendon_loss_relaxation, bar_stress, max_crack_strain, max_plastic_strain or crushed_points)"),
            ))
        }
    };
    Ok(kind)
}

/// A `tendon_*` monitor: of an external tendon (by span), or of a bonded tendon's bar.
fn tendon_monitor(
    ctx: &Ctx,
    key: &str,
    m: &MonitorIn,
    bonded_bar: Option<usize>,
    model: &Model,
) -> R<MonitorKind> {
    Ok(match m.kind.as_str() {
        "tendon_force" if bonded_bar.is_none() => {
            let tendon = required_ref(
                ctx,
                &format!("{key}.tendon"),
                "tendon",
                m.tendon.as_deref(),
                model.tendons.iter().map(|t| t.name.as_str()),
            )?;
            let span = span_of(ctx, key, m, &model.tendons[tendon])?;
            MonitorKind::TendonForce { tendon, span }
        }
        "tendon_stress"
        | "tendon_force"
        | "tendon_loss"
        | "tendon_loss_elastic"
        | "tendon_loss_creep"
        | "tendon_loss_relaxation"
            if bonded_bar.is_some() =>
        {
            // A bonded tendon is a bar: at the point nearest `point`, else its largest
            // stress or force, or its mean loss.
            let bar = bonded_bar.expect("guarded");
            if m.span.is_some() {
                return Err(ctx.err(
                    format!("{key}.span"),
                    "spans are for external tendons: a bonded tendon takes `point`",
                ));
            }
            let point = m.point.map(|p| nearest_bar_point(&model.bars[bar], p));
            match m.kind.as_str() {
                "tendon_stress" => MonitorKind::BarStress { bar, point },
                "tendon_force" => MonitorKind::BarForce { bar, point },
                kind => MonitorKind::BarLoss {
                    bar,
                    point,
                    part: loss_part(kind),
                },
            }
        }
        // tendon_stress and the loss kinds of an external tendon.
        _ => {
            let tendon = required_ref(
                ctx,
                &format!("{key}.tendon"),
                "tendon",
                m.tendon.as_deref(),
                model.tendons.iter().map(|t| t.name.as_str()),
            )?;
            let part = match m.kind.as_str() {
                "tendon_stress" => None,
                kind => Some(loss_part(kind)),
            };
            match part {
                None => MonitorKind::TendonStress {
                    tendon,
                    span: span_of(ctx, key, m, &model.tendons[tendon])?,
                },
                Some(part) => MonitorKind::TendonLoss { tendon, part },
            }
        }
    })
}

/// A `joint_*` monitor: one joint by name, or `"all"` (the largest over the joints).
fn joint_monitor(ctx: &Ctx, key: &str, m: &MonitorIn, model: &Model) -> R<MonitorKind> {
    let name = m.joint.as_deref().ok_or_else(|| {
        ctx.err(
            format!("{key}.joint"),
            "missing (a joint name such as J1, or \"all\")",
        )
    })?;
    let joint = if name == "all" {
        if m.kind == "joint_contact_depth" {
            return Err(ctx.err(
                format!("{key}.joint"),
                "joint_contact_depth needs one joint, not \"all\"",
            ));
        }
        if model.joints.is_empty() {
            return Err(ctx.err(format!("{key}.joint"), "the model has no joints"));
        }
        None
    } else {
        Some(index_by_name(
            ctx,
            &format!("{key}.joint"),
            "joint",
            model.joints.iter().map(|j| j.name.as_str()),
            name,
        )?)
    };
    Ok(match (m.kind.as_str(), joint) {
        ("joint_opening", j) => MonitorKind::JointOpening { joint: j },
        ("joint_slip", j) => MonitorKind::JointSlip { joint: j },
        ("joint_contact_stress", j) => MonitorKind::JointContactStress { joint: j },
        (_, j) => MonitorKind::JointContactDepth {
            joint: j.expect("checked above"),
        },
    })
}

/// The span (0-based) a `tendon_stress`/`tendon_force` monitor of an external tendon names
/// with its 1-based `span` key (None: the largest over the spans).
pub(super) fn span_of(ctx: &Ctx, key: &str, m: &MonitorIn, tendon: &TendonEl) -> R<Option<usize>> {
    let Some(k) = m.span else { return Ok(None) };
    let n = tendon.nodes.len() - 1;
    if k < 1 || k as usize > n {
        return Err(ctx.err(
            format!("{key}.span"),
            format!(
                "tendon '{}' has spans 1 to {n} (between its anchors and deviators), not {k}",
                tendon.name
            ),
        ));
    }
    Ok(Some(k as usize - 1))
}

/// The loss part of a `tendon_loss*` monitor kind.
pub(super) fn loss_part(kind: &str) -> LossPart {
    match kind {
        "tendon_loss" => LossPart::Total,
        "tendon_loss_elastic" => LossPart::Elastic,
        "tendon_loss_creep" => LossPart::CreepShrinkage,
        _ => LossPart::Relaxation,
    }
}

/// Optional region by name (None = all regions).
pub(super) fn optional_region(
    ctx: &Ctx,
    key: &str,
    model: &Model,
    name: Option<&str>,
) -> R<Option<usize>> {
    name.map(|n| {
        index_by_name(
            ctx,
            key,
            "region",
            model.regions.iter().map(|r| r.name.as_str()),
            n,
        )
    })
    .transpose()
}

/// Bar-stress and concrete-state monitors.
/// Index of the bar's integration point nearest `p` [m].
pub(super) fn nearest_bar_point(bar: &Bar, p: [f64; 2]) -> usize {
    let pts = &bar.points;
    (0..pts.len())
        .min_by(|&a, &b| {
            let d = |i: usize| {
                let x = pts[i].point.x;
                (x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2)
            };
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(0)
}

pub(super) fn material_monitor(
    ctx: &Ctx,
    key: &str,
    m: &MonitorIn,
    model: &Model,
) -> R<MonitorKind> {
    if m.kind == "bar_stress" {
        let name = m
            .bar
            .as_deref()
            .ok_or_else(|| ctx.err(format!("{key}.bar"), "missing"))?;
        let bar = index_by_name(
            ctx,
            &format!("{key}.bar"),
            "bar",
            model.bars.iter().map(|b| b.name.as_str()),
            name,
        )?;
        let point = m.point.map(|p| nearest_bar_point(&model.bars[bar], p));
        return Ok(MonitorKind::BarStress { bar, point });
    }
    if m.point.is_some() || m.node.is_some() {
        return Err(ctx.err(
            format!("{key}.point"),
            format!(
                "a {} monitor takes an optional region, not a location",
                m.kind
            ),
        ));
    }
    let region = optional_region(ctx, &format!("{key}.region"), model, m.region.as_deref())?;
    Ok(match m.kind.as_str() {
        "max_crack_strain" => MonitorKind::MaxCrackStrain { region },
        "max_plastic_strain" => MonitorKind::MaxPlasticStrain { region },
        _ => MonitorKind::CrushedPoints { region },
    })
}

/// A `stress` monitor: a component (`sx`, `sy`, `txy`, `s1`, `s2`) at the Gauss point
/// nearest `point`, or its extreme over a region (all regions without `region`).
fn stress_monitor(ctx: &Ctx, key: &str, m: &MonitorIn, model: &Model) -> R<MonitorKind> {
    let component = match m.component.as_deref() {
        Some("sx") => StressComponent::Sx,
        Some("sy") => StressComponent::Sy,
        Some("txy") => StressComponent::Txy,
        Some("s1") => StressComponent::S1,
        Some("s2") => StressComponent::S2,
        Some(o) => {
            return Err(ctx.err(
                format!("{key}.component"),
                format!("unknown stress component '{o}' (expected sx, sy, txy, s1 or s2)"),
            ))
        }
        None => {
            return Err(ctx.err(
                format!("{key}.component"),
                "missing (sx, sy, txy, s1 or s2)",
            ))
        }
    };
    if m.node.is_some() {
        return Err(ctx.err(
            format!("{key}.node"),
            "a stress monitor reads a Gauss point: give `point` (the nearest Gauss point) or a `region`",
        ));
    }
    if let Some(p) = m.point {
        if m.region.is_some() || m.extreme.is_some() {
            return Err(ctx.err(
                format!("{key}.point"),
                "give either `point` (the Gauss point nearest it) or `region`/`extreme` (the extreme over the region), not both",
            ));
        }
        return Ok(MonitorKind::StressAtPoint {
            component,
            gauss_point: nearest_gauss_point(model, p),
        });
    }
    let region = optional_region(ctx, &format!("{key}.region"), model, m.region.as_deref())?;
    let extreme = match m.extreme.as_deref() {
        Some("max") => Extreme::Max,
        Some("min") => Extreme::Min,
        Some("abs") => Extreme::Abs,
        Some(o) => {
            return Err(ctx.err(
                format!("{key}.extreme"),
                format!("unknown extreme '{o}' (expected max, min or abs)"),
            ))
        }
        // The design checks: the largest tension, the most compressive value, else the
        // largest magnitude.
        None => match component {
            StressComponent::S1 => Extreme::Max,
            StressComponent::S2 => Extreme::Min,
            _ => Extreme::Abs,
        },
    };
    Ok(MonitorKind::StressExtreme {
        component,
        region,
        extreme,
    })
}

/// Index of the continuum Gauss point nearest `p` [m] (element order, then rule order: the
/// order of the analysis' point states).
fn nearest_gauss_point(model: &Model, p: [f64; 2]) -> usize {
    use crate::elements::continuum::rule_points;
    use crate::fem::shape::map_point;
    let mut best = (f64::INFINITY, 0);
    let mut k = 0;
    for e in &model.elements {
        let coords = model.element_coords(e);
        for &(xi, eta, _) in rule_points(e.kind, e.integration) {
            let x = map_point(&e.kind.eval(xi, eta), &coords);
            let d = (x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2);
            if d < best.0 {
                best = (d, k);
            }
            k += 1;
        }
    }
    best.1
}
