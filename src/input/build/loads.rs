//! `[[load_cases]]`: gravity, point loads, line loads along element edges and thermal
//! actions (temperature fields, imposed strains).

use super::anchorage::{self, LocalZone};
use super::fields::{locate_nodes, unique_names};
use super::R;
use crate::input::error::Ctx;
use crate::input::gmsh_mesh;
use crate::input::locate;
use crate::input::schema::{File, LoadCaseIn, PointLoadIn};
use crate::model::{EdgeLoad, LoadCase, Model, PathControl};

/// The load cases, located in the mesh.
pub(super) fn build(
    ctx: &Ctx,
    list: &[LoadCaseIn],
    groups: &gmsh_mesh::Groups,
    model: &mut Model,
    used: &[bool],
    zones: &mut Vec<LocalZone>,
) -> R<()> {
    unique_names(ctx, "load_cases", list.iter().map(|c| c.name.as_str()))?;
    for (i, c) in list.iter().enumerate() {
        if c.gravity.is_some_and(|g| g.iter().any(|v| !v.is_finite())) {
            return Err(ctx.err(
                format!("load_cases[{i}].gravity"),
                "must be finite numbers [m/s²]",
            ));
        }
        let mut case = LoadCase {
            name: c.name.clone(),
            gravity: c.gravity,
            ..Default::default()
        };
        if let Some(t) = &c.temperature {
            case.thermal = Some(temperature(ctx, i, t, model)?);
        }
        for (j, p) in c.point_loads.iter().enumerate() {
            let key = format!("load_cases[{i}].point_loads[{j}]");
            if p.force.iter().any(|f| !f.is_finite()) {
                return Err(ctx.err(format!("{key}.force"), "must be finite numbers"));
            }
            let n = locate_nodes(ctx, &key, model, used, p.node, p.point, None)?[0];
            match bearing(ctx, &key, p, model, n, zones)? {
                Some(weights) => case.point_forces.extend(
                    weights
                        .into_iter()
                        .map(|(m, w)| (m, [w * p.force[0], w * p.force[1]])),
                ),
                None => case.point_forces.push((n, p.force)),
            }
        }
        for (j, l) in c.line_loads.iter().enumerate() {
            let key = format!("load_cases[{i}].line_loads[{j}]");
            if l.q.iter().any(|v| !v.is_finite()) {
                return Err(ctx.err(format!("{key}.q"), "must be finite numbers"));
            }
            let edges = match (&l.line, &l.group) {
                (Some([a, b]), None) => {
                    let (edges, covered) = locate::edges_on_segment(model, *a, *b);
                    let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                    if edges.is_empty()
                        || (covered - length).abs() > 1e-6 * locate::model_size(model)
                    {
                        return Err(ctx.err(
                            format!("{key}.line"),
                            format!(
                                "the segment {a:?}–{b:?} must run along element edges over its whole length (edges cover {covered:.6} m of {length:.6} m)"
                            ),
                        ));
                    }
                    edges
                }
                (None, Some(g)) => groups
                    .edges
                    .get(g)
                    .ok_or_else(|| {
                        ctx.err(
                            format!("{key}.group"),
                            format!("no physical curve named '{g}' (groups come from a gmsh mesh)"),
                        )
                    })?
                    .iter()
                    .map(|e| (e.clone(), [-1.0, 1.0]))
                    .collect(),
                _ => return Err(ctx.err(&key, "give exactly one of line or group")),
            };
            for (nodes, range) in edges {
                case.edge_loads.push(EdgeLoad {
                    nodes,
                    q: l.q,
                    range,
                });
            }
        }
        model.load_cases.push(case);
    }
    Ok(())
}

/// `point_loads[j].bearing`: the load spread as a uniform pressure over a bearing of that
/// length [m] centred on node `n`, along the element edge through the node most nearly
/// perpendicular to the force (nodes and shares of the force, summing to 1), and its local
/// zone if `local_zone = true`; None without a bearing.
fn bearing(
    ctx: &Ctx,
    key: &str,
    p: &PointLoadIn,
    model: &Model,
    n: usize,
    zones: &mut Vec<LocalZone>,
) -> R<Option<Vec<(usize, f64)>>> {
    let Some(b) = super::anchorage::bearing_length(ctx, key, p.bearing, p.local_zone, "under")?
    else {
        return Ok(None);
    };
    let f = p.force[0].hypot(p.force[1]);
    if f == 0.0 {
        return Ok(None);
    }
    let axis = [p.force[0] / f, p.force[1] / f];
    let s = anchorage::spread(model, n, axis, b);
    if s.covered < (1.0 - 1e-6) * b {
        return Err(ctx.err(
            format!("{key}.bearing"),
            format!(
                "the {b} m bearing centred on ({:.3}, {:.3}) runs off the element edges (it lies on them over {:.4} m): shorten it or move the load",
                model.nodes[n][0], model.nodes[n][1], s.covered
            ),
        ));
    }
    // Opt-in: a load bearing's pressure is usually far below f_cm (EN 1992-1-1 6.7 checks
    // it), and an elastic block in a member's compression zone would attract the bending
    // compression that plain concrete carries there.
    if p.local_zone == Some(true) {
        zones.push(LocalZone {
            centre: model.nodes[n],
            axis,
            plate: b,
            kind: super::anchorage::ZoneKind::Bearing,
        });
    }
    Ok(Some(s.weights))
}

/// EN 1992-1-1 3.1.3(5) (and EN 1991-1-5 Table C.1): α of normal-weight concrete [1/K].
pub const ALPHA_CONCRETE: f64 = 10e-6;
/// EN 1991-1-5 Table C.1 (EN 1993-1-1 3.2.6): α of structural, reinforcing and prestressing
/// steel [1/K].
pub const ALPHA_STEEL: f64 = 12e-6;

/// `load_cases[i].temperature`: the temperature field ΔT(y) of a thermal load case (the
/// expansion coefficients follow in [`thermal_coefficients`], once the bars are known).
fn temperature(
    ctx: &Ctx,
    i: usize,
    t: &crate::input::schema::TemperatureIn,
    model: &Model,
) -> R<crate::model::ThermalAction> {
    use crate::model::thermal::{aashto_profile, en1991_profile, ThermalAction};
    let k = |f: &str| format!("load_cases[{i}].temperature.{f}");
    let finite = |f: &str, v: Option<f64>| -> R<Option<f64>> {
        match v {
            Some(x) if !x.is_finite() => Err(ctx.err(k(f), "must be a finite number")),
            v => Ok(v),
        }
    };
    let uniform = finite("uniform", t.uniform)?;
    let linear = finite("linear", t.linear)?;
    let tendons = finite("tendons", t.tendons)?;
    if uniform.is_none() && linear.is_none() && t.profile.is_none() && t.code_profile.is_none() {
        return Err(ctx.err(
            format!("load_cases[{i}].temperature"),
            "give at least one of uniform, linear, profile or code_profile [K]",
        ));
    }
    // The section's extent: the mesh's by default.
    let ys = model
        .elements
        .iter()
        .flat_map(|e| e.nodes.iter().map(|&n| model.nodes[n][1]));
    let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    let top = finite("top", t.top)?.unwrap_or(hi);
    let bottom = finite("bottom", t.bottom)?.unwrap_or(lo);
    if top <= bottom {
        return Err(ctx.err(
            k("top"),
            format!("the top fibre (y = {top} m) must lie above the bottom fibre (y = {bottom} m)"),
        ));
    }
    let h = top - bottom;
    let profile = match (&t.profile, t.code_profile.as_deref()) {
        (Some(_), Some(_)) => {
            return Err(ctx.err(k("code_profile"), "give profile or code_profile, not both"))
        }
        (Some(p), None) => {
            let ok = p.len() >= 2
                && p.iter().all(|q| q[0].is_finite() && q[1].is_finite())
                && p[0][0] >= 0.0
                && p.windows(2).all(|w| w[1][0] >= w[0][0]);
            if !ok {
                return Err(ctx.err(
                    k("profile"),
                    "give at least two finite [depth below the top fibre [m], ΔT [K]] points, depths from 0 up and not decreasing",
                ));
            }
            p.clone()
        }
        (None, Some(c)) => {
            let zone = match (t.zone, c.starts_with("aashto")) {
                (Some(z), true) if (1..=4).contains(&z) => z as u8,
                (Some(z), true) => {
                    return Err(ctx.err(
                        k("zone"),
                        format!("AASHTO solar radiation zones are 1 to 4 (got {z})"),
                    ))
                }
                (None, true) => {
                    return Err(ctx.err(
                        k("zone"),
                        "missing: the AASHTO gradient needs the solar radiation zone (1–4)",
                    ))
                }
                (Some(_), false) => {
                    return Err(ctx.err(k("zone"), "is used by the AASHTO profiles only"))
                }
                (None, false) => 0,
            };
            if t.negative_factor.is_some() && c != "aashto-negative" {
                return Err(ctx.err(
                    k("negative_factor"),
                    "is used by code_profile = \"aashto-negative\" only",
                ));
            }
            let nf = finite("negative_factor", t.negative_factor)?.unwrap_or(-0.30);
            if !(-1.0..0.0).contains(&nf) {
                return Err(ctx.err(
                    k("negative_factor"),
                    format!("must lie in [-1, 0) (AASHTO: -0.30 plain deck, -0.20 with asphalt overlay; got {nf})"),
                ));
            }
            match c {
                "en1991-1-5-heating" => en1991_profile(h, true),
                "en1991-1-5-cooling" => en1991_profile(h, false),
                "aashto-positive" => aashto_profile(h, zone, 1.0).unwrap_or_default(),
                "aashto-negative" => aashto_profile(h, zone, nf).unwrap_or_default(),
                o => {
                    return Err(ctx.err(
                        k("code_profile"),
                        format!("unknown profile '{o}' (expected en1991-1-5-heating, en1991-1-5-cooling, aashto-positive or aashto-negative)"),
                    ))
                }
            }
        }
        (None, None) => {
            for f in ["zone", "negative_factor"] {
                let given = if f == "zone" {
                    t.zone.is_some()
                } else {
                    t.negative_factor.is_some()
                };
                if given {
                    return Err(ctx.err(k(f), "is used by code_profile only"));
                }
            }
            Vec::new()
        }
    };
    Ok(ThermalAction {
        uniform: uniform.unwrap_or(0.0),
        linear: linear.unwrap_or(0.0),
        top,
        bottom,
        profile,
        tendon_temperature: tendons,
        ..Default::default()
    })
}

/// A `thermal_expansion` value at `key`: a coefficient in 1/K, zero or positive and below
/// 1e-3 (a value like 10 means 10e-6 was meant).
fn alpha_value(ctx: &Ctx, key: &str, v: f64) -> R<f64> {
    if !(v.is_finite() && (0.0..1e-3).contains(&v)) {
        return Err(ctx.err(
            key,
            format!(
                "must be a coefficient in 1/K in [0, 1e-3), e.g. 1.0e-5 for concrete (got {v})"
            ),
        ));
    }
    Ok(v)
}

/// The expansion coefficients of the thermal load cases, once regions, bars, tendons and
/// steps are built: α per region's material (default: its kind's, `Schema::thermal_expansion`
/// of build/materials/: [`ALPHA_CONCRETE`] for the concrete kinds, none for `elastic`, which
/// could be concrete or steel), per bar (its steel, default [`ALPHA_STEEL`]) and per external tendon. Tendons must be stressed and
/// grouted while no temperature is held (their reference length is taken stress-free at
/// stressing); an arc-length step cannot scale a thermal case.
pub(super) fn thermal_coefficients(ctx: &Ctx, file: &File, model: &mut Model) -> R<()> {
    // Values given are checked whether or not a thermal case uses them.
    for (i, m) in file.materials.iter().enumerate() {
        if let Some(a) = m.number("thermal_expansion") {
            alpha_value(ctx, &format!("materials[{i}].thermal_expansion"), a)?;
        }
    }
    for (i, t) in file.tendons.iter().enumerate() {
        if let Some(a) = t.thermal_expansion {
            alpha_value(ctx, &format!("tendons[{i}].thermal_expansion"), a)?;
        }
    }
    let Some(first) = model.load_cases.iter().position(|c| c.thermal.is_some()) else {
        return Ok(());
    };
    let first_name = model.load_cases[first].name.clone();
    let material = |name: &str| {
        file.materials
            .iter()
            .enumerate()
            .find(|(_, m)| m.name == name)
    };
    let mut region_alpha = Vec::with_capacity(model.regions.len());
    for r in &model.regions {
        // A creep material copied per casting day (segment_cast_days) is its file entry.
        let name = super::regions::file_material_name(&model.materials[r.material].name);
        let Some((i, m)) = material(name) else {
            return Err(ctx.err(
                "regions",
                format!("internal error: material '{name}' not in the file"),
            ));
        };
        // The value given, else the kind's default (its schema's).
        region_alpha.push(match m.thermal_expansion() {
            Some(a) => a,
            None => {
                return Err(ctx.err(
                    format!("materials[{i}].thermal_expansion"),
                    format!("missing: the thermal load case '{first_name}' heats region '{}', and an elastic material has no default coefficient (1.0e-5 1/K for concrete)", r.name),
                ))
            }
        });
    }
    let steel_alpha = |name: &str| {
        material(name)
            .and_then(|(_, m)| m.thermal_expansion())
            .unwrap_or(ALPHA_STEEL)
    };
    let tendon_alpha = |name: &str| {
        file.tendons
            .iter()
            .find(|t| t.name == name)
            .and_then(|t| t.thermal_expansion)
            .unwrap_or(ALPHA_STEEL)
    };
    let bar_alpha: Vec<f64> = model
        .bars
        .iter()
        .map(|b| {
            if let Some(bi) = file.bars.iter().find(|x| x.name == b.name) {
                steel_alpha(&bi.material)
            } else if let Some(l) = file.bar_layers.iter().find(|x| x.name == b.name) {
                steel_alpha(&l.material)
            } else {
                tendon_alpha(&b.name)
            }
        })
        .collect();
    let tendon_alphas: Vec<f64> = model
        .tendons
        .iter()
        .map(|t| tendon_alpha(&t.name))
        .collect();
    for c in model.load_cases.iter_mut() {
        if let Some(th) = c.thermal.as_mut() {
            th.region_alpha.clone_from(&region_alpha);
            th.bar_alpha.clone_from(&bar_alpha);
            th.tendon_alpha.clone_from(&tendon_alphas);
        }
    }
    check_thermal_steps(ctx, model)
}

/// Thermal cases in the steps: not the reference load of an arc-length step (the load
/// factor there is an unknown of forces, not of strains), and held at zero when a tendon
/// is stressed or grouted.
fn check_thermal_steps(ctx: &Ctx, model: &Model) -> R<()> {
    let thermal: Vec<usize> = (0..model.load_cases.len())
        .filter(|&c| model.load_cases[c].thermal.is_some())
        .collect();
    for (si, s) in model.steps.iter().enumerate() {
        if let Some(PathControl::ArcLength(a)) = &s.path {
            if let Some(&c) = thermal.iter().find(|&&c| a.reference[c] != 0.0) {
                return Err(ctx.err(
                    format!("steps[{si}].loads.{}", model.load_cases[c].name),
                    "a thermal load case cannot be the reference load of an arc-length step: apply it in a load step before",
                ));
            }
        }
        // Factors held at the start of step si.
        let held = |c: usize| {
            if si == 0 {
                0.0
            } else {
                model.steps[si - 1].factors[c]
            }
        };
        let Some(&c) = thermal.iter().find(|&&c| held(c) != 0.0) else {
            continue;
        };
        let stressed = model
            .tendons
            .iter()
            .filter(|t| t.stressed_in_step == si)
            .map(|t| t.name.as_str())
            .chain(model.bars.iter().filter_map(|b| {
                b.post_tension.as_ref().and_then(|p| {
                    (p.stressed_in_step == si || p.grouted_in_step == Some(si))
                        .then_some(b.name.as_str())
                })
            }))
            .next();
        if let Some(name) = stressed {
            return Err(ctx.err(
                format!("steps[{si}]"),
                format!(
                    "tendon '{name}' is stressed or grouted at the start of step '{}' while the thermal load case '{}' is held at factor {}: stress and grout tendons before temperature is applied",
                    s.name, model.load_cases[c].name, held(c)
                ),
            ));
        }
    }
    Ok(())
}
