//! `[[joint_materials]]` and the interface elements of the joints between segments
//! (`mesh.joint_material`), with automatic penalty stiffnesses.

use super::fields::{index_by_name, positive, unique_names};
use super::R;
use crate::elements::interface::{
    suggest_normal_stiffness, InterfaceElement, InterfaceParams, JointNeighbour,
};
use crate::input::error::Ctx;
use crate::input::schema::{JointMaterialIn, MeshIn};
use crate::input::units;
use crate::mesh::segmental;
use crate::model::{InterfaceEl, Joint, Model};

/// The `[[joint_materials]]` by name.
pub(super) fn materials(
    ctx: &Ctx,
    list: &[JointMaterialIn],
    warnings: &mut Vec<String>,
) -> R<Vec<(String, JointSpec)>> {
    unique_names(ctx, "joint_materials", list.iter().map(|m| m.name.as_str()))?;
    let mut joint_materials = Vec::new();
    for (i, j) in list.iter().enumerate() {
        joint_materials.push(joint_material(ctx, i, j)?);
        for (name, v) in [
            ("tensile_strength", j.tensile_strength),
            ("cohesion", j.cohesion),
        ] {
            let key = format!("joint_materials[{i}].{name}");
            units::strength(warnings, ctx, &key, v.unwrap_or(0.0));
        }
    }
    Ok(joint_materials)
}

/// A joint material from its table; penalties may be left for the mesh to resolve (kn = 0).
pub(super) fn joint_material(ctx: &Ctx, i: usize, j: &JointMaterialIn) -> R<(String, JointSpec)> {
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
pub(super) struct JointSpec {
    params: InterfaceParams,
    factor: f64,
}

/// Create the interface elements of the generated joints with the mesh's joint material,
/// resolving automatic penalty stiffnesses from the neighbouring elements.
pub(super) fn add(
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
        if j.cast {
            // Cast in place: the faces share their nodes, no contact element.
            continue;
        }
        let index = model.joints.len();
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
                joint: index,
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

/// A warning for every embedded bar or bonded tendon whose path crosses a joint: its pieces
/// on either side load their own segments (the faces do not share nodes), so it carries no
/// force across the joint — the joint opens as if the steel were not there, and a
/// prestressed bar's force does not press it (docs/theory-joints-tendons.md). Match-cast
/// joints are crossed by external tendons, not by embedded steel.
pub(super) fn bars_across(ctx: &Ctx, model: &Model, warnings: &mut Vec<String>) {
    if model.interfaces.is_empty() {
        return;
    }
    let tol = 1e-6 * crate::input::locate::model_size(model);
    // Face A of each contact element as a segment (its start and end nodes).
    let faces: Vec<([f64; 2], [f64; 2], usize)> = model
        .interfaces
        .iter()
        .map(|i| (model.nodes[i.nodes[0]], model.nodes[i.nodes[1]], i.joint))
        .collect();
    let on = |p: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l = dx.hypot(dy);
        if l == 0.0 {
            return false;
        }
        let off = ((p[0] - a[0]) * dy - (p[1] - a[1]) * dx).abs() / l;
        let t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (l * l);
        off <= tol && t >= -tol / l && t <= 1.0 + tol / l
    };
    for bar in model.bars.iter().filter(|b| !b.layer) {
        // Inner piece ends: where the path passes from one host element to the next.
        let inner = bar
            .piece_ends
            .iter()
            .skip(1)
            .map(|e| e[0])
            .chain(bar.piece_ends.iter().rev().skip(1).map(|e| e[1]));
        let mut crossed: Vec<usize> = Vec::new();
        for p in inner {
            for &(a, b, j) in &faces {
                if on(p, a, b) && !crossed.contains(&j) {
                    crossed.push(j);
                }
            }
        }
        if crossed.is_empty() {
            continue;
        }
        crossed.sort_unstable();
        let names: Vec<&str> = crossed
            .iter()
            .map(|&j| model.joints[j].name.as_str())
            .collect();
        warnings.push(format!(
            "{}: '{}' is embedded steel crossing joint(s) {}: its pieces on either side load their own segments, so it carries no force across a joint (the joint opens as if it were not there) and its prestress, if any, does not press the joint; a tendon that crosses match-cast joints is an external one (kind = \"external\")",
            ctx.file,
            bar.name,
            names.join(", ")
        ));
    }
}
