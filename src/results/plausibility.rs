//! Checks that a converged result is physically meaningful before it is called "completed":
//! a model held only by numerical stiffness converges (Newton is happy with a residual
//! stiffness of 1e-6 K_n) but its displacements are nonsense. Two symptoms are watched at
//! every converged increment (docs/running.md, "Implausible results"):
//!
//! - load carried through the residual stiffness of open joint points: more than
//!   [`RESIDUAL_SHARE`] of the applied load crosses a joint through points that are open
//!   (the physical contact carries nothing there);
//! - displacements larger than [`DISPLACEMENT_SHARE`] of the model size (bounding-box
//!   diagonal).

use crate::analysis::steps::Snapshot;
use crate::fem::dofs::CONSTRAINED;

/// Share of the applied load [-] that may cross a joint through open points' residual
/// stiffness. The residual stiffness (1e-6 K_n by default) only keeps the tangent regular:
/// on a prestressed segmental beam at failure its forces are below 0.3 % of the load; 5 %
/// means the structure stands on it.
pub const RESIDUAL_SHARE: f64 = 0.05;

/// Largest displacement [-, of the bounding-box diagonal] taken as plausible. Concrete
/// members fail at deflections of the order of 1/100 to 1/50 of their span (the bundled RC
/// beam at the end of its plateau: 1.9 % of its size); 10 % is beyond any concrete
/// structure still standing and far beyond the small-displacement theory.
pub const DISPLACEMENT_SHARE: f64 = 0.10;

/// Watches the converged increments; keeps the first implausible one of each kind.
#[derive(Debug, Default)]
pub struct Plausibility {
    residual: Option<String>,
    displacement: Option<String>,
}

impl Plausibility {
    /// A watch with nothing seen.
    pub fn new() -> Self {
        Self::default()
    }

    /// Check one converged increment.
    pub fn increment(&mut self, snap: &Snapshot) {
        let sys = snap.system;
        let model = sys.model;
        let at = || {
            format!(
                "step '{}' increment {}",
                model.steps[snap.step].name, snap.increment
            )
        };
        if self.displacement.is_none() {
            let (lo, hi) = model.nodes.iter().fold(
                ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
                |(lo, hi), x| {
                    (
                        [lo[0].min(x[0]), lo[1].min(x[1])],
                        [hi[0].max(x[0]), hi[1].max(x[1])],
                    )
                },
            );
            let size = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
            let (node, u) = sys
                .displacements()
                .chunks(2)
                .map(|d| d[0].hypot(d[1]))
                .enumerate()
                .fold((0, 0.0), |b, (n, u)| if u > b.1 { (n, u) } else { b });
            if size > 0.0 && u > DISPLACEMENT_SHARE * size {
                let [x, y] = model.nodes[node];
                self.displacement = Some(format!(
                    "{}: node {} ({x}, {y}) moved {:.4} m, {:.0} % of the model size {:.3} m (limit {:.0} %): no concrete structure stands there; the model is (nearly) a mechanism held by numerical stiffness, or the loads or units are wrong",
                    at(),
                    node + 1,
                    u,
                    100.0 * u / size,
                    size,
                    100.0 * DISPLACEMENT_SHARE
                ));
            }
        }
        if self.residual.is_none() && !model.joints.is_empty() {
            // The load scale: external forces, or the reactions when a displacement
            // control moves the structure.
            let external: f64 = snap.f_ext.iter().map(|f| f.abs()).sum();
            let reactions: f64 = sys
                .dofs
                .eq
                .iter()
                .enumerate()
                .filter(|(_, &q)| q == CONSTRAINED)
                .map(|(d, _)| (snap.f_int[d] - snap.f_ext[d]).abs())
                .sum();
            let load = external.max(reactions);
            for (j, joint) in model.joints.iter().enumerate() {
                let (mut fn_, mut ft) = (0.0, 0.0);
                for &i in &joint.interfaces {
                    let t = model.interfaces[i].thickness;
                    for (p, st) in sys.interfaces[i].points().iter().zip(sys.joint_points(i)) {
                        if !(st.closed || st.bonded) {
                            fn_ += st.normal_stress() * p.weight * t;
                            ft += st.shear_stress() * p.weight * t;
                        }
                    }
                }
                let f = fn_.hypot(ft);
                if load > 0.0 && f > RESIDUAL_SHARE * load {
                    self.residual = Some(format!(
                        "{}: joint {} carries {:.1} kN through the residual stiffness of its open points, {:.0} % of the applied load (sum of force magnitudes {:.1} kN) (limit {:.0} %): the structure stands only on numerical stiffness — an open dry joint without friction or prestress transfers nothing in reality",
                        at(),
                        model.joints[j].name,
                        f / 1e3,
                        100.0 * f / load,
                        load / 1e3,
                        100.0 * RESIDUAL_SHARE
                    ));
                    break;
                }
            }
        }
    }

    /// What was found, first the joints (the cause), then the displacements (the symptom).
    pub fn findings(&self) -> Vec<String> {
        self.residual
            .iter()
            .chain(&self.displacement)
            .cloned()
            .collect()
    }
}
