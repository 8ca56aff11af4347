//! The displacements as a state block: the Newton iterate of the increment under way (the
//! trial), the last converged displacements (committed) and the ones converged before them
//! (previous). The extrapolated start of the next increment and the arc-length sign read
//! the last converged increment, committed − previous; a checkpoint saves those two.
//!
//! The trial lives in [`super::system::System`] beside the states it is assembled with:
//! the drivers move it (`System::disp`), [`super::system::System::assemble_trial`] reads it
//! in place, and a converged increment commits it with the family blocks.

use super::staged::{same_count, Mismatch, StateBlock};
use crate::fem::dofs::CONSTRAINED;

/// Trial, committed and previous displacements (all dofs, x and y per node) [m].
#[derive(Debug, Clone, PartialEq)]
pub struct Displacements {
    /// The iterate of the increment under way (all dofs) [m].
    pub trial: Vec<f64>,
    /// Displacements at the end of the last converged increment [m].
    pub committed: Vec<f64>,
    /// Displacements at the end of the increment before it [m].
    pub previous: Vec<f64>,
}

impl Displacements {
    /// All three zero, `n_dofs` long.
    pub fn zero(n_dofs: usize) -> Self {
        Self::saved(vec![0.0; n_dofs], vec![0.0; n_dofs])
    }

    /// The block of a saved state (committed and previous [m]); the trial equals the
    /// committed displacements.
    pub fn saved(committed: Vec<f64>, previous: Vec<f64>) -> Self {
        Self {
            trial: committed.clone(),
            committed,
            previous,
        }
    }

    /// Add `scale` × the free-equation vector `du` [m] to the trial, through the equation
    /// numbers `eq` of the dofs (constrained dofs stay).
    pub fn add_free(&mut self, eq: &[usize], du: &[f64], scale: f64) {
        for (d, &q) in eq.iter().enumerate() {
            if q != CONSTRAINED {
                self.trial[d] += scale * du[q];
            }
        }
    }
}

impl StateBlock for Displacements {
    /// The model's number of dofs.
    type Shape<'a> = usize;

    /// previous ← committed ← trial (the previous vector's memory is reused for the
    /// committed one: one copy).
    fn commit(&mut self) {
        std::mem::swap(&mut self.committed, &mut self.previous);
        self.committed.copy_from_slice(&self.trial);
    }

    /// trial ← committed.
    fn revert(&mut self) {
        self.trial.copy_from_slice(&self.committed);
    }

    fn check_shape(&self, saved: &Self, n_dofs: usize) -> Result<(), Mismatch> {
        same_count("displacements (dofs)", saved.committed.len(), n_dofs)?;
        same_count(
            "previous displacements (dofs)",
            saved.previous.len(),
            n_dofs,
        )?;
        same_count("trial displacements (dofs)", saved.trial.len(), n_dofs)
    }
}

/// The displacements an assembly is made at ([`super::system::System::assemble_at`]).
#[derive(Debug, Clone, Copy)]
pub enum At<'u> {
    /// The trial displacements, `disp.trial` (the Newton iterate).
    Trial,
    /// The committed displacements, `disp.committed`.
    Committed,
    /// Displacements the caller holds (a line-search point, an influence probe; all dofs)
    /// [m].
    Given(&'u [f64]),
}

impl<'u> At<'u> {
    /// The displacements this names, taken from the block `disp` [m].
    pub fn of<'s>(self, disp: &'s Displacements) -> &'s [f64]
    where
        'u: 's,
    {
        match self {
            At::Trial => &disp.trial,
            At::Committed => &disp.committed,
            At::Given(u) => u,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Commit shifts committed to previous and takes the trial, revert goes back to the
    /// committed values, and no two copies alias afterwards.
    #[test]
    fn commit_shifts_and_revert_returns() {
        let mut d = Displacements::zero(3);
        d.trial = vec![1.0, 2.0, 3.0];
        d.commit();
        assert_eq!(d.committed, vec![1.0, 2.0, 3.0]);
        assert_eq!(d.previous, vec![0.0; 3]);
        d.trial[1] = 5.0;
        d.commit();
        assert_eq!(d.committed, vec![1.0, 5.0, 3.0]);
        assert_eq!(d.previous, vec![1.0, 2.0, 3.0], "the last committed");
        d.trial[0] = -4.0;
        assert_eq!(d.committed[0], 1.0, "trial edits after commit stay trial");
        d.revert();
        assert_eq!(d.trial, vec![1.0, 5.0, 3.0]);
        assert_eq!(d.previous, vec![1.0, 2.0, 3.0], "revert leaves previous");
        d.trial[2] = 9.0;
        assert_eq!((d.committed[2], d.previous[2]), (3.0, 3.0));
    }

    /// The free-equation correction goes to the free dofs' equations, scaled.
    #[test]
    fn free_corrections_skip_constrained_dofs() {
        let mut d = Displacements::zero(3);
        d.add_free(&[1, CONSTRAINED, 0], &[10.0, 20.0], 0.5);
        assert_eq!(d.trial, vec![10.0, 0.0, 5.0]);
        assert_eq!(d.committed, vec![0.0; 3]);
    }

    /// A saved block of the model's dof count fits; one of another count is refused with
    /// the vector and both counts named.
    #[test]
    fn shape_check_names_the_vector() {
        let now = Displacements::zero(4);
        assert!(now.check_shape(&Displacements::zero(4), 4).is_ok());
        let e = now
            .check_shape(&Displacements::saved(vec![0.0; 6], vec![0.0; 6]), 4)
            .unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 6 displacements (dofs), the model 4"),
            "{e}"
        );
        let e = now
            .check_shape(&Displacements::saved(vec![0.0; 4], vec![0.0; 3]), 4)
            .unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 3 previous displacements (dofs), the model 4"),
            "{e}"
        );
        let mut short_trial = Displacements::zero(4);
        short_trial.trial.pop();
        let e = now.check_shape(&short_trial, 4).unwrap_err();
        assert!(e.contains("3 trial displacements (dofs)"), "{e}");
    }
}
