//! The analysis state saved in a checkpoint: everything a converged step leaves behind that
//! later increments read (displacements; committed material, joint, tendon, bar and time
//! states; the driver's load factors and clock). Restoring it gives the same arithmetic as
//! an uninterrupted run, so the results continue bit for bit.
//!
//! Trial copies, latched cracks and factorisations are not saved: at a step end the trial
//! states equal the committed ones, no crack is latched, and every factorisation is
//! recomputed from the same matrix.

use super::displacements::Displacements;
use super::families::Families;
use super::staged::StateBlock;
use super::stages::{StageShape, StageState};
use super::system::System;
use crate::materials::point::TimeContext;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

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

/// The committed state of a [`System`]: the displacements, the clock of the last increment,
/// the family blocks as they are ([`Families`]) and the construction stage. Declared once
/// for both uses: borrowed from the system for writing ([`SystemStateRef`],
/// [`System::state`]) and owned when read from a checkpoint or kept as a snapshot
/// ([`SystemState`]); the two encode alike (a `Cow` is saved as what it holds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedState<'a> {
    /// Displacements (all dofs) [m].
    pub u: Cow<'a, [f64]>,
    /// Displacements before the last committed increment [m].
    pub u_prev: Cow<'a, [f64]>,
    /// Time interval of the last increment [d].
    pub time: TimeContext,
    /// The element families' states.
    pub families: Cow<'a, Families>,
    /// The construction stage reached (None: the model has no stages).
    pub stages: Option<Cow<'a, StageState>>,
}

/// The committed state of a [`System`], owned (read from a checkpoint, or a snapshot).
pub type SystemState = SavedState<'static>;

/// The committed state of a [`System`], borrowed for writing.
pub type SystemStateRef<'a> = SavedState<'a>;

impl System<'_> {
    /// The committed state, borrowed (call between increments).
    pub fn state(&self) -> SystemStateRef<'_> {
        SavedState {
            u: Cow::Borrowed(&self.disp.committed),
            u_prev: Cow::Borrowed(&self.disp.previous),
            time: self.time,
            families: Cow::Borrowed(&self.families),
            stages: self.stages.as_ref().map(Cow::Borrowed),
        }
    }

    /// The committed state, owned (for a time-substep pair that may be rejected and
    /// restored with [`System::restore`]).
    pub(crate) fn snapshot(&self) -> SystemState {
        let s = self.state();
        SavedState {
            u: Cow::Owned(s.u.into_owned()),
            u_prev: Cow::Owned(s.u_prev.into_owned()),
            time: s.time,
            families: Cow::Owned(s.families.into_owned()),
            stages: s.stages.map(|st| Cow::Owned(st.into_owned())),
        }
    }

    /// Replace the committed (and trial) states by a saved state of the same model. Errors
    /// name what does not match (the model changed since the state was saved): each block
    /// checks its own sizes ([`StateBlock::check_shape`]). The trial displacements equal the
    /// committed ones after it.
    pub fn restore(&mut self, s: SystemState) -> Result<(), String> {
        let n_dofs = self.disp.committed.len();
        let disp = Displacements::saved(s.u.into_owned(), s.u_prev.into_owned());
        self.disp.check_shape(&disp, n_dofs)?;
        self.families.check_shape(&s.families, self.model)?;
        match (&s.stages, &self.stages) {
            (Some(saved), Some(now)) => {
                let shape = StageShape {
                    model: self.model,
                    n_eq: self.dofs.n_eq,
                    n_dofs,
                };
                now.check_shape(saved, shape)?;
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
        // The tendon elements are rebuilt on the geometry they were stressed on (the initial
        // strains in force are the block's).
        let tb = &s.families.tendons;
        for t in 0..self.tendons.len() {
            self.tendons[t] =
                (tb.states.committed[t].as_ref()).map(|_| self.build_tendon(t, &tb.u0[t]));
        }
        self.disp = disp;
        self.time = s.time;
        self.families = s.families.into_owned();
        if let Some(st) = s.stages {
            self.stages = Some(st.into_owned());
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
    use crate::materials::point::{AgeingState, PointState};
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
        SavedState {
            u: Cow::Owned(vec![1.0, 2.0]),
            u_prev: Cow::Owned(vec![3.0, 4.0]),
            time: TimeContext {
                t_from: 1.0,
                t_to: 2.0,
                extrapolation: 0.5,
            },
            families: Cow::Owned(Families {
                continuum: ContinuumBlock {
                    points: Staged::new(vec![
                        PointState::Elastic,
                        PointState::Concrete(Box::default()),
                        PointState::Ageing(Box::new(AgeingState {
                            chain: ChainState {
                                hidden: vec![[1.0, 2.0, 3.0]],
                            },
                            strain: [4.0, 5.0, 6.0],
                        })),
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
            }),
            stages: Some(Cow::Owned(StageState {
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
            })),
        }
    }

    /// The writer's view of `s`.
    pub(crate) fn as_ref(s: &SystemState) -> SystemStateRef<'_> {
        SavedState {
            u: Cow::Borrowed(&s.u),
            u_prev: Cow::Borrowed(&s.u_prev),
            time: s.time,
            families: Cow::Borrowed(&s.families),
            stages: s.stages.as_deref().map(Cow::Borrowed),
        }
    }

    /// What is written can be read back, equal: the borrowed form writes what the owned one
    /// reads.
    #[test]
    fn writer_and_reader_agree() {
        let s = sample();
        let bytes = postcard::to_stdvec(&as_ref(&s)).unwrap();
        let back: SystemState = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(back, s);
    }
}
