//! One-way supports (bearings, props, falsework: `supports[i].one_way`) as an active set
//! (docs/theory-stages.md, "One-way supports"). Each node a one-way support holds is a
//! contact point on its pushing dof, an equation of the analysis: held (as a staged
//! support's dof, [`super::stages::StageState::hold_tangent`]) while the point touches its
//! seat, free once it has lifted off. After an attempt has converged with the statuses it
//! had, a touching point whose reaction pulls lifts off and a lifted point that has moved
//! through its seat touches down again; if any status changed, the increment is solved again
//! from its start with the new statuses (the statuses of one increment are consistent with
//! its converged state, as in a contact problem). The trial statuses are kept apart from the
//! committed ones: a thrown-away attempt goes back to the committed statuses.

use super::staged::Staged;
use crate::fem::dofs::CONSTRAINED;
use crate::model::Model;

/// Most status changes (rounds of solving the increment again) in one increment. The
/// statuses of a structure on a few supports settle in one or two rounds; past this many
/// they chatter (a point lifts off and touches down in turn) and the increment is kept with
/// the statuses of its last round (counted in summary.json `timings.support_chatter`).
pub const MAX_ROUNDS: usize = 50;

/// A reaction that pulls by less than this fraction of the largest nodal force (external
/// forces, contact reactions) is zero, not a pull [-]: a point carrying nothing (a prop
/// exactly at the load that lifts it) is left as it is rather than switched on round-off.
const FORCE_TOLERANCE: f64 = 1e-9;

/// A lifted point counts as through its seat when it is below it by more than this
/// fraction of the model's size [-] (round-off of the displacements is ~1e-16 of them).
const GAP_TOLERANCE: f64 = 1e-10;

/// One node held by a one-way support on its pushing dof.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactPoint {
    /// Support index.
    pub support: usize,
    /// Node index.
    pub node: usize,
    /// Dof index (2 node + direction).
    pub dof: usize,
    /// Equation of the dof.
    pub eq: usize,
    /// +1 when the support pushes along the positive axis, −1 along the negative one.
    pub sign: f64,
    /// Displacement of the seat along the dof [m]: where the node stood when the support
    /// started to act (0 for a support from the start).
    pub seat: f64,
    /// Whether the support acts in the current stage and the node is on an active element.
    pub acting: bool,
    /// Status: touching its seat (held), committed and of the increment being solved (both
    /// saved: the layout of checkpoint format 10).
    #[serde(with = "super::staged::both")]
    pub touching: Staged<bool>,
}

/// The contact points of all one-way supports (empty for a model without any).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OneWay {
    /// The points, support by support in the order of their dofs.
    pub points: Vec<ContactPoint>,
}

impl OneWay {
    /// Enter the stage of step `step` at displacements `u` [m]: the points of the one-way
    /// supports that start to act (support active, node on an active element: `alive`)
    /// touch a seat where their node stands; those that stop acting are let go.
    pub fn enter(&mut self, model: &Model, step: usize, u: &[f64], eq: &[usize], alive: &[bool]) {
        let st = &model.staging;
        if self.points.is_empty() {
            for (s, sp) in model.supports.iter().enumerate() {
                let Some(p) = st.push(s) else { continue };
                for &(n, dir, _) in sp.dofs.iter().filter(|d| d.1 == p.dir()) {
                    let d = 2 * n + dir.index();
                    if eq[d] == CONSTRAINED {
                        continue;
                    }
                    self.points.push(ContactPoint {
                        support: s,
                        node: n,
                        dof: d,
                        eq: eq[d],
                        sign: p.sign(),
                        seat: 0.0,
                        acting: false,
                        touching: Staged::new(false),
                    });
                }
            }
        }
        for p in &mut self.points {
            let acts = st.support(p.support).active_in(step) && alive[p.node];
            if acts && !p.acting {
                p.seat = u[p.dof];
                p.touching = Staged::new(true);
            } else if !acts {
                p.touching = Staged::new(false);
            }
            p.acting = acts;
        }
    }

    /// The held equations: `base` (held for other reasons) and the touching points (trial).
    pub fn held(&self, base: &[bool]) -> Vec<bool> {
        let mut held = base.to_vec();
        for p in self.points.iter().filter(|p| p.acting && p.touching.trial) {
            held[p.eq] = true;
        }
        held
    }

    /// The statuses of a converged attempt at displacements `u` [m], internal forces
    /// `f_int` and external forces `f_ext` [N] (all dofs), with `size` the model's size
    /// [m]: the points to switch (index into `points`; a touching point that pulls, a lifted
    /// one through its seat). Empty: the attempt's statuses hold.
    pub fn switches(&self, u: &[f64], f_int: &[f64], f_ext: &[f64], size: f64) -> Vec<usize> {
        let reaction = |p: &ContactPoint| p.sign * (f_int[p.dof] - f_ext[p.dof]);
        let scale = self
            .points
            .iter()
            .filter(|p| p.acting && p.touching.trial)
            .map(|p| reaction(p).abs())
            .chain(f_ext.iter().map(|f| f.abs()))
            .fold(0.0_f64, f64::max);
        self.points
            .iter()
            .enumerate()
            .filter(|(_, p)| p.acting)
            .filter(|(_, p)| {
                if p.touching.trial {
                    reaction(p) < -FORCE_TOLERANCE * scale
                } else {
                    p.sign * (u[p.dof] - p.seat) < -GAP_TOLERANCE * size
                }
            })
            .map(|(i, _)| i)
            .collect()
    }

    /// Switch the trial status of the points `which`.
    pub fn switch(&mut self, which: &[usize]) {
        for &i in which {
            self.points[i].touching.trial = !self.points[i].touching.trial;
        }
    }

    /// Put the points that touch down in this attempt (trial touching, committed lifted)
    /// on their seats in `u` [m]: a held equation keeps the value it starts with.
    pub fn seat(&self, u: &mut [f64]) {
        for p in self
            .points
            .iter()
            .filter(|p| p.acting && p.touching.trial && !p.touching.committed)
        {
            u[p.dof] = p.seat;
        }
    }

    /// The trial statuses become the committed ones (a kept increment).
    pub fn commit(&mut self) {
        self.points.iter_mut().for_each(|p| p.touching.commit());
    }

    /// Back to the committed statuses (a thrown-away attempt).
    pub fn revert(&mut self) {
        self.points.iter_mut().for_each(|p| p.touching.revert());
    }

    /// Whether some trial status differs from the committed one.
    pub fn changed(&self) -> bool {
        self.points
            .iter()
            .any(|p| p.touching.trial != p.touching.committed)
    }

    /// Per support: (points lifted off, points acting) of the committed statuses.
    pub fn lifted_per_support(&self, n_supports: usize) -> Vec<(usize, usize)> {
        let mut out = vec![(0, 0); n_supports];
        for p in self.points.iter().filter(|p| p.acting) {
            out[p.support].1 += 1;
            if !p.touching.committed {
                out[p.support].0 += 1;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A touching point of a support pushing along `sign` on dof 1 (equation 0), seat 0.
    fn point(sign: f64, touching: bool) -> OneWay {
        OneWay {
            points: vec![ContactPoint {
                support: 0,
                node: 0,
                dof: 1,
                eq: 0,
                sign,
                seat: 0.0,
                acting: true,
                touching: Staged::new(touching),
            }],
        }
    }

    /// The reaction f_int − f_ext at the dof decides: a bearing pushing up (+y) lifts off
    /// when it would pull down (−5 N), not when it pushes (+5 N); one pushing down (−y), the
    /// other way round. 5 N is well above 1e-9 of the largest force (10 N here).
    #[test]
    fn a_touching_point_lifts_off_when_its_reaction_pulls() {
        let f_ext = [10.0, 0.0];
        let u = [0.0; 2];
        for (sign, f_int, lifts) in [(1.0, -5.0, true), (1.0, 5.0, false), (-1.0, 5.0, true)] {
            let w = point(sign, true);
            let which = w.switches(&u, &[0.0, f_int], &f_ext, 1.0);
            assert_eq!(which.is_empty(), !lifts, "sign {sign}, R = {f_int}");
        }
    }

    /// A lifted point touches down when it is through its seat by more than 1e-10 of the
    /// model size (here 1 m): 1e-6 m below a +y seat does, 1e-6 m above does not, nor
    /// 1e-12 m below (round-off).
    #[test]
    fn a_lifted_point_touches_down_through_its_seat() {
        let w = point(1.0, false);
        let zero = [0.0; 2];
        for (uy, touches) in [(-1e-6, true), (1e-6, false), (-1e-12, false)] {
            let which = w.switches(&[0.0, uy], &zero, &zero, 1.0);
            assert_eq!(which.is_empty(), !touches, "uy = {uy}");
        }
        // One pushing down (−y): through its seat is above it.
        let w = point(-1.0, false);
        assert_eq!(w.switches(&[0.0, 1e-6], &zero, &zero, 1.0), [0]);
    }

    /// Trial and committed statuses: a switch changes the trial status and the held
    /// equations only; revert goes back to the committed one, commit keeps the trial one.
    /// A point touching down is put on its seat.
    #[test]
    fn trial_statuses_revert_and_commit() {
        let mut w = point(1.0, false);
        w.points[0].seat = 0.25;
        assert_eq!(w.held(&[false]), [false]);
        w.switch(&[0]);
        assert!(w.changed());
        assert_eq!(w.held(&[false]), [true]);
        let mut u = [0.0, 0.2];
        w.seat(&mut u);
        assert_eq!(u, [0.0, 0.25]);
        w.revert();
        assert!(!w.changed() && !w.points[0].touching.trial);
        w.switch(&[0]);
        w.commit();
        assert!(!w.changed() && w.points[0].touching.committed);
        assert_eq!(w.lifted_per_support(1), [(0, 1)]);
    }
}
