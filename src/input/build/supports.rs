//! `[[supports]]`: restrained displacements; the check that every part of the mesh is held
//! against rigid-body motion.

use super::anchorage::{self, LocalZone};
use super::fields::{locate_nodes, unique_names};
use super::R;
use crate::input::error::Ctx;
use crate::input::gmsh_mesh;
use crate::input::locate;
use crate::input::schema::SupportIn;
use crate::model::{Dir, Model, Push, Support};
use std::collections::HashMap;

/// The `[[supports]]`: restrained dofs at a node, a point, along a line or a gmsh group.
pub(super) fn build(
    ctx: &Ctx,
    list: &[SupportIn],
    groups: &gmsh_mesh::Groups,
    model: &mut Model,
    used: &[bool],
    zones: &mut Vec<LocalZone>,
) -> R<()> {
    unique_names(ctx, "supports", list.iter().map(|s| s.name.as_str()))?;
    if list.is_empty() {
        return Err(ctx.err(
            "supports",
            "no supports given: the structure would be a mechanism",
        ));
    }
    // The support, and value [m], that first prescribed each dof (node, direction).
    let mut prescribed: HashMap<(usize, usize), (usize, f64)> = HashMap::new();
    // How the support that first held each dof pushes (None: both ways).
    let mut pushes: HashMap<(usize, usize), Option<Push>> = HashMap::new();
    let mut one_way = Vec::with_capacity(list.len());
    for (i, s) in list.iter().enumerate() {
        let key = format!("supports[{i}]");
        for (name, v) in [("ux", s.ux), ("uy", s.uy)] {
            if v.is_some_and(|v| !v.is_finite()) {
                return Err(ctx.err(format!("{key}.{name}"), "must be a finite number [m]"));
            }
        }
        let nodes = match &s.group {
            Some(g) => {
                if s.node.is_some() || s.point.is_some() || s.line.is_some() {
                    return Err(ctx.err(&key, "give exactly one of node, point, line or group"));
                }
                groups.nodes.get(g).cloned().ok_or_else(|| {
                    ctx.err(
                        format!("{key}.group"),
                        format!("no physical group named '{g}' (groups come from a gmsh mesh)"),
                    )
                })?
            }
            None => locate_nodes(ctx, &key, model, used, s.node, s.point, s.line.as_deref())?,
        };
        let mut dofs = Vec::new();
        for n in nodes {
            if let Some(v) = s.ux {
                dofs.push((n, Dir::X, v));
            }
            if let Some(v) = s.uy {
                dofs.push((n, Dir::Y, v));
            }
        }
        if s.ux.is_none() && s.uy.is_none() {
            return Err(ctx.err(&key, "restrains nothing: give ux and/or uy (0.0 = fixed)"));
        }
        // Two supports may hold one dof (a falsework under a bearing) only at one value:
        // otherwise which one acts would depend on their order.
        for &(n, d, v) in &dofs {
            let (first, was) = *prescribed.entry((n, d.index())).or_insert((i, v));
            if first != i && was != v {
                let c = if d.index() == 0 { "ux" } else { "uy" };
                let [x, y] = model.nodes[n];
                return Err(ctx.err(
                    format!("{key}.{c}"),
                    format!(
                        "{c} = {v:.3e} m at node {} ({x}, {y}), which supports[{first}] ('{}') holds at {c} = {was:.3e} m: a displacement takes one prescribed value",
                        n + 1,
                        list[first].name
                    ),
                ));
            }
        }
        let push = push(ctx, &key, s)?;
        for &(n, d, _) in &dofs {
            let mine = push.filter(|p| p.dir() == d);
            let was = *pushes.entry((n, d.index())).or_insert(mine);
            if was != mine {
                let (first, _) = prescribed[&(n, d.index())];
                let how = |p: Option<Push>| {
                    p.map_or("both ways".to_string(), |p| {
                        format!("one way (one_way = \"{}\")", p.name())
                    })
                };
                let c = if d.index() == 0 { "ux" } else { "uy" };
                return Err(ctx.err(
                    format!("{key}.one_way"),
                    format!(
                        "holds {c} of node {} {}, which supports[{first}] ('{}') holds {}: a displacement is held one way by every support on it, or both ways by every one",
                        n + 1,
                        how(mine),
                        list[first].name,
                        how(was)
                    ),
                ));
            }
        }
        one_way.push(push);
        if let Some(z) = bearing_zone(ctx, &key, s, model, &dofs)? {
            zones.push(z);
        }
        model.supports.push(Support {
            name: s.name.clone(),
            dofs,
        });
    }
    if one_way.iter().any(Option::is_some) {
        model.staging.one_way = one_way;
    }
    Ok(())
}

/// `supports[i].one_way`: the way a bearing, prop or falsework pushes the structure
/// ("+x", "-x", "+y", "-y"; None: a two-way support). It must be a direction the support
/// holds, at zero: a one-way support holds the structure where it stands when it acts.
fn push(ctx: &Ctx, key: &str, s: &SupportIn) -> R<Option<Push>> {
    let Some(name) = &s.one_way else {
        return Ok(None);
    };
    let Some(&(p, _)) = Push::ALL.iter().find(|(_, n)| n == name) else {
        return Err(ctx.err(
            format!("{key}.one_way"),
            format!(
                "unknown direction '{name}' (expected \"+y\", \"-y\", \"+x\" or \"-x\": the way the support pushes the structure)"
            ),
        ));
    };
    let (c, v) = match p.dir() {
        Dir::X => ("ux", s.ux),
        Dir::Y => ("uy", s.uy),
    };
    match v {
        None => Err(ctx.err(
            format!("{key}.one_way"),
            format!("\"{name}\" pushes along {c}, which the support does not hold: give {c} = 0.0"),
        )),
        Some(v) if v != 0.0 => Err(ctx.err(
            format!("{key}.{c}"),
            format!("{c} = {v:e} m on a one-way support: it must be 0.0 (a one-way support holds the structure where it stands; model a settlement as a two-way support)"),
        )),
        Some(_) => Ok(Some(p)),
    }
}

/// `supports[i].bearing`: a pinned bearing. The support holds its node (a pin at the
/// bearing's centre: no fixed-end moment), and the concrete under the bearing is a local
/// zone (unless `local_zone = false`) that spreads the reaction as the bearing plate does.
fn bearing_zone(
    ctx: &Ctx,
    key: &str,
    s: &SupportIn,
    model: &Model,
    dofs: &[(usize, Dir, f64)],
) -> R<Option<LocalZone>> {
    let Some(b) = super::anchorage::bearing_length(ctx, key, s.bearing, s.local_zone, "over")?
    else {
        return Ok(None);
    };
    if s.line.is_some() || s.group.is_some() {
        return Err(ctx.err(
            format!("{key}.bearing"),
            "only for a support at a node or point (a line support is already spread)",
        ));
    }
    if s.local_zone == Some(false) {
        return Ok(None);
    }
    let node = dofs[0].0;
    let held = if s.uy.is_some() {
        [0.0, 1.0]
    } else {
        [1.0, 0.0]
    };
    Ok(Some(anchorage::support_zone(model, node, held, b)))
}

/// Hold the nodes no element uses, so that they add no zero pivots.
pub(super) fn hold_unused(model: &mut Model, used: &[bool]) {
    let held: Vec<(usize, Dir, f64)> = (0..model.nodes.len())
        .filter(|&n| !used[n])
        .flat_map(|n| [(n, Dir::X, 0.0), (n, Dir::Y, 0.0)])
        .collect();
    if !held.is_empty() {
        model.supports.push(Support {
            name: "(unused nodes)".into(),
            dofs: held,
        });
    }
}

/// Each connected part of the mesh must be held against its three rigid-body motions: the
/// constrained dofs must give rank 3 on the modes (1,0), (0,1), (−y, x).
pub(super) fn check_rigid_body(ctx: &Ctx, model: &Model, used: &[bool]) -> R<()> {
    // Union–find over nodes through elements.
    let mut parent: Vec<usize> = (0..model.nodes.len()).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    // Joints and tendons tie parts together too (a joint can only hold a part while closed;
    // the check is about supports, not about whether the joints stay closed).
    let groups = model
        .elements
        .iter()
        .map(|e| &e.nodes)
        .chain(model.interfaces.iter().map(|i| &i.nodes))
        .chain(model.tendons.iter().map(|t| &t.nodes));
    for nodes in groups {
        let r0 = find(&mut parent, nodes[0]);
        for &n in &nodes[1..] {
            let r = find(&mut parent, n);
            parent[r] = r0;
        }
    }
    let mut rows: HashMap<usize, Vec<[f64; 3]>> = HashMap::new();
    for s in &model.supports {
        for &(n, d, _) in &s.dofs {
            if !used[n] {
                continue;
            }
            let [x, y] = model.nodes[n];
            let row = match d {
                Dir::X => [1.0, 0.0, -y],
                Dir::Y => [0.0, 1.0, x],
            };
            rows.entry(find(&mut parent, n)).or_default().push(row);
        }
    }
    let size = locate::model_size(model);
    let mut checked = HashMap::new();
    for e in &model.elements {
        let root = find(&mut parent, e.nodes[0]);
        if checked.contains_key(&root) {
            continue;
        }
        let r = rows.get(&root).map(|v| rank3(v, size)).unwrap_or(0);
        checked.insert(root, r);
        if r < 3 {
            let region = &model.regions[e.region].name;
            return Err(ctx.err(
                "supports",
                format!(
                    "the part of the mesh containing region '{region}' can move as a rigid body (supports restrain {r} of its 3 rigid-body motions)"
                ),
            ));
        }
    }
    Ok(())
}

/// Numerical rank of a set of 3-vectors (rotation column scaled by the model size).
pub(super) fn rank3(rows: &[[f64; 3]], size: f64) -> usize {
    let mut m: Vec<[f64; 3]> = rows.iter().map(|r| [r[0], r[1], r[2] / size]).collect();
    let mut rank = 0;
    for c in 0..3 {
        let piv = (rank..m.len()).max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()));
        let Some(p) = piv else { break };
        if m[p][c].abs() < 1e-9 {
            continue;
        }
        m.swap(rank, p);
        for i in 0..m.len() {
            if i != rank {
                let f = m[i][c] / m[rank][c];
                for k in 0..3 {
                    m[i][k] -= f * m[rank][k];
                }
            }
        }
        rank += 1;
    }
    rank
}
