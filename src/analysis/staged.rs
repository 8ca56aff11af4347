//! The committed/trial pair every element family keeps its state in: Newton iterations write
//! the trial copy from the committed one, a converged increment commits it, a cut increment
//! reverts it. The two copies never alias.
//!
//! Only the committed copy is saved (checkpoints are written between increments, where the
//! trial copy equals it); reading one back sets both copies. The few pairs that format 10
//! of the checkpoint saved with both copies (relaxation strains, one-way contact statuses)
//! keep that layout through [`both`], so older checkpoints still read.
//!
//! A state block (one per element family, `analysis::families`) declares its staged pairs
//! once, in its [`StateBlock`] implementation: commit, revert and the size check of a saved
//! block against the model's all follow from it.

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

/// Lists from this many items are committed on all cores ([`Staged::commit_parallel`]).
const PARALLEL_COMMIT_MIN: usize = 65_536;

impl<E: Clone + Send + Sync> Staged<Vec<E>> {
    /// As [`Staged::commit`], a long list copied on all cores (at 5e5 dofs the material
    /// points and Gauss outputs of a million points, ~0.05 s on one core after every
    /// converged increment). The same values: item by item clones either way.
    pub fn commit_parallel(&mut self) {
        use rayon::prelude::*;
        if self.trial.len() < PARALLEL_COMMIT_MIN || self.trial.len() != self.committed.len() {
            return self.commit();
        }
        self.committed
            .par_iter_mut()
            .zip(self.trial.par_iter())
            .with_min_len(PARALLEL_COMMIT_MIN / 4)
            .for_each(|(c, t)| c.clone_from(t));
    }
}

/// A saved state that does not fit the model: what differs, in words ("the checkpoint has
/// 3 tendons, the model 2").
pub type Mismatch = String;

/// A part of the analysis state with committed/trial pairs: a family block, the
/// displacements, the construction stage. Implemented where the block is declared, so a new
/// field is committed, reverted and size-checked next to its declaration.
pub trait StateBlock {
    /// The sizes (and kinds) the model gives this block, against which a saved block is
    /// checked (e.g. the number of tendon nodes per tendon).
    type Shape<'a>;

    /// Accept the trial values (a converged increment).
    fn commit(&mut self);

    /// Throw the trial values away (a cut increment or a thrown-away attempt).
    fn revert(&mut self);

    /// Whether `saved` (read from a checkpoint) fits `self`, the block of the model as it
    /// is built now, of shape `shape`. The error names what differs.
    fn check_shape(&self, saved: &Self, shape: Self::Shape<'_>) -> Result<(), Mismatch>;
}

/// `Ok` when the saved count equals the model's, else the error naming `what`.
pub fn same_count(what: &str, saved: usize, now: usize) -> Result<(), Mismatch> {
    if saved == now {
        Ok(())
    } else {
        Err(format!(
            "the checkpoint has {saved} {what}, the model {now}: the model changed since the checkpoint was written"
        ))
    }
}

/// A list's committed and trial copies both as long as the model's (`now`).
pub fn same_len<E>(what: &str, saved: &Staged<Vec<E>>, now: usize) -> Result<(), Mismatch> {
    same_count(what, saved.committed.len(), now)?;
    same_count(what, saved.trial.len(), now)
}

/// Serde of a [`Staged`] field saved with both copies, committed then trial (the layout of
/// a pair of plain fields): `#[serde(with = "staged::both")]`.
pub mod both {
    use super::Staged;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Write the committed, then the trial copy.
    pub fn serialize<T: Serialize, S: Serializer>(v: &Staged<T>, s: S) -> Result<S::Ok, S::Error> {
        (&v.committed, &v.trial).serialize(s)
    }

    /// Read the committed, then the trial copy.
    pub fn deserialize<'de, T: Deserialize<'de>, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Staged<T>, D::Error> {
        let (committed, trial) = <(T, T)>::deserialize(d)?;
        Ok(Staged { committed, trial })
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

    /// The parallel commit of a long list gives the trial list, as the plain commit.
    #[test]
    fn parallel_commit_takes_the_trial_list() {
        let n = 3 * PARALLEL_COMMIT_MIN + 7;
        let mut s = Staged::new(vec![0.0_f64; n]);
        s.trial = (0..n).map(|i| (i as f64).sqrt()).collect();
        s.commit_parallel();
        assert_eq!(s.committed, s.trial);
        let mut short = Staged::new(vec![1u8; 10]);
        short.trial[3] = 7;
        short.commit_parallel();
        assert_eq!(short.committed, short.trial);
    }

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

    /// A pair saved with both copies is laid out as the two plain fields it replaced (the
    /// bytes of a struct of two f64 fields), and reads back both copies.
    #[test]
    fn both_copies_as_two_fields() {
        #[derive(Serialize, Deserialize, PartialEq, Debug)]
        struct Pair {
            #[serde(with = "both")]
            r: Staged<f64>,
        }
        #[derive(Serialize)]
        struct Plain {
            r: f64,
            r_trial: f64,
        }
        let p = Pair {
            r: Staged {
                committed: 1.5,
                trial: -2.25,
            },
        };
        let bytes = postcard::to_stdvec(&p).unwrap();
        let plain = Plain {
            r: 1.5,
            r_trial: -2.25,
        };
        assert_eq!(bytes, postcard::to_stdvec(&plain).unwrap());
        assert_eq!(postcard::from_bytes::<Pair>(&bytes).unwrap(), p);
    }

    /// The size checks name what differs and accept equal sizes.
    #[test]
    fn size_checks() {
        assert!(same_count("tendons", 2, 2).is_ok());
        let e = same_count("tendons", 3, 2).unwrap_err();
        assert!(
            e.starts_with("the checkpoint has 3 tendons, the model 2"),
            "{e}"
        );
        let mut s = Staged::new(vec![0; 4]);
        assert!(same_len("points", &s, 4).is_ok());
        s.trial.pop();
        assert!(same_len("points", &s, 4).is_err(), "a short trial copy");
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
