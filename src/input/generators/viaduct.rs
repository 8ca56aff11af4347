//! `[viaduct]`: a continuous segmental box girder over several spans, built span by span on
//! falsework, from a few keys (docs/input.md, "[viaduct]"; docs/theory-stages.md §6).
//!
//! It writes the tables a hand-written model would have — `[[regions]]` (one per band of
//! the box), the segmental `[mesh]` with casting days, bearings and falsework
//! (`[[supports]]`), span and continuity tendons (`[[tendons]]`), the `self_weight` load
//! case and the erection `[[steps]]` — in front of the user's own entries, which then
//! continue the analysis (finishes, 30 years, traffic …).

use super::Generated;
use crate::input::build::MaterialKind;
use crate::input::error::{Ctx, InputError};
use crate::input::schema::{
    BandIn, File, LoadCaseIn, MeshIn, RegionIn, StepIn, SupportIn, TendonIn,
};
use serde::Deserialize;
use std::collections::BTreeMap;

type R<T> = Result<T, InputError>;

/// Standard gravity [m/s²] of the generated `self_weight` load case.
pub const GRAVITY: f64 = 9.81;

/// Default number of increments over which a struck falsework releases its reactions.
pub const STRIKE_INCREMENTS: usize = 4;

/// The `[viaduct]` table as read (keys documented in docs/input.md, "[viaduct]").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)] // keys documented in docs/input.md
pub struct ViaductIn {
    pub sequence: String,
    pub spans: Vec<f64>,
    pub segment_length: f64,
    pub pier_segment: f64,
    pub end_segment: f64,
    pub overhang: f64,
    pub section: Vec<SectionBandIn>,
    pub concrete: String,
    pub joint_material: String,
    pub element: Option<String>,
    pub integration: Option<String>,
    pub nx_per_segment: usize,
    #[serde(default)]
    pub cast_start: Vec<f64>,
    pub cast_interval: Option<f64>,
    pub erection_start: Option<f64>,
    pub span_interval: Option<f64>,
    pub segment_age: Option<f64>,
    pub cantilever: Option<super::cantilever::CantileverIn>,
    pub closure_tendons: Option<super::cantilever::ClosureTendonsIn>,
    #[serde(default)]
    pub camber: Vec<[f64; 2]>,
    pub strike_increments: Option<usize>,
    pub strand: Option<String>,
    pub span_tendons: Option<SpanTendonsIn>,
    pub continuity_tendons: Option<ContinuityTendonsIn>,
    #[serde(default)]
    pub hold_down: Vec<String>,
    /// Length of the permanent bearings along the span [m] (default
    /// [`DEFAULT_BEARING`]; `0`: the reaction on the bearing's node alone).
    pub bearing: Option<f64>,
}

/// Default length of the generated permanent bearings along the span [m]: an estimate of
/// a pot bearing (EN 1337-5) for a reaction of about 10 MN at about 35 MPa on the
/// concrete, √(10 MN / 35 MPa) ≈ 0.53 m, rounded up to the pot's outer size
/// (docs/input.md, "[viaduct]"; docs/theory-prestress.md, "Anchor plates, bearings and
/// local zones").
pub const DEFAULT_BEARING: f64 = 0.6;

/// One band of the box section, bottom up: a region of out-of-plane `width` [m].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct SectionBandIn {
    pub name: String,
    pub width: f64,
    pub depth: f64,
    pub rows: usize,
    pub material: Option<String>,
}

/// `[viaduct.span_tendons]`: one external tendon per span, pier to pier.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct SpanTendonsIn {
    pub area: f64,
    pub end_anchor_height: f64,
    pub pier_anchor_height: f64,
    pub deviators: Vec<DeviatorIn>,
    pub jacking_stress: f64,
    pub jacking: Option<String>,
    pub friction: Option<f64>,
    pub wobble: Option<f64>,
    pub anchorage_set: Option<f64>,
    pub relaxation_class: Option<i64>,
    pub deviator_mode: Option<String>,
    pub deviator_friction: Option<f64>,
}

/// A deviator: at the centre of the `segment`-th typical segment of each span (from the
/// span's left end), `height` [m] above the soffit.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct DeviatorIn {
    pub segment: usize,
    pub height: f64,
}

/// `[viaduct.continuity_tendons]`: a straight tendon over each pier.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ContinuityTendonsIn {
    pub area: f64,
    pub height: f64,
    pub reach: f64,
    pub jacking_stress: f64,
    pub jacking: Option<String>,
    pub friction: Option<f64>,
    pub wobble: Option<f64>,
    pub anchorage_set: Option<f64>,
    pub relaxation_class: Option<i64>,
}

/// The girder along x [m]: segment lengths left to right, which span erects each, and the
/// bearings.
struct Layout {
    /// Segment lengths [m], left to right (S1, S2, …).
    lengths: Vec<f64>,
    /// Per span: the (0-based) indices of the segments erected with it.
    groups: Vec<Vec<usize>>,
    /// Per span: index of its first typical segment and the number of typical segments.
    typical: Vec<(usize, usize)>,
    /// Bearing abscissae [m]: abutment, piers, abutment.
    bearings: Vec<f64>,
    /// Left end of the girder [m] (−overhang).
    x0: f64,
}

impl Layout {
    /// Left end [m] of segment `s`.
    fn start(&self, s: usize) -> f64 {
        self.x0 + self.lengths[..s].iter().sum::<f64>()
    }

    /// Right end [m] of the girder.
    fn end(&self) -> f64 {
        self.start(self.lengths.len())
    }
}

/// Expand `v` into `file`'s tables (generated entries first); the counts let errors found
/// later be reported against `[viaduct]`.
pub fn expand(v: &ViaductIn, file: &mut File, ctx: &Ctx) -> R<Generated> {
    let k = |f: &str| format!("viaduct.{f}");
    match v.sequence.as_str() {
        "span_by_span" => {}
        "balanced_cantilever" => return super::cantilever::expand(v, file, ctx),
        o => {
            return Err(ctx.err(
                k("sequence"),
                format!(
                    "unknown erection sequence '{o}' (expected span_by_span or balanced_cantilever)"
                ),
            ))
        }
    }
    for (key, given) in [
        ("segment_age", v.segment_age.is_some()),
        ("cantilever", v.cantilever.is_some()),
        ("closure_tendons", v.closure_tendons.is_some()),
        ("camber", !v.camber.is_empty()),
    ] {
        if given {
            return Err(ctx.err(k(key), "only with sequence = \"balanced_cantilever\""));
        }
    }
    let span_interval = v.span_interval.ok_or_else(|| {
        ctx.err(
            k("span_interval"),
            "missing: days between the erection of successive spans",
        )
    })?;
    let cast_interval = v.cast_interval.ok_or_else(|| {
        ctx.err(
            k("cast_interval"),
            "missing: days between the castings of a span's segments",
        )
    })?;
    no_generated_mesh(file, ctx)?;
    let layout = layout(v, ctx)?;
    node_columns(v, ctx)?;
    let depth = section(v, ctx)?;
    check_materials(v, file, ctx)?;
    let n = v.spans.len();
    let finite = |key: &str, x: f64| -> R<f64> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(ctx.err(k(key), format!("must be a finite number (got {x})")))
        }
    };
    // Casting days also name the segments (their regions are split per segment), which
    // the erection steps place: required even for a concrete that does not age.
    if v.cast_start.len() != n {
        return Err(ctx.err(
            k("cast_start"),
            format!(
                "give one casting day per span, for the first segment erected with it ({n} spans, {} days)",
                v.cast_start.len()
            ),
        ));
    }
    for (i, d) in v.cast_start.iter().enumerate() {
        finite(&format!("cast_start[{i}]"), *d)?;
    }
    if !(cast_interval.is_finite() && cast_interval >= 0.0) {
        return Err(ctx.err(
            k("cast_interval"),
            format!("must be zero or positive [days between castings] (got {cast_interval})"),
        ));
    }
    let start = finite("erection_start", v.erection_start.unwrap_or(0.0))?;
    if !(span_interval.is_finite() && span_interval > 0.0) {
        return Err(ctx.err(
            k("span_interval"),
            format!("must be positive [days per span] (got {span_interval})"),
        ));
    }
    let strike = v.strike_increments.unwrap_or(STRIKE_INCREMENTS);
    if strike == 0 {
        return Err(ctx.err(k("strike_increments"), "must be at least 1"));
    }

    let cast_days = cast_days(
        ctx,
        &layout,
        &v.cast_start,
        cast_interval,
        start,
        span_interval,
    )?;
    let mut generated = generated_regions(v, file);
    file.mesh = Some(mesh_in(v, &layout.lengths, layout.x0, cast_days));
    let steps = erection_steps(v, &layout, start, strike, span_interval);
    let supports = hold_down(v, supports(&layout), ctx)?;
    let supports = bearings(v, supports, v.spans.len(), ctx)?;
    let tendons = tendons(v, &layout, depth, file, ctx)?;
    let lists = Lists {
        supports,
        tendons,
        load_cases: vec![self_weight()],
        steps,
    };
    attach(ctx, &mut generated, file, lists)?;
    Ok(generated)
}

/// The generated entries of the model's lists, put in front of the user's by [`attach`].
pub(super) struct Lists {
    pub supports: Vec<SupportIn>,
    pub tendons: Vec<TendonIn>,
    pub load_cases: Vec<LoadCaseIn>,
    pub steps: Vec<StepIn>,
}

/// One region per band of the section (the generator owns `[[regions]]`).
pub(super) fn generated_regions(v: &ViaductIn, file: &mut File) -> Generated {
    let mut generated = Generated {
        section: "viaduct",
        lists: Vec::new(),
        owned: vec!["regions"],
        mesh: true,
    };
    let regions: Vec<RegionIn> = v
        .section
        .iter()
        .map(|b| RegionIn {
            name: b.name.clone(),
            material: b.material.clone().unwrap_or_else(|| v.concrete.clone()),
            thickness: b.width,
            cast_day: None,
            boxes: None,
        })
        .collect();
    generated
        .lists
        .push(("regions", names(&regions, |r| &r.name)));
    file.regions = regions;
    generated
}

/// The segmental `[mesh]` of the girder: segments of `lengths` [m] from `x0`, the section's
/// bands, one casting day per segment.
pub(super) fn mesh_in(v: &ViaductIn, lengths: &[f64], x0: f64, cast_days: Vec<f64>) -> MeshIn {
    MeshIn {
        kind: "segmental".into(),
        length: None,
        origin: Some([x0, 0.0]),
        nx: None,
        element: v.element.clone(),
        integration: v.integration.clone(),
        bands: v
            .section
            .iter()
            .map(|b| BandIn {
                region: b.name.clone(),
                depth: b.depth,
                rows: b.rows,
            })
            .collect(),
        segments: Some(lengths.to_vec()),
        n_segments: None,
        nx_per_segment: Some(v.nx_per_segment),
        joint_material: Some(v.joint_material.clone()),
        cast_joints: Vec::new(),
        soffit: Vec::new(),
        soffit_band: None,
        camber: Vec::new(),
        file: None,
        joints: Vec::new(),
        segment_cast_days: Some(cast_days),
        nodes: Vec::new(),
        blocks: Vec::new(),
    }
}

/// Give the permanent bearings of `n` spans (A1, P1 …, A2) the length `viaduct.bearing`
/// [m]: the reaction still holds the bearing's node (a pin), and on `kind = "concrete"` the
/// concrete over the bearing is a local zone (docs/theory-prestress.md, "Anchor plates,
/// bearings and local zones").
pub(super) fn bearings(
    v: &ViaductIn,
    mut supports: Vec<SupportIn>,
    n: usize,
    ctx: &Ctx,
) -> R<Vec<SupportIn>> {
    let b = v.bearing.unwrap_or(DEFAULT_BEARING);
    if !(b.is_finite() && b >= 0.0) {
        return Err(ctx.err(
            "viaduct.bearing",
            format!("must be a bearing length ≥ 0 in m (got {b})"),
        ));
    }
    if b == 0.0 {
        return Ok(supports);
    }
    let names: Vec<String> = (0..=n).map(|i| bearing_name(i, n)).collect();
    for s in supports.iter_mut() {
        if names.contains(&s.name) {
            s.bearing = Some(b);
        }
    }
    Ok(supports)
}

/// Make the supports named in `hold_down` two-way (an error for a name not generated).
pub(super) fn hold_down(v: &ViaductIn, supports: Vec<SupportIn>, ctx: &Ctx) -> R<Vec<SupportIn>> {
    for (i, name) in v.hold_down.iter().enumerate() {
        if !supports.iter().any(|s| &s.name == name) {
            let names: Vec<&str> = supports.iter().map(|s| s.name.as_str()).collect();
            return Err(ctx.err(
                format!("viaduct.hold_down[{i}]"),
                format!(
                    "no bearing or falsework named '{name}' (the generated ones: {})",
                    names.join(", ")
                ),
            ));
        }
    }
    Ok(supports
        .into_iter()
        .map(|mut s| {
            if v.hold_down.contains(&s.name) {
                s.one_way = None;
            }
            s
        })
        .collect())
}

/// The generated `self_weight` load case (gravity [`GRAVITY`] downwards).
pub(super) fn self_weight() -> LoadCaseIn {
    LoadCaseIn {
        name: "self_weight".into(),
        gravity: Some([0.0, -GRAVITY]),
        point_loads: Vec::new(),
        line_loads: Vec::new(),
        temperature: None,
    }
}

/// Put the generated lists in front of the user's.
pub(super) fn attach(ctx: &Ctx, generated: &mut Generated, file: &mut File, l: Lists) -> R<()> {
    prepend(
        ctx,
        generated,
        "supports",
        &mut file.supports,
        l.supports,
        |s| &s.name,
    )?;
    prepend(
        ctx,
        generated,
        "tendons",
        &mut file.tendons,
        l.tendons,
        |t| &t.name,
    )?;
    prepend(
        ctx,
        generated,
        "load_cases",
        &mut file.load_cases,
        l.load_cases,
        |c| &c.name,
    )?;
    prepend(ctx, generated, "steps", &mut file.steps, l.steps, |s| {
        &s.name
    })
}

/// `concrete` and every band's `material` name a `[[materials]]` entry.
pub(super) fn check_materials(v: &ViaductIn, file: &File, ctx: &Ctx) -> R<()> {
    let k = |f: &str| format!("viaduct.{f}");
    let materials: Vec<&str> = file.materials.iter().map(|m| m.name.as_str()).collect();
    for (key, name) in std::iter::once(("concrete".to_string(), &v.concrete)).chain(
        v.section.iter().enumerate().filter_map(|(i, b)| {
            b.material
                .as_ref()
                .map(|m| (format!("section[{i}].material"), m))
        }),
    ) {
        if !materials.contains(&name.as_str()) {
            return Err(ctx.err(
                k(&key),
                format!(
                    "no [[materials]] entry named '{name}' (defined: {})",
                    materials.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// `[mesh]` and `[[regions]]` are the generator's.
pub(super) fn no_generated_mesh(file: &File, ctx: &Ctx) -> R<()> {
    if file.mesh.is_some() {
        return Err(ctx.err(
            "mesh",
            "[viaduct] generates the mesh: leave out the [mesh] table",
        ));
    }
    if !file.regions.is_empty() {
        return Err(ctx.err(
            "regions",
            "[viaduct] generates the regions from viaduct.section: leave out [[regions]]",
        ));
    }
    Ok(())
}

/// The casting day of every segment: span by span from its first segment's, `interval`
/// apart; each cast by its span's erection day.
fn cast_days(
    ctx: &Ctx,
    layout: &Layout,
    first: &[f64],
    interval: f64,
    start: f64,
    span_interval: f64,
) -> R<Vec<f64>> {
    let mut days = vec![0.0; layout.lengths.len()];
    for (g, group) in layout.groups.iter().enumerate() {
        for (j, &s) in group.iter().enumerate() {
            days[s] = first[g] + j as f64 * interval;
        }
        let last = days[group[group.len() - 1]];
        let placed = start + g as f64 * span_interval;
        if last > placed {
            return Err(ctx.err(
                format!("viaduct.cast_start[{g}]"),
                format!(
                    "span {}'s segments are cast from day {} to day {last}, after the span is erected on day {placed}: cast them earlier",
                    g + 1,
                    first[g]
                ),
            ));
        }
    }
    Ok(days)
}

/// The names of `items`.
pub(super) fn names<T>(items: &[T], name: impl Fn(&T) -> &String) -> Vec<String> {
    items.iter().map(|t| name(t).clone()).collect()
}

/// Put the generated `new` entries in front of the user's `list`, refusing a user's entry
/// that takes a generated name.
pub(super) fn prepend<T>(
    ctx: &Ctx,
    generated: &mut Generated,
    list_name: &'static str,
    list: &mut Vec<T>,
    new: Vec<T>,
    name: impl Fn(&T) -> &String,
) -> R<()> {
    let gen_names = names(&new, &name);
    for (i, t) in list.iter().enumerate() {
        if gen_names.contains(name(t)) {
            return Err(ctx.err(
                format!("{list_name}[{i}].name"),
                format!(
                    "'{}' is a name [viaduct] gives to one of the {list_name} it generates: choose another",
                    name(t)
                ),
            ));
        }
    }
    let user = std::mem::take(list);
    *list = new;
    list.extend(user);
    generated.lists.push((list_name, gen_names));
    Ok(())
}

/// Segment lengths and bearings from the spans: an end segment over each abutment
/// (`overhang` beyond its bearing), a pier segment centred on each pier, and between them
/// a whole number of typical segments per span.
fn layout(v: &ViaductIn, ctx: &Ctx) -> R<Layout> {
    let k = |f: &str| format!("viaduct.{f}");
    let positive = |key: &str, x: f64| -> R<f64> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(ctx.err(k(key), format!("must be a positive length [m] (got {x})")))
        }
    };
    if v.spans.is_empty() {
        return Err(ctx.err(k("spans"), "give at least one span length [m]"));
    }
    for (i, l) in v.spans.iter().enumerate() {
        positive(&format!("spans[{i}]"), *l)?;
    }
    let seg = positive("segment_length", v.segment_length)?;
    let pier = positive("pier_segment", v.pier_segment)?;
    let end = positive("end_segment", v.end_segment)?;
    if !(v.overhang.is_finite() && v.overhang >= 0.0 && v.overhang < end) {
        return Err(ctx.err(
            k("overhang"),
            format!(
                "the girder's end beyond the end bearing must lie in [0, end_segment = {end}) m (got {})",
                v.overhang
            ),
        ));
    }
    let n = v.spans.len();
    let mut lengths = vec![end];
    let mut groups = vec![vec![0]];
    let mut typical = Vec::new();
    let mut bearings = vec![0.0];
    for (i, &l) in v.spans.iter().enumerate() {
        // Span i runs from bearing i to bearing i+1; the end and pier segments reach into it.
        let left = if i == 0 { end - v.overhang } else { pier / 2.0 };
        let right = if i + 1 == n {
            end - v.overhang
        } else {
            pier / 2.0
        };
        let free = l - left - right;
        let m = (free / seg).round();
        // Segments are cast to the millimetre; 1e-6 m leaves room for round-off only.
        if !(m >= 1.0 && (m * seg - free).abs() <= 1e-6) {
            let hint = if free > 0.0 {
                let m = (free / seg).round().max(1.0);
                format!(" (nearest: {m} segments of {:.4} m)", free / m)
            } else {
                String::new()
            };
            return Err(ctx.err(
                k("segment_length"),
                format!(
                    "span {} leaves {free:.4} m between its end and pier segments: not a whole number of {seg} m segments{hint}",
                    i + 1
                ),
            ));
        }
        let m = m as usize;
        if groups.len() <= i {
            groups.push(Vec::new());
        }
        typical.push((lengths.len(), m));
        for _ in 0..m {
            groups[i].push(lengths.len());
            lengths.push(seg);
        }
        groups[i].push(lengths.len());
        lengths.push(if i + 1 == n { end } else { pier });
        bearings.push(bearings[i] + l);
    }
    Ok(Layout {
        lengths,
        groups,
        typical,
        bearings,
        x0: -v.overhang,
    })
}

/// Bearings, pier-segment centres and deviators must fall on node columns (a point load or
/// support between columns would be moved to the nearest node without a word from the
/// generator's user, who never wrote the point): node columns are `nx_per_segment` per
/// segment for Q4, with the mid-side nodes twice as many for Q8 and Q9.
pub(super) fn node_columns(v: &ViaductIn, ctx: &Ctx) -> R<()> {
    let nx = v.nx_per_segment;
    if nx == 0 {
        return Err(ctx.err("viaduct.nx_per_segment", "must be at least 1"));
    }
    let q4 = matches!(v.element.as_deref(), Some("Q4" | "q4"));
    let per = if q4 { nx } else { 2 * nx };
    if per % 2 == 1 {
        return Err(ctx.err(
            "viaduct.nx_per_segment",
            format!("with Q4 elements it must be even (got {nx}): the piers and deviators sit at segment centres, which need a node column"),
        ));
    }
    let spacing = v.end_segment / per as f64;
    let columns = v.overhang / spacing;
    // Round-off only: the overhang is a whole number of column spacings or it is not.
    if (columns - columns.round()).abs() > 1e-9 * per as f64 {
        return Err(ctx.err(
            "viaduct.overhang",
            format!(
                "the end bearing, {} m from the girder's end, falls between the node columns of the end segment (every {spacing} m with nx_per_segment = {nx}{}): give an overhang that is a multiple of {spacing} m, or change end_segment or nx_per_segment",
                v.overhang,
                if q4 { ", Q4" } else { " and mid-side nodes" }
            ),
        ));
    }
    Ok(())
}

/// Check the section bands; their total depth [m].
pub(super) fn section(v: &ViaductIn, ctx: &Ctx) -> R<f64> {
    if v.section.is_empty() {
        return Err(ctx.err(
            "viaduct.section",
            "give the bands of the box section, bottom up: [{ name, width, depth, rows }, …]",
        ));
    }
    let mut depth = 0.0;
    for (i, b) in v.section.iter().enumerate() {
        let k = |f: &str| format!("viaduct.section[{i}].{f}");
        if b.name.trim().is_empty() {
            return Err(ctx.err(k("name"), "must not be empty"));
        }
        if v.section[..i].iter().any(|o| o.name == b.name) {
            return Err(ctx.err(
                k("name"),
                format!("'{}' names two bands: each band is its own region", b.name),
            ));
        }
        for (key, x, what) in [
            ("width", b.width, "out-of-plane width"),
            ("depth", b.depth, "depth"),
        ] {
            if !(x.is_finite() && x > 0.0) {
                return Err(ctx.err(k(key), format!("must be a positive {what} [m] (got {x})")));
            }
        }
        depth += b.depth;
    }
    Ok(depth)
}

/// Bearings (A1 fixed, the piers and A2 sliding) and one falsework per span, a line under
/// the soffit from bearing to bearing, bearings excluded. All push up only (`one_way =
/// "+y"`): a bearing or a falsework carries the girder and lets it lift off; `hold_down`
/// makes the named ones two-way.
fn supports(layout: &Layout) -> Vec<SupportIn> {
    let b = &layout.bearings;
    let n = b.len() - 1;
    let support = |name: String, point: Option<[f64; 2]>, line, ux| SupportIn {
        name,
        node: None,
        point,
        line,
        group: None,
        ux,
        uy: Some(0.0),
        bearing: None,
        local_zone: None,
        one_way: Some("+y".into()),
    };
    let mut list = Vec::new();
    for (i, &x) in b.iter().enumerate() {
        list.push(support(
            bearing_name(i, n),
            Some([x, 0.0]),
            None,
            (i == 0).then_some(0.0),
        ));
    }
    // Far enough inside the bearings (1e-4 of the girder, well above the 1e-6 × model size
    // tolerance of a line) not to take the bearing's node.
    let gap = 1e-4 * (layout.end() - layout.x0);
    for i in 0..n {
        list.push(support(
            format!("falsework {}", i + 1),
            None,
            Some(vec![[b[i] + gap, 0.0], [b[i + 1] - gap, 0.0]]),
            None,
        ));
    }
    list
}

/// The name of bearing `i` of `n` spans: A1, P1 … P(n−1), A2.
pub(super) fn bearing_name(i: usize, n: usize) -> String {
    if i == 0 {
        "A1".into()
    } else if i == n {
        "A2".into()
    } else {
        format!("P{i}")
    }
}

/// The name of the step that places span `k` (1-based) and stresses its tendons.
fn place_step(k: usize) -> String {
    format!("place and stress span {k}")
}

/// Per span: place its segments on their falsework (with the far bearing, from span 2 on)
/// and stress its tendons; strike the falsework; let it creep until the next span.
fn erection_steps(
    v: &ViaductIn,
    layout: &Layout,
    start: f64,
    strike: usize,
    span_interval: f64,
) -> Vec<StepIn> {
    let n = v.spans.len();
    let sw = || BTreeMap::from([("self_weight".to_string(), 1.0)]);
    let mut steps = Vec::new();
    for (i, group) in layout.groups.iter().enumerate() {
        let mut activate: Vec<String> = group.iter().map(|s| format!("S{}", s + 1)).collect();
        activate.push(format!("falsework {}", i + 1));
        if i > 0 {
            activate.push(bearing_name(i + 1, n));
        }
        let mut place = step(place_step(i + 1), "load");
        place.loads = sw();
        place.activate = activate;
        steps.push(place);
        let mut strike_step = step(format!("strike falsework {}", i + 1), "load");
        strike_step.loads = sw();
        strike_step.increments = Some(strike);
        strike_step.remove = vec![format!("falsework {}", i + 1)];
        steps.push(strike_step);
        let mut creep = step(format!("span {} creeps", i + 1), "time");
        creep.from = (i == 0).then_some(start);
        creep.to = Some(start + (i + 1) as f64 * span_interval);
        steps.push(creep);
    }
    steps
}

/// A step with every optional key left out.
pub(super) fn step(name: String, kind: &str) -> StepIn {
    StepIn {
        name,
        kind: kind.into(),
        loads: BTreeMap::new(),
        increments: None,
        output: None,
        control: None,
        initial_increment: None,
        desired_iterations: None,
        max_growth: None,
        target_factor: None,
        stop_displacement: None,
        from: None,
        to: None,
        duration: None,
        substeps: None,
        first_substep: None,
        substep_tolerance: None,
        activate: Vec::new(),
        remove: Vec::new(),
    }
}

/// The strand's E_p, f_ptk [Pa] and ε_uk from the `[[materials]]` entry `viaduct.strand`.
pub(super) fn strand(v: &ViaductIn, file: &File, ctx: &Ctx) -> R<(f64, f64, Option<f64>)> {
    let name = v.strand.as_deref().ok_or_else(|| {
        ctx.err(
            "viaduct.strand",
            "missing: the name of the prestressing_steel [[materials]] entry of the tendons",
        )
    })?;
    let (i, m) = file
        .materials
        .iter()
        .enumerate()
        .find(|(_, m)| m.name == name)
        .ok_or_else(|| {
            let known: Vec<&str> = file.materials.iter().map(|m| m.name.as_str()).collect();
            ctx.err(
                "viaduct.strand",
                format!(
                    "no [[materials]] entry named '{name}' (defined: {})",
                    known.join(", ")
                ),
            )
        })?;
    if MaterialKind::from_name(&m.kind) != Some(MaterialKind::PrestressingSteel) {
        return Err(ctx.err(
            "viaduct.strand",
            format!(
                "material '{name}' is of kind '{}': the tendons need a prestressing_steel",
                m.kind
            ),
        ));
    }
    let need = |key: &str, x: Option<f64>| {
        x.ok_or_else(|| {
            ctx.err(
                format!("materials[{i}].{key}"),
                "missing (the [viaduct] tendons take it from this strand)",
            )
        })
    };
    Ok((
        need("Ep", m.number("Ep"))?,
        need("fptk", m.number("fptk"))?,
        m.number("eps_uk"),
    ))
}

/// A tendon of the strand with every optional key left out.
pub(super) fn tendon(
    name: String,
    points: Vec<[f64; 2]>,
    area: f64,
    steel: (f64, f64, Option<f64>),
) -> TendonIn {
    TendonIn {
        name,
        kind: "external".into(),
        points,
        parabola: None,
        arc: None,
        segments: None,
        area,
        ep: steel.0,
        fptk: steel.1,
        eps_uk: steel.2,
        initial_stress: None,
        jacking_stress: None,
        jacking_force: None,
        anchorage_set: None,
        grouted_in_step: None,
        gauss_points: None,
        jacking: None,
        friction: None,
        wobble: None,
        deviators: None,
        deviator_friction: None,
        stressed_in_step: None,
        relaxation_class: None,
        thermal_expansion: None,
        anchor_plate: None,
        local_zone: None,
    }
}

/// Set a generated tendon's stressing: jacking stress [Pa] and end(s), friction μ, wobble
/// [rad/m] and anchorage set [m] (in that order, each optional), relaxation class.
pub(super) fn stressing(
    tn: &mut TendonIn,
    jacking_stress: f64,
    jacking: &Option<String>,
    [friction, wobble, anchorage_set]: [Option<f64>; 3],
    relaxation_class: Option<i64>,
) {
    tn.jacking_stress = Some(jacking_stress);
    tn.jacking = jacking.clone();
    tn.friction = friction;
    tn.wobble = wobble;
    tn.anchorage_set = anchorage_set;
    tn.relaxation_class = relaxation_class;
}

/// Span tendons T1 … Tn (anchored at the girder ends and on the pier axes, through the
/// deviators of each span; stressed when the span is placed) and continuity tendons
/// C1 … C(n−1) over the piers (stressed with the span after the pier).
fn tendons(v: &ViaductIn, layout: &Layout, depth: f64, file: &File, ctx: &Ctx) -> R<Vec<TendonIn>> {
    if v.span_tendons.is_none() && v.continuity_tendons.is_none() {
        return Ok(Vec::new());
    }
    let steel = strand(v, file, ctx)?;
    let height = |key: String, h: f64| -> R<f64> {
        if h.is_finite() && (0.0..=depth).contains(&h) {
            Ok(h)
        } else {
            Err(ctx.err(
                key,
                format!("must be a height above the soffit within the section's depth [0, {depth}] m (got {h})"),
            ))
        }
    };
    let n = v.spans.len();
    let b = &layout.bearings;
    let mut list = Vec::new();
    if let Some(t) = &v.span_tendons {
        let k = |f: &str| format!("viaduct.span_tendons.{f}");
        let end_h = height(k("end_anchor_height"), t.end_anchor_height)?;
        let pier_h = height(k("pier_anchor_height"), t.pier_anchor_height)?;
        if t.deviators.is_empty() {
            return Err(ctx.err(
                k("deviators"),
                "give the deviators of each span: [{ segment, height }, …]",
            ));
        }
        for (j, d) in t.deviators.iter().enumerate() {
            height(format!("{}[{j}].height", k("deviators")), d.height)?;
            let fewest = layout.typical.iter().map(|t| t.1).min().unwrap_or(0);
            if d.segment == 0 || d.segment > fewest {
                return Err(ctx.err(
                    format!("{}[{j}].segment", k("deviators")),
                    format!(
                        "must count a typical segment of every span from its left end, 1 … {fewest} (got {})",
                        d.segment
                    ),
                ));
            }
            if j > 0 && d.segment <= t.deviators[j - 1].segment {
                return Err(ctx.err(
                    format!("{}[{j}].segment", k("deviators")),
                    "deviators go left to right: each segment after the one before",
                ));
            }
        }
        for i in 0..n {
            let first = if i == 0 {
                [layout.x0, end_h]
            } else {
                [b[i], pier_h]
            };
            let last = if i + 1 == n {
                [layout.end(), end_h]
            } else {
                [b[i + 1], pier_h]
            };
            let mut points = vec![first];
            let (s0, _) = layout.typical[i];
            for d in &t.deviators {
                let s = s0 + d.segment - 1;
                points.push([layout.start(s) + layout.lengths[s] / 2.0, d.height]);
            }
            points.push(last);
            let mut tn = tendon(format!("T{}", i + 1), points, t.area, steel);
            stressing(
                &mut tn,
                t.jacking_stress,
                &t.jacking,
                [t.friction, t.wobble, t.anchorage_set],
                t.relaxation_class,
            );
            tn.deviators = t.deviator_mode.clone();
            tn.deviator_friction = t.deviator_friction;
            tn.stressed_in_step = Some(place_step(i + 1));
            list.push(tn);
        }
    }
    if let Some(c) = &v.continuity_tendons {
        let k = |f: &str| format!("viaduct.continuity_tendons.{f}");
        let h = height(k("height"), c.height)?;
        if n < 2 {
            return Err(ctx.err(
                "viaduct.continuity_tendons",
                "a single span has no pier to make continuous over",
            ));
        }
        if !(c.reach.is_finite() && c.reach > 0.0) {
            return Err(ctx.err(
                k("reach"),
                format!(
                    "must be a positive length [m] from the pier to each anchor (got {})",
                    c.reach
                ),
            ));
        }
        for i in 1..n {
            let (a, z) = (b[i] - c.reach, b[i] + c.reach);
            if a <= layout.x0 || z >= layout.end() {
                return Err(ctx.err(
                    k("reach"),
                    format!(
                        "the tendon over pier P{i} would run from x = {a:.3} to {z:.3} m, beyond the girder ({:.3} … {:.3} m)",
                        layout.x0,
                        layout.end()
                    ),
                ));
            }
            let mut tn = tendon(format!("C{i}"), vec![[a, h], [z, h]], c.area, steel);
            stressing(
                &mut tn,
                c.jacking_stress,
                &c.jacking,
                [c.friction, c.wobble, c.anchorage_set],
                c.relaxation_class,
            );
            tn.stressed_in_step = Some(place_step(i + 1));
            list.push(tn);
        }
    }
    Ok(list)
}
