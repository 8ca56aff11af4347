//! From the parsed file to a validated [`Model`]: names resolved, values checked, locations
//! found in the mesh. Every problem is an [`InputError`] naming the key.

use super::error::{Ctx, InputError};
use super::gmsh_mesh;
use super::limits;
use super::locate;
use super::schema::*;
use super::units;
use crate::elements::bar::{BarEmbedder, BarPath, EmbedOptions, HostElement};
use crate::elements::continuum::{min_jacobian, Integration};
use crate::elements::interface::{
    suggest_normal_stiffness, InterfaceElement, InterfaceParams, JointNeighbour,
};
use crate::elements::tendon::{DeviatorMode, ExternalTendon, TendonLaw};
use crate::fem::shape::map_point;
use crate::fem::shape::QuadKind;
use crate::materials::concrete::{
    CompressionSoftening, ConcreteParams, ShearRetention, TensionSoftening,
};
use crate::materials::mc90::{self, TensileRef};
use crate::materials::point::Material;
use crate::materials::steel::SteelParams;
use crate::mesh::banded::{self, Band};
use crate::mesh::segmental;
use crate::model::*;
use crate::prestress::friction::{jacking_profile, AnchorEnd, FrictionParams, Jacking, TendonPath};
use crate::prestress::posttension::{self, Samples, Stressing};
use std::collections::HashMap;

/// A validated model and the warnings met on the way (suspicious but legal values).
pub struct Built {
    /// The model.
    pub model: Model,
    /// Warnings, one line each.
    pub warnings: Vec<String>,
}

type R<T> = Result<T, InputError>;

fn positive(ctx: &Ctx, key: &str, v: f64) -> R<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ctx.err(key, format!("must be a positive number (got {v})")))
    }
}

fn index_by_name<'a>(
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
fn required_ref<'a>(
    ctx: &Ctx,
    key: &str,
    what: &str,
    value: Option<&str>,
    names: impl Iterator<Item = &'a str> + Clone,
) -> R<usize> {
    let name = value.ok_or_else(|| ctx.err(key, format!("missing (the name of a {what})")))?;
    index_by_name(ctx, key, what, names, name)
}

fn unique_names<'a>(ctx: &Ctx, list: &str, names: impl Iterator<Item = &'a str>) -> R<()> {
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

fn quad_kind(ctx: &Ctx, key: &str, s: &str) -> R<QuadKind> {
    match s {
        "Q4" | "q4" => Ok(QuadKind::Q4),
        "Q8" | "q8" => Ok(QuadKind::Q8),
        "Q9" | "q9" => Ok(QuadKind::Q9),
        _ => Err(ctx.err(
            key,
            format!("unknown element type '{s}' (expected Q4, Q8 or Q9)"),
        )),
    }
}

/// The `integration` of elements of `kind`: `incompatible` (incompatible bending modes) is
/// a Q4 formulation.
pub(super) fn integration(ctx: &Ctx, key: &str, s: Option<&str>, kind: QuadKind) -> R<Integration> {
    match s {
        None | Some("full") => Ok(Integration::Full),
        Some("reduced") => Ok(Integration::Reduced),
        Some("incompatible") if kind == QuadKind::Q4 => Ok(Integration::Incompatible),
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

fn dir(ctx: &Ctx, key: &str, s: Option<&str>) -> R<Dir> {
    match s {
        Some("x") => Ok(Dir::X),
        Some("y") => Ok(Dir::Y),
        Some(o) => Err(ctx.err(key, format!("unknown component '{o}' (expected x or y)"))),
        None => Err(ctx.err(key, "missing (expected x or y)")),
    }
}

/// Validate a parsed file into a model.
pub fn build(file: File, ctx: &Ctx) -> R<Built> {
    let mut warnings = Vec::new();
    // Materials.
    unique_names(
        ctx,
        "materials",
        file.materials.iter().map(|m| m.name.as_str()),
    )?;
    let mut materials = Vec::new();
    let mut steels: Vec<(String, SteelParams)> = Vec::new();
    for (i, m) in file.materials.iter().enumerate() {
        let k = |f: &str| format!("materials[{i}].{f}");
        let law = match m.kind.as_str() {
            "elastic" => {
                check_material_keys(ctx, i, m, &["E", "nu", "density"])?;
                let e = positive(ctx, &k("E"), m.e.ok_or_else(|| ctx.err(k("E"), "missing"))?)?;
                let (nu, density) = poisson_and_density(ctx, i, m)?;
                units::modulus(&mut warnings, ctx, &k("E"), e);
                if density > 0.0 && !(100.0..=20000.0).contains(&density) {
                    warnings.push(format!(
                        "{}: {}: density {density} kg/m³ is unusual; segfem works in kg/m³",
                        ctx.file,
                        k("density")
                    ));
                }
                Material::Elastic { e, nu, density }
            }
            "elastic_creep" => creep_material(ctx, i, m, &mut warnings)?,
            "concrete" => concrete_law(ctx, i, m, &mut warnings)?,
            "rebar" | "prestressing_steel" => {
                steels.push((m.name.clone(), steel_law(ctx, i, m, &mut warnings)?));
                continue;
            }
            other => {
                return Err(ctx.err(
                    k("kind"),
                    format!("unknown material kind '{other}' (expected elastic, elastic_creep, concrete, rebar or prestressing_steel)"),
                ))
            }
        };
        materials.push(NamedMaterial {
            name: m.name.clone(),
            law,
        });
    }
    // Regions.
    unique_names(ctx, "regions", file.regions.iter().map(|r| r.name.as_str()))?;
    let mut regions = Vec::new();
    for (i, r) in file.regions.iter().enumerate() {
        if steels.iter().any(|(n, _)| *n == r.material) {
            return Err(ctx.err(
                format!("regions[{i}].material"),
                format!(
                    "'{}' is a steel material (for [[bars]]); a region needs an elastic or concrete material",
                    r.material
                ),
            ));
        }
        let material = index_by_name(
            ctx,
            &format!("regions[{i}].material"),
            "material",
            materials.iter().map(|m| m.name.as_str()),
            &r.material,
        )?;
        let thickness = positive(ctx, &format!("regions[{i}].thickness"), r.thickness)?;
        units::thickness(
            &mut warnings,
            ctx,
            &format!("regions[{i}].thickness"),
            thickness,
        );
        regions.push(Region {
            name: r.name.clone(),
            material,
            thickness,
        });
    }
    let region_names = || regions.iter().map(|r| r.name.as_str());
    // Joint materials.
    unique_names(
        ctx,
        "joint_materials",
        file.joint_materials.iter().map(|m| m.name.as_str()),
    )?;
    let mut joint_materials = Vec::new();
    for (i, j) in file.joint_materials.iter().enumerate() {
        joint_materials.push(joint_material(ctx, i, j)?);
        for (name, v) in [
            ("tensile_strength", j.tensile_strength),
            ("cohesion", j.cohesion),
        ] {
            let key = format!("joint_materials[{i}].{name}");
            units::strength(&mut warnings, ctx, &key, v.unwrap_or(0.0));
        }
    }
    // Mesh.
    let mesh = file
        .mesh
        .as_ref()
        .ok_or_else(|| ctx.err("mesh", "missing: give a [mesh] table"))?;
    let mut groups = gmsh_mesh::Groups::default();
    let (nodes, mut elements, joints) = if mesh.kind == "segmental" {
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
    let mut cast_days: Vec<Option<f64>> = file.regions.iter().map(|r| r.cast_day).collect();
    if let Some(days) = &mesh.segment_cast_days {
        segment_regions(
            ctx,
            mesh,
            days,
            &joints,
            &nodes,
            &mut elements,
            &mut regions,
            &mut cast_days,
        )?;
    }
    region_boxes(ctx, &file.regions, &nodes, &mut elements)?;
    assign_cast_days(ctx, &cast_days, &mut regions, &mut materials, &mut warnings)?;
    let mut model = Model {
        title: file.title.clone().unwrap_or_default(),
        nodes,
        elements,
        regions,
        materials,
        interfaces: Vec::new(),
        joints: Vec::new(),
        tendons: Vec::new(),
        supports: Vec::new(),
        load_cases: Vec::new(),
        monitors: Vec::new(),
        steps: Vec::new(),
        controls: SolverControls::default(),
        geometry: Default::default(),
        bars: Vec::new(),
    };
    units::model_size(&mut warnings, ctx, locate::model_size(&model));
    if !joints.is_empty() {
        add_joints(ctx, mesh, &mut model, &joints, &joint_materials)?;
    }
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
    let size = locate::model_size(&model);
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
    // Supports.
    unique_names(
        ctx,
        "supports",
        file.supports.iter().map(|s| s.name.as_str()),
    )?;
    if file.supports.is_empty() {
        return Err(ctx.err(
            "supports",
            "no supports given: the structure would be a mechanism",
        ));
    }
    for (i, s) in file.supports.iter().enumerate() {
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
            None => locate_nodes(ctx, &key, &model, &used, s.node, s.point, s.line)?,
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
        model.supports.push(Support {
            name: s.name.clone(),
            dofs,
        });
    }
    // Tendons (the step they are stressed in is resolved with the steps below).
    unique_names(ctx, "tendons", file.tendons.iter().map(|t| t.name.as_str()))?;
    // External tendons go to `model.tendons`; bonded post-tensioned ones become bars (below).
    let mut external_of = vec![None; file.tendons.len()];
    for (i, t) in file.tendons.iter().enumerate() {
        if is_bonded_kind(&t.kind) {
            continue;
        }
        let tendon = build_tendon(ctx, i, t, &model, &used, &mut warnings)?;
        external_of[i] = Some(model.tendons.len());
        model.tendons.push(tendon);
    }
    // Unused nodes are held so that they add no zero pivots.
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
    check_rigid_body(ctx, &model, &used)?;
    // Load cases.
    unique_names(
        ctx,
        "load_cases",
        file.load_cases.iter().map(|c| c.name.as_str()),
    )?;
    for (i, c) in file.load_cases.iter().enumerate() {
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
        for (j, p) in c.point_loads.iter().enumerate() {
            let key = format!("load_cases[{i}].point_loads[{j}]");
            if p.force.iter().any(|f| !f.is_finite()) {
                return Err(ctx.err(format!("{key}.force"), "must be finite numbers"));
            }
            let n = locate_nodes(ctx, &key, &model, &used, p.node, p.point, None)?[0];
            case.point_forces.push((n, p.force));
        }
        for (j, l) in c.line_loads.iter().enumerate() {
            let key = format!("load_cases[{i}].line_loads[{j}]");
            if l.q.iter().any(|v| !v.is_finite()) {
                return Err(ctx.err(format!("{key}.q"), "must be finite numbers"));
            }
            let edges = match (&l.line, &l.group) {
                (Some([a, b]), None) => {
                    let (edges, covered) = locate::edges_on_segment(&model, *a, *b);
                    let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                    if edges.is_empty()
                        || (covered - length).abs() > 1e-6 * locate::model_size(&model)
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
    // Embedded bars (needed by bar monitors).
    build_bars(ctx, &file.bars, &file.tendons, &steels, &mut model)?;
    super::bar_layers::build(ctx, &file.bar_layers, &steels, &mut model)?;
    // Monitors.
    unique_names(
        ctx,
        "monitors",
        file.monitors.iter().map(|m| m.name.as_str()),
    )?;
    for (i, m) in file.monitors.iter().enumerate() {
        let key = format!("monitors[{i}]");
        // The bar of a bonded (post- or pre-tensioned) tendon named by `tendon`.
        let bonded_bar = m.tendon.as_deref().and_then(|n| {
            file.tendons
                .iter()
                .any(|t| t.name == n && is_bonded_kind(&t.kind))
                .then(|| model.bars.iter().position(|b| b.name == n))
                .flatten()
        });
        let kind = match m.kind.as_str() {
            "displacement" => {
                let node = locate_nodes(ctx, &key, &model, &used, m.node, m.point, None)?[0];
                let since_step = match &m.since_step {
                    Some(name) => Some(index_by_name(
                        ctx,
                        &format!("{key}.since_step"),
                        "step",
                        file.steps.iter().map(|s| s.name.as_str()),
                        name,
                    )?),
                    None => None,
                };
                MonitorKind::Displacement {
                    node,
                    dir: dir(ctx, &format!("{key}.component"), m.component.as_deref())?,
                    since_step,
                }
            }
            "reaction" => {
                let support = required_ref(
                    ctx,
                    &format!("{key}.support"),
                    "support",
                    m.support.as_deref(),
                    model.supports.iter().map(|s| s.name.as_str()),
                )?;
                MonitorKind::Reaction {
                    support,
                    dir: dir(ctx, &format!("{key}.component"), m.component.as_deref())?,
                }
            }
            "load_factor" => {
                MonitorKind::LoadFactor {
                    case: required_ref(
                        ctx,
                        &format!("{key}.case"),
                        "load case",
                        m.case.as_deref(),
                        model.load_cases.iter().map(|c| c.name.as_str()),
                    )?,
                }
            }
            "tendon_force" if bonded_bar.is_none() => {
                let tendon = required_ref(
                    ctx,
                    &format!("{key}.tendon"),
                    "tendon",
                    m.tendon.as_deref(),
                    model.tendons.iter().map(|t| t.name.as_str()),
                )?;
                let span = span_of(ctx, &key, m, &model.tendons[tendon])?;
                MonitorKind::TendonForce { tendon, span }
            }
            "tendon_stress" | "tendon_force" | "tendon_loss" | "tendon_loss_elastic"
            | "tendon_loss_creep" | "tendon_loss_relaxation"
                if bonded_bar.is_some() =>
            {
                // A bonded tendon is a bar: at the point nearest `point`, else its largest
                // stress or force, or its mean loss.
                let bar = bonded_bar.expect("guarded");
                if m.span.is_some() {
                    return Err(ctx.err(
                        format!("{key}.span"),
                        "spans are for external tendons: a bonded tendon takes `point`",
                    ));
                }
                let point = m.point.map(|p| nearest_bar_point(&model.bars[bar], p));
                match m.kind.as_str() {
                    "tendon_stress" => MonitorKind::BarStress { bar, point },
                    "tendon_force" => MonitorKind::BarForce { bar, point },
                    kind => MonitorKind::BarLoss {
                        bar,
                        point,
                        part: loss_part(kind),
                    },
                }
            }
            "tendon_stress" | "tendon_loss" | "tendon_loss_elastic" | "tendon_loss_creep"
            | "tendon_loss_relaxation" => {
                let tendon = required_ref(
                    ctx,
                    &format!("{key}.tendon"),
                    "tendon",
                    m.tendon.as_deref(),
                    model.tendons.iter().map(|t| t.name.as_str()),
                )?;
                let part = match m.kind.as_str() {
                    "tendon_stress" => None,
                    kind => Some(loss_part(kind)),
                };
                match part {
                    None => MonitorKind::TendonStress {
                        tendon,
                        span: span_of(ctx, &key, m, &model.tendons[tendon])?,
                    },
                    Some(part) => MonitorKind::TendonLoss { tendon, part },
                }
            }
            "joint_opening" | "joint_slip" | "joint_contact_depth" => {
                let name = m.joint.as_deref().ok_or_else(|| {
                    ctx.err(format!("{key}.joint"), "missing (a joint name such as J1, or \"all\")")
                })?;
                let joint = if name == "all" {
                    if m.kind == "joint_contact_depth" {
                        return Err(ctx.err(format!("{key}.joint"), "joint_contact_depth needs one joint, not \"all\""));
                    }
                    if model.joints.is_empty() {
                        return Err(ctx.err(format!("{key}.joint"), "the model has no joints"));
                    }
                    None
                } else {
                    Some(index_by_name(
                        ctx,
                        &format!("{key}.joint"),
                        "joint",
                        model.joints.iter().map(|j| j.name.as_str()),
                        name,
                    )?)
                };
                match (m.kind.as_str(), joint) {
                    ("joint_opening", j) => MonitorKind::JointOpening { joint: j },
                    ("joint_slip", j) => MonitorKind::JointSlip { joint: j },
                    (_, j) => MonitorKind::JointContactDepth { joint: j.expect("checked above") },
                }
            }
            "bar_stress" | "max_crack_strain" | "max_plastic_strain" | "crushed_points" => {
                material_monitor(ctx, &key, m, &model)?
            }
            o => {
                return Err(ctx.err(
                    format!("{key}.kind"),
                    format!("unknown monitor kind '{o}' (expected displacement, reaction, load_factor, joint_opening, joint_slip, joint_contact_depth, tendon_stress, tendon_force, tendon_loss, tendon_loss_elastic, tendon_loss_creep, tendon_loss_relaxation, bar_stress, max_crack_strain, max_plastic_strain or crushed_points)"),
                ))
            }
        };
        model.monitors.push(Monitor {
            name: m.name.clone(),
            kind,
        });
    }
    if let Some(a) = &file.analysis {
        model.geometry = match a.geometry.as_deref() {
            None | Some("linear") => Geometry::Linear,
            Some("nonlinear") => Geometry::Nonlinear,
            Some(o) => {
                return Err(ctx.err(
                    "analysis.geometry",
                    format!("unknown geometry '{o}' (expected linear or nonlinear)"),
                ))
            }
        };
        if model.geometry == Geometry::Nonlinear
            && model
                .elements
                .iter()
                .any(|e| e.integration == Integration::Incompatible)
        {
            return Err(ctx.err(
                "analysis.geometry",
                "'nonlinear' is not available with incompatible-mode Q4 elements (mesh integration = \"incompatible\"): use Q8 or Q9",
            ));
        }
    }
    // Steps.
    if file.steps.is_empty() {
        return Err(ctx.err("steps", "no steps given: add at least one [[steps]] table"));
    }
    unique_names(ctx, "steps", file.steps.iter().map(|s| s.name.as_str()))?;
    let linear = model.materials.iter().all(|m| m.law.is_linear());
    let mut factors = vec![0.0; model.load_cases.len()];
    // End of the last time step [d] (None before the first one).
    let mut clock: Option<f64> = None;
    for (i, s) in file.steps.iter().enumerate() {
        let key = format!("steps[{i}]");
        let kind = match s.kind.as_str() {
            "linear" => {
                if !linear {
                    return Err(ctx.err(
                        format!("{key}.kind"),
                        "a linear step needs linear materials; use kind = \"load\"",
                    ));
                }
                // One solve with the initial stiffness cannot follow nonlinear geometry.
                if model.geometry == Geometry::Nonlinear {
                    return Err(ctx.err(
                        format!("{key}.kind"),
                        "a linear step needs analysis.geometry = \"linear\"; use kind = \"load\"",
                    ));
                }
                StepKind::Linear
            }
            "load" => StepKind::Load,
            "displacement" => StepKind::Displacement,
            "arc_length" => StepKind::ArcLength,
            "time" => StepKind::Time,
            o => {
                return Err(ctx.err(
                    format!("{key}.kind"),
                    format!("unknown step kind '{o}' (expected linear, load, displacement, arc_length or time)"),
                ))
            }
        };
        let path = path_control(ctx, &key, s, kind, &model, &used)?;
        if kind == StepKind::Displacement && !s.loads.is_empty() {
            return Err(ctx.err(
                format!("{key}.loads"),
                "a displacement step holds the loads of the previous steps; give no loads",
            ));
        }
        let time = if kind == StepKind::Time {
            let span = time_span(ctx, &key, s, clock)?;
            clock = Some(span.to);
            Some(span)
        } else {
            for (name, given) in [
                ("from", s.from.is_some()),
                ("to", s.to.is_some()),
                ("duration", s.duration.is_some()),
                ("substeps", s.substeps.is_some()),
                ("first_substep", s.first_substep.is_some()),
            ] {
                if given {
                    return Err(ctx.err(
                        format!("{key}.{name}"),
                        "belongs to a time step (kind = \"time\")",
                    ));
                }
            }
            None
        };
        let held = factors.clone();
        for (name, f) in &s.loads {
            let c = index_by_name(
                ctx,
                &format!("{key}.loads.{name}"),
                "load case",
                model.load_cases.iter().map(|c| c.name.as_str()),
                name,
            )?;
            if !f.is_finite() {
                return Err(ctx.err(format!("{key}.loads.{name}"), "must be a finite number"));
            }
            factors[c] = *f;
        }
        let increments = match &time {
            Some(t) => t.substeps,
            None => s.increments.unwrap_or(1),
        };
        if increments == 0 || (kind == StepKind::Linear && increments != 1) {
            return Err(ctx.err(
                format!("{key}.increments"),
                "must be at least 1 (and exactly 1 for a linear step)",
            ));
        }
        if increments > limits::MAX_INCREMENTS {
            let k = if time.is_some() {
                "substeps"
            } else {
                "increments"
            };
            return Err(ctx.err(
                format!("{key}.{k}"),
                format!(
                    "{increments} is above the limit of {} per step (a typing error?)",
                    limits::MAX_INCREMENTS
                ),
            ));
        }
        let output_every_increment = match s.output.as_deref() {
            None | Some("end") => false,
            Some("increments") => true,
            Some(o) => {
                return Err(ctx.err(
                    format!("{key}.output"),
                    format!("unknown value '{o}' (expected end or increments)"),
                ))
            }
        };
        let path = match path {
            Some(PathControl::ArcLength(mut a)) => {
                // `loads` of an arc-length step is the reference pattern, not a total.
                a.reference = factors.iter().zip(&held).map(|(f, h)| f - h).collect();
                for (name, f) in &s.loads {
                    if let Some(c) = model.load_cases.iter().position(|c| &c.name == name) {
                        a.reference[c] = *f;
                    }
                }
                factors.clone_from(&held);
                if a.reference.iter().all(|r| *r == 0.0) {
                    return Err(ctx.err(
                        format!("{key}.loads"),
                        "an arc-length step needs a reference load: give loads = { case = factor }",
                    ));
                }
                Some(PathControl::ArcLength(a))
            }
            p => p,
        };
        model.steps.push(Step {
            name: s.name.clone(),
            kind,
            factors: factors.clone(),
            increments,
            output_every_increment,
            path,
            time,
        });
    }
    let start = model
        .steps
        .iter()
        .find_map(|s| s.time.map(|t| t.from))
        .unwrap_or(DEFAULT_START_DAY);
    check_ages(ctx, &model, start, &mut warnings)?;
    for (i, t) in file.tendons.iter().enumerate() {
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
    if let Some(sv) = &file.solver {
        let c = &mut model.controls;
        if let Some(v) = sv.force_tolerance {
            c.force_tolerance = positive(ctx, "solver.force_tolerance", v)?;
        }
        if let Some(v) = sv.energy_tolerance {
            c.energy_tolerance = positive(ctx, "solver.energy_tolerance", v)?;
        }
        if let Some(v) = sv.max_iterations {
            if v > limits::MAX_ITERATIONS {
                return Err(ctx.err(
                    "solver.max_iterations",
                    format!("{v} is above the limit of {}", limits::MAX_ITERATIONS),
                ));
            }
            c.max_iterations = v.max(1);
        }
        if let Some(v) = sv.max_cuts {
            if v > limits::MAX_CUTS {
                return Err(ctx.err(
                    "solver.max_cuts",
                    format!(
                        "{v} is above the limit of {} (2^-{} of an increment is below double precision)",
                        limits::MAX_CUTS,
                        limits::MAX_CUTS
                    ),
                ));
            }
            c.max_cuts = v;
        }
    }
    Ok(Built { model, warnings })
}

type Mesh = (Vec<[f64; 2]>, Vec<Element>);

/// Nodes, elements and joints of a segmental mesh.
type SegMesh = (Vec<[f64; 2]>, Vec<Element>, Vec<segmental::Joint>);

/// Area [m²], E_p [Pa] and f_ptk [Pa] of a bonded or pre-tensioned tendon (`key` =
/// "tendons[i]", `named` = how messages name it): positive, an area that is one (≤ 0.1 m²),
/// f_ptk below E_p (catches MPa given for Pa).
fn tendon_steel(
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
fn tendon_law(
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

/// `regions[i].boxes`: elements whose centroid (mean of the corner nodes) lies inside one of
/// the region's boxes [[x0, y0], [x1, y1]] (m) are moved to that region, whatever the mesh
/// generator gave them (anchor blocks, loading plates). Later regions win where boxes overlap.
fn region_boxes(
    ctx: &Ctx,
    regions: &[RegionIn],
    nodes: &[[f64; 2]],
    elements: &mut [crate::model::Element],
) -> Result<(), InputError> {
    for (i, r) in regions.iter().enumerate() {
        let Some(boxes) = &r.boxes else { continue };
        for (j, [[x0, y0], [x1, y1]]) in boxes.iter().enumerate() {
            let key = format!("regions[{i}].boxes[{j}]");
            if !(x0.is_finite()
                && y0.is_finite()
                && x1 > x0
                && y1 > y0
                && x1.is_finite()
                && y1.is_finite())
            {
                return Err(ctx.err(
                    key,
                    format!("must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0 (got [[{x0}, {y0}], [{x1}, {y1}]])"),
                ));
            }
            let mut hit = 0;
            for e in elements.iter_mut() {
                let k = e.nodes.len().min(4) as f64;
                let (cx, cy) = e.nodes.iter().take(4).fold((0.0, 0.0), |(a, b), &n| {
                    (a + nodes[n][0] / k, b + nodes[n][1] / k)
                });
                if (*x0..=*x1).contains(&cx) && (*y0..=*y1).contains(&cy) {
                    e.region = i;
                    hit += 1;
                }
            }
            if hit == 0 {
                return Err(ctx.err(key, "no element centroid lies inside the box"));
            }
        }
    }
    Ok(())
}

fn build_mesh<'a, I: Iterator<Item = &'a str> + Clone>(
    mesh: &MeshIn,
    ctx: &Ctx,
    region_names: &dyn Fn() -> I,
) -> R<Mesh> {
    match mesh.kind.as_str() {
        "banded" => {
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
            let kind = quad_kind(ctx, "mesh.element", mesh.element.as_deref().unwrap_or("Q4"))?;
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
                "mesh.nx",
                limits::grid_nodes(kind, nx as f64, ny),
                nx as f64 * ny,
                limits::available_memory(),
            )?;
            let g = banded::generate(origin, length, nx, &bands, kind);
            check_generated(ctx, &g.nodes, &g.elements)?;
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
        "explicit" => {
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
                let kind = quad_kind(ctx, &format!("mesh.blocks[{b}].element"), &blk.element)?;
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
                    if let Some(m) = limits::degenerate(&coords, &ids_of(conn), size) {
                        return Err(ctx.err(&key, m));
                    }
                    let detj = min_jacobian(kind, &coords, integ);
                    if detj.is_nan() || detj <= 0.0 {
                        return Err(ctx.err(
                            &key,
                            format!("element is inverted or degenerate (smallest det J = {detj:.3e}); list nodes counter-clockwise, corners first"),
                        ));
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
        o => Err(ctx.err(
            "mesh.type",
            format!("unknown mesh type '{o}' (expected banded, segmental, gmsh or explicit)"),
        )),
    }
}

/// Resolve exactly one of node / point / line to a non-empty node list.
fn locate_nodes(
    ctx: &Ctx,
    key: &str,
    model: &Model,
    used: &[bool],
    node: Option<i64>,
    point: Option<[f64; 2]>,
    line: Option<[[f64; 2]; 2]>,
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
    let [a, b] = line.expect("one location given");
    let nodes = locate::nodes_on_segment(model, used, a, b);
    if nodes.is_empty() {
        return Err(ctx.err(
            format!("{key}.line"),
            format!("no node lies on the segment {a:?}–{b:?}"),
        ));
    }
    Ok(nodes)
}

/// Each connected part of the mesh must be held against its three rigid-body motions: the
/// constrained dofs must give rank 3 on the modes (1,0), (0,1), (−y, x).
fn check_rigid_body(ctx: &Ctx, model: &Model, used: &[bool]) -> R<()> {
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
fn rank3(rows: &[[f64; 3]], size: f64) -> usize {
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

/// A joint material from its table; penalties may be left for the mesh to resolve (kn = 0).
fn joint_material(ctx: &Ctx, i: usize, j: &JointMaterialIn) -> R<(String, JointSpec)> {
    let k = |f: &str| format!("joint_materials[{i}].{f}");
    let nonneg = |key: String, v: Option<f64>| -> R<f64> {
        let v = v.unwrap_or(0.0);
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(ctx.err(key, format!("must be zero or positive (got {v})")))
        }
    };
    let friction = nonneg(k("friction"), j.friction)?;
    let cohesion = nonneg(k("cohesion"), j.cohesion)?;
    let ft = nonneg(k("tensile_strength"), j.tensile_strength)?;
    let (keyed, tensile_strength) = match j.kind.as_str() {
        "dry" => {
            if ft > 0.0 {
                return Err(ctx.err(
                    k("tensile_strength"),
                    "a dry joint has no tensile strength; use kind = \"epoxy\"",
                ));
            }
            (false, 0.0)
        }
        "keyed" => (true, 0.0),
        "epoxy" => {
            if ft <= 0.0 {
                return Err(ctx.err(
                    k("tensile_strength"),
                    "an epoxy joint needs a positive tensile strength [Pa]",
                ));
            }
            (false, ft)
        }
        o => {
            return Err(ctx.err(
                k("kind"),
                format!("unknown joint kind '{o}' (expected dry, keyed or epoxy)"),
            ))
        }
    };
    let kn = match j.kn {
        Some(v) => positive(ctx, &k("kn"), v)?,
        None => 0.0,
    };
    let kt = match j.kt {
        Some(v) => positive(ctx, &k("kt"), v)?,
        None => 0.0,
    };
    let factor = match j.penalty_factor {
        Some(v) => positive(ctx, &k("penalty_factor"), v)?,
        None => crate::elements::interface::DEFAULT_PENALTY_FACTOR,
    };
    let residual = j.residual_stiffness_ratio.unwrap_or(1e-6);
    if !(0.0..1.0).contains(&residual) {
        return Err(ctx.err(
            k("residual_stiffness_ratio"),
            format!("must lie in [0, 1) (got {residual})"),
        ));
    }
    let lobatto = match j.integration.as_deref() {
        None | Some("lobatto") => true,
        Some("gauss") => false,
        Some(o) => {
            return Err(ctx.err(
                k("integration"),
                format!("unknown integration '{o}' (expected lobatto or gauss)"),
            ))
        }
    };
    Ok((
        j.name.clone(),
        JointSpec {
            params: InterfaceParams {
                kn,
                kt,
                friction,
                cohesion,
                tensile_strength,
                keyed,
                lobatto,
                residual_ratio: residual,
            },
            factor,
        },
    ))
}

/// Joint parameters as given, with the penalty factor for automatic stiffnesses.
#[derive(Debug, Clone)]
struct JointSpec {
    params: InterfaceParams,
    factor: f64,
}

/// Segmental mesh: segments of given lengths (or equal ones), each a banded block.
fn build_segmental<'a, I: Iterator<Item = &'a str> + Clone>(
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
    let kind = quad_kind(ctx, "mesh.element", mesh.element.as_deref().unwrap_or("Q8"))?;
    let integ = integration(ctx, "mesh.integration", mesh.integration.as_deref(), kind)?;
    let bands = bands_of(mesh, ctx, region_names)?;
    let origin = origin_of(mesh, ctx)?;
    let ny: f64 = bands.iter().map(|b| b.rows as f64).sum();
    let n_seg = lengths.len() as f64;
    limits::check_size(
        ctx,
        "mesh.nx_per_segment",
        n_seg * limits::grid_nodes(kind, nx as f64, ny),
        n_seg * nx as f64 * ny,
        limits::available_memory(),
    )?;
    let g = segmental::generate_segments(
        origin[0],
        origin[1],
        &lengths,
        &vec![nx; lengths.len()],
        &bands,
        kind,
    );
    let elements = g
        .elements
        .into_iter()
        .map(|(nodes, region, _segment)| (nodes, region))
        .collect::<Vec<_>>();
    check_generated(ctx, &g.nodes, &elements)?;
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

/// Degenerate elements of a generated mesh: tiny lengths or depths next to large ones give
/// zero-length edges.
fn check_generated(ctx: &Ctx, nodes: &[[f64; 2]], elements: &[(Vec<usize>, usize)]) -> R<()> {
    if let Some(p) = nodes
        .iter()
        .find(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(ctx.err(
            "mesh",
            format!("generated node coordinates overflow ({p:?}): the lengths, depths or origin are too large (metres)"),
        ));
    }
    let size = limits::extent(nodes);
    for (i, (conn, _)) in elements.iter().enumerate() {
        let c: Vec<[f64; 2]> = conn.iter().map(|&n| nodes[n]).collect();
        let ids: Vec<u64> = conn.iter().map(|&n| n as u64 + 1).collect();
        if let Some(m) = limits::degenerate(&c, &ids, size) {
            return Err(ctx.err(
                "mesh",
                format!(
                    "generated element {}: {m}; check the lengths, depths and divisions",
                    i + 1
                ),
            ));
        }
    }
    Ok(())
}

fn bands_of<'a, I: Iterator<Item = &'a str> + Clone>(
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

/// Create the interface elements of the generated joints with the mesh's joint material,
/// resolving automatic penalty stiffnesses from the neighbouring elements.
fn add_joints(
    ctx: &Ctx,
    mesh: &MeshIn,
    model: &mut Model,
    joints: &[segmental::Joint],
    materials: &[(String, JointSpec)],
) -> R<()> {
    let name = mesh.joint_material.as_deref().ok_or_else(|| {
        ctx.err(
            "mesh.joint_material",
            "missing: name a [[joint_materials]] entry for the joints",
        )
    })?;
    let jm = index_by_name(
        ctx,
        "mesh.joint_material",
        "joint material",
        materials.iter().map(|m| m.0.as_str()),
        name,
    )?;
    let spec = &materials[jm].1;
    for (ji, j) in joints.iter().enumerate() {
        let mut ids = Vec::new();
        for f in &j.faces {
            let region = &model.regions[f.region];
            let e = model.materials[region.material].law.initial_modulus();
            // Element size normal to the joint: width of the elements on each side.
            let h = |nodes: &[usize]| -> f64 {
                model
                    .elements
                    .iter()
                    .find(|el| nodes.iter().all(|n| el.nodes.contains(n)))
                    .map(|el| {
                        let xs: Vec<f64> = el.nodes.iter().map(|&n| model.nodes[n][0]).collect();
                        xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                            - xs.iter().cloned().fold(f64::INFINITY, f64::min)
                    })
                    .unwrap_or(1.0)
            };
            let mut params = spec.params.clone();
            if params.kn == 0.0 {
                let t = region.thickness;
                params.kn = suggest_normal_stiffness(
                    JointNeighbour {
                        e,
                        h: h(&f.a),
                        thickness: t,
                    },
                    JointNeighbour {
                        e,
                        h: h(&f.b),
                        thickness: t,
                    },
                    t,
                    spec.factor,
                );
            }
            if params.kt == 0.0 {
                // Shear penalty as the shear/normal modulus ratio of the concrete (ν = 0.2).
                params.kt = params.kn / (2.0 * 1.2);
            }
            let mut nodes = f.a.clone();
            nodes.extend(&f.b);
            let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| model.nodes[n]).collect();
            InterfaceElement::new(&coords[..f.a.len()], &coords[f.a.len()..], &params)
                .map_err(|e| ctx.err("mesh", format!("joint J{} at x = {}: {e}", ji + 1, j.x)))?;
            ids.push(model.interfaces.len());
            model.interfaces.push(InterfaceEl {
                nodes,
                n_a: f.a.len(),
                thickness: region.thickness,
                params,
                joint: ji,
            });
        }
        model.joints.push(Joint {
            name: format!("J{}", ji + 1),
            x: j.x,
            interfaces: ids,
        });
    }
    Ok(())
}

// ------------------------------------------------------------------------------------------
// Concrete, steel and embedded bars; path-following steps; material monitors.
// ------------------------------------------------------------------------------------------

/// Names of the keys set in a material table (schema spelling).
fn given_material_keys(m: &MaterialIn) -> Vec<&'static str> {
    let f = |b: bool, k: &'static str| b.then_some(k);
    [
        f(m.e.is_some(), "E"),
        f(m.nu.is_some(), "nu"),
        f(m.density.is_some(), "density"),
        f(m.fcm.is_some(), "fcm"),
        f(m.ftm.is_some(), "ftm"),
        f(m.c.is_some(), "C"),
        f(m.tensile_reference.is_some(), "tensile_reference"),
        f(m.tension_softening.is_some(), "tension_softening"),
        f(m.alpha.is_some(), "alpha"),
        f(m.gf.is_some(), "Gf"),
        f(m.eps_c1.is_some(), "eps_c1"),
        f(m.eps_cu.is_some(), "eps_cu"),
        f(m.compression_softening.is_some(), "compression_softening"),
        f(m.gc.is_some(), "Gc"),
        f(m.initial_yield_ratio.is_some(), "initial_yield_ratio"),
        f(m.softening_limit.is_some(), "softening_limit"),
        f(m.crack_ratio.is_some(), "crack_ratio"),
        f(m.shear_k1.is_some(), "shear_k1"),
        f(m.shear_eps_ref.is_some(), "shear_eps_ref"),
        f(m.shear_beta_min.is_some(), "shear_beta_min"),
        f(m.residual_stiffness.is_some(), "residual_stiffness"),
        f(m.secant_crack_tangent.is_some(), "secant_crack_tangent"),
        f(m.double_crack.is_some(), "double_crack"),
        f(m.crack_integration.is_some(), "crack_integration"),
        f(
            m.normalize_equivalent_stress.is_some(),
            "normalize_equivalent_stress",
        ),
        f(m.viscoplastic.is_some(), "viscoplastic"),
        f(m.crack_model.is_some(), "crack_model"),
        f(m.compression_reduction.is_some(), "compression_reduction"),
        f(
            m.compression_reduction_min.is_some(),
            "compression_reduction_min",
        ),
        f(m.shear_retention.is_some(), "shear_retention"),
        f(m.aggregate_size.is_some(), "aggregate_size"),
        f(m.fy.is_some(), "fy"),
        f(m.et.is_some(), "Et"),
        f(m.ep.is_some(), "Ep"),
        f(m.fptk.is_some(), "fptk"),
        f(m.eps_uk.is_some(), "eps_uk"),
        f(m.rh.is_some(), "rh"),
        f(m.h0.is_some(), "h0"),
        f(m.cement.is_some(), "cement"),
        f(m.n_units.is_some(), "n_units"),
        f(m.shrinkage.is_some(), "shrinkage"),
        f(m.drying_start.is_some(), "drying_start"),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// A key that does not belong to the material's kind is an error, not silently ignored.
fn check_material_keys(ctx: &Ctx, i: usize, m: &MaterialIn, allowed: &[&str]) -> R<()> {
    for k in given_material_keys(m) {
        if !allowed.contains(&k) {
            return Err(ctx.err(
                format!("materials[{i}].{k}"),
                format!(
                    "not a key of kind '{}' (its keys: {})",
                    m.kind,
                    allowed.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

fn origin_of(mesh: &MeshIn, ctx: &Ctx) -> R<[f64; 2]> {
    let o = mesh.origin.unwrap_or([0.0, 0.0]);
    if o.iter().any(|v| !v.is_finite()) {
        return Err(ctx.err("mesh.origin", "must be finite numbers [m]"));
    }
    Ok(o)
}

/// An external tendon: points snapped to the nearest concrete nodes, span stresses after
/// friction losses.
fn build_tendon(
    ctx: &Ctx,
    i: usize,
    t: &TendonIn,
    model: &Model,
    used: &[bool],
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
    let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| model.nodes[n]).collect();
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
            let path = TendonPath::from_points(&coords)
                .map_err(|e| ctx.err(k("points"), e.to_string()))?;
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
        area,
        ep,
        fptk,
        steel,
        span_stress,
        mode,
        stressed_in_step: 0,
    })
}

/// The span (0-based) a `tendon_stress`/`tendon_force` monitor of an external tendon names
/// with its 1-based `span` key (None: the largest over the spans).
fn span_of(ctx: &Ctx, key: &str, m: &MonitorIn, tendon: &TendonEl) -> R<Option<usize>> {
    let Some(k) = m.span else { return Ok(None) };
    let n = tendon.nodes.len() - 1;
    if k < 1 || k as usize > n {
        return Err(ctx.err(
            format!("{key}.span"),
            format!(
                "tendon '{}' has spans 1 to {n} (between its anchors and deviators), not {k}",
                tendon.name
            ),
        ));
    }
    Ok(Some(k as usize - 1))
}

/// The loss part of a `tendon_loss*` monitor kind.
fn loss_part(kind: &str) -> LossPart {
    match kind {
        "tendon_loss" => LossPart::Total,
        "tendon_loss_elastic" => LossPart::Elastic,
        "tendon_loss_creep" => LossPart::CreepShrinkage,
        _ => LossPart::Relaxation,
    }
}

/// True for the tendon kinds that are embedded bars (bonded post-tensioned, pre-tensioned).
fn is_bonded_kind(kind: &str) -> bool {
    kind == "bonded" || kind == "pretensioned"
}

/// The relaxation class `class` of a tendon (key `key`), checked to be representable at each
/// of the initial `stresses` [Pa] (None = no relaxation).
fn relaxation_of(
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
fn jacking_stress_of(ctx: &Ctx, i: usize, t: &TendonIn, area: f64, fptk: f64) -> R<Option<f64>> {
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
fn friction_of(ctx: &Ctx, i: usize, t: &TendonIn) -> R<(FrictionParams, Jacking, f64)> {
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

fn fraction(ctx: &Ctx, key: &str, v: f64, lo: f64, hi: f64) -> R<f64> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(ctx.err(key, format!("must lie in [{lo}, {hi}] (got {v})")))
    }
}

/// `viscoplastic = { ... }` of a concrete: the Owen–Hinton option (docs/input.md).
fn viscoplastic_option(
    ctx: &Ctx,
    i: usize,
    v: &super::schema::ViscoplasticIn,
) -> R<crate::materials::concrete::compression::Viscoplastic> {
    use crate::materials::viscoplastic::OverstressFunction;
    let k = |f: &str| format!("materials[{i}].viscoplastic.{f}");
    let d = crate::materials::concrete::compression::Viscoplastic::default();
    let fluidity = positive(
        ctx,
        &k("fluidity"),
        v.fluidity
            .ok_or_else(|| ctx.err(k("fluidity"), "missing (fluidity γ [1/d])"))?,
    )?;
    let exponent = v
        .exponent
        .map(|e| positive(ctx, &k("exponent"), e))
        .transpose()?;
    let overstress = match (v.overstress.as_deref(), exponent) {
        (None | Some("linear"), None) => OverstressFunction::Linear,
        (None | Some("linear"), Some(_)) => {
            return Err(ctx.err(
                k("exponent"),
                "is used by overstress = \"power\" or \"exponential\" only",
            ))
        }
        (Some("power"), Some(n)) => OverstressFunction::Power(n),
        (Some("exponential"), Some(m)) => OverstressFunction::Exponential(m),
        (Some("power" | "exponential"), None) => {
            return Err(ctx.err(
                k("exponent"),
                "missing (N of the power law, M of the exponential)",
            ))
        }
        (Some(o), _) => {
            return Err(ctx.err(
                k("overstress"),
                format!("unknown value '{o}' (expected linear, power or exponential)"),
            ))
        }
    };
    let load_steps = match v.load_steps.as_deref() {
        None | Some("steady") => true,
        Some("elastic") => false,
        Some(o) => {
            return Err(ctx.err(
                k("load_steps"),
                format!("unknown value '{o}' (expected steady or elastic)"),
            ))
        }
    };
    Ok(crate::materials::concrete::compression::Viscoplastic {
        fluidity,
        overstress,
        theta: fraction(ctx, &k("theta"), v.theta.unwrap_or(d.theta), 0.0, 1.0)?,
        safety: fraction(ctx, &k("safety"), v.safety.unwrap_or(d.safety), 1e-3, 1.0)?,
        tau: fraction(ctx, &k("tau"), v.tau.unwrap_or(d.tau), 1e-4, 1.0)?,
        steady_load_steps: load_steps,
    })
}

/// `kind = "concrete"`: MC90 defaults from f_cm, each overridable.
fn concrete_law(ctx: &Ctx, i: usize, m: &MaterialIn, warnings: &mut Vec<String>) -> R<Material> {
    let k = |f: &str| format!("materials[{i}].{f}");
    check_material_keys(
        ctx,
        i,
        m,
        &[
            "fcm",
            "E",
            "nu",
            "density",
            "ftm",
            "C",
            "tensile_reference",
            "tension_softening",
            "alpha",
            "Gf",
            "eps_c1",
            "eps_cu",
            "compression_softening",
            "Gc",
            "initial_yield_ratio",
            "softening_limit",
            "crack_ratio",
            "shear_k1",
            "shear_eps_ref",
            "shear_beta_min",
            "residual_stiffness",
            "secant_crack_tangent",
            "double_crack",
            "crack_integration",
            "normalize_equivalent_stress",
            "viscoplastic",
            "crack_model",
            "compression_reduction",
            "compression_reduction_min",
            "shear_retention",
            "aggregate_size",
        ],
    )?;
    let fcm = positive(
        ctx,
        &k("fcm"),
        m.fcm
            .ok_or_else(|| ctx.err(k("fcm"), "missing (mean compressive strength [Pa])"))?,
    )?;
    if fcm < 1e6 {
        warnings.push(format!(
            "{}: {}: fcm = {fcm} Pa looks like MPa; segfem works in Pa",
            ctx.file,
            k("fcm")
        ));
    }
    let nu = fraction(ctx, &k("nu"), m.nu.unwrap_or(0.2), 0.0, 0.499)?;
    let density = m.density.unwrap_or(0.0);
    if !(density.is_finite() && density >= 0.0) {
        return Err(ctx.err(k("density"), "must be zero or positive"));
    }
    let tref = match m.tensile_reference.as_deref() {
        None | Some("fcm") => TensileRef::Fcm,
        Some("fck") => TensileRef::Fck,
        Some(o) => {
            return Err(ctx.err(
                k("tensile_reference"),
                format!("unknown value '{o}' (expected fcm or fck)"),
            ))
        }
    };
    if m.ftm.is_some() && m.c.is_some() {
        return Err(ctx.err(k("C"), "give ftm or C, not both"));
    }
    let c = m.c.unwrap_or(mc90::C_MEAN);
    if !(c > 0.0 && c < 1.0) {
        return Err(ctx.err(
            k("C"),
            format!("must lie in (0, 1) (MC90: 0.095–0.185; got {c})"),
        ));
    }
    let mut p = ConcreteParams::from_mc90_with(fcm, nu, c, tref);
    if let Some(ftm) = m.ftm {
        p.ftm = positive(ctx, &k("ftm"), ftm)?;
        units::strength(warnings, ctx, &k("ftm"), ftm);
        if ftm >= 0.5 * fcm {
            return Err(ctx.err(k("ftm"), "must be well below fcm (ftm/fcm < 0.5)"));
        }
        p.ottosen = mc90::ottosen_params(p.ftm, fcm);
    }
    if let Some(e) = m.e {
        p.ec = positive(ctx, &k("E"), e)?;
        units::modulus(warnings, ctx, &k("E"), e);
    }
    if let Some(v) = m.eps_c1 {
        p.eps_c1 = positive(ctx, &k("eps_c1"), v)?;
    }
    if let Some(v) = m.eps_cu {
        p.eps_cu = positive(ctx, &k("eps_cu"), v)?;
    }
    if let Some(v) = m.initial_yield_ratio {
        p.initial_yield_ratio = fraction(ctx, &k("initial_yield_ratio"), v, 0.0, 0.9)?;
    }
    if let Some(v) = m.softening_limit {
        p.softening_limit = positive(ctx, &k("softening_limit"), v)?;
    }
    if let Some(v) = m.crack_ratio {
        p.crack_ratio = fraction(ctx, &k("crack_ratio"), v, 0.0, 1.0)?;
    }
    if let Some(v) = m.residual_stiffness {
        p.residual_stiffness = fraction(ctx, &k("residual_stiffness"), v, 1e-12, 0.1)?;
    }
    if let Some(v) = m.secant_crack_tangent {
        p.secant_crack_tangent = v;
    }
    if let Some(v) = &m.double_crack {
        p.zero_double_crack = match v.as_str() {
            "softening" => false,
            "zero" => true,
            _ => {
                return Err(ctx.err(
                    k("double_crack"),
                    format!("must be \"softening\" or \"zero\", got \"{v}\""),
                ))
            }
        };
    }
    if let Some(v) = &m.crack_integration {
        p.implex = match v.as_str() {
            "implicit" => false,
            "implex" => true,
            _ => {
                return Err(ctx.err(
                    k("crack_integration"),
                    format!("must be \"implicit\" or \"implex\", got \"{v}\""),
                ))
            }
        };
    }
    if let Some(v) = m.normalize_equivalent_stress {
        p.normalize_equivalent_stress = v;
    }
    let d = ShearRetention::default();
    p.shear = ShearRetention {
        k1: positive(ctx, &k("shear_k1"), m.shear_k1.unwrap_or(d.k1))?,
        eps_ref: positive(
            ctx,
            &k("shear_eps_ref"),
            m.shear_eps_ref.unwrap_or(d.eps_ref),
        )?,
        beta_min: fraction(
            ctx,
            &k("shear_beta_min"),
            m.shear_beta_min.unwrap_or(d.beta_min),
            1e-9,
            1.0,
        )?,
    };
    p.tension = match m.tension_softening.as_deref() {
        None | Some("hinton") => {
            if m.gf.is_some() {
                return Err(ctx.err(
                    k("Gf"),
                    "Gf is used by tension_softening = \"crack_band\" only",
                ));
            }
            let alpha = m.alpha.unwrap_or(5e-4);
            TensionSoftening::Hinton {
                alpha: positive(ctx, &k("alpha"), alpha)?,
            }
        }
        Some("crack_band") => {
            if m.alpha.is_some() {
                return Err(ctx.err(
                    k("alpha"),
                    "alpha is used by tension_softening = \"hinton\" only",
                ));
            }
            let gf = m.gf.unwrap_or(mc90::fracture_energy(fcm, 30.0));
            TensionSoftening::CrackBand {
                gf: positive(ctx, &k("Gf"), gf)?,
            }
        }
        Some(o) => {
            return Err(ctx.err(
                k("tension_softening"),
                format!("unknown value '{o}' (expected hinton or crack_band)"),
            ))
        }
    };
    p.compression_softening = match m.compression_softening.as_deref() {
        None | Some("mc90") => {
            if m.gc.is_some() {
                return Err(ctx.err(
                    k("Gc"),
                    "Gc is used by compression_softening = \"crush_band\" only",
                ));
            }
            CompressionSoftening::Mc90
        }
        Some("crush_band") => {
            if m.eps_cu.is_some() {
                return Err(ctx.err(
                    k("eps_cu"),
                    "the crush band sets the crushing strain from Gc and the element size; \
                     give eps_cu only with compression_softening = \"mc90\"",
                ));
            }
            let gc = m.gc.unwrap_or(250.0 * mc90::fracture_energy(fcm, 30.0));
            CompressionSoftening::CrushBand {
                gc: positive(ctx, &k("Gc"), gc)?,
            }
        }
        Some(o) => {
            return Err(ctx.err(
                k("compression_softening"),
                format!("unknown value '{o}' (expected mc90 or crush_band)"),
            ))
        }
    };
    if let Some(v) = &m.viscoplastic {
        p.viscoplastic = Some(viscoplastic_option(ctx, i, v)?);
    }
    shear_options(ctx, i, m, &mut p)?;
    p.validate()
        .map_err(|e| ctx.err(format!("materials[{i}]"), e.to_string()))?;
    Ok(Material::Concrete {
        params: Box::new(p),
        density,
    })
}

/// The concrete keys of shear behaviour: crack model, compression softening of cracked
/// concrete, shear retention of fixed cracks (docs/input.md).
fn shear_options(ctx: &Ctx, i: usize, m: &MaterialIn, p: &mut ConcreteParams) -> R<()> {
    use crate::materials::concrete::{CompressionReduction, CrackModel, ShearRetentionLaw};
    let k = |f: &str| format!("materials[{i}].{f}");
    p.crack_model = match m.crack_model.as_deref() {
        None | Some("fixed") => CrackModel::Fixed,
        Some("rotating") => CrackModel::Rotating,
        Some(o) => {
            return Err(ctx.err(
                k("crack_model"),
                format!("unknown value '{o}' (expected fixed or rotating)"),
            ))
        }
    };
    p.compression_reduction = match m.compression_reduction.as_deref() {
        None | Some("none") => {
            if m.compression_reduction_min.is_some() {
                return Err(ctx.err(
                    k("compression_reduction_min"),
                    "used by compression_reduction = \"vecchio_collins_1993\" only",
                ));
            }
            CompressionReduction::None
        }
        Some("vecchio_collins_1993") => CompressionReduction::VecchioCollins1993 {
            beta_min: fraction(
                ctx,
                &k("compression_reduction_min"),
                m.compression_reduction_min.unwrap_or(0.4),
                1e-3,
                1.0,
            )?,
        },
        Some(o) => {
            return Err(ctx.err(
                k("compression_reduction"),
                format!("unknown value '{o}' (expected none or vecchio_collins_1993)"),
            ))
        }
    };
    let seed_keys = m.shear_k1.is_some() || m.shear_eps_ref.is_some();
    p.shear_retention = match m.shear_retention.as_deref() {
        None | Some("seed") => {
            if m.aggregate_size.is_some() {
                return Err(ctx.err(
                    k("aggregate_size"),
                    "used by shear_retention = \"aggregate\" only",
                ));
            }
            ShearRetentionLaw::Seed
        }
        Some("aggregate") if seed_keys => {
            return Err(ctx.err(
                k("shear_retention"),
                "shear_k1 and shear_eps_ref belong to shear_retention = \"seed\"",
            ))
        }
        Some("aggregate") => ShearRetentionLaw::Aggregate {
            d_agg: positive(ctx, &k("aggregate_size"), m.aggregate_size.unwrap_or(0.016))?,
        },
        Some(o) => {
            return Err(ctx.err(
                k("shear_retention"),
                format!("unknown value '{o}' (expected seed or aggregate)"),
            ))
        }
    };
    if p.crack_model == CrackModel::Rotating {
        if m.shear_retention.is_some() || seed_keys || m.shear_beta_min.is_some() {
            return Err(ctx.err(
                k("shear_retention"),
                "rotating cracks carry no shear across cracks: shear retention keys belong to crack_model = \"fixed\"",
            ));
        }
        for (f, given) in [
            (
                "crack_integration",
                m.crack_integration.as_deref() == Some("implex"),
            ),
            ("viscoplastic", m.viscoplastic.is_some()),
            ("initial_yield_ratio", m.initial_yield_ratio.is_some()),
        ] {
            if given {
                return Err(ctx.err(
                    k(f),
                    "not available with crack_model = \"rotating\" (fixed cracks only)",
                ));
            }
        }
    }
    Ok(())
}

/// `kind = "rebar"` or `"prestressing_steel"`: the uniaxial law of embedded bars.
fn steel_law(ctx: &Ctx, i: usize, m: &MaterialIn, warnings: &mut Vec<String>) -> R<SteelParams> {
    let k = |f: &str| format!("materials[{i}].{f}");
    let need = |v: Option<f64>, f: &str| -> R<f64> {
        positive(ctx, &k(f), v.ok_or_else(|| ctx.err(k(f), "missing"))?)
    };
    if m.kind == "rebar" {
        check_material_keys(ctx, i, m, &["E", "fy", "Et"])?;
        let e = need(m.e, "E")?;
        let fy = need(m.fy, "fy")?;
        units::modulus(warnings, ctx, &k("E"), e);
        units::strength(warnings, ctx, &k("fy"), fy);
        if fy >= e {
            return Err(ctx.err(k("fy"), "must be far below E (units are Pa)"));
        }
        match m.et {
            None => Ok(SteelParams::rebar(e, fy)),
            Some(et) if et.is_finite() && (0.0..e).contains(&et) => {
                Ok(SteelParams::rebar_hardening(e, fy, et))
            }
            Some(et) => Err(ctx.err(k("Et"), format!("must lie in [0, E) (got {et})"))),
        }
    } else {
        check_material_keys(ctx, i, m, &["Ep", "fptk", "eps_uk"])?;
        let ep = need(m.ep, "Ep")?;
        let fptk = need(m.fptk, "fptk")?;
        units::modulus(warnings, ctx, &k("Ep"), ep);
        units::strength(warnings, ctx, &k("fptk"), fptk);
        if fptk >= ep {
            return Err(ctx.err(k("fptk"), "must be far below Ep (units are Pa)"));
        }
        match m.eps_uk {
            None => Ok(SteelParams::prestressing(ep, fptk)),
            Some(e) if e.is_finite() && e > 0.9 * fptk / ep => {
                Ok(SteelParams::prestressing_hardening(ep, fptk, e))
            }
            Some(e) => Err(ctx.err(
                k("eps_uk"),
                format!(
                    "must exceed the yield strain 0.9 fptk/Ep = {:.5} (got {e})",
                    0.9 * fptk / ep
                ),
            )),
        }
    }
}

/// A bar or tendon path from its keys: exactly one of a polyline (`points_key`), `parabola`,
/// `arc` or `segments` (a chain of those).
#[allow(clippy::too_many_arguments)]
fn path_of(
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
struct Embedded {
    points: Vec<BarGaussPoint>,
    piece_ends: Vec<[[f64; 2]; 2]>,
    piece_points: Vec<(usize, usize)>,
    segment: Vec<usize>,
}

#[allow(clippy::too_many_arguments)]
fn embed_path(
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
fn build_bars(
    ctx: &Ctx,
    bars: &[BarIn],
    tendons: &[TendonIn],
    steels: &[(String, SteelParams)],
    model: &mut Model,
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
    let n_gauss_of = |key: &str, named: &str, g: Option<usize>| -> R<usize> {
        let n = g.unwrap_or(4);
        if !(1..=64).contains(&n) {
            return Err(ctx.err(key, format!("{named}: must lie in 1..=64")));
        }
        Ok(n)
    };
    let mut out = Vec::new();
    for (i, b) in bars.iter().enumerate() {
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
        let n_gauss = n_gauss_of(&format!("{key}.gauss_points"), &named, b.gauss_points)?;
        let e = embed_path(
            ctx,
            &format!("{key}.path"),
            &named,
            &embedder,
            model,
            &coords,
            &path,
            n_gauss,
        )?;
        out.push(Bar {
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
        });
    }
    for (i, t) in tendons.iter().enumerate() {
        if !is_bonded_kind(&t.kind) {
            continue;
        }
        if t.kind == "pretensioned" {
            out.push(pretensioned_tendon(
                ctx, i, t, bars, &embedder, model, &coords,
            )?);
            continue;
        }
        let key = format!("tendons[{i}]");
        let k = |f: &str| format!("{key}.{f}");
        let named = format!("tendon '{}'", t.name);
        if bars.iter().any(|b| b.name == t.name) {
            return Err(ctx.err(
                k("name"),
                format!("{named}: a bar has the same name (bonded tendons are output and monitored as bars)"),
            ));
        }
        for (f, given) in [
            ("initial_stress", t.initial_stress.is_some()),
            ("deviators", t.deviators.is_some()),
            ("deviator_friction", t.deviator_friction.is_some()),
        ] {
            if given {
                return Err(ctx.err(
                    k(f),
                    format!("{named}: not a key of a bonded post-tensioned tendon (stressed with jacking_stress or jacking_force; a pre-tensioned tendon is kind = \"pretensioned\" with initial_stress)"),
                ));
            }
        }
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
        let n_gauss = n_gauss_of(&k("gauss_points"), &named, t.gauss_points)?;
        let e = embed_path(ctx, &key, &named, &embedder, model, &coords, &path, n_gauss)?;
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
        out.push(Bar {
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
        });
    }
    model.bars = out;
    Ok(())
}

/// A pre-tensioned tendon (`kind = "pretensioned"`): an embedded prestressing-steel bar
/// bonded from the start that carries `initial_stress` at zero displacement (the stress in
/// the bed before release); its elastic shortening at transfer follows from equilibrium.
#[allow(clippy::too_many_arguments)]
fn pretensioned_tendon(
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
    if bars.iter().any(|b| b.name == t.name) {
        return Err(ctx.err(
            k("name"),
            format!("{named}: a bar has the same name (bonded tendons are output as bars)"),
        ));
    }
    for (f, given) in [
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
    ] {
        if given {
            return Err(ctx.err(
                k(f),
                format!("{named}: not a key of a pre-tensioned tendon (bonded from the start with initial_stress, the stress before release)"),
            ));
        }
    }
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

/// Optional region by name (None = all regions).
fn optional_region(ctx: &Ctx, key: &str, model: &Model, name: Option<&str>) -> R<Option<usize>> {
    name.map(|n| {
        index_by_name(
            ctx,
            key,
            "region",
            model.regions.iter().map(|r| r.name.as_str()),
            n,
        )
    })
    .transpose()
}

/// Bar-stress and concrete-state monitors.
/// Index of the bar's integration point nearest `p` [m].
fn nearest_bar_point(bar: &Bar, p: [f64; 2]) -> usize {
    let pts = &bar.points;
    (0..pts.len())
        .min_by(|&a, &b| {
            let d = |i: usize| {
                let x = pts[i].point.x;
                (x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2)
            };
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(0)
}

fn material_monitor(ctx: &Ctx, key: &str, m: &MonitorIn, model: &Model) -> R<MonitorKind> {
    if m.kind == "bar_stress" {
        let name = m
            .bar
            .as_deref()
            .ok_or_else(|| ctx.err(format!("{key}.bar"), "missing"))?;
        let bar = index_by_name(
            ctx,
            &format!("{key}.bar"),
            "bar",
            model.bars.iter().map(|b| b.name.as_str()),
            name,
        )?;
        let point = m.point.map(|p| nearest_bar_point(&model.bars[bar], p));
        return Ok(MonitorKind::BarStress { bar, point });
    }
    if m.point.is_some() || m.node.is_some() {
        return Err(ctx.err(
            format!("{key}.point"),
            format!(
                "a {} monitor takes an optional region, not a location",
                m.kind
            ),
        ));
    }
    let region = optional_region(ctx, &format!("{key}.region"), model, m.region.as_deref())?;
    Ok(match m.kind.as_str() {
        "max_crack_strain" => MonitorKind::MaxCrackStrain { region },
        "max_plastic_strain" => MonitorKind::MaxPlasticStrain { region },
        _ => MonitorKind::CrushedPoints { region },
    })
}

/// A node/point + component + value table → (node, direction, value).
fn control_dof(
    ctx: &Ctx,
    key: &str,
    c: &ControlIn,
    model: &Model,
    used: &[bool],
) -> R<(Vec<usize>, Dir, f64)> {
    let nodes = locate_nodes(ctx, key, model, used, c.node, c.point, c.line)?;
    let d = dir(ctx, &format!("{key}.component"), c.component.as_deref())?;
    if !c.value.is_finite() {
        return Err(ctx.err(format!("{key}.value"), "must be a finite number [m]"));
    }
    Ok((nodes, d, c.value))
}

/// Control of displacement and arc-length steps; keys of the wrong step kind are errors.
fn path_control(
    ctx: &Ctx,
    key: &str,
    s: &StepIn,
    kind: StepKind,
    model: &Model,
    used: &[bool],
) -> R<Option<PathControl>> {
    let arc_keys = [
        (s.initial_increment.is_some(), "initial_increment"),
        (s.desired_iterations.is_some(), "desired_iterations"),
        (s.max_growth.is_some(), "max_growth"),
        (s.target_factor.is_some(), "target_factor"),
        (s.stop_displacement.is_some(), "stop_displacement"),
    ];
    if kind != StepKind::ArcLength {
        if let Some((_, k)) = arc_keys.iter().find(|(g, _)| *g) {
            return Err(ctx.err(format!("{key}.{k}"), "only arc_length steps take this key"));
        }
    }
    if kind != StepKind::Displacement && s.control.is_some() {
        return Err(ctx.err(
            format!("{key}.control"),
            "only displacement steps take a control",
        ));
    }
    match kind {
        StepKind::Displacement => {
            let c = s.control.as_ref().ok_or_else(|| {
                ctx.err(
                    format!("{key}.control"),
                    "missing: give control = { point = [x, y], component = \"y\", value = -0.01 }",
                )
            })?;
            let (nodes, dir, value) = control_dof(ctx, &format!("{key}.control"), c, model, used)?;
            for &node in &nodes {
                let k = 2 * node + dir.index();
                if model
                    .supports
                    .iter()
                    .any(|sp| sp.dofs.iter().any(|(n, d, _)| 2 * n + d.index() == k))
                {
                    return Err(ctx.err(
                        format!("{key}.control"),
                        format!(
                            "node {} ({:?}) is supported in that direction; control a free dof",
                            node + 1,
                            model.nodes[node]
                        ),
                    ));
                }
            }
            Ok(Some(PathControl::Displacement { nodes, dir, value }))
        }
        StepKind::ArcLength => {
            let initial_increment = s.initial_increment.ok_or_else(|| {
                ctx.err(
                    format!("{key}.initial_increment"),
                    "missing: the load-factor increment of the first increment",
                )
            })?;
            let initial_increment =
                positive(ctx, &format!("{key}.initial_increment"), initial_increment)?;
            let target_displacement = s
                .stop_displacement
                .as_ref()
                .map(|c| {
                    let k = format!("{key}.stop_displacement");
                    if c.line.is_some() {
                        return Err(ctx.err(&k, "give a node or point, not a line"));
                    }
                    control_dof(ctx, &k, c, model, used).map(|(n, d, v)| (n[0], d, v))
                })
                .transpose()?;
            if let Some(t) = s.target_factor {
                positive(ctx, &format!("{key}.target_factor"), t)?;
            }
            let desired_iterations = s.desired_iterations.unwrap_or(6).max(1);
            let max_growth = positive(
                ctx,
                &format!("{key}.max_growth"),
                s.max_growth.unwrap_or(10.0),
            )?;
            Ok(Some(PathControl::ArcLength(ArcLengthControl {
                initial_increment,
                desired_iterations,
                max_growth,
                target_factor: s.target_factor,
                target_displacement,
                max_increments: s.increments.unwrap_or(100),
                reference: Vec::new(),
            })))
        }
        _ => Ok(None),
    }
}

/// An `elastic_creep` material: MC90 creep (ageing Maxwell chain) and shrinkage; the
/// modulus follows from fcm (E_ci of MC90), so `E` is not taken.
fn creep_material(ctx: &Ctx, i: usize, m: &MaterialIn, warnings: &mut Vec<String>) -> R<Material> {
    use crate::materials::chain::{MaxwellChain, DEFAULT_UNITS};
    use crate::materials::mc90_time::{CementClass, CreepShrinkageParams};
    let k = |f: &str| format!("materials[{i}].{f}");
    if m.e.is_some() {
        return Err(ctx.err(
            k("E"),
            "an elastic_creep material takes its modulus from fcm (MC90 E_ci); remove E",
        ));
    }
    check_material_keys(
        ctx,
        i,
        m,
        &[
            "fcm",
            "nu",
            "density",
            "rh",
            "h0",
            "cement",
            "n_units",
            "shrinkage",
            "drying_start",
        ],
    )?;
    let fcm = positive(
        ctx,
        &k("fcm"),
        m.fcm.ok_or_else(|| ctx.err(k("fcm"), "missing [Pa]"))?,
    )?;
    if !(5e6..=200e6).contains(&fcm) {
        return Err(ctx.err(
            k("fcm"),
            format!("{fcm} Pa is outside 5–200 MPa; segfem works in Pa (45 MPa = 45e6)"),
        ));
    }
    let rh = m.rh.ok_or_else(|| {
        ctx.err(
            k("rh"),
            "missing (relative humidity as a fraction, 0.7 = 70 %)",
        )
    })?;
    if !(rh.is_finite() && rh > 0.0 && rh <= 1.0) {
        return Err(ctx.err(
            k("rh"),
            format!("must be a fraction in (0, 1] (0.7 = 70 %), got {rh}"),
        ));
    }
    if rh < 0.4 {
        warnings.push(format!(
            "{}: {}: RH = {rh} is below the MC90 range 0.4–1.0 (extrapolated)",
            ctx.file,
            k("rh")
        ));
    }
    let h0 = positive(
        ctx,
        &k("h0"),
        m.h0.ok_or_else(|| ctx.err(k("h0"), "missing (notional size 2 Ac/u [m])"))?,
    )?;
    if h0 > 5.0 {
        return Err(ctx.err(
            k("h0"),
            format!("{h0} m is not a notional size 2 Ac/u in metres"),
        ));
    }
    let cement = match m.cement.as_deref() {
        None | Some("N") => CementClass::N,
        Some("R") => CementClass::R,
        Some("SL") => CementClass::SL,
        Some("RS") => CementClass::RS,
        Some(o) => {
            return Err(ctx.err(
                k("cement"),
                format!("unknown cement class '{o}' (expected SL, N, R or RS)"),
            ))
        }
    };
    let (nu, density) = poisson_and_density(ctx, i, m)?;
    let n_units = m.n_units.unwrap_or(DEFAULT_UNITS);
    if !(2..=12).contains(&n_units) {
        return Err(ctx.err(
            k("n_units"),
            format!("must lie in 2 … 12 (got {n_units}; the paper uses 5)"),
        ));
    }
    let drying_start = m.drying_start.unwrap_or(7.0);
    if !(drying_start.is_finite() && drying_start >= 0.0) {
        return Err(ctx.err(
            k("drying_start"),
            format!("must be an age ≥ 0 in days (got {drying_start})"),
        ));
    }
    let p = CreepShrinkageParams::new(fcm, rh, h0, cement, drying_start);
    let chain = MaxwellChain::fit(&p, n_units).map_err(|e| {
        ctx.err(
            k("n_units"),
            format!("creep chain identification failed: {e}"),
        )
    })?;
    Ok(Material::AgeingViscoelastic {
        chain: std::sync::Arc::new(chain),
        nu,
        density,
        cast_day: 0.0,
        shrinkage: m.shrinkage.unwrap_or(true),
    })
}

/// Give every region with an `elastic_creep` material its casting day: regions cast on
/// different days get copies of the material (sharing the chain and its per-age cache) that
/// differ only in `cast_day`.
fn assign_cast_days(
    ctx: &Ctx,
    input: &[Option<f64>],
    regions: &mut [Region],
    materials: &mut Vec<NamedMaterial>,
    warnings: &mut Vec<String>,
) -> R<()> {
    let mut seen = std::collections::HashSet::new();
    let mut copies: HashMap<(usize, u64), usize> = HashMap::new();
    for (i, (r, region)) in input.iter().zip(regions.iter_mut()).enumerate() {
        let m = region.material;
        let creep = matches!(materials[m].law, Material::AgeingViscoelastic { .. });
        let day = r.unwrap_or(0.0);
        if !day.is_finite() {
            return Err(ctx.err(
                format!("regions[{i}].cast_day"),
                "must be a finite number of days",
            ));
        }
        if !creep {
            if r.is_some() {
                warnings.push(format!(
                    "{}: regions[{i}].cast_day: ignored, material '{}' is not time dependent",
                    ctx.file, materials[m].name
                ));
            }
            continue;
        }
        let key = (m, day.to_bits());
        if let Some(&idx) = copies.get(&key) {
            region.material = idx;
            continue;
        }
        let idx = if seen.insert(m) {
            m
        } else {
            let mut copy = materials[m].clone();
            copy.name = format!("{} (cast day {day})", materials[m].name);
            materials.push(copy);
            materials.len() - 1
        };
        if let Material::AgeingViscoelastic { cast_day, .. } = &mut materials[idx].law {
            *cast_day = day;
        }
        copies.insert(key, idx);
        region.material = idx;
    }
    Ok(())
}

/// Check that every creep region exists (is cast) when the analysis starts at `start` [d].
fn check_ages(ctx: &Ctx, model: &Model, start: f64, warnings: &mut Vec<String>) -> R<()> {
    let mut used = vec![false; model.regions.len()];
    model.elements.iter().for_each(|e| used[e.region] = true);
    for (i, r) in model.regions.iter().enumerate() {
        if !used[i] {
            continue;
        }
        if let Material::AgeingViscoelastic { cast_day, .. } = &model.materials[r.material].law {
            let age = start - cast_day;
            if age < 0.0 {
                return Err(ctx.err(
                    format!("regions[{i}].cast_day"),
                    format!(
                        "region '{}' is cast on day {cast_day} but the analysis starts on day {start} (set the first time step's from, or an earlier cast_day)",
                        r.name
                    ),
                ));
            }
            if age < 1.0 {
                warnings.push(format!(
                    "{}: regions[{i}].cast_day: region '{}' is {age} d old at the start; ages below 1 d are taken as 1 d",
                    ctx.file, r.name
                ));
            }
        }
    }
    Ok(())
}

/// Default number of substeps per decade of a time step's duration. The exponential
/// algorithm with 1 substep per decade under-estimates creep at 1e4 d by ≈ 4 %, 2 by 1.6 %,
/// 5 by < 0.1 % of the converged value (docs/theory-time.md, step-size table).
pub const SUBSTEPS_PER_DECADE: f64 = 5.0;

/// Default first substep of a time step [d].
pub const DEFAULT_FIRST_SUBSTEP: f64 = 0.1;

/// The interval and substeps of a time step; `clock` = end of the previous time step.
/// Latest analysis day accepted [d].
const MAX_DAY: f64 = 1e6;

fn time_span(ctx: &Ctx, key: &str, s: &StepIn, clock: Option<f64>) -> R<TimeSpan> {
    if !s.loads.is_empty() {
        return Err(ctx.err(
            format!("{key}.loads"),
            "a time step holds the loads at their previous factors; change loads in a load step",
        ));
    }
    if s.increments.is_some() {
        return Err(ctx.err(
            format!("{key}.increments"),
            "a time step takes substeps (log-spaced), not increments",
        ));
    }
    let from = match (s.from, clock) {
        (Some(f), None) => {
            if !f.is_finite() {
                return Err(ctx.err(format!("{key}.from"), "must be a finite number of days"));
            }
            f
        }
        (Some(f), Some(c)) => {
            if (f - c).abs() > 1e-9 * c.abs().max(1.0) {
                return Err(ctx.err(
                    format!("{key}.from"),
                    format!("time steps follow each other: from must be {c} d (the end of the previous time step) or be left out"),
                ));
            }
            c
        }
        (None, Some(c)) => c,
        (None, None) => DEFAULT_START_DAY,
    };
    let to = match (s.to, s.duration) {
        (Some(t), None) => t,
        (None, Some(d)) => from + positive(ctx, &format!("{key}.duration"), d)?,
        _ => {
            return Err(ctx.err(
                format!("{key}.to"),
                "a time step needs exactly one of to (end day) or duration [d]",
            ))
        }
    };
    if !(to.is_finite() && to > from) {
        return Err(ctx.err(
            format!("{key}.to"),
            format!("must be later than from = {from} d (got {to})"),
        ));
    }
    // MC90 creep and shrinkage are at their final values within 1e5 d; a later day is a
    // typing or unit slip (seconds for days), and the power laws lose precision there.
    if to > MAX_DAY {
        return Err(ctx.err(
            format!("{key}.to"),
            format!("{to:e} d is beyond {MAX_DAY:e} d (2700 years; creep and shrinkage end long before): times are in days"),
        ));
    }
    let d = to - from;
    let first = match s.first_substep {
        Some(v) => {
            let v = positive(ctx, &format!("{key}.first_substep"), v)?;
            if v > d {
                return Err(ctx.err(
                    format!("{key}.first_substep"),
                    format!("{v} d is longer than the step ({d} d)"),
                ));
            }
            v
        }
        None => DEFAULT_FIRST_SUBSTEP.min(d),
    };
    let substeps = match s.substeps {
        Some(0) => return Err(ctx.err(format!("{key}.substeps"), "must be at least 1")),
        Some(n) => n,
        None => (SUBSTEPS_PER_DECADE * (d / first).log10()).ceil().max(0.0) as usize + 1,
    };
    Ok(TimeSpan {
        from,
        to,
        first,
        substeps,
    })
}

/// `mesh.segment_cast_days`: one casting day per segment of a segmental mesh. Each band
/// region is split into one region per segment ("webs@S2"), carrying that segment's day.
#[allow(clippy::too_many_arguments)]
fn segment_regions(
    ctx: &Ctx,
    mesh: &MeshIn,
    days: &[f64],
    joints: &[segmental::Joint],
    nodes: &[[f64; 2]],
    elements: &mut [Element],
    regions: &mut Vec<Region>,
    cast_days: &mut Vec<Option<f64>>,
) -> R<()> {
    if mesh.kind != "segmental" {
        return Err(ctx.err(
            "mesh.segment_cast_days",
            "only for type = \"segmental\" (give cast_day per region otherwise)",
        ));
    }
    let n_seg = joints.len() + 1;
    if days.len() != n_seg {
        return Err(ctx.err(
            "mesh.segment_cast_days",
            format!(
                "give one day per segment: {} for {n_seg} segments",
                days.len()
            ),
        ));
    }
    if let Some(i) = days.iter().position(|d| !d.is_finite()) {
        return Err(ctx.err(
            format!("mesh.segment_cast_days[{i}]"),
            "must be a finite number of days",
        ));
    }
    let n_base = regions.len();
    let mut map: HashMap<(usize, usize), usize> = HashMap::new();
    for el in elements.iter_mut() {
        let xc = el.nodes.iter().map(|&n| nodes[n][0]).sum::<f64>() / el.nodes.len() as f64;
        let seg = joints.iter().filter(|j| j.x < xc).count();
        let key = (el.region, seg);
        let idx = *map.entry(key).or_insert_with(|| {
            let base = &regions[el.region];
            regions.push(Region {
                name: format!("{}@S{}", base.name, seg + 1),
                material: base.material,
                thickness: base.thickness,
            });
            cast_days.push(Some(days[seg]));
            regions.len() - 1
        });
        el.region = idx;
    }
    // The band regions keep their names for monitors and output but no longer own elements;
    // their own cast_day (if any) is superseded.
    for d in cast_days.iter_mut().take(n_base) {
        *d = None;
    }
    Ok(())
}

/// The Poisson ratio (required, in (−1, 0.5)) and density (default 0, ≥ 0 [kg/m³]) of a
/// material table.
fn poisson_and_density(ctx: &Ctx, i: usize, m: &MaterialIn) -> R<(f64, f64)> {
    let k = |f: &str| format!("materials[{i}].{f}");
    let nu = m.nu.ok_or_else(|| ctx.err(k("nu"), "missing"))?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(ctx.err(
            k("nu"),
            format!("Poisson ratio must lie in (-1, 0.5) (got {nu})"),
        ));
    }
    let density = m.density.unwrap_or(0.0);
    if !(density.is_finite() && density >= 0.0) {
        return Err(ctx.err(
            k("density"),
            format!("must be zero or positive (got {density})"),
        ));
    }
    Ok((nu, density))
}
