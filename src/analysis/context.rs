//! The analysis state a step works on while it runs: the system (with the displacements of
//! the attempt, `sys.disp.trial`), the solver, the load cases and factors, timings; and the
//! round of the one-way supports after an attempt has converged ([`super::one_way`]). Shared
//! by the increment controller (`increments.rs`) and the step drivers (`steps.rs`,
//! `path.rs`); the methods that assemble, report and follow the path are in `path.rs`.

use super::driver::Timings;
use super::one_way::MAX_ROUNDS;
use super::staged::StateBlock;
use super::system::System;
use crate::linalg::solver::SparseCholesky;

/// The analysis state a step works on (owned by `steps::run`).
pub(super) struct PathContext<'a, 's> {
    /// The system.
    pub sys: &'a mut System<'s>,
    /// The linear solver.
    pub solver: &'a mut SparseCholesky,
    /// Load vectors of the load cases at factor 1 (all dofs) [N].
    pub cases: &'a [Vec<f64>],
    /// Current load-case factors (updated).
    pub factors: &'a mut Vec<f64>,
    /// Timings and counters.
    pub timings: &'a mut Timings,
    /// Negative pivots at the last converged increment.
    pub neg_pivots: &'a mut usize,
    /// The IMPL-EX path error of the attempt being kept (energy norm [-], set by the
    /// increment controller before the step reports it; None where not measured).
    pub implex_error: Option<f64>,
}

impl PathContext<'_, '_> {
    /// Throw the trial state of an attempt away: the displacements back to the committed
    /// ones and the iteration's crack holds released.
    pub(super) fn back_to_committed(&mut self) {
        self.sys.disp.revert();
        self.sys.unlatch();
        if let Some(st) = self.sys.stages.as_mut() {
            st.revert_contacts();
        }
    }

    /// The one-way supports after an attempt converged at the trial displacements with
    /// internal forces `f_int` and external forces `f_ext` [N]: the trial statuses to solve it
    /// again with (one round more in `rounds`), or None when its statuses hold (or have
    /// chattered for [`MAX_ROUNDS`] rounds: then counted in `support_chatter` and kept).
    /// `rounds` is set back to 0 when None is returned.
    pub(super) fn one_way_check(
        &mut self,
        f_int: &[f64],
        f_ext: &[f64],
        rounds: &mut usize,
    ) -> Option<Vec<bool>> {
        let st = self.sys.stages.as_ref()?;
        if st.one_way.points.is_empty() {
            return None;
        }
        let size = crate::model::model_size(self.sys.model);
        let which = st
            .one_way
            .switches(&self.sys.disp.trial, f_int, f_ext, size);
        if which.is_empty() || *rounds >= MAX_ROUNDS {
            if !which.is_empty() {
                self.timings.support_chatter += 1;
            }
            *rounds = 0;
            return None;
        }
        *rounds += 1;
        self.timings.support_switches += 1;
        let mut next = st.one_way.clone();
        if self.sys.model.controls.verbose {
            let off = which
                .iter()
                .filter(|&&i| next.points[i].touching.trial)
                .count();
            eprintln!(
                "    one-way supports: {off} points lift off, {} touch down: the increment again (round {rounds})",
                which.len() - off
            );
        }
        next.switch(&which);
        Some(next.points.iter().map(|p| p.touching.trial).collect())
    }

    /// Start the attempt again (after its trial state was thrown away) with the one-way
    /// supports' trial statuses `trial`: the held equations follow them and the points touching down are put
    /// on their seats.
    pub(super) fn one_way_resume(&mut self, trial: &[bool]) {
        let Some(st) = self.sys.stages.as_mut() else {
            return;
        };
        for (p, &t) in st.one_way.points.iter_mut().zip(trial) {
            p.touching.trial = t;
        }
        st.apply_contacts();
        st.one_way.seat(&mut self.sys.disp.trial);
    }
}
