//! `[[load_cases]]`: gravity, point loads and line loads along element edges.

use super::fields::{locate_nodes, unique_names};
use super::R;
use crate::input::error::Ctx;
use crate::input::gmsh_mesh;
use crate::input::locate;
use crate::input::schema::LoadCaseIn;
use crate::model::{EdgeLoad, LoadCase, Model};

/// The load cases, located in the mesh.
pub(super) fn build(
    ctx: &Ctx,
    list: &[LoadCaseIn],
    groups: &gmsh_mesh::Groups,
    model: &mut Model,
    used: &[bool],
) -> R<()> {
    unique_names(ctx, "load_cases", list.iter().map(|c| c.name.as_str()))?;
    for (i, c) in list.iter().enumerate() {
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
            let n = locate_nodes(ctx, &key, model, used, p.node, p.point, None)?[0];
            case.point_forces.push((n, p.force));
        }
        for (j, l) in c.line_loads.iter().enumerate() {
            let key = format!("load_cases[{i}].line_loads[{j}]");
            if l.q.iter().any(|v| !v.is_finite()) {
                return Err(ctx.err(format!("{key}.q"), "must be finite numbers"));
            }
            let edges = match (&l.line, &l.group) {
                (Some([a, b]), None) => {
                    let (edges, covered) = locate::edges_on_segment(model, *a, *b);
                    let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                    if edges.is_empty()
                        || (covered - length).abs() > 1e-6 * locate::model_size(model)
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
    Ok(())
}
