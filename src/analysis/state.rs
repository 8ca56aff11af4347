//! The analysis state saved in a checkpoint: everything a converged step leaves behind that
//! later increments read (displacements; committed material, joint, tendon, bar and time
//! states; the driver's load factors and clock). Restoring it gives the same arithmetic as
//! an uninterrupted run, so the results continue bit for bit.
//!
//! Trial copies, latched cracks and factorisations are not saved: at a step end the trial
//! states equal the committed ones, no crack is latched, and every factorisation is
//! recomputed from the same matrix.

use super::families::Families;
use super::stages::StageState;
use super::system::System;
use crate::materials::point::TimeContext;
use serde::{Deserialize, Serialize};

/// Where the step driver stands between two steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriverState {
    /// Index of the next step to run (0-based; = number of steps when done).
    pub next_step: usize,
    /// Load-case factors reached [-].
    pub factors: Vec<f64>,
    /// Analysis clock [d].
    pub clock: f64,
    /// Negative pivots at the last converged increment (limit-point detection) [-].
    pub neg_pivots: usize,
    /// Negative pivots of the solver's last factorisation [-].
    pub solver_negative_pivots: usize,
    /// Converged increments so far.
    pub increments: usize,
    /// Newton iterations so far.
    pub iterations: usize,
    /// Limit points passed so far (messages).
    pub limit_points: Vec<String>,
}

/// The committed state of a [`System`] (owned; read from a checkpoint): the displacements,
/// the clock of the last increment and the family blocks as they are ([`Families`]).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct SystemState {
    /// Displacements (all dofs) [m].
    pub u: Vec<f64>,
    /// Displacements before the last committed increment [m].
    pub u_prev: Vec<f64>,
    /// Time interval of the last increment [d].
    pub time: TimeContext,
    /// The element families' states.
    pub families: Families,
    /// The construction stage reached (None: the model has no stages).
    pub stages: Option<StageState>,
}

/// The committed state of a [`System`], borrowed for writing: the fields of
/// [`SystemState`] in the same order (a test reads one back as the other).
#[derive(Serialize)]
pub struct SystemStateRef<'a> {
    u: &'a [f64],
    u_prev: &'a [f64],
    time: TimeContext,
    families: &'a Families,
    stages: Option<&'a StageState>,
}

impl System<'_> {
    /// The committed state, borrowed (call between increments).
    pub fn state(&self) -> SystemStateRef<'_> {
        SystemStateRef {
            u: &self.u,
            u_prev: &self.u_prev,
            time: self.time,
            families: &self.families,
            stages: self.stages.as_ref(),
        }
    }

    /// The committed state, owned (for a time-substep pair that may be rejected and
    /// restored with [`System::restore`]).
    pub(crate) fn snapshot(&self) -> SystemState {
        SystemState {
            u: self.u.clone(),
            u_prev: self.u_prev.clone(),
            time: self.time,
            families: self.families.clone(),
            stages: self.stages.clone(),
        }
    }

    /// Replace the committed (and trial) states by a saved state of the same model. Errors
    /// name what does not match (the model changed since the state was saved).
    pub fn restore(&mut self, s: SystemState) -> Result<(), String> {
        let check = |what: &str, saved: usize, now: usize| {
            if saved == now {
                Ok(())
            } else {
                Err(format!(
                    "the checkpoint has {saved} {what}, the model {now}: the model changed since the checkpoint was written"
                ))
            }
        };
        let (new, old) = (&s.families, &self.families);
        check("dofs", s.u.len(), self.u.len())?;
        check("dofs (previous)", s.u_prev.len(), self.u_prev.len())?;
        let (nc, oc) = (&new.continuum, &old.continuum);
        check(
            "material points",
            nc.points.committed.len(),
            oc.points.committed.len(),
        )?;
        check(
            "Gauss outputs",
            nc.gauss.committed.len(),
            oc.gauss.committed.len(),
        )?;
        let (nj, oj) = (&new.joints.points.committed, &old.joints.points.committed);
        check("joint elements", nj.len(), oj.len())?;
        for (a, b) in nj.iter().zip(oj) {
            check("joint points in an element", a.len(), b.len())?;
        }
        let (nt, ot) = (&new.tendons, &old.tendons);
        check(
            "tendons",
            nt.states.committed.len(),
            ot.states.committed.len(),
        )?;
        check("tendon displacements", nt.u0.len(), ot.u0.len())?;
        check(
            "tendon strains",
            nt.initial_strains.len(),
            ot.initial_strains.len(),
        )?;
        check("tendon records", nt.time.len(), ot.time.len())?;
        let (nb, ob) = (&new.bars, &old.bars);
        check(
            "bar points",
            nb.steel.committed.len(),
            ob.steel.committed.len(),
        )?;
        check(
            "bar outputs",
            nb.out.committed.len(),
            ob.out.committed.len(),
        )?;
        check("bars", nb.phase.len(), ob.phase.len())?;
        check("bar strains", nb.eps_ref.len(), ob.eps_ref.len())?;
        check("bar records", nb.time.len(), ob.time.len())?;
        if let Some(p) = nc
            .points
            .committed
            .iter()
            .zip(&oc.points.committed)
            .position(|(a, b)| std::mem::discriminant(a) != std::mem::discriminant(b))
        {
            return Err(format!(
                "material point {} has another kind of state in the checkpoint than in the model: the model changed since the checkpoint was written",
                p + 1
            ));
        }
        for (t, saved) in nt.states.committed.iter().enumerate() {
            let Some(saved) = saved else { continue };
            let n = self.model.tendons[t].nodes.len();
            check("tendon nodes", nt.u0[t].len(), n)?;
            check("tendon spans", nt.initial_strains[t].len(), n - 1)?;
            check("tendon span states", saved.spans.len(), n - 1)?;
        }
        // The tendon elements are rebuilt on the geometry they were stressed on, with the
        // initial strains they had.
        for t in 0..self.tendons.len() {
            self.tendons[t] = s.families.tendons.states.committed[t].as_ref().map(|_| {
                let tb = &s.families.tendons;
                let mut el = self.build_tendon(t, &tb.u0[t]);
                el.set_initial_strains(&tb.initial_strains[t]);
                el
            });
        }
        match (&s.stages, &self.stages) {
            (Some(st), Some(_)) => {
                check("staged elements", st.element_active.len(), self.model.elements.len())?;
                check(
                    "staged element references",
                    st.element_ref.len(),
                    self.model.elements.len(),
                )?;
                check(
                    "staged joint elements",
                    st.interface_active.len(),
                    self.model.interfaces.len(),
                )?;
                check(
                    "staged joint references",
                    st.interface_ref.len(),
                    self.model.interfaces.len(),
                )?;
                check("staged equations", st.held.len(), self.dofs.n_eq)?;
                check("staged releases", st.release.len(), self.u.len())?;
                check("staged base equations", st.base_held.len(), self.dofs.n_eq)?;
                let one_way = self.model.staging.has_one_way();
                if st.step.is_some() && one_way == st.one_way.points.is_empty() {
                    return Err(
                        "the checkpoint and the model differ in their one-way supports: the model changed since the checkpoint was written".into(),
                    );
                }
            }
            (None, None) => {}
            (saved, _) => {
                return Err(format!(
                    "the checkpoint {} construction stages, the model {}: the model changed since the checkpoint was written",
                    if saved.is_some() { "has" } else { "has no" },
                    if saved.is_some() { "none" } else { "has" },
                ))
            }
        }
        self.u = s.u;
        self.u_prev = s.u_prev;
        self.time = s.time;
        self.families = s.families;
        if s.stages.is_some() {
            self.stages = s.stages;
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod layout {
    //! A state with one of everything (every family, every point-state kind, every optional
    //! record present), for the checkpoint layout test: its encoding changes whenever a
    //! saved type gains, loses or reorders a field.

    use super::*;
    use crate::analysis::families::*;
    use crate::analysis::staged::Staged;
    use crate::analysis::tendon_time::BarPointTime;
    use crate::analysis::tendon_time::{SpanTime, TendonTime};
    use crate::elements::continuum::GaussOutput;
    use crate::elements::interface::InterfacePointState;
    use crate::elements::tendon::{SpanState, TendonState};
    use crate::materials::chain::{ChainState, SteelRelaxationChain};
    use crate::materials::point::PointState;
    use crate::materials::steel::SteelState;

    /// The sample state.
    pub(crate) fn sample() -> SystemState {
        let chain = SteelRelaxationChain {
            ep: 1.95e11,
            taus: vec![1.0, f64::INFINITY],
            fractions: vec![0.25, 0.75],
        };
        let joint = InterfacePointState {
            plastic_slip: 1.0,
            bonded: true,
            closed: true,
            sliding: false,
            lambda: 2.0,
            slip: 3.0,
            normal_stress: 4.0,
            shear_stress: 5.0,
            position: [6.0, 7.0],
            arc: 8.0,
        };
        let span = SpanState {
            strain: 1.0,
            stress: 2.0,
            force: 3.0,
            length: 4.0,
            law: SteelState::default(),
        };
        let span_time = SpanTime {
            sigma_initial: 1.0,
            eps0: 2.0,
            relax_strain: Staged {
                committed: 3.0,
                trial: 4.0,
            },
            steel_strain: 5.0,
            hidden: vec![6.0],
            relax_drop: 7.0,
            loss_elastic: 8.0,
            loss_creep: 9.0,
            loss_relax: 10.0,
        };
        let bar_time = BarPointTime {
            sigma_initial: 1.0,
            stress: 2.0,
            relax_strain: Staged {
                committed: 3.0,
                trial: 4.0,
            },
            steel_strain: 5.0,
            chain: Some(chain.clone()),
            hidden: vec![6.0],
            relax_drop: 7.0,
            loss_elastic: 8.0,
            loss_creep: 9.0,
            loss_relax: 10.0,
        };
        SystemState {
            u: vec![1.0, 2.0],
            u_prev: vec![3.0, 4.0],
            time: TimeContext {
                t_from: 1.0,
                t_to: 2.0,
                extrapolation: 0.5,
            },
            families: Families {
                continuum: ContinuumBlock {
                    points: Staged::new(vec![
                        PointState::Elastic,
                        PointState::Concrete(Box::default()),
                        PointState::Ageing {
                            chain: ChainState {
                                hidden: vec![[1.0, 2.0, 3.0]],
                            },
                            strain: [4.0, 5.0, 6.0],
                        },
                    ]),
                    // The elastic point's outputs are not saved (read back as zero).
                    gauss: Staged::new(vec![
                        GaussOutput::default(),
                        GaussOutput {
                            strain: [1.0, 2.0, 3.0],
                            stress: [4.0, 5.0, 6.0],
                        },
                        GaussOutput {
                            strain: [7.0, 8.0, 9.0],
                            stress: [10.0, 11.0, 12.0],
                        },
                    ]),
                    holds: Holds::default(),
                },
                joints: JointBlock {
                    points: Staged::new(vec![vec![joint]]),
                    held: Vec::new(),
                },
                tendons: TendonBlock {
                    u0: vec![vec![[1.0, 2.0], [3.0, 4.0]]],
                    initial_strains: vec![vec![5.0]],
                    states: Staged::new(vec![Some(TendonState {
                        spans: vec![span],
                        slips: vec![1.0],
                        slipping: vec![-1],
                    })]),
                    time: vec![Some(TendonTime {
                        spans: vec![span_time],
                        chains: vec![Some(chain)],
                        lengths: vec![1.0],
                    })],
                },
                bars: BarBlock {
                    steel: Staged::new(vec![SteelState::default()]),
                    out: Staged::new(vec![BarOutput::default()]),
                    phase: vec![BarPhase::Inactive, BarPhase::Locked, BarPhase::Bonded],
                    eps_ref: vec![1.0],
                    time: vec![Some(bar_time)],
                },
            },
            stages: Some(StageState {
                step: Some(1),
                element_active: vec![true, false],
                element_ref: vec![None, Some(vec![1.0, 2.0])],
                interface_active: vec![true],
                interface_ref: vec![Some(vec![3.0, 4.0])],
                held: vec![false, true],
                release: vec![5.0, 6.0],
                base_held: vec![false, false],
                one_way: crate::analysis::one_way::OneWay {
                    points: vec![crate::analysis::one_way::ContactPoint {
                        support: 0,
                        node: 1,
                        dof: 3,
                        eq: 1,
                        sign: -1.0,
                        seat: 7.0,
                        acting: true,
                        touching: Staged::new(false),
                    }],
                },
            }),
        }
    }

    /// The writer's view of `s`.
    pub(crate) fn as_ref(s: &SystemState) -> SystemStateRef<'_> {
        SystemStateRef {
            u: &s.u,
            u_prev: &s.u_prev,
            time: s.time,
            families: &s.families,
            stages: s.stages.as_ref(),
        }
    }

    /// What is written can be read back, equal: the borrowed writer and the owned reader
    /// agree field for field.
    #[test]
    fn writer_and_reader_agree() {
        let s = sample();
        let bytes = postcard::to_stdvec(&as_ref(&s)).unwrap();
        let back: SystemState = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(back, s);
    }
}
