//! `[[bars]]` and bonded (post- and pre-tensioned) `[[tendons]]`: paths cut through the mesh
//! into integration points of embedded bars; lock-off stresses of post-tensioned tendons.

use super::anchorage::LocalZone;
use super::fields::{positive, unique_names};
use super::tendons::{
    friction_of, is_bonded_kind, jacking_stress_of, relaxation_of, tendon_law, tendon_steel,
};
use super::R;
use crate::fem::shape::map_point;
use crate::input::error::Ctx;
use crate::input::schema::{ArcIn, BarIn, ParabolaIn, PathPartIn, TendonIn};
use crate::materials::steel::SteelParams;
use crate::mesh::embed::{BarEmbedder, BarPath, EmbedOptions, HostElement};
use crate::model::{Bar, BarGaussPoint, Model, PostTension};
use crate::prestress::posttension::{self, Samples, Stressing};

/// A bar or tendon path from its keys: exactly one of a polyline (`points_key`), `parabola`,
/// `arc` or `segments` (a chain of those).
#[allow(clippy::too_many_arguments)]
pub(super) fn path_of(
    ctx: &Ctx,
    key: &str,
    named: &str,
    points_key: &str,
    points: Option<&Vec<[f64; 2]>>,
    parabola: Option<&ParabolaIn>,
    arc: Option<&ArcIn>,
    segments: Option<&Vec<PathPartIn>>,
) -> R<BarPath> {
    let one = |points: Option<&Vec<[f64; 2]>>,
               parabola: Option<&ParabolaIn>,
               arc: Option<&ArcIn>|
     -> Option<BarPath> {
        if let Some(p) = points {
            Some(BarPath::Polyline(p.clone()))
        } else if let Some(p) = parabola {
            Some(BarPath::Parabola {
                start: p.start,
                end: p.end,
                sag: p.sag,
            })
        } else {
            arc.map(|a| BarPath::Arc {
                center: a.center,
                radius: a.radius,
                theta_start: a.theta_start,
                theta_end: a.theta_end,
            })
        }
    };
    let given = points.is_some() as u8
        + parabola.is_some() as u8
        + arc.is_some() as u8
        + segments.is_some() as u8;
    if given != 1 {
        return Err(ctx.err(
            key,
            format!("{named}: give exactly one of {points_key}, parabola, arc or segments"),
        ));
    }
    match segments {
        None => Ok(one(points, parabola, arc).expect("one path given")),
        Some(parts) => {
            if parts.is_empty() {
                return Err(ctx.err(format!("{key}.segments"), format!("{named}: is empty")));
            }
            let mut out = Vec::new();
            for (j, p) in parts.iter().enumerate() {
                let n =
                    p.points.is_some() as u8 + p.parabola.is_some() as u8 + p.arc.is_some() as u8;
                if n != 1 {
                    return Err(ctx.err(
                        format!("{key}.segments[{j}]"),
                        format!("{named}: give exactly one of points, parabola or arc"),
                    ));
                }
                out.push(
                    one(p.points.as_ref(), p.parabola.as_ref(), p.arc.as_ref())
                        .expect("one part given"),
                );
            }
            Ok(BarPath::Chain(out))
        }
    }
}

/// A path cut through the mesh: integration points, piece ends and ranges, and the path
/// segment of each point.
pub(super) struct Embedded {
    points: Vec<BarGaussPoint>,
    piece_ends: Vec<[[f64; 2]; 2]>,
    piece_points: Vec<(usize, usize)>,
    segment: Vec<usize>,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn embed_path(
    ctx: &Ctx,
    key: &str,
    named: &str,
    embedder: &BarEmbedder,
    model: &Model,
    coords: &[Vec<[f64; 2]>],
    path: &BarPath,
    n_gauss: usize,
) -> R<Embedded> {
    let pieces = embedder
        .embed(
            path,
            &EmbedOptions {
                n_gauss,
                ..Default::default()
            },
        )
        .map_err(|e| ctx.err(key, format!("{named}: {e}")))?;
    let mut out = Embedded {
        points: Vec::new(),
        piece_ends: Vec::new(),
        piece_points: Vec::new(),
        segment: Vec::new(),
    };
    for pc in &pieces {
        let el = &model.elements[pc.element];
        let c = &coords[pc.element];
        let at = |q: [f64; 2]| map_point(&el.kind.eval(q[0], q[1]), c);
        out.piece_ends
            .push([at(pc.nat_nodes[0]), at(pc.nat_nodes[1])]);
        let p0 = out.points.len();
        out.points.extend(pc.points.iter().map(|p| BarGaussPoint {
            element: pc.element,
            point: *p,
        }));
        out.segment.extend(pc.points.iter().map(|_| pc.segment));
        out.piece_points.push((p0, out.points.len()));
    }
    Ok(out)
}

/// Cut the bars and the bonded post-tensioned tendons through the mesh and store their
/// integration points; the tendons' lock-off stresses after friction and anchorage set.
pub(super) fn build(
    ctx: &Ctx,
    bars: &[BarIn],
    tendons: &[TendonIn],
    steels: &[(String, SteelParams)],
    model: &mut Model,
    zones: &mut Vec<LocalZone>,
) -> R<()> {
    if bars.is_empty() && !tendons.iter().any(|t| is_bonded_kind(&t.kind)) {
        return Ok(());
    }
    unique_names(ctx, "bars", bars.iter().map(|b| b.name.as_str()))?;
    let coords: Vec<Vec<[f64; 2]>> = model
        .elements
        .iter()
        .map(|e| model.element_coords(e))
        .collect();
    let hosts: Vec<HostElement> = model
        .elements
        .iter()
        .zip(&coords)
        .map(|(e, c)| HostElement {
            kind: e.kind,
            coords: c,
        })
        .collect();
    let embedder = BarEmbedder::new(&hosts).map_err(|e| ctx.err("mesh", e.to_string()))?;
    let mut out = Vec::new();
    for (i, b) in bars.iter().enumerate() {
        out.push(bar(ctx, i, b, steels, &embedder, model, &coords)?);
    }
    for (i, t) in tendons.iter().enumerate() {
        match t.kind.as_str() {
            "pretensioned" => out.push(pretensioned_tendon(
                ctx, i, t, bars, &embedder, model, &coords,
            )?),
            "bonded" => {
                let bar = post_tensioned_tendon(ctx, i, t, bars, &embedder, model, &coords)?;
                bonded_anchor_zones(ctx, i, t, &bar, zones)?;
                out.push(bar);
            }
            _ => {}
        }
    }
    model.bars = out;
    Ok(())
}

/// The number of integration points per piece (`gauss_points`, default 4, at most 64).
fn n_gauss_of(ctx: &Ctx, key: &str, named: &str, g: Option<usize>) -> R<usize> {
    let n = g.unwrap_or(4);
    if !(1..=64).contains(&n) {
        return Err(ctx.err(key, format!("{named}: must lie in 1..=64")));
    }
    Ok(n)
}

/// Bar `b` (`bars[i]`) of one of the `steels`, cut through the mesh.
#[allow(clippy::too_many_arguments)]
fn bar(
    ctx: &Ctx,
    i: usize,
    b: &BarIn,
    steels: &[(String, SteelParams)],
    embedder: &BarEmbedder,
    model: &Model,
    coords: &[Vec<[f64; 2]>],
) -> R<Bar> {
    let key = format!("bars[{i}]");
    let named = format!("bar '{}'", b.name);
    let steel = steels
        .iter()
        .find(|(n, _)| *n == b.material)
        .map(|(_, s)| *s)
        .ok_or_else(|| {
            let known: Vec<&str> = steels.iter().map(|(n, _)| n.as_str()).collect();
            ctx.err(
                format!("{key}.material"),
                format!(
                    "{named}: no rebar or prestressing_steel material named '{}' (defined: {})",
                    b.material,
                    known.join(", ")
                ),
            )
        })?;
    let area = positive(ctx, &format!("{key}.area"), b.area)?;
    if area > 0.1 {
        return Err(ctx.err(
            format!("{key}.area"),
            format!("{named}: {area} m² is not a bar area (units are m²)"),
        ));
    }
    let initial_stress = b.initial_stress.unwrap_or(0.0);
    if !initial_stress.is_finite() || initial_stress.abs() >= steel.fy {
        return Err(ctx.err(
            format!("{key}.initial_stress"),
            format!(
                "{named}: must be finite and below the yield stress {:.4e} Pa in magnitude",
                steel.fy
            ),
        ));
    }
    let path = path_of(
        ctx,
        &key,
        &named,
        "path",
        b.path.as_ref(),
        b.parabola.as_ref(),
        b.arc.as_ref(),
        b.segments.as_ref(),
    )?;
    let n_gauss = n_gauss_of(ctx, &format!("{key}.gauss_points"), &named, b.gauss_points)?;
    let e = embed_path(
        ctx,
        &format!("{key}.path"),
        &named,
        embedder,
        model,
        coords,
        &path,
        n_gauss,
    )?;
    Ok(Bar {
        name: b.name.clone(),
        area,
        steel,
        initial_stress,
        n_pieces: e.piece_points.len(),
        points: e.points,
        piece_ends: e.piece_ends,
        piece_points: e.piece_points,
        post_tension: None,
        relaxation: None,
        layer: false,
    })
}

/// Refuse a bonded tendon whose name is a bar's (`clash` says why that matters) or that
/// gives a key of another tendon kind (`refused`: key and whether it is given; `hint` names
/// the keys this kind takes).
#[allow(clippy::too_many_arguments)]
fn refuse_clash_and_keys(
    ctx: &Ctx,
    key: &str,
    named: &str,
    t: &TendonIn,
    bars: &[BarIn],
    clash: &str,
    refused: &[(&str, bool)],
    hint: &str,
) -> R<()> {
    if bars.iter().any(|b| b.name == t.name) {
        return Err(ctx.err(
            format!("{key}.name"),
            format!("{named}: a bar has the same name ({clash})"),
        ));
    }
    match refused.iter().find(|(_, given)| *given) {
        Some((f, _)) => Err(ctx.err(format!("{key}.{f}"), format!("{named}: {hint}"))),
        None => Ok(()),
    }
}

/// A bonded post-tensioned tendon (`kind = "bonded"`, `tendons[i]`): a bar whose stress
/// after lock-off follows from the jacking stress, friction and anchorage set.
#[allow(clippy::too_many_arguments)]
fn post_tensioned_tendon(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    bars: &[BarIn],
    embedder: &BarEmbedder,
    model: &Model,
    coords: &[Vec<[f64; 2]>],
) -> R<Bar> {
    let key = format!("tendons[{i}]");
    let k = |f: &str| format!("{key}.{f}");
    let named = format!("tendon '{}'", t.name);
    refuse_clash_and_keys(
        ctx,
        &key,
        &named,
        t,
        bars,
        "bonded tendons are output and monitored as bars",
        &[
            ("initial_stress", t.initial_stress.is_some()),
            ("deviators", t.deviators.is_some()),
            ("deviator_friction", t.deviator_friction.is_some()),
        ],
        "not a key of a bonded post-tensioned tendon (stressed with jacking_stress or jacking_force; a pre-tensioned tendon is kind = \"pretensioned\" with initial_stress)",
    )?;
    let (area, ep, fptk) = tendon_steel(ctx, &key, &named, t)?;
    let steel = tendon_law(ctx, &key, &named, t, ep, fptk)?;
    let sigma_pi = jacking_stress_of(ctx, i, t, area, fptk)?.ok_or_else(|| {
        ctx.err(
            k("jacking_stress"),
            format!("{named}: missing: give jacking_stress or jacking_force"),
        )
    })?;
    let (friction, jacking, draw_in) = friction_of(ctx, i, t)?;
    let points = (!t.points.is_empty()).then_some(&t.points);
    let path = path_of(
        ctx,
        &key,
        &named,
        "points",
        points,
        t.parabola.as_ref(),
        t.arc.as_ref(),
        t.segments.as_ref(),
    )?;
    let turns = path
        .turn_table()
        .map_err(|e| ctx.err(&key, format!("{named}: {e}")))?;
    let n_gauss = n_gauss_of(ctx, &k("gauss_points"), &named, t.gauss_points)?;
    let e = embed_path(ctx, &key, &named, embedder, model, coords, &path, n_gauss)?;
    let samples = Samples {
        s: e.points.iter().map(|p| p.point.s).collect(),
        alpha: e
            .points
            .iter()
            .zip(&e.segment)
            .map(|(p, &sg)| turns.at(sg, p.point.s, p.point.dir))
            .collect(),
        length: turns.length,
        total_turn: turns.total,
    };
    let lock = posttension::lock_off(
        &Stressing {
            jacking_stress: sigma_pi,
            friction,
            jacking,
            draw_in,
            ep,
        },
        &samples,
    )
    .map_err(|err| ctx.err(k("anchorage_set"), format!("{named}: {err}")))?;
    let relaxation = relaxation_of(
        ctx,
        &k("relaxation_class"),
        t.relaxation_class,
        &lock.stress,
        fptk,
        ep,
    )?;
    Ok(Bar {
        name: t.name.clone(),
        area,
        steel,
        initial_stress: 0.0,
        n_pieces: e.piece_points.len(),
        points: e.points,
        piece_ends: e.piece_ends,
        piece_points: e.piece_points,
        post_tension: Some(PostTension {
            stressed_in_step: 0,
            grouted_in_step: None,
            point_stress: lock.stress,
            jacking_stress: sigma_pi,
            set_length: lock.set_length,
        }),
        relaxation: relaxation.map(|c| (c, fptk)),
        layer: false,
    })
}

/// The local zones behind the two anchors of bonded tendon `t` (`tendons[i]`) unless
/// `local_zone = false`: each anchor is the path's end, found from the integration point
/// nearest it (its position less its arc length along its direction), the zone as wide and
/// as deep as the anchor plate. The anchorage force itself enters through the host element
/// of the tendon's end (the bar's equivalent forces), not over plate nodes.
fn bonded_anchor_zones(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    bar: &Bar,
    zones: &mut Vec<LocalZone>,
) -> R<()> {
    let plate = super::tendons::anchor_plate(ctx, &format!("tendons[{i}]"), t, bar.area)?;
    if t.local_zone == Some(false) || plate == 0.0 {
        return Ok(());
    }
    let by_s = |a: &&crate::model::BarGaussPoint, b: &&crate::model::BarGaussPoint| {
        a.point.s.total_cmp(&b.point.s)
    };
    let (Some(first), Some(last)) = (
        bar.points.iter().min_by(by_s),
        bar.points.iter().max_by(by_s),
    ) else {
        return Ok(());
    };
    let length: f64 = bar.points.iter().map(|p| p.point.weight_length).sum();
    let (p, d) = (&first.point, first.point.dir);
    zones.push(LocalZone {
        centre: [p.x[0] - p.s * d[0], p.x[1] - p.s * d[1]],
        axis: d,
        plate,
        kind: super::anchorage::ZoneKind::Anchor,
    });
    let (p, d) = (&last.point, last.point.dir);
    let rest = length - p.s;
    zones.push(LocalZone {
        centre: [p.x[0] + rest * d[0], p.x[1] + rest * d[1]],
        axis: [-d[0], -d[1]],
        plate,
        kind: super::anchorage::ZoneKind::Anchor,
    });
    Ok(())
}

/// A pre-tensioned tendon (`kind = "pretensioned"`): an embedded prestressing-steel bar
/// bonded from the start that carries `initial_stress` at zero displacement (the stress in
/// the bed before release); its elastic shortening at transfer follows from equilibrium.
#[allow(clippy::too_many_arguments)]
pub(super) fn pretensioned_tendon(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    bars: &[BarIn],
    embedder: &BarEmbedder,
    model: &Model,
    coords: &[Vec<[f64; 2]>],
) -> R<Bar> {
    let key = format!("tendons[{i}]");
    let k = |f: &str| format!("{key}.{f}");
    let named = format!("tendon '{}'", t.name);
    refuse_clash_and_keys(
        ctx,
        &key,
        &named,
        t,
        bars,
        "bonded tendons are output as bars",
        &[
            ("jacking_stress", t.jacking_stress.is_some()),
            ("jacking_force", t.jacking_force.is_some()),
            ("jacking", t.jacking.is_some()),
            ("friction", t.friction.is_some()),
            ("wobble", t.wobble.is_some()),
            ("anchorage_set", t.anchorage_set.is_some()),
            ("deviators", t.deviators.is_some()),
            ("deviator_friction", t.deviator_friction.is_some()),
            ("stressed_in_step", t.stressed_in_step.is_some()),
            ("grouted_in_step", t.grouted_in_step.is_some()),
            ("anchor_plate", t.anchor_plate.is_some()),
            ("local_zone", t.local_zone.is_some()),
        ],
        "not a key of a pre-tensioned tendon (bonded from the start with initial_stress, the stress before release)",
    )?;
    let (area, ep, fptk) = tendon_steel(ctx, &key, &named, t)?;
    let s0 = t.initial_stress.ok_or_else(|| {
        ctx.err(
            k("initial_stress"),
            format!("{named}: missing: the stress before release [Pa]"),
        )
    })?;
    if !(s0.is_finite() && s0 > 0.0 && s0 < 0.9 * fptk) {
        return Err(ctx.err(
            k("initial_stress"),
            format!("{named}: must lie in (0, 0.9 fptk) (got {s0} Pa)"),
        ));
    }
    let relaxation = relaxation_of(
        ctx,
        &k("relaxation_class"),
        t.relaxation_class,
        &[s0],
        fptk,
        ep,
    )?;
    let points = (!t.points.is_empty()).then_some(&t.points);
    let path = path_of(
        ctx,
        &key,
        &named,
        "points",
        points,
        t.parabola.as_ref(),
        t.arc.as_ref(),
        t.segments.as_ref(),
    )?;
    let n_gauss = t.gauss_points.unwrap_or(4);
    if !(1..=64).contains(&n_gauss) {
        return Err(ctx.err(k("gauss_points"), format!("{named}: must lie in 1..=64")));
    }
    let e = embed_path(ctx, &key, &named, embedder, model, coords, &path, n_gauss)?;
    Ok(Bar {
        name: t.name.clone(),
        area,
        steel: tendon_law(ctx, &key, &named, t, ep, fptk)?,
        initial_stress: s0,
        n_pieces: e.piece_points.len(),
        points: e.points,
        piece_ends: e.piece_ends,
        piece_points: e.piece_points,
        post_tension: None,
        relaxation: relaxation.map(|c| (c, fptk)),
        layer: false,
    })
}
