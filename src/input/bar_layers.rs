//! `[[bar_layers]]`: smeared layers of parallel bars (web stirrups, distributed longitudinal
//! bars) given by a direction and a reinforcement ratio over a region, instead of one
//! `[[bars]]` entry per bar.
//!
//! A layer becomes a [`Bar`] whose integration points are the Gauss points of its host
//! elements (the host's full rule): at each, the bar strain is the host strain projected on
//! the layer's direction, exactly as for a discrete embedded bar (docs/theory-bars.md §6).
//! With the area per unit width ρ·t [m²/m] as the bar's `area` and w·det J [m²] as each
//! point's weight, the layer adds ∫ ρ t σ_s Bᵀ d dA to the element forces: the stress of
//! the steel, smeared over the section of the region.

use super::error::{Ctx, InputError};
use super::schema::BarLayerIn;
use crate::elements::bar::BarPoint;
use crate::fem::shape::{jacobian, map_point};
use crate::materials::steel::SteelParams;
use crate::model::{Bar, BarGaussPoint, Model};

type R<T> = Result<T, InputError>;

/// Append one smeared [`Bar`] per `[[bar_layers]]` entry to `model.bars` (after the discrete
/// bars and bonded tendons, whose names it must not repeat).
pub fn build(
    ctx: &Ctx,
    layers: &[BarLayerIn],
    steels: &[(String, SteelParams)],
    model: &mut Model,
) -> R<()> {
    for (i, l) in layers.iter().enumerate() {
        let bar = layer(ctx, i, l, steels, model)?;
        model.bars.push(bar);
    }
    Ok(())
}

fn layer(
    ctx: &Ctx,
    i: usize,
    l: &BarLayerIn,
    steels: &[(String, SteelParams)],
    model: &Model,
) -> R<Bar> {
    let key = |f: &str| format!("bar_layers[{i}].{f}");
    let named = format!("bar layer '{}'", l.name);
    if l.name.trim().is_empty() {
        return Err(ctx.err(key("name"), "must not be empty"));
    }
    if model.bars.iter().any(|b| b.name == l.name) {
        return Err(ctx.err(
            key("name"),
            format!("{named}: a bar, bonded tendon or bar layer has the same name"),
        ));
    }
    let steel = steels
        .iter()
        .find(|(n, _)| *n == l.material)
        .map(|(_, s)| *s)
        .ok_or_else(|| {
            let known: Vec<&str> = steels.iter().map(|(n, _)| n.as_str()).collect();
            ctx.err(
                key("material"),
                format!(
                    "{named}: no rebar or prestressing_steel material named '{}' (defined: {})",
                    l.material,
                    known.join(", ")
                ),
            )
        })?;
    let region = model
        .regions
        .iter()
        .position(|r| r.name == l.region)
        .ok_or_else(|| {
            let known: Vec<&str> = model.regions.iter().map(|r| r.name.as_str()).collect();
            ctx.err(
                key("region"),
                format!(
                    "{named}: no region named '{}' (defined: {})",
                    l.region,
                    known.join(", ")
                ),
            )
        })?;
    // A ratio is a fraction of the concrete section: above 0.2 it is not reinforcement
    // (and most likely a percentage given as a number).
    if !(l.ratio.is_finite() && l.ratio > 0.0 && l.ratio <= 0.2) {
        return Err(ctx.err(
            key("ratio"),
            format!(
                "{named}: must be the steel area per unit concrete area A_s/(t·s), in (0, 0.2] (got {})",
                l.ratio
            ),
        ));
    }
    let [dx, dy] = l.direction;
    let norm = dx.hypot(dy);
    if !(norm.is_finite() && norm > 0.0) {
        return Err(ctx.err(
            key("direction"),
            format!(
                "{named}: must be a non-zero vector [cx, cy] along the bars (got [{dx}, {dy}])"
            ),
        ));
    }
    let dir = [dx / norm, dy / norm];
    let boxes = l.boxes.as_deref().unwrap_or(&[]);
    for (j, [[x0, y0], [x1, y1]]) in boxes.iter().enumerate() {
        if !([x0, y0, x1, y1].iter().all(|v| v.is_finite()) && x1 > x0 && y1 > y0) {
            return Err(ctx.err(
                format!("bar_layers[{i}].boxes[{j}]"),
                format!("{named}: must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0 (got [[{x0}, {y0}], [{x1}, {y1}]])"),
            ));
        }
    }
    let thickness = model.regions[region].thickness;
    let mut bar = Bar {
        name: l.name.clone(),
        area: l.ratio * thickness,
        steel,
        initial_stress: 0.0,
        points: Vec::new(),
        n_pieces: 0,
        piece_ends: Vec::new(),
        piece_points: Vec::new(),
        post_tension: None,
        relaxation: None,
        layer: true,
    };
    for (e, el) in model.elements.iter().enumerate() {
        if el.region != region {
            continue;
        }
        let coords = model.element_coords(el);
        // Same centroid rule as `regions[].boxes`: the corner nodes' mean.
        let nc = el.kind.n_corners();
        let k = coords.len().min(nc) as f64;
        let c = coords
            .iter()
            .take(nc)
            .fold([0.0, 0.0], |a, x| [a[0] + x[0] / k, a[1] + x[1] / k]);
        let inside = |[[x0, y0], [x1, y1]]: &[[f64; 2]; 2]| {
            (*x0..=*x1).contains(&c[0]) && (*y0..=*y1).contains(&c[1])
        };
        if !boxes.is_empty() && !boxes.iter().any(inside) {
            continue;
        }
        let p0 = bar.points.len();
        for &(xi, eta, w) in el.kind.rule(crate::model::Integration::Full) {
            let sv = el.kind.eval(xi, eta);
            let (_, det_j, _) = jacobian(&sv, &coords);
            bar.points.push(BarGaussPoint {
                element: e,
                point: BarPoint {
                    xi,
                    eta,
                    dir,
                    weight_length: w * det_j,
                    s: 0.0,
                    x: map_point(&sv, &coords),
                },
            });
        }
        let (first, last) = (
            bar.points[p0].point.x,
            bar.points[bar.points.len() - 1].point.x,
        );
        bar.piece_ends.push([first, last]);
        bar.piece_points.push((p0, bar.points.len()));
    }
    if bar.points.is_empty() {
        let (k, why) = if boxes.is_empty() {
            ("region", "has no elements")
        } else {
            (
                "boxes",
                "has no element whose centroid lies inside the boxes",
            )
        };
        return Err(ctx.err(key(k), format!("{named}: region '{}' {why}", l.region)));
    }
    bar.n_pieces = bar.piece_points.len();
    Ok(bar)
}
