//! `[mesh]`: banded, segmental and explicit meshes generated or checked here (gmsh meshes
//! in `input::gmsh_mesh`), element types and integration rules.

use super::fields::{index_by_name, positive};
use super::R;
use crate::elements::continuum::{fold, fold_message, min_jacobian, Integration};
use crate::input::error::Ctx;
use crate::input::schema::MeshIn;
use crate::input::{gmsh_mesh, limits, locate};
use crate::mesh::banded::{self, Band};
use crate::mesh::segmental;
use crate::model::ElementKind;
use crate::model::{Element, Model, Region};
use rayon::prelude::*;

/// A generated or read mesh: nodes [m], elements, the joints between segments and the gmsh
/// physical groups (empty for the other mesh types).
pub(super) struct Generated {
    pub(super) nodes: Vec<[f64; 2]>,
    pub(super) elements: Vec<Element>,
    pub(super) joints: Vec<segmental::Joint>,
    pub(super) groups: gmsh_mesh::Groups,
}

/// The `[mesh]` of type banded, segmental, gmsh or explicit; elements refer to `regions`.
pub(super) fn generate(ctx: &Ctx, mesh: &MeshIn, regions: &[Region]) -> R<Generated> {
    let region_names = || regions.iter().map(|r| r.name.as_str());
    let mut groups = gmsh_mesh::Groups::default();
    if mesh.kind != "segmental" {
        for (key, given) in [
            ("cast_joints", !mesh.cast_joints.is_empty()),
            ("soffit", !mesh.soffit.is_empty()),
            ("soffit_band", mesh.soffit_band.is_some()),
            ("camber", !mesh.camber.is_empty()),
        ] {
            if given {
                return Err(ctx.err(format!("mesh.{key}"), "only for type = \"segmental\""));
            }
        }
    }
    let (nodes, elements, joints) = if mesh.kind == "segmental" {
        build_segmental(mesh, ctx, &region_names)?
    } else if mesh.kind == "gmsh" {
        let names: Vec<&str> = region_names().collect();
        let g = gmsh_mesh::build_gmsh(mesh, ctx, &names)?;
        groups = g.groups;
        (g.nodes, g.elements, g.joints)
    } else {
        let (n, e) = build_mesh(mesh, ctx, &region_names)?;
        (n, e, Vec::new())
    };
    Ok(Generated {
        nodes,
        elements,
        joints,
        groups,
    })
}

/// Nodes in use by an element (the others are held); warnings for loose coincident nodes
/// (parts not connected) and unused nodes.
pub(super) fn used_nodes(ctx: &Ctx, model: &Model, warnings: &mut Vec<String>) -> Vec<bool> {
    let mut used = vec![false; model.nodes.len()];
    for e in &model.elements {
        for &n in &e.nodes {
            used[n] = true;
        }
    }
    let mut tied = vec![false; model.nodes.len()];
    for i in &model.interfaces {
        i.nodes.iter().for_each(|&n| tied[n] = true);
    }
    let size = locate::model_size(model);
    if let (k, Some((a, b))) = limits::loose_coincident(&model.nodes, &used, &tied, size) {
        warnings.push(format!(
            "{}: mesh: nodes {} and {} coincide at {:?} but no element or joint connects them ({k} such pair(s)): the parts of the mesh there are not connected; a joint missing from [[mesh.joints]]?",
            ctx.file,
            a + 1,
            b + 1,
            model.nodes[a]
        ));
    }
    let unused = used.iter().filter(|u| !**u).count();
    if unused > 0 {
        warnings.push(format!(
            "{}: mesh.nodes: {unused} node(s) belong to no element and are ignored (fixed)",
            ctx.file
        ));
    }
    used
}

/// The element kind named `s` (the one name parser, [`ElementKind::from_name`]).
pub(super) fn element_kind(ctx: &Ctx, key: &str, s: &str) -> R<ElementKind> {
    ElementKind::from_name(s).ok_or_else(|| {
        ctx.err(
            key,
            format!(
                "unknown element type '{s}' (expected {})",
                ElementKind::names()
            ),
        )
    })
}

/// The element kind named `s` for a generated (structured) mesh: a quadrilateral.
fn grid_kind(ctx: &Ctx, key: &str, s: &str) -> R<ElementKind> {
    let kind = element_kind(ctx, key, s)?;
    if kind.grid_layout().is_none() {
        let quads: Vec<&str> = crate::fem::kinds::ALL
            .iter()
            .filter(|k| k.grid_layout().is_some())
            .map(|k| k.info().name)
            .collect();
        return Err(ctx.err(
            key,
            format!(
                "the mesh generators make quadrilaterals ({}), not {s}: {s} elements come from an explicit mesh (mesh.blocks) or a Gmsh file",
                quads.join(", ")
            ),
        ));
    }
    Ok(kind)
}

/// The `integration` of elements of `kind`: `incompatible` (incompatible bending modes) is
/// a Q4 formulation.
pub(in crate::input) fn integration(
    ctx: &Ctx,
    key: &str,
    s: Option<&str>,
    kind: ElementKind,
) -> R<Integration> {
    match s {
        None | Some("full") => Ok(Integration::Full),
        Some("reduced") if kind.info().reduced_rule.is_some() => Ok(Integration::Reduced),
        Some("reduced") => Err(ctx.err(
            key,
            format!("{kind:?} elements have no reduced rule: use 'full'"),
        )),
        Some("incompatible") if kind.info().incompatible_modes => Ok(Integration::Incompatible),
        Some("incompatible") => Err(ctx.err(
            key,
            format!("'incompatible' (bending modes) is for Q4 elements only, not {kind:?}: Q8 and Q9 bend well with full or reduced integration"),
        )),
        Some(o) => Err(ctx.err(
            key,
            format!("unknown integration '{o}' (expected full, reduced or incompatible)"),
        )),
    }
}

pub(super) type Mesh = (Vec<[f64; 2]>, Vec<Element>);

/// Nodes, elements and joints of a segmental mesh.
pub(super) type SegMesh = (Vec<[f64; 2]>, Vec<Element>, Vec<segmental::Joint>);

pub(super) fn build_mesh<'a, I: Iterator<Item = &'a str> + Clone>(
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &dyn Fn() -> I,
) -> R<Mesh> {
    match mesh.kind.as_str() {
        "banded" => banded_mesh(mesh, ctx, region_names),
        "explicit" => explicit_mesh(mesh, ctx, region_names),
        o => Err(ctx.err(
            "mesh.type",
            format!("unknown mesh type '{o}' (expected banded, segmental, gmsh or explicit)"),
        )),
    }
}

/// A banded mesh: horizontal bands of given depths, `nx` columns over `length`.
fn banded_mesh<'a, I: Iterator<Item = &'a str> + Clone>(
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &dyn Fn() -> I,
) -> R<Mesh> {
    let length = positive(
        ctx,
        "mesh.length",
        mesh.length
            .ok_or_else(|| ctx.err("mesh.length", "missing"))?,
    )?;
    let nx = mesh.nx.ok_or_else(|| ctx.err("mesh.nx", "missing"))?;
    if nx == 0 {
        return Err(ctx.err("mesh.nx", "must be at least 1"));
    }
    let kind = grid_kind(ctx, "mesh.element", mesh.element.as_deref().unwrap_or("Q4"))?;
    let integ = integration(ctx, "mesh.integration", mesh.integration.as_deref(), kind)?;
    if mesh.bands.is_empty() {
        return Err(ctx.err(
            "mesh.bands",
            "a banded mesh needs at least one [[mesh.bands]]",
        ));
    }
    if !mesh.nodes.is_empty() || !mesh.blocks.is_empty() {
        return Err(ctx.err("mesh", "a banded mesh takes no nodes or blocks"));
    }
    let bands = bands_of(mesh, ctx, region_names)?;
    let origin = origin_of(mesh, ctx)?;
    let ny: f64 = bands.iter().map(|b| b.rows as f64).sum();
    limits::check_size(
        ctx,
        &size_key("mesh.nx", nx, &bands),
        limits::grid_nodes(kind, nx as f64, ny),
        nx as f64 * ny,
        limits::available_memory(),
    )?;
    let g = banded::generate(origin, length, nx, &bands, kind);
    check_generated(ctx, kind, &g.nodes, &g.elements)?;
    let elements = g
        .elements
        .into_iter()
        .map(|(nodes, region)| Element {
            kind,
            nodes,
            region,
            integration: integ,
        })
        .collect();
    Ok((g.nodes, elements))
}

/// An explicit mesh: nodes and blocks of elements of one type and region each, checked for
/// repeated nodes and inverted or degenerate elements.
fn explicit_mesh<'a, I: Iterator<Item = &'a str> + Clone>(
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &dyn Fn() -> I,
) -> R<Mesh> {
    let banded_keys = [
        ("length", mesh.length.is_some()),
        ("origin", mesh.origin.is_some()),
        ("nx", mesh.nx.is_some()),
        ("element", mesh.element.is_some()),
        ("integration", mesh.integration.is_some()),
        ("bands", !mesh.bands.is_empty()),
        ("segments", mesh.segments.is_some()),
        ("n_segments", mesh.n_segments.is_some()),
        ("nx_per_segment", mesh.nx_per_segment.is_some()),
        ("joint_material", mesh.joint_material.is_some()),
    ];
    if let Some((k, _)) = banded_keys.iter().find(|(_, given)| *given) {
        return Err(ctx.err(
            format!("mesh.{k}"),
            "not used by an explicit mesh (element types and integration go in each block)",
        ));
    }
    if mesh.nodes.is_empty() {
        return Err(ctx.err("mesh.nodes", "an explicit mesh needs nodes"));
    }
    if mesh.blocks.is_empty() {
        return Err(ctx.err(
            "mesh.blocks",
            "an explicit mesh needs at least one [[mesh.blocks]]",
        ));
    }
    for (i, p) in mesh.nodes.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(ctx.err(format!("mesh.nodes[{i}]"), "coordinates must be finite"));
        }
        if let Some(m) = limits::bad_coordinates(*p) {
            return Err(ctx.err(format!("mesh.nodes[{i}]"), m));
        }
    }
    let nn = mesh.nodes.len();
    let n_el: usize = mesh.blocks.iter().map(|b| b.elements.len()).sum();
    limits::check_size(
        ctx,
        "mesh.nodes",
        nn as f64,
        n_el as f64,
        limits::available_memory(),
    )?;
    let size = limits::extent(&mesh.nodes);
    let ids_of = |c: &[i64]| c.iter().map(|&i| i as u64).collect::<Vec<u64>>();
    let mut elements = Vec::new();
    for (b, blk) in mesh.blocks.iter().enumerate() {
        let region = index_by_name(
            ctx,
            &format!("mesh.blocks[{b}].region"),
            "region",
            region_names(),
            &blk.region,
        )?;
        let kind = element_kind(ctx, &format!("mesh.blocks[{b}].element"), &blk.element)?;
        let integ = integration(
            ctx,
            &format!("mesh.blocks[{b}].integration"),
            blk.integration.as_deref(),
            kind,
        )?;
        for (j, conn) in blk.elements.iter().enumerate() {
            let key = format!("mesh.blocks[{b}].elements[{j}]");
            if conn.len() != kind.n_nodes() {
                return Err(ctx.err(
                    &key,
                    format!(
                        "a {kind:?} element needs {} nodes, got {}",
                        kind.n_nodes(),
                        conn.len()
                    ),
                ));
            }
            let mut nodes = Vec::with_capacity(conn.len());
            for &id in conn {
                if id < 1 || id as usize > nn {
                    return Err(ctx.err(
                        &key,
                        format!("unknown node {id} (nodes are numbered 1..={nn})"),
                    ));
                }
                let n = id as usize - 1;
                if nodes.contains(&n) {
                    return Err(ctx.err(&key, format!("node {id} is repeated")));
                }
                nodes.push(n);
            }
            let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| mesh.nodes[n]).collect();
            if let Some(m) = limits::degenerate(&coords, kind.n_corners(), &ids_of(conn), size) {
                return Err(ctx.err(&key, m));
            }
            let detj = min_jacobian(kind, &coords, integ);
            if detj.is_nan() || detj <= 0.0 {
                return Err(ctx.err(
                    &key,
                    format!("element is inverted or degenerate (smallest det J = {detj:.3e}); list nodes counter-clockwise, corners first"),
                ));
            }
            if let Some(f) = fold(kind, &coords) {
                return Err(ctx.err(&key, fold_message(f)));
            }
            elements.push(Element {
                kind,
                nodes,
                region,
                integration: integ,
            });
        }
    }
    Ok((mesh.nodes.clone(), elements))
}

/// Segmental mesh: segments of given lengths (or equal ones), each a banded block.
pub(super) fn build_segmental<'a, I: Iterator<Item = &'a str> + Clone>(
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &dyn Fn() -> I,
) -> R<SegMesh> {
    let lengths: Vec<f64> = match (&mesh.segments, mesh.n_segments, mesh.length) {
        (Some(l), None, None) => {
            if l.is_empty() {
                return Err(ctx.err("mesh.segments", "give at least one segment length"));
            }
            for (i, v) in l.iter().enumerate() {
                positive(ctx, &format!("mesh.segments[{i}]"), *v)?;
            }
            l.clone()
        }
        (None, Some(n), Some(len)) => {
            if n == 0 {
                return Err(ctx.err("mesh.n_segments", "must be at least 1"));
            }
            let len = positive(ctx, "mesh.length", len)?;
            vec![len / n as f64; n]
        }
        _ => {
            return Err(ctx.err(
                "mesh",
                "a segmental mesh needs either segments = [lengths] or length and n_segments",
            ))
        }
    };
    let nx = mesh
        .nx_per_segment
        .ok_or_else(|| ctx.err("mesh.nx_per_segment", "missing"))?;
    if nx == 0 {
        return Err(ctx.err("mesh.nx_per_segment", "must be at least 1"));
    }
    if mesh.nx.is_some() || !mesh.nodes.is_empty() || !mesh.blocks.is_empty() {
        return Err(ctx.err(
            "mesh",
            "a segmental mesh takes nx_per_segment, not nx, nodes or blocks",
        ));
    }
    let kind = grid_kind(ctx, "mesh.element", mesh.element.as_deref().unwrap_or("Q8"))?;
    let integ = integration(ctx, "mesh.integration", mesh.integration.as_deref(), kind)?;
    let bands = bands_of(mesh, ctx, region_names)?;
    let origin = origin_of(mesh, ctx)?;
    let ny: f64 = bands.iter().map(|b| b.rows as f64).sum();
    let n_seg = lengths.len() as f64;
    limits::check_size(
        ctx,
        &size_key("mesh.nx_per_segment", nx, &bands),
        n_seg * limits::grid_nodes(kind, nx as f64, ny),
        n_seg * nx as f64 * ny,
        limits::available_memory(),
    )?;
    let mut g = segmental::generate_segments(
        origin[0],
        origin[1],
        &lengths,
        &vec![nx; lengths.len()],
        &bands,
        kind,
    );
    shape_segmental(mesh, ctx, &bands, origin, &mut g)?;
    let elements = g
        .elements
        .into_iter()
        .map(|(nodes, region, _segment)| (nodes, region))
        .collect::<Vec<_>>();
    check_generated(ctx, kind, &g.nodes, &elements)?;
    let elements = elements
        .into_iter()
        .map(|(nodes, region)| Element {
            kind,
            nodes,
            region,
            integration: integ,
        })
        .collect();
    Ok((g.nodes, elements, g.joints))
}

/// `cast_joints`, `soffit` (with `soffit_band`) and `camber` of a segmental mesh, applied to
/// the generated segments in that order.
fn shape_segmental(
    mesh: &MeshIn,
    ctx: &Ctx,
    bands: &[Band],
    origin: [f64; 2],
    g: &mut segmental::SegmentalMesh,
) -> R<()> {
    let mut wet = Vec::new();
    for (i, name) in mesh.cast_joints.iter().enumerate() {
        let key = format!("mesh.cast_joints[{i}]");
        let j = name
            .strip_prefix('J')
            .and_then(|n| n.parse::<usize>().ok())
            .filter(|&n| n >= 1 && n <= g.joints.len())
            .ok_or_else(|| {
                ctx.err(
                    &key,
                    format!(
                        "'{name}' is not a joint of this mesh (J1 … J{})",
                        g.joints.len()
                    ),
                )
            })?;
        if wet.contains(&(j - 1)) {
            return Err(ctx.err(key, format!("'{name}' is listed twice")));
        }
        wet.push(j - 1);
    }
    segmental::cast_joints(g, &wet);
    let profile = |key: &str, points: &[[f64; 2]]| -> R<()> {
        for (i, p) in points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(ctx.err(
                    format!("mesh.{key}[{i}]"),
                    "must be two finite numbers [x, y] (m)",
                ));
            }
            if i > 0 && p[0] <= points[i - 1][0] {
                return Err(ctx.err(
                    format!("mesh.{key}[{i}]"),
                    format!(
                        "x must increase along the list (x = {} after {})",
                        p[0],
                        points[i - 1][0]
                    ),
                ));
            }
        }
        Ok(())
    };
    match (mesh.soffit.is_empty(), &mesh.soffit_band) {
        (true, None) => {}
        (true, Some(_)) => {
            return Err(ctx.err(
                "mesh.soffit_band",
                "only with mesh.soffit (the band that takes a lowered soffit's extra depth)",
            ))
        }
        (false, None) => return Err(ctx.err(
            "mesh.soffit_band",
            "missing: name the band (its region) that deepens where mesh.soffit lowers the soffit",
        )),
        (false, Some(name)) => {
            profile("soffit", &mesh.soffit)?;
            let stretch = mesh
                .bands
                .iter()
                .position(|b| &b.region == name)
                .ok_or_else(|| {
                    let names: Vec<&str> = mesh.bands.iter().map(|b| b.region.as_str()).collect();
                    ctx.err(
                        "mesh.soffit_band",
                        format!("no band of region '{name}' (bands: {})", names.join(", ")),
                    )
                })?;
            if let Some(i) = mesh.soffit.iter().position(|p| p[1] > origin[1]) {
                return Err(ctx.err(
                    format!("mesh.soffit[{i}]"),
                    format!(
                        "the soffit can only be lowered: y = {} lies above the mesh's origin y = {}",
                        mesh.soffit[i][1], origin[1]
                    ),
                ));
            }
            segmental::lower_soffit(
                g,
                origin[1],
                bands,
                stretch,
                segmental::piecewise_linear(&mesh.soffit),
            );
        }
    }
    if !mesh.camber.is_empty() {
        profile("camber", &mesh.camber)?;
        segmental::raise(g, segmental::piecewise_linear(&mesh.camber));
    }
    Ok(())
}

/// Degenerate elements of a generated mesh: tiny lengths or depths next to large ones give
/// zero-length edges.
pub(super) fn check_generated(
    ctx: &Ctx,
    kind: ElementKind,
    nodes: &[[f64; 2]],
    elements: &[(Vec<usize>, usize)],
) -> R<()> {
    if let Some(p) = nodes
        .iter()
        .find(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(ctx.err(
            "mesh",
            format!("generated node coordinates overflow ({p:?}): the lengths, depths or origin are too large (metres)"),
        ));
    }
    if let Some(m) = nodes.iter().find_map(|&p| limits::bad_coordinates(p)) {
        return Err(ctx.err(
            "mesh",
            format!("generated node {m}: the lengths, depths or origin are too large"),
        ));
    }
    let size = limits::extent(nodes);
    let nc = kind.n_corners();
    // Only the corners are read: no list per element, and the elements checked in
    // parallel, the first failing one in element order reported.
    let failed = elements
        .par_iter()
        .enumerate()
        .find_map_first(|(i, (conn, _))| {
            let mut c = [[0.0; 2]; 4];
            let mut ids = [0u64; 4];
            for (k, &n) in conn[..nc].iter().enumerate() {
                c[k] = nodes[n];
                ids[k] = n as u64 + 1;
            }
            limits::degenerate(&c[..nc], nc, &ids[..nc], size).map(|m| (i, m))
        });
    if let Some((i, m)) = failed {
        return Err(ctx.err(
            "mesh",
            format!(
                "generated element {}: {m}; check the lengths, depths and divisions",
                i + 1
            ),
        ));
    }
    Ok(())
}

/// The key a too-large grid names: the band with the most rows when the rows outnumber the
/// columns `nx` (a slip in `rows`), else `nx_key`.
fn size_key(nx_key: &str, nx: usize, bands: &[Band]) -> String {
    let (i, most) = bands
        .iter()
        .enumerate()
        .max_by_key(|(_, b)| b.rows)
        .map_or((0, 0), |(i, b)| (i, b.rows));
    if most > nx {
        format!("mesh.bands[{i}].rows")
    } else {
        nx_key.to_string()
    }
}

pub(super) fn bands_of<'a, I: Iterator<Item = &'a str> + Clone>(
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &dyn Fn() -> I,
) -> R<Vec<Band>> {
    if mesh.bands.is_empty() {
        return Err(ctx.err("mesh.bands", "needs at least one [[mesh.bands]]"));
    }
    let mut bands = Vec::new();
    for (i, b) in mesh.bands.iter().enumerate() {
        let region = index_by_name(
            ctx,
            &format!("mesh.bands[{i}].region"),
            "region",
            region_names(),
            &b.region,
        )?;
        let depth = positive(ctx, &format!("mesh.bands[{i}].depth"), b.depth)?;
        if b.rows == 0 {
            return Err(ctx.err(format!("mesh.bands[{i}].rows"), "must be at least 1"));
        }
        bands.push(Band {
            depth,
            rows: b.rows,
            region,
        });
    }
    Ok(bands)
}

pub(super) fn origin_of(mesh: &MeshIn, ctx: &Ctx) -> R<[f64; 2]> {
    let o = mesh.origin.unwrap_or([0.0, 0.0]);
    if o.iter().any(|v| !v.is_finite()) {
        return Err(ctx.err("mesh.origin", "must be finite numbers [m]"));
    }
    Ok(o)
}
