//! The committed/trial pair every element family keeps its state in: Newton iterations write
//! the trial copy from the committed one, a converged increment commits it, a cut increment
//! reverts it. The two copies never alias.
//!
//! Only the committed copy is saved (checkpoints are written between increments, where the
//! trial copy equals it); reading one back sets both copies.

use serde::{Deserialize, Serialize, Serializer};

/// A committed value and the trial value of the increment under way.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(from = "T", bound(deserialize = "T: Deserialize<'de> + Clone"))]
pub struct Staged<T> {
    /// Value at the end of the last converged increment.
    pub committed: T,
    /// Value of the last trial (iteration) of the current increment.
    pub trial: T,
}

impl<T: Clone> Staged<T> {
    /// Both copies set to `value`.
    pub fn new(value: T) -> Self {
        Self {
            trial: value.clone(),
            committed: value,
        }
    }

    /// Accept the trial value (end of a converged increment); the trial copy stays equal to
    /// it.
    pub fn commit(&mut self) {
        self.committed.clone_from(&self.trial);
    }

    /// Throw the trial value away (a cut increment, or a restore).
    pub fn revert(&mut self) {
        self.trial.clone_from(&self.committed);
    }
}

impl<T: Clone> From<T> for Staged<T> {
    fn from(value: T) -> Self {
        Self::new(value)
    }
}

impl<T: Serialize> Serialize for Staged<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.committed.serialize(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Commit takes the trial value, revert restores the committed one, and neither copy
    /// aliases the other afterwards.
    #[test]
    fn commit_and_revert() {
        let mut s = Staged::new(vec![1.0, 2.0]);
        s.trial[0] = 5.0;
        assert_eq!(s.committed, vec![1.0, 2.0]);
        s.commit();
        assert_eq!(s.committed, vec![5.0, 2.0]);
        s.trial[1] = 7.0;
        assert_eq!(
            s.committed,
            vec![5.0, 2.0],
            "trial edits after commit stay trial"
        );
        s.revert();
        assert_eq!(s.trial, vec![5.0, 2.0]);
    }

    /// Saved: the committed copy only; read back: both copies equal to it.
    #[test]
    fn saves_the_committed_copy() {
        let mut s = Staged::new(vec![1.0_f64, -0.0, f64::NAN]);
        s.trial = vec![9.0; 3];
        let bytes = postcard::to_stdvec(&s).unwrap();
        assert_eq!(bytes, postcard::to_stdvec(&s.committed).unwrap());
        let back: Staged<Vec<f64>> = postcard::from_bytes(&bytes).unwrap();
        // Bit patterns: -0.0 and NaN must survive.
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.committed), bits(&s.committed));
        assert_eq!(bits(&back.trial), bits(&s.committed));
    }
}
