//! A mesh read from a Gmsh `.msh` file: 2-D physical groups name regions; pairs of 1-D
//! physical groups name the two faces of each joint; any physical group can locate supports
//! and line loads.

use super::error::{Ctx, InputError};
use super::limits::{available_memory, check_size, degenerate, extent};
use super::schema::MeshIn;
use crate::elements::continuum::{fold, fold_message, min_jacobian, Integration};
use crate::mesh::gmsh::{parse_msh, GmshElementKind, GmshMesh};
use crate::mesh::segmental::{Joint, JointFace};
use crate::model::Element;
use crate::model::ElementKind;
use std::collections::HashMap;
use std::path::Path;

type R<T> = Result<T, InputError>;

/// Node sets and edge sets of the file's physical groups, by name.
#[derive(Debug, Default, Clone)]
pub struct Groups {
    /// Nodes (0-based) of each named group of dimension 0 or 1.
    pub nodes: HashMap<String, Vec<usize>>,
    /// Line elements (nodes start, end, [mid]) of each named group of dimension 1.
    pub edges: HashMap<String, Vec<Vec<usize>>>,
}

/// What a Gmsh mesh gives the model.
pub struct GmshBuilt {
    /// Node coordinates [m].
    pub nodes: Vec<[f64; 2]>,
    /// Continuum elements.
    pub elements: Vec<Element>,
    /// Joints (pairs of facing edges).
    pub joints: Vec<Joint>,
    /// Named groups for supports and loads.
    pub groups: Groups,
}

/// Read the `.msh` file named by `mesh.file` (relative to the model file) and map its groups.
pub fn build_gmsh(mesh: &MeshIn, ctx: &Ctx, region_names: &[&str]) -> R<GmshBuilt> {
    let file = mesh
        .file
        .as_deref()
        .ok_or_else(|| ctx.err("mesh.file", "missing: the .msh file to read"))?;
    let base = Path::new(&ctx.file).parent().unwrap_or(Path::new("."));
    let path = base.join(file);
    let bytes = crate::input::limits::read_bounded(&path)
        .map_err(|e| ctx.err("mesh.file", format!("{}: {e}", path.display())))?;
    let g = parse_msh(&bytes, &path.display().to_string())
        .map_err(|e| ctx.err("mesh.file", e.to_string()))?;
    // Checked for Q4 here; each element's kind is checked again where it is built.
    let integ = super::build::integration(
        ctx,
        "mesh.integration",
        mesh.integration.as_deref(),
        crate::model::ElementKind::Q4,
    )?;
    for k in [
        "length",
        "nx",
        "element",
        "segments",
        "n_segments",
        "nx_per_segment",
    ] {
        let given = match k {
            "length" => mesh.length.is_some(),
            "nx" => mesh.nx.is_some(),
            "element" => mesh.element.is_some(),
            "segments" => mesh.segments.is_some(),
            "n_segments" => mesh.n_segments.is_some(),
            _ => mesh.nx_per_segment.is_some(),
        };
        if given {
            return Err(ctx.err(
                format!("mesh.{k}"),
                "not used by a gmsh mesh (the .msh file gives the elements)",
            ));
        }
    }
    if !mesh.bands.is_empty() || !mesh.nodes.is_empty() || !mesh.blocks.is_empty() {
        return Err(ctx.err("mesh", "a gmsh mesh takes no bands, nodes or blocks"));
    }
    map(&g, mesh, ctx, region_names, integ, file)
}

fn name_of(g: &GmshMesh, dim: i32, tag: i32) -> Option<&str> {
    g.physical_names
        .iter()
        .find(|(d, t, _)| *d == dim && *t == tag)
        .map(|(_, _, n)| n.as_str())
}

fn map(
    g: &GmshMesh,
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &[&str],
    integ: Integration,
    file: &str,
) -> R<GmshBuilt> {
    let index = g.node_index();
    let nodes: Vec<[f64; 2]> = g.nodes.iter().map(|(_, x)| *x).collect();
    check_size(
        ctx,
        "mesh.file",
        nodes.len() as f64,
        g.elements.len() as f64,
        available_memory(),
    )?;
    if let Some((tag, m)) = g
        .nodes
        .iter()
        .find_map(|(t, x)| crate::input::limits::bad_coordinates(*x).map(|m| (t, m)))
    {
        return Err(ctx.err("mesh.file", format!("{file}: node {tag}: {m}")));
    }
    let size = extent(&nodes);
    let mut elements = Vec::new();
    let mut groups = Groups::default();
    // Every 2-D physical group must be a region, and every 2-D element must be in one.
    for (d, _, n) in &g.physical_names {
        if *d == 2 && !region_names.contains(&n.as_str()) {
            return Err(ctx.err(
                "mesh.file",
                format!("{file}: physical surface '{n}' is not mapped: add a [[regions]] entry named '{n}' (regions: {})", region_names.join(", ")),
            ));
        }
    }
    for el in &g.elements {
        let ids: Vec<usize> = el
            .nodes
            .iter()
            .map(|t| {
                index.get(t).copied().ok_or_else(|| {
                    ctx.err(
                        "mesh.file",
                        format!("{file}: element {} uses unknown node {t}", el.tag),
                    )
                })
            })
            .collect::<R<_>>()?;
        if let Some(kind) = el.kind.element_kind() {
            let names: Vec<&str> = el
                .physical
                .iter()
                .filter_map(|t| name_of(g, 2, *t))
                .collect();
            let Some(name) = names.first() else {
                return Err(ctx.err("mesh.file", format!("{file}: surface element {} belongs to no named physical surface (regions come from physical surface names)", el.tag)));
            };
            let region = region_names
                .iter()
                .position(|r| r == name)
                .expect("checked above");
            let coords: Vec<[f64; 2]> = ids.iter().map(|&i| nodes[i]).collect();
            if let Some(m) = degenerate(&coords, kind.n_corners(), &el.nodes, size) {
                return Err(ctx.err("mesh.file", format!("{file}: element {}: {m}", el.tag)));
            }
            if integ == Integration::Incompatible && !kind.info().incompatible_modes {
                return Err(ctx.err("mesh.integration", format!("{file}: element {} is a {kind:?}: 'incompatible' (bending modes) is for Q4 elements only", el.tag)));
            }
            if integ == Integration::Reduced && kind.info().reduced_rule.is_none() {
                return Err(ctx.err(
                    "mesh.integration",
                    format!(
                        "{file}: element {} is a {kind:?}, which has no reduced rule: use 'full'",
                        el.tag
                    ),
                ));
            }
            let detj = min_jacobian(kind, &coords, integ);
            if detj.is_nan() || detj <= 0.0 {
                return Err(ctx.err("mesh.file", format!("{file}: element {} is inverted or degenerate (smallest det J = {detj:.3e})", el.tag)));
            }
            if let Some(f) = fold(kind, &coords) {
                return Err(ctx.err(
                    "mesh.file",
                    format!("{file}: element {}: {}", el.tag, fold_message(f)),
                ));
            }
            elements.push(Element {
                kind,
                nodes: ids,
                region,
                integration: integ,
            });
        } else {
            let dim = if el.kind == GmshElementKind::Point {
                0
            } else {
                1
            };
            for t in &el.physical {
                if let Some(n) = name_of(g, dim, *t) {
                    groups.nodes.entry(n.to_string()).or_default().extend(&ids);
                    if dim == 1 {
                        groups
                            .edges
                            .entry(n.to_string())
                            .or_default()
                            .push(ids.clone());
                    }
                }
            }
        }
    }
    if elements.is_empty() {
        return Err(ctx.err(
            "mesh.file",
            format!(
                "{file}: no continuum elements ({}) found",
                ElementKind::names()
            ),
        ));
    }
    for v in groups.nodes.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    let joints = joints(mesh, ctx, &nodes, &elements, &groups)?;
    Ok(GmshBuilt {
        nodes,
        elements,
        joints,
        groups,
    })
}

/// Pair the edges of each joint's face A with the coincident edges of face B; orient face A
/// counter-clockwise with respect to its element.
fn joints(
    mesh: &MeshIn,
    ctx: &Ctx,
    nodes: &[[f64; 2]],
    elements: &[Element],
    groups: &Groups,
) -> R<Vec<Joint>> {
    let size = {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in nodes {
            for c in 0..2 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        (hi[0] - lo[0]).hypot(hi[1] - lo[1])
    };
    let tol = 1e-6 * size;
    let same =
        |a: usize, b: usize| (nodes[a][0] - nodes[b][0]).hypot(nodes[a][1] - nodes[b][1]) <= tol;
    let mut out = Vec::new();
    // The joint that first tied each pair of faces (both faces' nodes, sorted): a pair tied
    // twice would count its contact stiffness twice.
    let mut tied: std::collections::HashMap<Vec<usize>, usize> = Default::default();
    for (j, pair) in mesh.joints.iter().enumerate() {
        let key = format!("mesh.joints[{j}]");
        let get = |name: &str, k: &str| {
            groups.edges.get(name).ok_or_else(|| {
                ctx.err(
                    format!("{key}.{k}"),
                    format!("no physical curve named '{name}' in the mesh file"),
                )
            })
        };
        let (ea, eb) = (get(&pair.a, "a")?, get(&pair.b, "b")?);
        let mut faces = Vec::new();
        let mut matched_b = vec![false; eb.len()];
        for a in ea {
            // The element owning this edge, and its counter-clockwise order.
            let owners: Vec<(usize, Vec<usize>)> = elements
                .iter()
                .enumerate()
                .filter_map(|(ei, el)| {
                    el.kind.edges().iter().find_map(|edge| {
                        let e: Vec<usize> = edge.iter().map(|&l| el.nodes[l]).collect();
                        let fits = e.len() == a.len() && e.iter().all(|n| a.contains(n));
                        fits.then_some((ei, e))
                    })
                })
                .collect();
            let (owner, face_a) = match owners.as_slice() {
                [one] => one.clone(),
                [] => return Err(ctx.err(format!("{key}.a"), format!("an edge of '{}' is not an edge of any element", pair.a))),
                _ => return Err(ctx.err(format!("{key}.a"), format!("an edge of '{}' lies inside a segment (two elements share it): joint faces must be segment boundaries with their own nodes", pair.a))),
            };
            let b = eb.iter().position(|b| {
                b.len() == a.len()
                    && ((same(a[0], b[0]) && same(a[1], b[1]))
                        || (same(a[0], b[1]) && same(a[1], b[0])))
            });
            let Some(b) = b.map(|k| {
                matched_b[k] = true;
                &eb[k]
            }) else {
                let p = nodes[a[0]];
                return Err(ctx.err(format!("{key}.b"), format!("no edge of '{}' faces the edge of '{}' at {p:?} (faces must coincide, node for node)", pair.b, pair.a)));
            };
            if b.iter().any(|n| a.contains(n)) {
                return Err(ctx.err(
                    key.clone(),
                    "the two faces share nodes: each segment needs its own nodes at the joint",
                ));
            }
            let mut both: Vec<usize> = a.iter().chain(b).copied().collect();
            both.sort_unstable();
            if let Some(&first) = tied.get(&both) {
                let p = nodes[a[0]];
                return Err(ctx.err(key.clone(), format!("the faces of '{}' and '{}' at {p:?} are already joined by mesh.joints[{first}]: a joint declared twice would count its stiffness twice", pair.a, pair.b)));
            }
            tied.insert(both, j);
            faces.push(JointFace {
                a: face_a,
                b: b.clone(),
                region: elements[owner].region,
            });
        }
        // Every edge of face B must face one of A too: otherwise part of the joint has no
        // opposite face and the segments there would not touch.
        if let Some(k) = matched_b.iter().position(|m| !m) {
            let p = nodes[eb[k][0]];
            return Err(ctx.err(format!("{key}.a"), format!("no edge of '{}' faces the edge of '{}' at {p:?}: the joint has no opposite face there (faces must coincide, node for node)", pair.a, pair.b)));
        }
        let x = faces.first().map(|f| nodes[f.a[0]][0]).unwrap_or(0.0);
        out.push(Joint {
            left: j,
            x,
            faces,
            cast: false,
        });
    }
    Ok(out)
}
