//! Construction stages: the `activate` and `remove` lists of `[[steps]]` resolved into the
//! lifetimes of regions (or whole segments) and supports, with the checks a staged model
//! needs (docs/theory-stages.md): nothing activated twice or removed while inactive, each
//! region cast before it is placed, tendons stressed on active parts only.

use super::R;
use crate::input::error::Ctx;
use crate::input::schema::StepIn;
use crate::model::{Lifetime, Model, Staging, StepKind, DEFAULT_START_DAY};

/// A part a stage can activate or remove.
#[derive(Debug, Clone, PartialEq)]
enum Part {
    /// Regions (one, or all the regions of a segment: "webs@S2", "slab@S2" for "S2").
    Regions(Vec<usize>),
    /// A support.
    Support(usize),
}

/// Resolve the stage lists of the steps into `model.staging` (left empty when no step
/// activates or removes anything).
pub(super) fn build(ctx: &Ctx, list: &[StepIn], model: &mut Model) -> R<()> {
    if list
        .iter()
        .all(|s| s.activate.is_empty() && s.remove.is_empty())
    {
        return Ok(());
    }
    let mut regions: Vec<Option<Lifetime>> = vec![None; model.regions.len()];
    let mut supports: Vec<Option<Lifetime>> = vec![None; model.supports.len()];
    for (i, s) in list.iter().enumerate() {
        for (j, name) in s.activate.iter().enumerate() {
            let key = format!("steps[{i}].activate[{j}]");
            for slot in slots(ctx, &key, model, name, &mut regions, &mut supports)? {
                if let Some(l) = slot {
                    let what = match l.until {
                        Some(u) => format!(
                            "removed in step '{}'; a removed part does not come back",
                            list[u].name
                        ),
                        None => format!("already activated in step '{}'", list[l.from].name),
                    };
                    return Err(ctx.err(&key, format!("'{name}' is {what}")));
                }
                *slot = Some(Lifetime {
                    from: i,
                    until: None,
                });
            }
        }
        for (j, name) in s.remove.iter().enumerate() {
            let key = format!("steps[{i}].remove[{j}]");
            if matches!(
                model.steps[i].kind,
                StepKind::Displacement | StepKind::ArcLength
            ) {
                return Err(ctx.err(
                    &key,
                    "parts are removed in load, linear or time steps (the released reactions are ramped over the step's increments)",
                ));
            }
            for slot in slots(ctx, &key, model, name, &mut regions, &mut supports)? {
                if i == 0 {
                    return Err(ctx.err(
                        &key,
                        "nothing can be removed in the first step (leave the part out of the model)",
                    ));
                }
                let l = slot.get_or_insert(Lifetime::ALWAYS);
                if let Some(u) = l.until {
                    return Err(ctx.err(
                        &key,
                        format!("'{name}' is already removed in step '{}'", list[u].name),
                    ));
                }
                if l.from >= i {
                    return Err(ctx.err(
                        &key,
                        format!(
                            "'{name}' is not active in step '{}' (activated in step '{}')",
                            s.name, list[l.from].name
                        ),
                    ));
                }
                l.until = Some(i);
            }
        }
    }
    model.staging = Staging {
        regions: regions
            .into_iter()
            .map(|l| l.unwrap_or(Lifetime::ALWAYS))
            .collect(),
        supports: supports
            .into_iter()
            .map(|l| l.unwrap_or(Lifetime::ALWAYS))
            .collect(),
        // Set with the supports, before the stages.
        one_way: std::mem::take(&mut model.staging.one_way),
    };
    for (s, sp) in model.supports.iter().enumerate() {
        if model.staging.support_is_staged(s) && sp.dofs.iter().any(|d| d.2 != 0.0) {
            return Err(ctx.err(
                format!("supports[{s}]"),
                format!(
                    "support '{}' is activated or removed by a step: it must prescribe zero displacements (a staged support holds the structure where it stands)",
                    sp.name
                ),
            ));
        }
    }
    Ok(())
}

/// The lifetime slots a stage name refers to (`key` names the list entry).
fn slots<'a>(
    ctx: &Ctx,
    key: &str,
    model: &Model,
    name: &str,
    regions: &'a mut [Option<Lifetime>],
    supports: &'a mut [Option<Lifetime>],
) -> R<Vec<&'a mut Option<Lifetime>>> {
    let part = part(ctx, key, model, name)?;
    Ok(match part {
        Part::Regions(rs) => regions
            .iter_mut()
            .enumerate()
            .filter(|(r, _)| rs.contains(r))
            .map(|(_, l)| l)
            .collect(),
        Part::Support(s) => vec![&mut supports[s]],
    })
}

/// What a stage name refers to: a region, a segment (its regions "…@name"), or a support;
/// a name that is more than one of these, or none, is an error.
fn part(ctx: &Ctx, key: &str, model: &Model, name: &str) -> R<Part> {
    let mut found = Vec::new();
    if let Some(r) = model.regions.iter().position(|r| r.name == name) {
        found.push(("region", Part::Regions(vec![r])));
    }
    let suffix = format!("@{name}");
    let segment: Vec<usize> = (0..model.regions.len())
        .filter(|&r| model.regions[r].name.ends_with(&suffix))
        .collect();
    if !segment.is_empty() {
        found.push(("segment", Part::Regions(segment)));
    }
    if let Some(s) = model.supports.iter().position(|s| s.name == name) {
        found.push(("support", Part::Support(s)));
    }
    match found.len() {
        1 => Ok(found.pop().expect("one").1),
        0 => {
            let hint = if model.joints.iter().any(|j| j.name == name) {
                " ('{name}' is a joint: a joint acts while the segments on both its faces act; name the segment)"
                    .replace("{name}", name)
            } else if model.tendons.iter().any(|t| t.name == name)
                || model.bars.iter().any(|b| b.name == name)
            {
                format!(" ('{name}' is a tendon or bar: a tendon acts from its stressed_in_step, a bar with the regions it is embedded in)")
            } else {
                String::new()
            };
            let known: Vec<&str> = model
                .regions
                .iter()
                .map(|r| r.name.as_str())
                .chain(model.supports.iter().map(|s| s.name.as_str()))
                .filter(|n| !n.starts_with('('))
                .collect();
            Err(ctx.err(
                key,
                format!(
                    "no region, segment or support named '{name}'{hint} (defined: {})",
                    known.join(", ")
                ),
            ))
        }
        _ => Err(ctx.err(
            key,
            format!(
                "'{name}' names more than one part ({}): rename one of them",
                found.iter().map(|f| f.0).collect::<Vec<_>>().join(" and ")
            ),
        )),
    }
}

/// Nodes touched by the continuum elements active in step `step`.
pub(crate) fn alive_nodes(model: &Model, step: usize) -> Vec<bool> {
    let mut alive = vec![false; model.nodes.len()];
    for e in &model.elements {
        if model.staging.region(e.region).active_in(step) {
            e.nodes.iter().for_each(|&n| alive[n] = true);
        }
    }
    alive
}

/// A tendon point on a joint lies on two coincident nodes, one of each face; the nearest
/// node found first may belong to a segment placed later than the tendon is stressed (a
/// cantilever tendon anchored at the tip face of the pair just placed). Tie such a point
/// to the coincident node of the part that is active when the tendon is stressed.
fn tie_to_active_faces(model: &mut Model) {
    // Coincident: the faces' nodes are generated from the same abscissae (round-off only).
    let tol = 1e-9 * crate::input::locate::model_size(model);
    let same = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol;
    for t in 0..model.tendons.len() {
        let alive = alive_nodes(model, model.tendons[t].stressed_in_step);
        for j in 0..model.tendons[t].nodes.len() {
            let n = model.tendons[t].nodes[j];
            if alive[n] {
                continue;
            }
            let p = model.nodes[n];
            if let Some(m) = (0..model.nodes.len()).find(|&m| alive[m] && same(model.nodes[m], p)) {
                model.tendons[t].nodes[j] = m;
            }
        }
    }
}

/// Analysis time [d] at the start of step `step`: the end of the last time step before it,
/// else the start of the first time step (the default start day without time steps).
pub(super) fn clock_at(model: &Model, step: usize) -> f64 {
    model.steps[..step]
        .iter()
        .rev()
        .find_map(|s| s.time.map(|t| t.to))
        .or_else(|| model.steps.iter().find_map(|s| s.time.map(|t| t.from)))
        .unwrap_or(DEFAULT_START_DAY)
}

/// Checks that need the tendons' steps: an external tendon is anchored and deviated on
/// nodes of active parts from its stressing on, a bonded post-tensioned tendon runs through
/// active elements when stressed.
pub(super) fn check_tendons(ctx: &Ctx, model: &mut Model) -> R<()> {
    if !model.staging.is_staged() {
        return Ok(());
    }
    tie_to_active_faces(model);
    let model = &*model;
    for (t, tendon) in model.tendons.iter().enumerate() {
        for k in tendon.stressed_in_step..model.steps.len() {
            let alive = alive_nodes(model, k);
            if let Some(&n) = tendon.nodes.iter().find(|&&n| !alive[n]) {
                return Err(ctx.err(
                    format!("tendons[{t}]"),
                    format!(
                        "tendon '{}' is tied at ({}, {}) to a part that is not active in step '{}': a tendon pulls on active parts only (stress it in a later step)",
                        tendon.name, model.nodes[n][0], model.nodes[n][1], model.steps[k].name
                    ),
                ));
            }
        }
    }
    for bar in &model.bars {
        let Some(pt) = &bar.post_tension else {
            continue;
        };
        let k = pt.stressed_in_step;
        if let Some(p) = bar.points.iter().find(|p| {
            !model
                .staging
                .region(model.elements[p.element].region)
                .active_in(k)
        }) {
            return Err(ctx.err(
                "tendons",
                format!(
                    "bonded tendon '{}' runs at ({:.3}, {:.3}) through a region not active in step '{}', where it is stressed",
                    bar.name, p.point.x[0], p.point.x[1], model.steps[k].name
                ),
            ));
        }
    }
    Ok(())
}

/// The stage table `segfem check` prints: per step, what it activates and removes.
pub fn table(model: &Model) -> Option<String> {
    let st = &model.staging;
    if !st.is_staged() {
        return None;
    }
    let mut s = String::from("Construction stages:\n");
    for (k, step) in model.steps.iter().enumerate() {
        let mut on = Vec::new();
        let mut off = Vec::new();
        for (r, region) in model.regions.iter().enumerate() {
            let l = st.region(r);
            if l.from == k && k > 0 {
                on.push(region.name.clone());
            }
            if l.until == Some(k) {
                off.push(region.name.clone());
            }
        }
        for (i, sp) in model.supports.iter().enumerate() {
            let l = st.support(i);
            if l.from == k && k > 0 {
                on.push(format!("support {}", sp.name));
            }
            if l.until == Some(k) {
                off.push(format!("support {}", sp.name));
            }
        }
        let n_el = model
            .elements
            .iter()
            .filter(|e| st.region(e.region).active_in(k))
            .count();
        s.push_str(&format!(
            "  {:>3} {:<20} {:>6} elements active",
            k + 1,
            step.name,
            n_el
        ));
        if !on.is_empty() {
            s.push_str(&format!("; activates {}", on.join(", ")));
        }
        if !off.is_empty() {
            s.push_str(&format!("; removes {}", off.join(", ")));
        }
        s.push('\n');
    }
    Some(s)
}
