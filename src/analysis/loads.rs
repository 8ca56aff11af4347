//! External load vectors of the load cases (consistent nodal forces over all dofs).

use crate::elements::continuum::{body_force, edge_force_partial};
use crate::model::{LoadCase, Model};

/// Full-dof external force vector [N] of one load case at factor 1.
pub fn load_vector(model: &Model, case: &LoadCase) -> Vec<f64> {
    load_vector_of(model, case, None)
}

/// As [`load_vector`] with gravity on the active elements only (`active[e]`; all if None):
/// a part not yet placed, or removed, carries no self-weight.
pub fn load_vector_of(model: &Model, case: &LoadCase, active: Option<&[bool]>) -> Vec<f64> {
    let mut f = vec![0.0; model.n_dofs()];
    for &(n, [fx, fy]) in &case.point_forces {
        f[2 * n] += fx;
        f[2 * n + 1] += fy;
    }
    for el in &case.edge_loads {
        let coords: Vec<[f64; 2]> = el.nodes.iter().map(|&n| model.nodes[n]).collect();
        let fe = edge_force_partial(&coords, el.q, el.range[0], el.range[1]);
        for (a, &n) in el.nodes.iter().enumerate() {
            f[2 * n] += fe[2 * a];
            f[2 * n + 1] += fe[2 * a + 1];
        }
    }
    if let Some(g) = case.gravity {
        for (i, e) in model.elements.iter().enumerate() {
            if active.is_some_and(|a| !a[i]) {
                continue;
            }
            let region = &model.regions[e.region];
            let rho = model.materials[region.material].law.density();
            if rho == 0.0 {
                continue;
            }
            let fe = body_force(
                e.kind,
                &model.element_coords(e),
                region.thickness,
                [rho * g[0], rho * g[1]],
            );
            for (a, &n) in e.nodes.iter().enumerate() {
                f[2 * n] += fe[2 * a];
                f[2 * n + 1] += fe[2 * a + 1];
            }
        }
    }
    f
}
