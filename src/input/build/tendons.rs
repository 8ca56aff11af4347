//! `[[tendons]]`: external tendons (chains of spans between anchors and deviators, stressed
//! with friction losses); the steel, jacking and relaxation checks shared with bonded and
//! pre-tensioned tendons (built as bars, in `bars`).

use super::anchorage::{self, LocalZone};
use super::fields::{index_by_name, positive, unique_names};
use super::R;
use crate::elements::tendon::{DeviatorMode, ExternalTendon, TendonLaw};
use crate::input::error::{Ctx, InputError};
use crate::input::schema::TendonIn;
use crate::input::{locate, units};
use crate::materials::steel::SteelParams;
use crate::model::{Model, TendonEl};
use crate::prestress::friction::{jacking_profile, AnchorEnd, FrictionParams, Jacking, TendonPath};

/// The external `[[tendons]]` into `model.tendons` (bonded and pre-tensioned ones are built
/// as bars); returns, per input tendon, its index in `model.tendons`.
pub(super) fn build_external(
    ctx: &Ctx,
    list: &[TendonIn],
    model: &mut Model,
    used: &[bool],
    zones: &mut Vec<LocalZone>,
    warnings: &mut Vec<String>,
) -> R<Vec<Option<usize>>> {
    unique_names(ctx, "tendons", list.iter().map(|t| t.name.as_str()))?;
    // A prestress below 1 MPa is a unit slip (MPa for Pa), as the moduli are checked.
    for (i, t) in list.iter().enumerate() {
        if let Some(s) = t.initial_stress.filter(|s| *s > 0.0 && *s < 1e6) {
            warnings.push(format!(
                "{}: tendons[{i}].initial_stress: {s} Pa looks like MPa; segfem works in Pa",
                ctx.file
            ));
        }
    }
    // External tendons go to `model.tendons`; bonded post-tensioned ones become bars (below).
    let mut external_of = vec![None; list.len()];
    for (i, t) in list.iter().enumerate() {
        if is_bonded_kind(&t.kind) {
            continue;
        }
        let tendon = build_tendon(ctx, i, t, model, used, zones, warnings)?;
        external_of[i] = Some(model.tendons.len());
        model.tendons.push(tendon);
    }
    Ok(external_of)
}

/// The steps tendons are stressed (and ducts grouted) in, once the steps are known.
pub(super) fn assign_steps(
    ctx: &Ctx,
    list: &[TendonIn],
    external_of: &[Option<usize>],
    model: &mut Model,
) -> R<()> {
    for (i, t) in list.iter().enumerate() {
        if t.kind == "pretensioned" {
            continue;
        }
        let step_of = |key: &str, name: &str| {
            index_by_name(
                ctx,
                &format!("tendons[{i}].{key}"),
                "step",
                model.steps.iter().map(|s| s.name.as_str()),
                name,
            )
        };
        let stressed = match &t.stressed_in_step {
            Some(name) => step_of("stressed_in_step", name)?,
            None => 0,
        };
        let grouted = match &t.grouted_in_step {
            Some(name) => Some(step_of("grouted_in_step", name)?),
            None => None,
        };
        match external_of[i] {
            Some(e) => model.tendons[e].stressed_in_step = stressed,
            None => {
                if grouted.is_some_and(|g| g <= stressed) {
                    return Err(ctx.err(
                        format!("tendons[{i}].grouted_in_step"),
                        format!(
                            "tendon '{}': the duct is grouted after stressing: name a step after '{}'",
                            t.name, model.steps[stressed].name
                        ),
                    ));
                }
                let bar = model
                    .bars
                    .iter_mut()
                    .find(|b| b.name == t.name && b.post_tension.is_some())
                    .expect("bonded tendons are built with the bars");
                let pt = bar.post_tension.as_mut().expect("checked");
                pt.stressed_in_step = stressed;
                pt.grouted_in_step = grouted;
            }
        }
    }
    Ok(())
}

/// Area [m²], E_p [Pa] and f_ptk [Pa] of a bonded or pre-tensioned tendon (`key` =
/// "tendons[i]", `named` = how messages name it): positive, an area that is one (≤ 0.1 m²),
/// f_ptk below E_p (catches MPa given for Pa).
pub(super) fn tendon_steel(
    ctx: &Ctx,
    key: &str,
    named: &str,
    t: &TendonIn,
) -> Result<(f64, f64, f64), InputError> {
    let k = |f: &str| format!("{key}.{f}");
    let area = positive(ctx, &k("area"), t.area)?;
    if area > 0.1 {
        return Err(ctx.err(
            k("area"),
            format!("{named}: {area} m² is not a tendon area (units are m²)"),
        ));
    }
    let ep = positive(ctx, &k("Ep"), t.ep)?;
    let fptk = positive(ctx, &k("fptk"), t.fptk)?;
    if fptk >= ep {
        return Err(ctx.err(
            k("fptk"),
            format!("{named}: must be far below Ep (units are Pa)"),
        ));
    }
    Ok((area, ep, fptk))
}

/// The steel law of tendon `t` (`key` = "tendons[i]"): yield at 0.9 f_ptk, perfectly
/// plastic, or with `eps_uk` linear hardening to f_ptk at ε_uk (> 0.9 f_ptk/E_p, < 0.1).
pub(super) fn tendon_law(
    ctx: &Ctx,
    key: &str,
    named: &str,
    t: &TendonIn,
    ep: f64,
    fptk: f64,
) -> R<SteelParams> {
    match t.eps_uk {
        None => Ok(SteelParams::prestressing(ep, fptk)),
        Some(e) if e.is_finite() && e > 0.9 * fptk / ep && e < 0.1 => {
            Ok(SteelParams::prestressing_hardening(ep, fptk, e))
        }
        Some(e) => Err(ctx.err(
            format!("{key}.eps_uk"),
            format!(
                "{named}: must lie between the yield strain 0.9 fptk/Ep = {:.5} and 0.1 (got {e})",
                0.9 * fptk / ep
            ),
        )),
    }
}

/// An external tendon: points snapped to the nearest concrete nodes, span stresses after
/// friction losses.
pub(super) fn build_tendon(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    model: &Model,
    used: &[bool],
    zones: &mut Vec<LocalZone>,
    warnings: &mut Vec<String>,
) -> R<TendonEl> {
    let k = |f: &str| format!("tendons[{i}].{f}");
    if t.kind != "external" {
        return Err(ctx.err(
            k("kind"),
            format!(
                "unknown tendon kind '{}' (expected external, bonded or pretensioned)",
                t.kind
            ),
        ));
    }
    for (key, given) in [
        ("parabola", t.parabola.is_some()),
        ("arc", t.arc.is_some()),
        ("segments", t.segments.is_some()),
        ("grouted_in_step", t.grouted_in_step.is_some()),
        ("gauss_points", t.gauss_points.is_some()),
    ] {
        if given {
            return Err(ctx.err(
                k(key),
                "only for kind = \"bonded\": an external tendon is a chain of straight spans through its points",
            ));
        }
    }
    if t.points.len() < 2 {
        return Err(ctx.err(k("points"), "needs at least the two anchors"));
    }
    let area = positive(ctx, &k("area"), t.area)?;
    let ep = positive(ctx, &k("Ep"), t.ep)?;
    let fptk = positive(ctx, &k("fptk"), t.fptk)?;
    units::modulus(warnings, ctx, &k("Ep"), ep);
    units::strength(warnings, ctx, &k("fptk"), fptk);
    let steel = tendon_law(
        ctx,
        &format!("tendons[{i}]"),
        &format!("tendon '{}'", t.name),
        t,
        ep,
        fptk,
    )?;
    let nodes = tendon_nodes(ctx, i, t, model, used, warnings)?;
    let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| model.nodes[n]).collect();
    let ties = anchor_ties(ctx, i, t, model, &nodes, area, zones, warnings)?;
    let span_stress = span_stresses(ctx, i, t, &coords, area, ep, fptk)?;
    let mode = deviator_mode(ctx, i, t)?;
    // Check the element can be built (zero-length spans, etc.).
    ExternalTendon::new(
        &coords,
        area,
        ep,
        span_stress[0],
        TendonLaw::from_steel(&steel),
        mode,
    )
    .map_err(|e| ctx.err(k("points"), e.to_string()))?;
    let relaxation = relaxation_of(
        ctx,
        &k("relaxation_class"),
        t.relaxation_class,
        &span_stress,
        fptk,
        ep,
    )?;
    Ok(TendonEl {
        relaxation,
        name: t.name.clone(),
        nodes,
        ties,
        area,
        ep,
        fptk,
        steel,
        span_stress,
        mode,
        stressed_in_step: 0,
    })
}

/// The nodes of an external tendon: each point snapped to the nearest node in use (a warning
/// when it is not on one).
fn tendon_nodes(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    model: &Model,
    used: &[bool],
    warnings: &mut Vec<String>,
) -> R<Vec<usize>> {
    let k = |f: &str| format!("tendons[{i}].{f}");
    let size = locate::model_size(model);
    let mut nodes = Vec::new();
    for (j, p) in t.points.iter().enumerate() {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(ctx.err(
                format!("{}[{j}]", k("points")),
                "must be finite numbers [m]",
            ));
        }
        if !locate::inside_mesh(model, *p) {
            return Err(ctx.err(
                format!("{}[{j}]", k("points")),
                format!("point {p:?} lies outside the mesh"),
            ));
        }
        let n = locate::nearest_node(model, used, *p);
        let q = model.nodes[n];
        let d = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
        if d > 1e-6 * size {
            warnings.push(format!(
                "{}: {}[{j}]: tendon point {p:?} tied to the nearest node at {q:?} ({d:.4} m away)",
                ctx.file,
                k("points")
            ));
        }
        if nodes.last() == Some(&n) {
            return Err(ctx.err(
                format!("{}[{j}]", k("points")),
                "two consecutive tendon points fall on the same node",
            ));
        }
        nodes.push(n);
    }
    Ok(nodes)
}

/// The initial stress of each span of an external tendon through `coords` [m]: given, or
/// after friction (and anchorage set) from the jacking stress.
fn span_stresses(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    coords: &[[f64; 2]],
    area: f64,
    ep: f64,
    fptk: f64,
) -> R<Vec<f64>> {
    let k = |f: &str| format!("tendons[{i}].{f}");
    let n_spans = coords.len() - 1;
    let jacking_stress = jacking_stress_of(ctx, i, t, area, fptk)?;
    let span_stress = match (t.initial_stress, jacking_stress) {
        (Some(s), None) => {
            if !(s.is_finite() && s >= 0.0 && s < 0.9 * fptk) {
                return Err(ctx.err(
                    k("initial_stress"),
                    format!("must lie in [0, 0.9 fptk) (got {s} Pa)"),
                ));
            }
            if t.friction.is_some()
                || t.wobble.is_some()
                || t.jacking.is_some()
                || t.anchorage_set.is_some()
            {
                return Err(ctx.err(
                    k("friction"),
                    "friction, wobble, jacking and anchorage_set go with jacking_stress or jacking_force, not initial_stress",
                ));
            }
            vec![s; n_spans]
        }
        (None, Some(s)) => {
            let (friction, jacking, draw_in) = friction_of(ctx, i, t)?;
            let path =
                TendonPath::from_points(coords).map_err(|e| ctx.err(k("points"), e.to_string()))?;
            let mut profile = jacking_profile(&path, s, &friction, jacking);
            if draw_in > 0.0 {
                let ends: &[AnchorEnd] = match jacking {
                    Jacking::Start => &[AnchorEnd::Start],
                    Jacking::End => &[AnchorEnd::End],
                    Jacking::Both => &[AnchorEnd::Start, AnchorEnd::End],
                };
                for &end in ends {
                    profile = profile
                        .with_anchorage_set(end, draw_in, ep)
                        .map_err(|e| ctx.err(k("anchorage_set"), e.to_string()))?
                        .profile;
                }
            }
            profile.segment_means()
        }
        (Some(_), Some(_)) | (None, None) => {
            return Err(ctx.err(
                k("initial_stress"),
                "give exactly one of initial_stress, jacking_stress or jacking_force",
            ))
        }
    };
    Ok(span_stress)
}

/// How an external tendon slides at its deviators (`deviators`, default held).
fn deviator_mode(ctx: &Ctx, i: usize, t: &TendonIn) -> R<DeviatorMode> {
    let k = |f: &str| format!("tendons[{i}].{f}");
    let mode = match t.deviators.as_deref() {
        None | Some("held") => DeviatorMode::Held,
        Some("frictionless") => DeviatorMode::Frictionless,
        Some("friction") => {
            let mu = t.deviator_friction.ok_or_else(|| {
                ctx.err(
                    k("deviator_friction"),
                    "missing for deviators = \"friction\"",
                )
            })?;
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(ctx.err(k("deviator_friction"), "must be zero or positive"));
            }
            DeviatorMode::Friction { mu }
        }
        Some(o) => {
            return Err(ctx.err(
                k("deviators"),
                format!("unknown value '{o}' (expected held, frictionless or friction)"),
            ))
        }
    };
    Ok(mode)
}

/// True for the tendon kinds that are embedded bars (bonded post-tensioned, pre-tensioned).
pub(super) fn is_bonded_kind(kind: &str) -> bool {
    kind == "bonded" || kind == "pretensioned"
}

/// The relaxation class `class` of a tendon (key `key`), checked to be representable at each
/// of the initial `stresses` [Pa] (None = no relaxation).
pub(super) fn relaxation_of(
    ctx: &Ctx,
    key: &str,
    class: Option<i64>,
    stresses: &[f64],
    fptk: f64,
    ep: f64,
) -> R<Option<crate::materials::mc90_time::RelaxationClass>> {
    use crate::materials::mc90_time::RelaxationClass;
    let Some(c) = class else { return Ok(None) };
    let class = match c {
        1 => RelaxationClass::Class1,
        2 => RelaxationClass::Class2,
        3 => RelaxationClass::Class3,
        o => {
            return Err(ctx.err(
                key,
                format!("unknown relaxation class {o} (expected 1 = normal strands/wires, 2 = low relaxation, 3 = bars)"),
            ))
        }
    };
    for &s in stresses {
        crate::materials::chain::SteelRelaxationChain::fit(class, s / fptk, ep).map_err(|e| {
            ctx.err(
                key,
                format!("relaxation at {s} Pa cannot be represented: {e}"),
            )
        })?;
    }
    Ok(Some(class))
}

/// The stress at the jack from `jacking_stress` or `jacking_force` / area (None if neither),
/// checked to lie in (0, 0.9 fptk).
pub(super) fn jacking_stress_of(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    area: f64,
    fptk: f64,
) -> R<Option<f64>> {
    let k = |f: &str| format!("tendons[{i}].{f}");
    let (key, s) = match (t.jacking_stress, t.jacking_force) {
        (None, None) => return Ok(None),
        (Some(s), None) => ("jacking_stress", s),
        (None, Some(f)) => ("jacking_force", f / area),
        (Some(_), Some(_)) => {
            return Err(ctx.err(
                k("jacking_force"),
                "give jacking_stress or jacking_force, not both",
            ))
        }
    };
    if !(s.is_finite() && s > 0.0 && s < 0.9 * fptk) {
        return Err(ctx.err(
            k(key),
            format!(
                "the stress at the jack must lie in (0, 0.9 fptk) = (0, {:.4e}) Pa (got {s:.4e} Pa)",
                0.9 * fptk
            ),
        ));
    }
    Ok(Some(s))
}

/// Friction parameters, jacked end(s) and anchorage set of a tendon stressed with a jack.
pub(super) fn friction_of(ctx: &Ctx, i: usize, t: &TendonIn) -> R<(FrictionParams, Jacking, f64)> {
    let k = |f: &str| format!("tendons[{i}].{f}");
    let mu = t.friction.unwrap_or(0.0);
    if !(mu >= 0.0 && mu.is_finite()) {
        return Err(ctx.err(
            k("friction"),
            format!("must be zero or positive (got {mu})"),
        ));
    }
    let wobble = t.wobble.unwrap_or(crate::prestress::friction::SEED_WOBBLE);
    if !(wobble >= 0.0 && wobble.is_finite()) {
        return Err(ctx.err(
            k("wobble"),
            format!("must be zero or positive [rad/m] (got {wobble})"),
        ));
    }
    let jacking = match t.jacking.as_deref() {
        None | Some("both") => Jacking::Both,
        Some("start") => Jacking::Start,
        Some("end") => Jacking::End,
        Some(o) => {
            return Err(ctx.err(
                k("jacking"),
                format!("unknown value '{o}' (expected start, end or both)"),
            ))
        }
    };
    let draw_in = t.anchorage_set.unwrap_or(0.0);
    if !(draw_in >= 0.0 && draw_in.is_finite()) {
        return Err(ctx.err(
            k("anchorage_set"),
            format!("must be zero or positive [m] (got {draw_in})"),
        ));
    }
    if draw_in > 0.05 {
        return Err(ctx.err(
            k("anchorage_set"),
            format!("{draw_in} m is not a wedge draw-in (units are m; typical 0.004–0.008)"),
        ));
    }
    Ok((FrictionParams { mu, wobble }, jacking, draw_in))
}

/// The anchor plate of tendon `t` [m]: `anchor_plate` (0: the anchor at its node alone), or
/// the default from the strand count ([`anchorage::default_plate`]).
pub(super) fn anchor_plate(ctx: &Ctx, key: &str, t: &TendonIn, area: f64) -> R<f64> {
    match t.anchor_plate {
        None => Ok(anchorage::default_plate(area)),
        Some(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Some(v) => Err(ctx.err(
            format!("{key}.anchor_plate"),
            format!("must be a plate size ≥ 0 in m (0: no plate; got {v})"),
        )),
    }
}

/// The ties of an external tendon's points: each anchor spread over the nodes under its
/// plate (along the element edge through the anchor most nearly perpendicular to the
/// tendon), the deviators on their own nodes; the local zones behind the plates.
#[allow(clippy::too_many_arguments)]
fn anchor_ties(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    model: &Model,
    nodes: &[usize],
    area: f64,
    zones: &mut Vec<LocalZone>,
    warnings: &mut Vec<String>,
) -> R<Vec<Vec<(usize, f64)>>> {
    let key = format!("tendons[{i}]");
    let plate = anchor_plate(ctx, &key, t, area)?;
    let mut ties: Vec<Vec<(usize, f64)>> = nodes.iter().map(|&n| vec![(n, 1.0)]).collect();
    if plate == 0.0 {
        return Ok(ties);
    }
    let m = nodes.len() - 1;
    for (p, q) in [(0, 1), (m, m - 1)] {
        let (a, b) = (model.nodes[nodes[p]], model.nodes[nodes[q]]);
        let l = (b[0] - a[0]).hypot(b[1] - a[1]);
        let axis = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
        let s = anchorage::spread(model, nodes[p], axis, plate);
        // A given plate that overhangs the member is warned about; the default plate is a
        // size rule and is limited to the member without a word (docs/input.md).
        if t.anchor_plate.is_some() && s.covered < (1.0 - 1e-6) * plate {
            warnings.push(format!(
                "{}: {key}.anchor_plate: the {plate:.3} m plate at ({:.3}, {:.3}) lies on element edges over {:.3} m only (the mesh ends): the force is spread over that part",
                ctx.file, a[0], a[1], s.covered
            ));
        }
        ties[p] = s.weights;
        if t.local_zone != Some(false) {
            zones.push(LocalZone {
                centre: a,
                axis,
                plate,
                kind: super::anchorage::ZoneKind::Anchor,
            });
        }
    }
    Ok(ties)
}
