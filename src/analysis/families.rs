//! The analysis state, one block per element family. Each block keeps its committed/trial
//! pairs in [`Staged`] values and its other state (stages, reference strains, time records)
//! beside them, and says once, in its [`StateBlock`] implementation below its declaration,
//! how they are committed, reverted and checked against the model when read back;
//! [`Families`] calls the four blocks. The checkpoint saves these blocks as they are
//! (serde), so adding a state field to a block adds it to the checkpoint; the layout test
//! of `results::checkpoint` then asks for a new format version. One exception: the Gauss
//! outputs of linear elastic points (stateless, a function of the displacements) are left
//! out, and a restart recomputes them ([`ContinuumBlock`]).
//!
//! Not in the blocks: the model's topology (Gauss-point and bar-point offsets, element
//! numbers), which `System::new` derives from the model.

use super::staged::{same_count, same_len, Mismatch, Staged, StateBlock};
use super::tendon_time::{BarPointTime, SpanTime, TendonTime};
use crate::elements::continuum::GaussOutput;
use crate::elements::interface::InterfacePointState;
use crate::elements::tendon::TendonState;
use crate::materials::point::PointState;
use crate::materials::steel::SteelState;
use crate::model::Model;
use serde::{Deserialize, Serialize};

/// The state of every element family.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Families {
    /// Continuum material points.
    pub continuum: ContinuumBlock,
    /// Joint integration points.
    pub joints: JointBlock,
    /// External tendons.
    pub tendons: TendonBlock,
    /// Embedded bars, bar layers and bonded tendons (points in host-element order).
    pub bars: BarBlock,
}

impl StateBlock for Families {
    /// The model the blocks were built for.
    type Shape<'a> = &'a Model;

    /// Accept the trial states of every family.
    fn commit(&mut self) {
        self.continuum.commit();
        self.joints.commit();
        self.tendons.commit();
        self.bars.commit();
    }

    /// Throw away the trial states of every family.
    fn revert(&mut self) {
        self.continuum.revert();
        self.joints.revert();
        self.tendons.revert();
        self.bars.revert();
    }

    fn check_shape(&self, saved: &Self, model: &Model) -> Result<(), Mismatch> {
        self.continuum.check_shape(&saved.continuum, ())?;
        self.joints.check_shape(&saved.joints, ())?;
        let nodes: Vec<usize> = model.tendons.iter().map(|t| t.nodes.len()).collect();
        self.tendons.check_shape(&saved.tendons, &nodes)?;
        self.bars.check_shape(&saved.bars, ())
    }
}

/// Continuum material points (order: element by element, Gauss points within).
///
/// Saved as the point states and the Gauss outputs of the points that are not linear
/// elastic ([`PointState::Elastic`]): those of elastic points are a function of the
/// displacements (and imposed strains) alone, and at 5e5 dofs they were 48 MB of a 57 MB
/// checkpoint. Read back, they are zero until `System::recover_elastic_outputs` recomputes
/// them with the element routine that produced them (bit-identical).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "ContinuumSaved")]
pub struct ContinuumBlock {
    /// Material point states.
    pub points: Staged<Vec<PointState>>,
    /// Gauss-point outputs (strain, stress).
    pub gauss: Staged<Vec<GaussOutput>>,
    /// Branch holds of the increment under way (empty between increments: not saved).
    #[serde(skip)]
    pub holds: Holds,
}

impl StateBlock for ContinuumBlock {
    type Shape<'a> = ();

    /// Accept the trial states; the holds last one increment only, so the committed points
    /// end their increment ([`PointState::end_increment`]) when any was held.
    fn commit(&mut self) {
        self.points.commit_parallel();
        self.gauss.commit_parallel();
        self.holds.latched.clear();
        let frozen = std::mem::take(&mut self.holds.frozen);
        if std::mem::take(&mut self.holds.held_plastic) || frozen {
            self.points
                .committed
                .iter_mut()
                .for_each(PointState::end_increment);
        }
    }

    /// Back to the committed states; the holds are released.
    fn revert(&mut self) {
        self.points.revert();
        self.gauss.revert();
        self.holds = Holds::default();
    }

    /// As many points and outputs as the model, each point of the kind its material gives.
    fn check_shape(&self, saved: &Self, (): ()) -> Result<(), Mismatch> {
        same_len(
            "material points",
            &saved.points,
            self.points.committed.len(),
        )?;
        same_len("Gauss outputs", &saved.gauss, self.gauss.committed.len())?;
        if let Some(p) = (saved.points.committed.iter())
            .zip(&self.points.committed)
            .position(|(a, b)| std::mem::discriminant(a) != std::mem::discriminant(b))
        {
            return Err(format!(
                "material point {} has another kind of state in the checkpoint than in the model: the model changed since the checkpoint was written",
                p + 1
            ));
        }
        Ok(())
    }
}

/// The saved form of a [`ContinuumBlock`] as read back.
#[derive(Deserialize)]
struct ContinuumSaved {
    points: Staged<Vec<PointState>>,
    /// Gauss outputs of the points that are not elastic, in point order.
    gauss: Vec<GaussOutput>,
}

impl TryFrom<ContinuumSaved> for ContinuumBlock {
    type Error = String;

    fn try_from(s: ContinuumSaved) -> Result<Self, String> {
        let points = &s.points.committed;
        let kept = points.iter().filter(|p| !is_elastic(p)).count();
        if kept != s.gauss.len() {
            return Err(format!(
                "{} Gauss outputs saved for {kept} inelastic points",
                s.gauss.len()
            ));
        }
        let mut saved = s.gauss.into_iter();
        let gauss: Vec<GaussOutput> = points
            .iter()
            .map(|p| {
                if is_elastic(p) {
                    GaussOutput::default()
                } else {
                    saved.next().unwrap_or_default()
                }
            })
            .collect();
        Ok(Self {
            points: s.points,
            gauss: Staged::new(gauss),
            holds: Holds::default(),
        })
    }
}

/// A point whose Gauss outputs the checkpoint leaves out (stateless linear elastic).
pub(crate) fn is_elastic(p: &PointState) -> bool {
    matches!(p, PointState::Elastic)
}

impl Serialize for ContinuumBlock {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{SerializeSeq, SerializeStruct};
        /// The committed Gauss outputs of the inelastic points.
        struct Inelastic<'a>(&'a ContinuumBlock);
        impl Serialize for Inelastic<'_> {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                let (points, gauss) = (&self.0.points.committed, &self.0.gauss.committed);
                let kept = || points.iter().zip(gauss).filter(|(p, _)| !is_elastic(p));
                let mut seq = s.serialize_seq(Some(kept().count()))?;
                for (_, g) in kept() {
                    seq.serialize_element(g)?;
                }
                seq.end()
            }
        }
        let mut st = s.serialize_struct("ContinuumBlock", 2)?;
        st.serialize_field("points", &self.points)?;
        st.serialize_field("gauss", &Inelastic(self))?;
        st.end()
    }
}

/// Crack and plastic-route holds within one increment.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Holds {
    /// Points whose crack formed during the current increment, with the state their updates
    /// start from until the increment ends (sorted by point index; see
    /// [`crate::materials::point::crack_base`]).
    pub latched: Vec<(usize, PointState)>,
    /// True once the crack branches were frozen in the current increment.
    pub frozen: bool,
    /// Some point was held on the plastic route in this increment.
    pub held_plastic: bool,
}

/// Joint integration points, per joint element.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointBlock {
    /// Point states.
    pub points: Staged<Vec<Vec<InterfacePointState>>>,
    /// Contact status (closed) of every point, per joint element, held for the rest of the
    /// increment once its Newton iterations cycled (`System::hold_contacts`); empty when
    /// nothing is held. It lasts one increment (released by commit, revert and
    /// `System::unlatch`), so it is empty between increments and not saved.
    #[serde(skip)]
    pub held: Vec<Vec<bool>>,
}

impl StateBlock for JointBlock {
    type Shape<'a> = ();

    /// Accept the trial states and release the held statuses (they last one increment).
    fn commit(&mut self) {
        self.points.commit();
        self.held.clear();
    }

    /// Back to the committed states; the held statuses are released.
    fn revert(&mut self) {
        self.points.revert();
        self.held.clear();
    }

    /// As many joint elements as the model, each with its number of points.
    fn check_shape(&self, saved: &Self, (): ()) -> Result<(), Mismatch> {
        let now = &self.points.committed;
        same_len("joint elements", &saved.points, now.len())?;
        for (a, b) in saved.points.committed.iter().zip(now) {
            same_count("joint points in an element", a.len(), b.len())?;
        }
        Ok(())
    }
}

/// External tendons (one entry per tendon of the model; None until stressed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TendonBlock {
    /// Displacements of each tendon's nodes when it was stressed [m].
    pub u0: Vec<Vec<[f64; 2]>>,
    /// Initial span strains in force (after relaxation) [-], one list per stressed tendon:
    /// the only copy, which the element is given at each response
    /// ([`crate::elements::tendon::InForce`]); set from the element's strains at stressing
    /// and by the relaxation at the start of each time increment (`analysis::time`).
    pub initial_strains: Vec<Vec<f64>>,
    /// Span states.
    pub states: Staged<Vec<Option<TendonState>>>,
    /// Relaxation and loss records (see `analysis::time`).
    pub time: Vec<Option<TendonTime>>,
}

impl StateBlock for TendonBlock {
    /// The number of nodes of each tendon of the model.
    type Shape<'a> = &'a [usize];

    /// Accept the trial span states and relaxation strains.
    fn commit(&mut self) {
        self.states.commit();
        self.relaxation_spans()
            .for_each(|s| s.relax_strain.commit());
    }

    /// Back to the committed span states and relaxation strains.
    fn revert(&mut self) {
        self.states.revert();
        self.relaxation_spans()
            .for_each(|s| s.relax_strain.revert());
    }

    /// One entry per tendon of the model; a stressed tendon has one displacement per node,
    /// one initial strain, span state and time record per span.
    fn check_shape(&self, saved: &Self, tendon_nodes: &[usize]) -> Result<(), Mismatch> {
        let n = tendon_nodes.len();
        same_len("tendons", &saved.states, n)?;
        same_count("tendon displacements", saved.u0.len(), n)?;
        same_count("tendon strains", saved.initial_strains.len(), n)?;
        same_count("tendon records", saved.time.len(), n)?;
        for (t, state) in saved.states.committed.iter().enumerate() {
            let Some(state) = state else { continue };
            let nodes = tendon_nodes[t];
            same_count("tendon nodes", saved.u0[t].len(), nodes)?;
            same_count("tendon spans", saved.initial_strains[t].len(), nodes - 1)?;
            same_count("tendon span states", state.spans.len(), nodes - 1)?;
            if let Some(rec) = &saved.time[t] {
                same_count("tendon span records", rec.spans.len(), nodes - 1)?;
            }
        }
        Ok(())
    }
}

impl TendonBlock {
    /// The time records of every span of every tendon that has them.
    fn relaxation_spans(&mut self) -> impl Iterator<Item = &mut SpanTime> {
        self.time
            .iter_mut()
            .flatten()
            .flat_map(|r| r.spans.iter_mut())
    }
}

/// Embedded bar points (order of `System::bar_gps`) and bar stages (order of the bars).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BarBlock {
    /// Steel states of the points.
    pub steel: Staged<Vec<SteelState>>,
    /// Point outputs.
    pub out: Staged<Vec<BarOutput>>,
    /// Stage of each bar: bars and pre-tensioned tendons are bonded from the start,
    /// post-tensioned tendons go through the stages at their steps.
    pub phase: Vec<BarPhase>,
    /// Bond strain of each point when it became bonded [-] (0 for bars bonded from the
    /// start): the bar strain is measured from it.
    pub eps_ref: Vec<f64>,
    /// Relaxation and loss records of the bonded-tendon points (None for plain bars and
    /// tendons not yet stressed; see `analysis::bonded_time`).
    pub time: Vec<Option<BarPointTime>>,
}

impl StateBlock for BarBlock {
    type Shape<'a> = ();

    /// Accept the trial steel states, outputs and relaxation strains.
    fn commit(&mut self) {
        self.steel.commit();
        self.out.commit();
        (self.time.iter_mut().flatten()).for_each(|r| r.relax_strain.commit());
    }

    /// Back to the committed steel states, outputs and relaxation strains.
    fn revert(&mut self) {
        self.steel.revert();
        self.out.revert();
        (self.time.iter_mut().flatten()).for_each(|r| r.relax_strain.revert());
    }

    /// As many bar points (states, outputs, reference strains, records) and bars as the
    /// model.
    fn check_shape(&self, saved: &Self, (): ()) -> Result<(), Mismatch> {
        let n = self.steel.committed.len();
        same_len("bar points", &saved.steel, n)?;
        same_len("bar outputs", &saved.out, n)?;
        same_count("bars", saved.phase.len(), self.phase.len())?;
        same_count("bar strains", saved.eps_ref.len(), n)?;
        same_count("bar records", saved.time.len(), n)
    }
}

/// Stage of an embedded bar or bonded tendon.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BarPhase {
    /// Post-tensioned tendon not yet stressed: absent.
    Inactive,
    /// Post-tensioned tendon stressed and locked off, duct not grouted: it loads the concrete
    /// with its lock-off stresses (the equivalent prestressing forces, seed eq. 24–26) and
    /// has no stiffness; its stress is held (changes of an ungrouted tendon are neglected).
    Locked,
    /// Bonded (perfect bond): stress from the bond strain measured since bonding plus the
    /// bonding stress.
    Bonded,
}

/// Values at one bar integration point for output.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct BarOutput {
    /// Total bar strain including the prestrain σ_b,0/E_s [-].
    pub strain: f64,
    /// Bar stress [Pa].
    pub stress: f64,
    /// Plastic strain [-].
    pub plastic_strain: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::state::layout::sample;

    /// Every staged pair of every block, the relaxation strains included: (committed,
    /// trial) values that tell whether a commit or revert reached them.
    fn pairs(f: &Families) -> Vec<(String, String)> {
        let d =
            |c: &dyn std::fmt::Debug, t: &dyn std::fmt::Debug| (format!("{c:?}"), format!("{t:?}"));
        let mut v = vec![
            d(&f.continuum.points.committed, &f.continuum.points.trial),
            d(&f.continuum.gauss.committed, &f.continuum.gauss.trial),
            d(&f.joints.points.committed, &f.joints.points.trial),
            d(&f.tendons.states.committed, &f.tendons.states.trial),
            d(&f.bars.steel.committed, &f.bars.steel.trial),
            d(&f.bars.out.committed, &f.bars.out.trial),
        ];
        for r in f.tendons.time.iter().flatten().flat_map(|r| &r.spans) {
            v.push(d(&r.relax_strain.committed, &r.relax_strain.trial));
        }
        for r in f.bars.time.iter().flatten() {
            v.push(d(&r.relax_strain.committed, &r.relax_strain.trial));
        }
        v
    }

    /// A state whose every trial copy differs from its committed one (the sample's
    /// relaxation strains already do: committed 3, trial 4).
    fn with_trials() -> Families {
        let mut f = sample().families.into_owned();
        f.continuum.points.trial[0] = PointState::Concrete(Box::default());
        f.continuum.gauss.trial[0].stress[0] = 99.0;
        f.joints.points.trial[0][0].slip = 99.0;
        f.tendons.states.trial[0] = None;
        f.bars.steel.trial[0].plastic_strain = 99.0;
        f.bars.out.trial[0].stress = 99.0;
        f.joints.held = vec![vec![true]];
        f
    }

    /// Revert reaches every pair (trial = committed, as before) and releases the holds;
    /// commit reaches every pair (committed = trial).
    #[test]
    fn commit_and_revert_reach_every_pair() {
        let before = pairs(&with_trials());
        assert!(before.iter().all(|(c, t)| c != t), "{before:?}");
        let mut f = with_trials();
        f.continuum.holds.frozen = true;
        f.revert();
        for ((c, t), (c0, _)) in pairs(&f).iter().zip(&before) {
            assert_eq!((c, t), (c0, c0));
        }
        assert!(!f.continuum.holds.frozen && f.joints.held.is_empty());
        let mut f = with_trials();
        f.commit();
        for ((c, t), (_, t0)) in pairs(&f).iter().zip(&before) {
            assert_eq!((c, t), (t0, t0));
        }
        assert!(f.joints.held.is_empty());
    }

    /// A saved tendon block that does not fit the model's tendons is refused, naming what
    /// differs; one that fits is accepted.
    #[test]
    fn tendon_sizes_are_checked() {
        let now = sample().families.into_owned().tendons;
        // The sample's one tendon: 2 nodes, 1 span.
        assert!(now.check_shape(&now, &[2]).is_ok());
        let e = now.check_shape(&now, &[2, 3]).unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 1 tendons, the model 2"),
            "{e}"
        );
        let e = now.check_shape(&now, &[3]).unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 2 tendon nodes, the model 3"),
            "{e}"
        );
        let mut saved = now.clone();
        saved.initial_strains[0].push(0.0);
        let e = now.check_shape(&saved, &[2]).unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 2 tendon spans, the model 1"),
            "{e}"
        );
        let mut saved = now.clone();
        saved.time[0].as_mut().unwrap().spans.clear();
        let e = now.check_shape(&saved, &[2]).unwrap_err();
        assert!(e.contains("0 tendon span records"), "{e}");
    }

    /// A continuum point whose kind of state differs from the model's is named.
    #[test]
    fn point_kinds_are_checked() {
        let now = sample().families.into_owned().continuum;
        let mut saved = now.clone();
        saved.points.committed.swap(0, 1);
        let e = now.check_shape(&saved, ()).unwrap_err();
        assert!(e.starts_with("material point 1 has another kind"), "{e}");
        saved.points.committed.pop();
        let e = now.check_shape(&saved, ()).unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 2 material points, the model 3"),
            "{e}"
        );
    }
}
