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
        for (p, st) in el
            .points()
            .iter()
            .zip(&sys.families.joints.points.committed[i])
        {
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
