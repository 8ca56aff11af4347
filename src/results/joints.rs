//! Joint results: opening profile along the depth, largest opening, depth still in contact,
//! and slip, from the committed joint states.

use crate::analysis::system::System;

/// One integration point of a joint, as reported.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct JointPoint {
    /// Position on face A [m].
    pub x: [f64; 2],
    /// Opening (≥ 0 when open) [m].
    pub opening: f64,
    /// Normal stress, compression positive [Pa].
    pub normal_stress: f64,
    /// Shear stress [Pa].
    pub shear_stress: f64,
    /// Relative tangential displacement [m].
    pub slip: f64,
    /// Closed (in contact).
    pub closed: bool,
}

/// Summary of one joint.
#[derive(Debug, Clone, serde::Serialize)]
pub struct JointSummary {
    /// Largest opening [m].
    pub max_opening: f64,
    /// Length of the joint in contact [m] (sum of the closed points' integration lengths).
    pub contact_depth: f64,
    /// Largest |slip| [m].
    pub max_slip: f64,
    /// Points sorted by height.
    pub profile: Vec<JointPoint>,
}

/// Summarise joint `j` of the model from the committed states.
pub fn summarise(sys: &System, j: usize) -> JointSummary {
    let mut s = JointSummary {
        max_opening: 0.0,
        contact_depth: 0.0,
        max_slip: 0.0,
        profile: Vec::new(),
    };
    for &i in &sys.model.joints[j].interfaces {
        let el = &sys.interfaces[i];
        for (p, st) in el.points().iter().zip(sys.joint_points(i)) {
            let closed = st.closed || st.bonded;
            if closed {
                s.contact_depth += p.weight;
            }
            s.max_opening = s.max_opening.max(st.opening());
            s.max_slip = s.max_slip.max(st.slip().abs());
            s.profile.push(JointPoint {
                x: p.position,
                opening: st.opening(),
                normal_stress: st.normal_stress(),
                shear_stress: st.shear_stress(),
                slip: st.slip(),
                closed,
            });
        }
    }
    s.profile.sort_by(|a, b| a.x[1].total_cmp(&b.x[1]));
    s
}

/// The joints' integration points as a .vtu of vertices (part 4 of `results.pvd`): per
/// point the joint (1-based, model order), opening [m], normal stress (compression
/// positive) [Pa], shear stress [Pa] and slip [m] — the diagrams along the joint depth
/// and their true extremes, where the line cells of part 1 show element means. None when
/// the model has no joints.
pub fn render_joint_points(sys: &System) -> Option<String> {
    use super::vtu::{render, Array, Grid};
    if sys.model.joints.is_empty() {
        return None;
    }
    let (mut points, mut joint, mut opening, mut sn, mut tau, mut slip) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    for j in 0..sys.model.joints.len() {
        for p in summarise(sys, j).profile {
            points.push(p.x);
            joint.push(j as i32 + 1);
            opening.push(p.opening);
            sn.push(p.normal_stress);
            tau.push(p.shear_stress);
            slip.push(p.slip);
        }
    }
    let cells: Vec<Vec<usize>> = (0..points.len()).map(|i| vec![i]).collect();
    let types = vec![1u8; points.len()]; // VTK_VERTEX
    let scalar = |name, values| Array::F64 {
        name,
        components: 1,
        values,
    };
    Some(render(
        &Grid {
            points: &points,
            cells: &cells,
            types: &types,
        },
        &[
            Array::I32 {
                name: "joint",
                values: &joint,
            },
            scalar("opening", &opening),
            scalar("normal_stress", &sn),
            scalar("shear_stress", &tau),
            scalar("slip", &slip),
        ],
        &[],
    ))
}
