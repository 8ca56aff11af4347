//! `[viaduct]` with `sequence = "balanced_cantilever"`: a continuous segmental box girder
//! built by balanced cantilever from its piers (docs/input.md, "[viaduct]";
//! docs/theory-stages.md §6b).
//!
//! Each pier segment is set on its pier with a temporary fixity; segment pairs are placed
//! either side of every pier and stressed together with a cantilever tendon in the deck
//! slab, the form traveller or lifting frame moving out with the tips; the ends of the side
//! spans stand on falsework; closures are cast in place; the fixities are released onto the
//! permanent bearings, the continuity tendons stressed and the falsework struck.

use super::viaduct::{
    attach, bearing_name, bearings, check_materials, generated_regions, hold_down, mesh_in,
    no_generated_mesh, node_columns, section, self_weight, step, strand, stressing, tendon, Lists,
    ViaductIn, STRIKE_INCREMENTS,
};
use super::Generated;
use crate::input::error::{Ctx, InputError};
use crate::input::schema::{File, LoadCaseIn, PointLoadIn, StepIn, SupportIn, TendonIn};
use crate::mesh::segmental::piecewise_linear;
use serde::Deserialize;
use std::collections::BTreeMap;

type R<T> = Result<T, InputError>;

/// Default days between casting a closure and loading it (its formwork struck, its
/// concrete able to carry the continuity tendons).
pub const CLOSURE_AGE: f64 = 3.0;

/// `[viaduct.cantilever]` (keys documented in docs/input.md, "[viaduct]").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CantileverIn {
    pub pairs: Vec<usize>,
    pub closure: f64,
    pub closure_age: Option<f64>,
    pub pair_interval: f64,
    pub traveller: Option<f64>,
    pub pier_depth: Option<f64>,
    pub haunch_band: Option<String>,
    pub haunch_length: Option<f64>,
    pub tendons: Option<CantileverTendonsIn>,
}

/// `[viaduct.cantilever.tendons]`: one bonded tendon per segment pair, straight in the deck.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CantileverTendonsIn {
    pub area: f64,
    pub height: f64,
    pub jacking_stress: f64,
    pub jacking: Option<String>,
    pub friction: Option<f64>,
    pub wobble: Option<f64>,
    pub anchorage_set: Option<f64>,
    pub relaxation_class: Option<i64>,
}

/// `[viaduct.closure_tendons]`: a bonded tendon through each closure, following the soffit.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ClosureTendonsIn {
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

/// What a segment of the girder is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Part {
    /// Over an abutment (side span 0 or the last).
    End,
    /// A typical segment of a side span's end, on falsework.
    Side,
    /// Cast in place, closing span `span` (0-based).
    Closure { span: usize },
    /// Centred on pier `pier` (0-based: P1 is 0).
    Pier { pier: usize },
    /// Pair `pair` (1-based, from the pier out) of pier `pier`.
    Arm { pier: usize, pair: usize },
}

/// The girder along x [m].
struct Girder {
    /// Segment lengths [m], left to right.
    lengths: Vec<f64>,
    /// What each segment is.
    parts: Vec<Part>,
    /// Bearing abscissae [m]: A1, P1 …, A2.
    bearings: Vec<f64>,
    /// Left end of the girder [m].
    x0: f64,
}

impl Girder {
    fn start(&self, s: usize) -> f64 {
        self.x0 + self.lengths[..s].iter().sum::<f64>()
    }
    fn end(&self) -> f64 {
        self.start(self.lengths.len())
    }
    /// Node-column abscissae [m] from `a` to `b` (both included when on a column).
    fn columns(&self, per: usize, a: f64, b: f64) -> Vec<f64> {
        let mut xs = Vec::new();
        for (s, &len) in self.lengths.iter().enumerate() {
            let x = self.start(s);
            for i in 0..=per {
                let xi = x + len * i as f64 / per as f64;
                if xi >= a - 1e-9 && xi <= b + 1e-9 && xs.last().is_none_or(|&l| xi > l + 1e-9) {
                    xs.push(xi);
                }
            }
        }
        xs
    }
}

/// The keys a balanced-cantilever `[viaduct]` must and must not have: its
/// `[viaduct.cantilever]` and the precast segments' `segment_age` [d], checked.
fn cantilever_table<'v>(v: &'v ViaductIn, ctx: &Ctx) -> R<(&'v CantileverIn, f64)> {
    let k = |f: &str| format!("viaduct.{f}");
    for (key, given) in [
        ("cast_start", !v.cast_start.is_empty()),
        ("cast_interval", v.cast_interval.is_some()),
        ("span_interval", v.span_interval.is_some()),
        ("span_tendons", v.span_tendons.is_some()),
        ("continuity_tendons", v.continuity_tendons.is_some()),
    ] {
        if given {
            return Err(ctx.err(
                k(key),
                "only with sequence = \"span_by_span\" (balanced_cantilever: segment_age, [viaduct.cantilever], [viaduct.closure_tendons])",
            ));
        }
    }
    let c = v.cantilever.as_ref().ok_or_else(|| {
        ctx.err(
            k("cantilever"),
            "missing: balanced_cantilever needs [viaduct.cantilever] (pairs, closure, pair_interval)",
        )
    })?;
    let age = v.segment_age.ok_or_else(|| {
        ctx.err(
            k("segment_age"),
            "missing: the age of the precast segments when they are placed [days]",
        )
    })?;
    if !(age.is_finite() && age > 0.0) {
        return Err(ctx.err(
            k("segment_age"),
            format!("must be a positive number of days (got {age})"),
        ));
    }
    Ok((c, age))
}

/// Expand a balanced-cantilever `[viaduct]` into the model's tables.
pub fn expand(v: &ViaductIn, file: &mut File, ctx: &Ctx) -> R<Generated> {
    let (c, age) = cantilever_table(v, ctx)?;
    let k = |f: &str| format!("viaduct.{f}");
    no_generated_mesh(file, ctx)?;
    node_columns(v, ctx)?;
    let depth = section(v, ctx)?;
    check_materials(v, file, ctx)?;
    let g = girder(v, c, ctx)?;
    let start = v.erection_start.unwrap_or(0.0);
    if !start.is_finite() {
        return Err(ctx.err(k("erection_start"), "must be a finite number [days]"));
    }
    let ck = |f: &str| format!("viaduct.cantilever.{f}");
    if !(c.pair_interval.is_finite() && c.pair_interval > 0.0) {
        return Err(ctx.err(
            ck("pair_interval"),
            format!(
                "must be a positive number of days (got {})",
                c.pair_interval
            ),
        ));
    }
    let closure_age = c.closure_age.unwrap_or(CLOSURE_AGE);
    if !(closure_age.is_finite() && closure_age > 0.0) {
        return Err(ctx.err(
            ck("closure_age"),
            format!("must be a positive number of days (got {closure_age})"),
        ));
    }
    let strike = v.strike_increments.unwrap_or(STRIKE_INCREMENTS);
    if strike == 0 {
        return Err(ctx.err(k("strike_increments"), "must be at least 1"));
    }
    let traveller = c.traveller.unwrap_or(0.0);
    if !(traveller.is_finite() && traveller >= 0.0) {
        return Err(ctx.err(
            ck("traveller"),
            format!("must be zero or a positive weight [N] (got {traveller})"),
        ));
    }
    let soffit = haunch(v, c, &g, depth, ctx)?;
    for (i, p) in v.camber.iter().enumerate() {
        let ok = p[0].is_finite() && p[1].is_finite();
        if !ok || (i > 0 && p[0] <= v.camber[i - 1][0]) {
            return Err(ctx.err(
                format!("viaduct.camber[{i}]"),
                "points [x, dy] (m) with finite values and x increasing",
            ));
        }
    }
    let camber = |x: f64| {
        if v.camber.is_empty() {
            0.0
        } else {
            piecewise_linear(&v.camber)(x)
        }
    };
    let per = columns_per_segment(v);
    let geo = Geometry {
        g: &g,
        per,
        corners: v.nx_per_segment,
        soffit: &soffit,
        camber: &camber,
        depth,
    };

    let pairs = c.pairs.iter().copied().max().unwrap_or(0);
    let t = |j: usize| start + j as f64 * c.pair_interval;
    let closing = t(pairs);
    let cast_days: Vec<f64> = g
        .parts
        .iter()
        .map(|p| match p {
            Part::Arm { pair, .. } => t(*pair) - age,
            Part::Closure { .. } => closing,
            _ => start - age,
        })
        .collect();
    let mut generated = generated_regions(v, file);
    let mut mesh = mesh_in(v, &g.lengths, g.x0, cast_days);
    for (s, p) in g.parts.iter().enumerate() {
        if matches!(p, Part::Closure { .. }) {
            // Joint J(s) is left of segment s (0-based), J(s+1) right of it.
            mesh.cast_joints.push(format!("J{s}"));
            mesh.cast_joints.push(format!("J{}", s + 1));
        }
    }
    if let Some(band) = &c.haunch_band {
        mesh.soffit = g
            .columns(per, g.x0, g.end())
            .into_iter()
            .map(|x| [x, soffit(x)])
            .collect();
        mesh.soffit_band = Some(band.clone());
    }
    mesh.camber = v.camber.clone();
    file.mesh = Some(mesh);

    let supports = hold_down(v, supports(&geo), ctx)?;
    let supports = bearings(v, supports, geo.g.bearings.len() - 1, ctx)?;
    let mut load_cases = vec![self_weight()];
    if traveller > 0.0 {
        load_cases.extend((0..=pairs).map(|j| traveller_case(&geo, c, j, traveller)));
    }
    let tendons = tendons(v, c, &geo, file, ctx)?;
    let steps = steps(
        v,
        c,
        &g,
        start,
        closing + closure_age,
        strike,
        traveller > 0.0,
    );
    let lists = Lists {
        supports,
        tendons,
        load_cases,
        steps,
    };
    attach(ctx, &mut generated, file, lists)?;
    Ok(generated)
}

/// Node columns per segment: `nx_per_segment` for Q4, twice that with mid-side nodes.
fn columns_per_segment(v: &ViaductIn) -> usize {
    if matches!(v.element.as_deref(), Some("Q4" | "q4")) {
        v.nx_per_segment
    } else {
        2 * v.nx_per_segment
    }
}

/// The girder's shape as the generated tables need it.
struct Geometry<'a> {
    g: &'a Girder,
    per: usize,
    /// Element (corner-node) columns per segment.
    corners: usize,
    soffit: &'a dyn Fn(f64) -> f64,
    camber: &'a dyn Fn(f64) -> f64,
    depth: f64,
}

impl Geometry<'_> {
    /// The soffit, cambered, at `x` [m].
    fn bottom(&self, x: f64) -> f64 {
        (self.soffit)(x) + (self.camber)(x)
    }
    /// The polyline under the soffit from `a` to `b` through every node column.
    fn under(&self, a: f64, b: f64) -> Vec<[f64; 2]> {
        let mut xs = vec![a];
        xs.extend(
            self.g
                .columns(self.per, a, b)
                .into_iter()
                .filter(|&x| x > a && x < b),
        );
        xs.push(b);
        xs.into_iter().map(|x| [x, self.bottom(x)]).collect()
    }
    /// Spacing of the node columns of a typical segment [m].
    fn spacing(&self, s: usize) -> f64 {
        self.g.lengths[s] / self.per as f64
    }
}

/// Segments left to right and the check that the spans close.
fn girder(v: &ViaductIn, c: &CantileverIn, ctx: &Ctx) -> R<Girder> {
    let k = |f: &str| format!("viaduct.{f}");
    let positive = |key: String, x: f64| -> R<f64> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(ctx.err(key, format!("must be a positive length [m] (got {x})")))
        }
    };
    let n = v.spans.len();
    if n < 2 {
        return Err(ctx.err(
            k("spans"),
            "balanced cantilever needs at least two spans (a pier to build from)",
        ));
    }
    for (i, l) in v.spans.iter().enumerate() {
        positive(k(&format!("spans[{i}]")), *l)?;
    }
    let seg = positive(k("segment_length"), v.segment_length)?;
    let pier = positive(k("pier_segment"), v.pier_segment)?;
    let end = positive(k("end_segment"), v.end_segment)?;
    let closure = positive(k("cantilever.closure"), c.closure)?;
    if !(v.overhang.is_finite() && v.overhang >= 0.0 && v.overhang < end) {
        return Err(ctx.err(
            k("overhang"),
            format!(
                "the girder's end beyond the end bearing must lie in [0, end_segment = {end}) m (got {})",
                v.overhang
            ),
        ));
    }
    if c.pairs.len() != n - 1 {
        return Err(ctx.err(
            k("cantilever.pairs"),
            format!(
                "give the number of segment pairs of each pier: {} piers, {} numbers",
                n - 1,
                c.pairs.len()
            ),
        ));
    }
    if let Some(i) = c.pairs.iter().position(|&p| p == 0) {
        return Err(ctx.err(
            format!("viaduct.cantilever.pairs[{i}]"),
            "must be at least 1",
        ));
    }
    let arm = |p: usize| c.pairs[p] as f64 * seg;
    // Side spans: abutment end, whole typical segments on falsework, closure, the arm.
    let side = |span: usize, p: usize| -> R<usize> {
        let l = v.spans[span];
        let free = l - (end - v.overhang) - closure - arm(p) - pier / 2.0;
        let m = (free / seg).round();
        // Segments are cast to the millimetre: 1e-6 m leaves room for round-off only.
        if m >= 0.0 && (m * seg - free).abs() <= 1e-6 {
            return Ok(m as usize);
        }
        Err(ctx.err(
            k(&format!("spans[{span}]")),
            format!(
                "side span {} leaves {free:.4} m between its end segment and its closure: not a whole number of {seg} m segments on falsework (change the span, the pairs of P{}, the closure or the segments)",
                span + 1,
                p + 1
            ),
        ))
    };
    let first = side(0, 0)?;
    let last = side(n - 1, n - 2)?;
    for i in 1..n - 1 {
        let total = pier + arm(i - 1) + closure + arm(i);
        if (total - v.spans[i]).abs() > 1e-6 {
            return Err(ctx.err(
                k(&format!("spans[{i}]")),
                format!(
                    "span {} is {} m but the arms of P{} and P{} ({} and {} pairs of {seg} m), the closure and the pier segments give {total:.4} m",
                    i + 1,
                    v.spans[i],
                    i,
                    i + 1,
                    c.pairs[i - 1],
                    c.pairs[i]
                ),
            ));
        }
    }
    let mut lengths = vec![end];
    let mut parts = vec![Part::End];
    let mut push = |len: f64, p: Part| {
        lengths.push(len);
        parts.push(p);
    };
    for _ in 0..first {
        push(seg, Part::Side);
    }
    push(closure, Part::Closure { span: 0 });
    for p in 0..n - 1 {
        for pair in (1..=c.pairs[p]).rev() {
            push(seg, Part::Arm { pier: p, pair });
        }
        push(pier, Part::Pier { pier: p });
        for pair in 1..=c.pairs[p] {
            push(seg, Part::Arm { pier: p, pair });
        }
        push(closure, Part::Closure { span: p + 1 });
    }
    for _ in 0..last {
        push(seg, Part::Side);
    }
    push(end, Part::End);
    let mut bearings = vec![0.0];
    for l in &v.spans {
        bearings.push(bearings.last().expect("starts at 0") + l);
    }
    Ok(Girder {
        lengths,
        parts,
        bearings,
        x0: -v.overhang,
    })
}

/// The soffit's ordinate y(x) [m]: 0 where the section has its `section` depth, lowered
/// towards each pier where `pier_depth` is given — constant over the pier segment, then a
/// parabola with its vertex at the pier segment's face, back to 0 at `haunch_length` from
/// it (default: the arm).
fn haunch(
    v: &ViaductIn,
    c: &CantileverIn,
    g: &Girder,
    depth: f64,
    ctx: &Ctx,
) -> R<Box<dyn Fn(f64) -> f64>> {
    let ck = |f: &str| format!("viaduct.cantilever.{f}");
    let d = match (c.pier_depth, &c.haunch_band) {
        (None, None) => {
            if c.haunch_length.is_some() {
                return Err(ctx.err(ck("haunch_length"), "only with pier_depth"));
            }
            return Ok(Box::new(|_| 0.0));
        }
        (Some(_), None) => return Err(ctx.err(
            ck("haunch_band"),
            "missing: name the band of viaduct.section that deepens towards the piers (the webs)",
        )),
        (None, Some(_)) => {
            return Err(ctx.err(
                ck("pier_depth"),
                "missing: the section's depth over the piers [m]",
            ))
        }
        (Some(h), Some(band)) => {
            if !v.section.iter().any(|b| &b.name == band) {
                let names: Vec<&str> = v.section.iter().map(|b| b.name.as_str()).collect();
                return Err(ctx.err(
                    ck("haunch_band"),
                    format!("no band named '{band}' (bands: {})", names.join(", ")),
                ));
            }
            if !(h.is_finite() && h > depth) {
                return Err(ctx.err(
                    ck("pier_depth"),
                    format!("must exceed the section's depth {depth} m (got {h})"),
                ));
            }
            h - depth
        }
    };
    let piers: Vec<(f64, f64)> = (0..c.pairs.len())
        .map(|p| {
            let arm = c.pairs[p] as f64 * v.segment_length;
            (g.bearings[p + 1], c.haunch_length.unwrap_or(arm))
        })
        .collect();
    for (p, &(_, a)) in piers.iter().enumerate() {
        let arm = c.pairs[p] as f64 * v.segment_length;
        if !(a.is_finite() && a > 0.0 && a <= arm + 1e-9) {
            return Err(ctx.err(
                ck("haunch_length"),
                format!(
                    "must be positive and reach no further than the arm of P{} ({arm} m), got {a}",
                    p + 1
                ),
            ));
        }
    }
    let half = v.pier_segment / 2.0;
    Ok(Box::new(move |x| {
        let mut y: f64 = 0.0;
        for &(xp, a) in &piers {
            let s = ((x - xp).abs() - half).max(0.0);
            if s < a {
                y = y.min(-d * (1.0 - s / a).powi(2));
            }
        }
        y
    }))
}

/// Bearings A1 (fixed), P1 …, A2 (one-way up); a two-way fixity under each pier segment
/// (in x and y, released at "release fixity"); falsework under the ends of the side spans.
fn supports(geo: &Geometry) -> Vec<SupportIn> {
    let g = geo.g;
    let b = &g.bearings;
    let n = b.len() - 1;
    let support = |name: String, point, line, ux, one_way: bool| SupportIn {
        name,
        node: None,
        point,
        line,
        group: None,
        ux,
        uy: Some(0.0),
        bearing: None,
        local_zone: None,
        one_way: one_way.then(|| "+y".into()),
    };
    let mut list = Vec::new();
    for (i, &x) in b.iter().enumerate() {
        let ux = (i == 0).then_some(0.0);
        list.push(support(
            bearing_name(i, n),
            Some([x, geo.bottom(x)]),
            None,
            ux,
            true,
        ));
    }
    // The far side span's end stands on sliding A2 and falsework: a temporary restraint in
    // x holds it until the girder is continuous and rests on its fixed bearing A1.
    let mut restraint = support(
        RESTRAINT.into(),
        Some([b[n], geo.bottom(b[n])]),
        None,
        Some(0.0),
        false,
    );
    restraint.uy = None;
    list.push(restraint);
    // Far enough inside the segment ends (1e-4 of the girder, well above the 1e-6 × model
    // size tolerance of a line) not to take the neighbouring segment's joint nodes.
    let gap = 1e-4 * (g.end() - g.x0);
    for (s, p) in g.parts.iter().enumerate() {
        if let Part::Pier { pier } = p {
            // Two lines either side of the bearing's node (which the bearing holds one way).
            let (a, z) = (g.start(s) + gap, g.start(s + 1) - gap);
            let xp = b[pier + 1];
            for (side, a, z) in [("left", a, xp - gap), ("right", xp + gap, z)] {
                list.push(support(
                    fixity(*pier, side),
                    None,
                    Some(geo.under(a, z)),
                    Some(0.0),
                    false,
                ));
            }
        }
    }
    // The side spans' ends: from the bearing to the closure (the bearing's node excluded).
    let first_closure = g
        .parts
        .iter()
        .position(|p| matches!(p, Part::Closure { .. }));
    let last_closure = g
        .parts
        .iter()
        .rposition(|p| matches!(p, Part::Closure { .. }));
    if let (Some(f), Some(l)) = (first_closure, last_closure) {
        list.push(support(
            "falsework 1".into(),
            None,
            Some(geo.under(b[0] + gap, g.start(f) - gap)),
            None,
            true,
        ));
        list.push(support(
            format!("falsework {n}"),
            None,
            Some(geo.under(g.start(l + 1) + gap, b[n] - gap)),
            None,
            true,
        ));
    }
    list
}

/// Load case "traveller j": the form traveller (or lifting frame) of every pier at the tips
/// of its pair j (pair 0: the pier segment's faces; a pier with fewer pairs keeps it at its
/// last tip), one node column in from each tip, on the deck.
fn traveller_case(geo: &Geometry, c: &CantileverIn, j: usize, weight: f64) -> LoadCaseIn {
    let g = geo.g;
    let mut point_loads = Vec::new();
    for (s, p) in g.parts.iter().enumerate() {
        if let Part::Pier { pier } = p {
            let reach = j.min(c.pairs[*pier]);
            let left = s - reach;
            let right = s + reach;
            for (x, inward) in [
                (g.start(left), geo.spacing(left)),
                (g.start(right + 1), -geo.spacing(right)),
            ] {
                let x = x + inward;
                point_loads.push(PointLoadIn {
                    node: None,
                    point: Some([x, geo.depth + (geo.camber)(x)]),
                    force: [0.0, -weight],
                    bearing: None,
                    local_zone: None,
                });
            }
        }
    }
    LoadCaseIn {
        name: traveller_name(j),
        gravity: None,
        point_loads,
        line_loads: Vec::new(),
        temperature: None,
    }
}

/// The temporary fixity of pier `pier` (0-based) on one side of its bearing.
fn fixity(pier: usize, side: &str) -> String {
    format!("fixity P{} {side}", pier + 1)
}

/// Both fixities of every pier.
fn fixities(piers: usize) -> Vec<String> {
    (0..piers)
        .flat_map(|p| [fixity(p, "left"), fixity(p, "right")])
        .collect()
}

fn traveller_name(j: usize) -> String {
    format!("traveller {j}")
}

fn pair_step(j: usize) -> String {
    format!("place pair {j}")
}

/// The temporary restraint in x of the far side span's end, released with the fixities.
const RESTRAINT: &str = "restraint A2";
const PIER_STEP: &str = "place pier segments";
const CLOSE_STEP: &str = "close spans";
const RELEASE_STEP: &str = "release fixity";
const CONTINUITY_STEP: &str = "stress continuity";
const STRIKE_STEP: &str = "strike falsework";

/// The erection sequence: pier segments and side-span ends; per pair j, `pair_interval`
/// days of creep, then pair j placed at every pier and its tendons stressed; the closures
/// harden `closure_age` days; closures placed, fixities released onto the bearings,
/// continuity tendons stressed, falsework struck.
fn steps(
    v: &ViaductIn,
    c: &CantileverIn,
    g: &Girder,
    start: f64,
    closed: f64,
    strike: usize,
    travellers: bool,
) -> Vec<StepIn> {
    let n = v.spans.len();
    let pairs = c.pairs.iter().copied().max().unwrap_or(0);
    let sw = || BTreeMap::from([("self_weight".to_string(), 1.0)]);
    let mut steps = Vec::new();
    let mut first = step(PIER_STEP.into(), "load");
    first.loads = sw();
    if travellers {
        first.loads.insert(traveller_name(0), 1.0);
    }
    // Pier segments, fixities, and the side spans' ends on falsework with their abutments.
    first.activate = segment_names(g, |p| {
        matches!(p, Part::Pier { .. } | Part::End | Part::Side)
    });
    first.activate.extend(fixities(n - 1));
    first.activate.push(RESTRAINT.into());
    first.activate.extend([
        "A1".into(),
        "A2".into(),
        "falsework 1".into(),
        format!("falsework {n}"),
    ]);
    steps.push(first);
    for j in 1..=pairs {
        let mut wait = step(format!("cantilevers creep {j}"), "time");
        wait.from = (j == 1).then_some(start);
        wait.to = Some(start + j as f64 * c.pair_interval);
        steps.push(wait);
        let mut place = step(pair_step(j), "load");
        place.loads = sw();
        if travellers {
            place.loads.insert(traveller_name(j - 1), 0.0);
            place.loads.insert(traveller_name(j), 1.0);
        }
        place.activate = segment_names(g, |p| matches!(p, Part::Arm { pair, .. } if *pair == j));
        steps.push(place);
    }
    let mut harden = step("closures harden".into(), "time");
    harden.from = (pairs == 0).then_some(start);
    harden.to = Some(closed);
    steps.push(harden);
    let mut close = step(CLOSE_STEP.into(), "load");
    close.loads = sw();
    if travellers {
        close.loads.insert(traveller_name(pairs), 0.0);
    }
    close.activate = segment_names(g, |p| matches!(p, Part::Closure { .. }));
    steps.push(close);
    let mut release = step(RELEASE_STEP.into(), "load");
    release.loads = sw();
    release.increments = Some(strike);
    release.activate = (1..n).map(|p| format!("P{p}")).collect();
    release.remove = fixities(n - 1);
    release.remove.push(RESTRAINT.into());
    steps.push(release);
    if v.closure_tendons.is_some() {
        let mut stress = step(CONTINUITY_STEP.into(), "load");
        stress.loads = sw();
        steps.push(stress);
    }
    let mut strike_step = step(STRIKE_STEP.into(), "load");
    strike_step.loads = sw();
    strike_step.increments = Some(strike);
    strike_step.remove = vec!["falsework 1".into(), format!("falsework {n}")];
    steps.push(strike_step);
    steps
}

/// Names of the segments whose part passes `keep`.
fn segment_names(g: &Girder, keep: impl Fn(&Part) -> bool) -> Vec<String> {
    g.parts
        .iter()
        .enumerate()
        .filter(|(_, p)| keep(p))
        .map(|(s, _)| format!("S{}", s + 1))
        .collect()
}

/// Cantilever tendons "P{k}-{j}" (straight in the deck at `height`, anchored at the tip
/// faces of pair j of pier k, stressed when the pair is placed) and continuity tendons
/// "C{i}" through each span's closure (`height` above the soffit, tied to every node column
/// from `reach` before the closure's centre to `reach` after it; a side span's stops at the
/// girder's end), stressed after the fixities are released.
///
/// Both are unbonded (`external`, tied to the girder at their anchors and ties): an
/// embedded bonded tendon carries its force across a dry joint only where the two faces
/// share nodes, which match-cast segments do not (each segment's part of the tendon would
/// load that segment alone). Grouted internal tendons are so modelled as unbonded: the same
/// prestress and creep, a lower tendon stress at ultimate (docs/theory-stages.md §6b).
fn tendons(
    v: &ViaductIn,
    c: &CantileverIn,
    geo: &Geometry,
    file: &File,
    ctx: &Ctx,
) -> R<Vec<TendonIn>> {
    let ct = c.tendons.as_ref();
    let bt = v.closure_tendons.as_ref();
    if ct.is_none() && bt.is_none() {
        return Ok(Vec::new());
    }
    let steel = strand(v, file, ctx)?;
    let g = geo.g;
    let mut list = Vec::new();
    let positive = |key: &str, x: f64| -> R<f64> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(ctx.err(key, format!("must be positive (got {x})")))
        }
    };

    if let Some(t) = ct {
        let key = "viaduct.cantilever.tendons";
        positive(&format!("{key}.area"), t.area)?;
        if !(t.height.is_finite() && t.height > 0.0 && t.height < geo.depth) {
            return Err(ctx.err(
                format!("{key}.height"),
                format!(
                    "must lie inside the section, above the soffit and below its top ({} m), got {}",
                    geo.depth, t.height
                ),
            ));
        }
        for (s, p) in g.parts.iter().enumerate() {
            let Part::Pier { pier } = p else { continue };
            for j in 1..=c.pairs[*pier] {
                let (a, z) = (g.start(s - j), g.start(s + j + 1));
                let points = [a, z].map(|x| [x, t.height + (geo.camber)(x)]).to_vec();
                let mut tn = tendon(format!("P{}-{j}", pier + 1), points, t.area, steel);
                stressing(
                    &mut tn,
                    t.jacking_stress,
                    &t.jacking,
                    [t.friction, t.wobble, t.anchorage_set],
                    t.relaxation_class,
                );
                tn.stressed_in_step = Some(pair_step(j));
                list.push(tn);
            }
        }
    }
    if let Some(t) = bt {
        let key = "viaduct.closure_tendons";
        positive(&format!("{key}.area"), t.area)?;
        let reach = positive(&format!("{key}.reach"), t.reach)?;
        if !(t.height.is_finite() && t.height > 0.0 && t.height < geo.depth) {
            return Err(ctx.err(
                format!("{key}.height"),
                format!(
                    "must lie inside the section: above the soffit and below {} m (got {})",
                    geo.depth, t.height
                ),
            ));
        }
        for (s, p) in g.parts.iter().enumerate() {
            let Part::Closure { span } = p else { continue };
            let centre = g.start(s) + g.lengths[s] / 2.0;
            let (a, z) = ((centre - reach).max(g.x0), (centre + reach).min(g.end()));
            // Corner columns only: with mid-side nodes, a middle column has no node at
            // mid-height of a row to tie to.
            let points = g
                .columns(geo.corners, a, z)
                .into_iter()
                .map(|x| [x, geo.bottom(x) + t.height])
                .collect();
            let mut tn = tendon(format!("C{}", span + 1), points, t.area, steel);
            stressing(
                &mut tn,
                t.jacking_stress,
                &t.jacking,
                [t.friction, t.wobble, t.anchorage_set],
                t.relaxation_class,
            );
            tn.stressed_in_step = Some(CONTINUITY_STEP.into());
            list.push(tn);
        }
    }
    Ok(list)
}
