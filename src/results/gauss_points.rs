//! The concrete's Gauss points as a .vtu of vertices (part 3 of `results.pvd`): the state
//! of every integration point — cracks, their normals and opening strains, plastic strain,
//! crushing — where the element .vtu shows only each cell's worst point.

use super::vtu::{render, Array, Grid};
use crate::analysis::steps::Snapshot;
use crate::elements::continuum::rule_points;
use crate::fem::shape::map_point;
use crate::model::Model;

/// True when some region's material has a state worth a point file (concrete that cracks,
/// flows or crushes); elastic and creeping models have none.
pub fn wanted(model: &Model) -> bool {
    model
        .materials
        .iter()
        .any(|m| matches!(m.law, crate::materials::point::Material::Concrete { .. }))
}

/// Render the Gauss-point file of a converged increment.
pub fn render_gauss_points(snap: &Snapshot) -> String {
    let sys = snap.system;
    let model = sys.model;
    let n = sys.point_states().len();
    let mut points = Vec::with_capacity(n);
    for e in &model.elements {
        let coords = model.element_coords(e);
        for &(xi, eta, _) in rule_points(e.kind, e.integration) {
            points.push(map_point(&e.kind.eval(xi, eta), &coords));
        }
    }
    debug_assert_eq!(points.len(), n, "one state per Gauss point");
    let cells: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
    let types = vec![1u8; n]; // VTK_VERTEX
    let (mut cracks, mut crushed) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut normal, mut opening, mut max_opening) = (
        Vec::with_capacity(3 * n),
        Vec::with_capacity(2 * n),
        Vec::with_capacity(2 * n),
    );
    let (mut plastic, mut stress, mut strain) = (
        Vec::with_capacity(n),
        Vec::with_capacity(3 * n),
        Vec::with_capacity(3 * n),
    );
    for (p, g) in sys.point_states().iter().zip(sys.gauss_outputs()) {
        let c = p.concrete();
        let k = p.n_cracks();
        cracks.push(k as i32);
        crushed.push(p.is_crushed() as i32);
        let t = p.crack_angle();
        if k > 0 {
            normal.extend([t.cos(), t.sin(), 0.0]);
        } else {
            normal.extend([0.0; 3]);
        }
        opening.extend(c.map_or([0.0; 2], |c| c.crack_strains()));
        max_opening.extend(c.map_or([0.0; 2], |c| c.max_crack_strains()));
        plastic.push(p.equivalent_plastic_strain());
        stress.extend(g.stress);
        strain.extend(g.strain);
    }
    render(
        &Grid {
            points: &points,
            cells: &cells,
            types: &types,
        },
        &[
            Array::I32 {
                name: "cracks",
                values: &cracks,
            },
            Array::F64 {
                name: "crack_normal",
                components: 3,
                values: &normal,
            },
            Array::F64 {
                name: "crack_strains",
                components: 2,
                values: &opening,
            },
            Array::F64 {
                name: "max_crack_strains",
                components: 2,
                values: &max_opening,
            },
            Array::F64 {
                name: "plastic_strain",
                components: 1,
                values: &plastic,
            },
            Array::I32 {
                name: "crushed",
                values: &crushed,
            },
            Array::F64 {
                name: "stress",
                components: 3,
                values: &stress,
            },
            Array::F64 {
                name: "strain",
                components: 3,
                values: &strain,
            },
        ],
        &[],
    )
}
