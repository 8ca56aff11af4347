//! `[[influence]]`: influence lines of monitors for a unit downward load moved along a
//! line of nodes, taken on the tangent stiffness at the end of a step; traffic models
//! (`[[influence.traffic]]`) enveloped over them and load combinations
//! (`[[influence.combinations]]`) of the state and the envelopes.

use super::fields::{index_by_name, positive, unique_names};
use super::R;
use crate::input::error::Ctx;
use crate::input::locate;
use crate::input::schema::{CombinationIn, File, InfluenceIn, PlaceIn, TrafficIn};
use crate::model::{Combination, Influence, Model, MonitorKind, Placement, StressComponent};
use crate::traffic::{self, Traffic};

/// The influence tables, resolved against the steps and monitors.
pub(super) fn build(ctx: &Ctx, file: &File, model: &mut Model, used: &[bool]) -> R<()> {
    unique_names(
        ctx,
        "influence",
        file.influence.iter().map(|t| t.name.as_str()),
    )?;
    let mut placed = vec![false; model.load_cases.len()];
    for (i, t) in file.influence.iter().enumerate() {
        let inf = table(ctx, i, t, model, used)?;
        for (j, p) in inf.place.iter().enumerate() {
            if std::mem::replace(&mut placed[p.case], true) {
                return Err(ctx.err(
                    format!("influence[{i}].place[{j}].case"),
                    format!(
                        "load case '{}' is placed twice: one placement per load case",
                        model.load_cases[p.case].name
                    ),
                ));
            }
        }
        model.influence.push(inf);
    }
    Ok(())
}

/// `influence[i]`.
fn table(ctx: &Ctx, i: usize, t: &InfluenceIn, model: &Model, used: &[bool]) -> R<Influence> {
    let key = format!("influence[{i}]");
    if t.name.is_empty()
        || !t
            .name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
    {
        return Err(ctx.err(
            format!("{key}.name"),
            format!(
                "'{}': the name goes into file names (influence_<name>.csv); use letters, digits, '-' and '_'",
                t.name
            ),
        ));
    }
    let after = t.after_step.as_deref().ok_or_else(|| {
        ctx.err(
            format!("{key}.after_step"),
            "missing: the step at whose end the influence lines are taken",
        )
    })?;
    let after_step = index_by_name(
        ctx,
        &format!("{key}.after_step"),
        "step",
        model.steps.iter().map(|s| s.name.as_str()),
        after,
    )?;
    let [a, b] = t.line.ok_or_else(|| {
        ctx.err(
            format!("{key}.line"),
            "missing: the path of the unit load, [[x1, y1], [x2, y2]] along the deck's top",
        )
    })?;
    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    if !(len > 0.0 && len.is_finite()) {
        return Err(ctx.err(
            format!("{key}.line"),
            "the two points coincide: give the start and the end of the path",
        ));
    }
    let along = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
    let mut path: Vec<(usize, f64)> = locate::nodes_on_segment(model, used, a, b)
        .into_iter()
        .map(|n| {
            let p = model.nodes[n];
            (n, (p[0] - a[0]) * along[0] + (p[1] - a[1]) * along[1])
        })
        .collect();
    path.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
    // Coincident nodes (the two faces of a joint): the load on the first only.
    let tol = 1e-6 * locate::model_size(model);
    path.dedup_by(|later, kept| (later.1 - kept.1).abs() <= tol);
    if path.len() < 2 {
        return Err(ctx.err(
            format!("{key}.line"),
            format!(
                "{} node(s) lie on the segment {a:?}–{b:?}: a path needs at least two",
                path.len()
            ),
        ));
    }
    let joints = t.joints.unwrap_or(false);
    if joints && model.joints.is_empty() {
        return Err(ctx.err(format!("{key}.joints"), "the model has no joints"));
    }
    let fibres = t.fibres.unwrap_or(false);
    let monitors = if (joints || fibres) && t.monitors.is_none() {
        // The joints' or fibres' lines alone are enough: the monitors with a line, if any.
        (0..model.monitors.len())
            .filter(|&m| linear(model, &model.monitors[m].kind))
            .collect()
    } else {
        monitors(ctx, &key, t, model)?
    };
    unique_names(
        ctx,
        &format!("{key}.traffic"),
        t.traffic.iter().map(|x| x.name.as_str()),
    )?;
    let traffic = t
        .traffic
        .iter()
        .enumerate()
        .map(|(j, x)| {
            let length = path[path.len() - 1].1 - path[0].1;
            traffic_model(ctx, &format!("{key}.traffic[{j}]"), x, length)
        })
        .collect::<R<Vec<_>>>()?;
    unique_names(
        ctx,
        &format!("{key}.combinations"),
        t.combinations.iter().map(|x| x.name.as_str()),
    )?;
    let combinations = t
        .combinations
        .iter()
        .enumerate()
        .map(|(j, c)| combination(ctx, &format!("{key}.combinations[{j}]"), c, &traffic))
        .collect::<R<Vec<_>>>()?;
    let place = t
        .place
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let k = format!("{key}.place[{j}]");
            placement(ctx, &k, p, model, &monitors, &traffic, after_step)
        })
        .collect::<R<Vec<_>>>()?;
    Ok(Influence {
        name: t.name.clone(),
        after_step,
        from: a,
        along,
        path,
        monitors,
        joints,
        fibres,
        traffic,
        combinations,
        place,
    })
}

/// The monitors named by `monitors` (all with an influence line when absent), each of a
/// kind linear in the displacements.
fn monitors(ctx: &Ctx, key: &str, t: &InfluenceIn, model: &Model) -> R<Vec<usize>> {
    let Some(names) = &t.monitors else {
        let all: Vec<usize> = (0..model.monitors.len())
            .filter(|&m| linear(model, &model.monitors[m].kind))
            .collect();
        if all.is_empty() {
            return Err(ctx.err(
                format!("{key}.monitors"),
                "the model has no monitor with an influence line (displacement, reaction, stress at a point of sx, sy or txy, tendon_stress or tendon_force of one span or point, bar_stress at a point)",
            ));
        }
        return Ok(all);
    };
    if names.is_empty() {
        return Err(ctx.err(
            format!("{key}.monitors"),
            "empty: name at least one monitor",
        ));
    }
    names
        .iter()
        .enumerate()
        .map(|(j, n)| {
            let k = format!("{key}.monitors[{j}]");
            let m = index_by_name(
                ctx,
                &k,
                "monitor",
                model.monitors.iter().map(|m| m.name.as_str()),
                n,
            )?;
            if !linear(model, &model.monitors[m].kind) {
                return Err(ctx.err(
                    k,
                    format!(
                        "monitor '{n}' has no influence line: its value is not linear in the displacements (a load factor, a loss, a joint opening, an extreme over a region or over spans, a principal stress); use displacement, reaction, stress at a point (sx, sy, txy), tendon_stress or tendon_force of one span or point, bar_stress at a point"
                    ),
                ));
            }
            Ok(m)
        })
        .collect()
}

/// Whether a monitor's change under a small extra load is linear in the displacement change
/// (so that it has an influence line on the tangent stiffness).
pub(crate) fn linear(model: &Model, kind: &MonitorKind) -> bool {
    match kind {
        MonitorKind::Displacement { .. } | MonitorKind::Reaction { .. } => true,
        MonitorKind::StressAtPoint { component, .. } => matches!(
            component,
            StressComponent::Sx | StressComponent::Sy | StressComponent::Txy
        ),
        MonitorKind::TendonStress { tendon, span } | MonitorKind::TendonForce { tendon, span } => {
            span.is_some() || model.tendons[*tendon].nodes.len() == 2
        }
        MonitorKind::BarStress { point, .. } | MonitorKind::BarForce { point, .. } => {
            point.is_some()
        }
        _ => false,
    }
}

/// A placement (`influence[i].place[j]`): an empty load case, unused up to the step the
/// lines are taken after, a traffic model, one of the table's monitors and an extreme.
fn placement(
    ctx: &Ctx,
    key: &str,
    p: &PlaceIn,
    model: &Model,
    monitors: &[usize],
    traffic: &[Traffic],
    after_step: usize,
) -> R<Placement> {
    let case = index_by_name(
        ctx,
        &format!("{key}.case"),
        "load case",
        model.load_cases.iter().map(|c| c.name.as_str()),
        &p.case,
    )?;
    let c = &model.load_cases[case];
    if !c.point_forces.is_empty()
        || !c.edge_loads.is_empty()
        || c.gravity.is_some()
        || c.thermal.is_some()
    {
        return Err(ctx.err(
            format!("{key}.case"),
            format!(
                "load case '{}' has loads of its own: a placed case is declared empty (`[[load_cases]]` with its name only) and takes the traffic's loads",
                c.name
            ),
        ));
    }
    if let Some(s) = model.steps[..=after_step]
        .iter()
        .find(|s| s.factors[case] != 0.0)
    {
        return Err(ctx.err(
            format!("{key}.case"),
            format!(
                "load case '{}' acts in step '{}', before its loads are placed at the end of step '{}': use it in later steps only",
                c.name, s.name, model.steps[after_step].name
            ),
        ));
    }
    let t = match &p.traffic {
        Some(n) => index_by_name(
            ctx,
            &format!("{key}.traffic"),
            "traffic model",
            traffic.iter().map(|t| t.name.as_str()),
            n,
        )?,
        None if traffic.len() == 1 => 0,
        None => {
            return Err(ctx.err(
                format!("{key}.traffic"),
                "missing: name the traffic model to place (the table has none or several)",
            ))
        }
    };
    let monitor = monitors
        .iter()
        .position(|&m| model.monitors[m].name == p.monitor)
        .ok_or_else(|| {
            ctx.err(
                format!("{key}.monitor"),
                format!(
                    "'{}' is not one of the table's monitors ({})",
                    p.monitor,
                    monitors
                        .iter()
                        .map(|&m| model.monitors[m].name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
    let max = match p.extreme.as_str() {
        "max" => true,
        "min" => false,
        o => {
            return Err(ctx.err(
                format!("{key}.extreme"),
                format!("unknown extreme '{o}' (expected max or min)"),
            ))
        }
    };
    Ok(Placement {
        case,
        traffic: t,
        monitor,
        max,
    })
}

/// A traffic model (`influence[i].traffic[j]`) on a path `length` [m] long.
fn traffic_model(ctx: &Ctx, key: &str, x: &TrafficIn, length: f64) -> R<Traffic> {
    let given = |name: &str, v: bool| -> R<()> {
        if v {
            Err(ctx.err(
                format!("{key}.{name}"),
                format!("not a key of model '{}'", x.model),
            ))
        } else {
            Ok(())
        }
    };
    let width = || -> R<f64> {
        let w = x.carriageway_width.ok_or_else(|| {
            ctx.err(
                format!("{key}.carriageway_width"),
                "missing: the carriageway (roadway) width between kerbs or barriers [m], which sets the lanes",
            )
        })?;
        positive(ctx, &format!("{key}.carriageway_width"), w)
    };
    let factors = |name: &str, v: Option<[f64; 3]>| -> R<[f64; 3]> {
        let v = v.unwrap_or([1.0; 3]);
        if v.iter().any(|a| !(a.is_finite() && *a >= 0.0)) {
            return Err(ctx.err(
                format!("{key}.{name}"),
                format!("adjustment factors must be numbers ≥ 0 (got {v:?})"),
            ));
        }
        Ok(v)
    };
    let impact = |default: f64| -> R<f64> {
        let im = x.impact.unwrap_or(default);
        if !(im.is_finite() && im >= 0.0) {
            return Err(ctx.err(
                format!("{key}.impact"),
                format!("must be a number ≥ 0, a fraction of the axle loads (got {im})"),
            ));
        }
        Ok(im)
    };
    let vehicle_keys = x.loads.is_some() || x.spacings.is_some() || x.lane_load.is_some();
    match x.model.as_str() {
        "lm1" => {
            given("impact", x.impact.is_some())?;
            given("loads", vehicle_keys)?;
            given("lanes", x.lanes.is_some())?;
            Ok(traffic::lm1(
                &x.name,
                width()?,
                factors("alpha_Q", x.alpha_big_q)?,
                factors("alpha_q", x.alpha_q)?,
            ))
        }
        "hl93" | "hl93_two_trucks" => {
            given("alpha_Q", x.alpha_big_q.is_some() || x.alpha_q.is_some())?;
            given("loads", vehicle_keys)?;
            given("lanes", x.lanes.is_some())?;
            let (w, im) = (width()?, impact(traffic::HL93_IM)?);
            Ok(if x.model == "hl93" {
                traffic::hl93(&x.name, w, im)
            } else {
                traffic::hl93_two_trucks(&x.name, w, im, length)
            })
        }
        "vehicle" => {
            given("carriageway_width", x.carriageway_width.is_some())?;
            given("alpha_Q", x.alpha_big_q.is_some() || x.alpha_q.is_some())?;
            user_vehicle(ctx, key, x, impact(0.0)?)
        }
        o => Err(ctx.err(
            format!("{key}.model"),
            format!("unknown traffic model '{o}' (expected lm1, hl93, hl93_two_trucks or vehicle)"),
        )),
    }
}

/// A user vehicle: axle loads, spacings, optional lane load and number of lanes.
fn user_vehicle(ctx: &Ctx, key: &str, x: &TrafficIn, impact: f64) -> R<Traffic> {
    let loads = x.loads.as_deref().unwrap_or(&[]);
    if loads.is_empty() {
        return Err(ctx.err(
            format!("{key}.loads"),
            "missing: the axle loads [N], first axle first",
        ));
    }
    for (j, p) in loads.iter().enumerate() {
        positive(ctx, &format!("{key}.loads[{j}]"), *p)?;
    }
    let spacings = x.spacings.as_deref().unwrap_or(&[]);
    if spacings.len() + 1 != loads.len() {
        return Err(ctx.err(
            format!("{key}.spacings"),
            format!(
                "{} spacing(s) for {} axles: give one fewer spacing than axles [m]",
                spacings.len(),
                loads.len()
            ),
        ));
    }
    for (j, s) in spacings.iter().enumerate() {
        if !(s.is_finite() && *s >= 0.0) {
            return Err(ctx.err(
                format!("{key}.spacings[{j}]"),
                format!("must be a distance ≥ 0 [m] (got {s})"),
            ));
        }
    }
    let lane_load = x.lane_load.unwrap_or(0.0);
    if !(lane_load.is_finite() && lane_load >= 0.0) {
        return Err(ctx.err(
            format!("{key}.lane_load"),
            format!("must be a line load ≥ 0 [N/m] (got {lane_load})"),
        ));
    }
    let lanes = match x.lanes {
        Some(l) => positive(ctx, &format!("{key}.lanes"), l)?,
        None => 1.0,
    };
    Ok(traffic::user_vehicle(
        &x.name, loads, spacings, impact, lane_load, lanes,
    ))
}

/// A combination (`influence[i].combinations[j]`): a code kind or user factors.
fn combination(ctx: &Ctx, key: &str, c: &CombinationIn, traffic: &[Traffic]) -> R<Combination> {
    let t = match &c.traffic {
        Some(n) => index_by_name(
            ctx,
            &format!("{key}.traffic"),
            "traffic model",
            traffic.iter().map(|t| t.name.as_str()),
            n,
        )?,
        None if traffic.len() == 1 => 0,
        None => {
            return Err(ctx.err(
                format!("{key}.traffic"),
                format!(
                    "missing: name the traffic model the combination takes ({})",
                    if traffic.is_empty() {
                        "the table has none: add an [[influence.traffic]]".to_string()
                    } else {
                        traffic
                            .iter()
                            .map(|t| t.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
            ))
        }
    };
    let user = c.state.is_some() || c.vehicle.is_some() || c.lane.is_some();
    let factors = match c.kind.as_str() {
        "user" => {
            let f = |name: &str, v: Option<f64>| -> R<f64> {
                let v = v.ok_or_else(|| {
                    ctx.err(
                        format!("{key}.{name}"),
                        "missing (a user combination gives state, vehicle and lane factors)",
                    )
                })?;
                if v.is_finite() && v >= 0.0 {
                    Ok(v)
                } else {
                    Err(ctx.err(
                        format!("{key}.{name}"),
                        format!("must be a factor ≥ 0 (got {v})"),
                    ))
                }
            };
            (
                f("state", c.state)?,
                f("vehicle", c.vehicle)?,
                f("lane", c.lane)?,
            )
        }
        kind => {
            if user {
                return Err(ctx.err(
                    format!("{key}.kind"),
                    format!("kind '{kind}' has its factors from the code: give state, vehicle and lane only with kind = \"user\""),
                ));
            }
            code_factors(kind).ok_or_else(|| {
                ctx.err(
                    format!("{key}.kind"),
                    format!("unknown combination kind '{kind}' (expected characteristic, frequent, quasi_permanent, uls, service_i, service_iii, strength_i or user)"),
                )
            })?
        }
    };
    Ok(Combination {
        name: c.name.clone(),
        traffic: t,
        state: factors.0,
        vehicle: factors.1,
        lane: factors.2,
    })
}

/// The code combinations' factors (state, vehicle part, lane part) with traffic leading:
/// EN 1990 6.5.3 and Annex A2 (Table A2.1: ψ1 = 0.75 tandems, 0.40 UDL, ψ2 = 0; Table
/// A2.4(B): γG,sup = 1.35, γQ = 1.35) and AASHTO LRFD Table 3.4.1-1 (Service I: DC 1.0,
/// LL+IM 1.0; Service III: LL+IM 0.8; Strength I: DC 1.25, LL+IM 1.75).
pub(crate) fn code_factors(kind: &str) -> Option<(f64, f64, f64)> {
    Some(match kind {
        "characteristic" => (1.0, 1.0, 1.0),
        "frequent" => (1.0, 0.75, 0.40),
        "quasi_permanent" => (1.0, 0.0, 0.0),
        "uls" => (1.35, 1.35, 1.35),
        "service_i" => (1.0, 1.0, 1.0),
        "service_iii" => (1.0, 0.8, 0.8),
        "strength_i" => (1.25, 1.75, 1.75),
        _ => return None,
    })
}
