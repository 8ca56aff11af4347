//! Shared field checks of the builder: numbers in range, names unique and resolved,
//! locations (node, point or line) found in the mesh.

use super::R;
use crate::input::error::Ctx;
use crate::input::locate;
use crate::model::{Dir, Model};
use std::collections::HashMap;

pub(super) fn positive(ctx: &Ctx, key: &str, v: f64) -> R<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ctx.err(key, format!("must be a positive number (got {v})")))
    }
}

pub(super) fn index_by_name<'a>(
    ctx: &Ctx,
    key: &str,
    what: &str,
    names: impl Iterator<Item = &'a str> + Clone,
    wanted: &str,
) -> R<usize> {
    names.clone().position(|n| n == wanted).ok_or_else(|| {
        let known: Vec<&str> = names.collect();
        ctx.err(
            key,
            format!("no {what} named '{wanted}' (defined: {})", known.join(", ")),
        )
    })
}

/// A required reference by name (`missing` when absent, else it must name one of `names`).
pub(super) fn required_ref<'a>(
    ctx: &Ctx,
    key: &str,
    what: &str,
    value: Option<&str>,
    names: impl Iterator<Item = &'a str> + Clone,
) -> R<usize> {
    let name = value.ok_or_else(|| ctx.err(key, format!("missing (the name of a {what})")))?;
    index_by_name(ctx, key, what, names, name)
}

pub(super) fn unique_names<'a>(
    ctx: &Ctx,
    list: &str,
    names: impl Iterator<Item = &'a str>,
) -> R<()> {
    let mut seen = HashMap::new();
    for (i, n) in names.enumerate() {
        if n.trim().is_empty() {
            return Err(ctx.err(format!("{list}[{i}].name"), "must not be empty"));
        }
        // Names head the columns of history.csv and are typed on the command line.
        if let Some(c) = n.chars().find(|c| *c == ',' || *c == '"' || c.is_control()) {
            return Err(ctx.err(
                format!("{list}[{i}].name"),
                format!(
                    "{c:?} is not allowed in a name (names head the columns of history.csv: no commas, quotes or control characters)"
                ),
            ));
        }
        if let Some(j) = seen.insert(n, i) {
            return Err(ctx.err(
                format!("{list}[{i}].name"),
                format!("'{n}' is already used by {list}[{j}]"),
            ));
        }
    }
    Ok(())
}

pub(super) fn dir(ctx: &Ctx, key: &str, s: Option<&str>) -> R<Dir> {
    match s {
        Some("x") => Ok(Dir::X),
        Some("y") => Ok(Dir::Y),
        Some(o) => Err(ctx.err(key, format!("unknown component '{o}' (expected x or y)"))),
        None => Err(ctx.err(key, "missing (expected x or y)")),
    }
}

/// Resolve exactly one of node / point / line to a non-empty node list.
pub(super) fn locate_nodes(
    ctx: &Ctx,
    key: &str,
    model: &Model,
    used: &[bool],
    node: Option<i64>,
    point: Option<[f64; 2]>,
    line: Option<&[[f64; 2]]>,
) -> R<Vec<usize>> {
    let given = node.is_some() as u8 + point.is_some() as u8 + line.is_some() as u8;
    if given != 1 {
        return Err(ctx.err(key, "give exactly one of node, point or line"));
    }
    if let Some(id) = node {
        let nn = model.nodes.len() as i64;
        if id < 1 || id > nn || !used[id as usize - 1] {
            return Err(ctx.err(
                format!("{key}.node"),
                format!("node {id} is not a node of an element (1..={nn})"),
            ));
        }
        return Ok(vec![id as usize - 1]);
    }
    if let Some(p) = point {
        if !locate::inside_mesh(model, p) {
            return Err(ctx.err(
                format!("{key}.point"),
                format!("point {p:?} lies outside the mesh"),
            ));
        }
        return Ok(vec![locate::nearest_node(model, used, p)]);
    }
    let line = line.expect("one location given");
    if line.len() < 2 {
        return Err(ctx.err(
            format!("{key}.line"),
            format!(
                "give at least two points [[x, y], …] (got {}): a line or a polyline",
                line.len()
            ),
        ));
    }
    let mut nodes: Vec<usize> = Vec::new();
    for w in line.windows(2) {
        for n in locate::nodes_on_segment(model, used, w[0], w[1]) {
            if !nodes.contains(&n) {
                nodes.push(n);
            }
        }
    }
    if nodes.is_empty() {
        let pts: Vec<String> = line.iter().map(|p| format!("{p:?}")).collect();
        let what = if line.len() == 2 { "segment" } else { "line" };
        return Err(ctx.err(
            format!("{key}.line"),
            format!("no node lies on the {what} {}", pts.join("–")),
        ));
    }
    Ok(nodes)
}

pub(super) fn fraction(ctx: &Ctx, key: &str, v: f64, lo: f64, hi: f64) -> R<f64> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(ctx.err(key, format!("must lie in [{lo}, {hi}] (got {v})")))
    }
}
