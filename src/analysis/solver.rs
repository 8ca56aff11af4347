//! The one linear-solver interface of segfem: a symmetric sparse matrix in compressed-column
//! form (lower triangle), symbolic analysis (AMD ordering) once per pattern, numeric
//! factorisation per iteration, solve. faer's supernodal/simplicial Cholesky does the work.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

/// Why a factorisation or solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The matrix is not positive definite: a mechanism, or a limit point of the response.
    #[error("stiffness matrix is not positive definite (pivot at equation {equation})")]
    NotPositiveDefinite {
        /// Equation (free dof) index in the original numbering.
        equation: usize,
    },
    /// Out of memory or another failure inside the sparse library.
    #[error("sparse factorisation failed: {0}")]
    Internal(String),
}

/// Compressed sparse column pattern of the lower triangle of a symmetric matrix.
#[derive(Debug, Clone)]
pub struct LowerPattern {
    /// Matrix order.
    pub n: usize,
    /// Column pointers (length n + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column, all ≥ the column index.
    pub row_idx: Vec<usize>,
}

impl LowerPattern {
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry (i, j) with i ≥ j in the value array, if stored.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|p| a + p)
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    /// y = A x for the symmetric matrix whose lower triangle has `values`.
    pub fn sym_mul(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..self.n {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[p];
                y[i] += values[p] * x[j];
                if i != j {
                    y[j] += values[p] * x[i];
                }
            }
        }
    }
}

/// Timing and size figures of the solver, for summaries and benchmarks.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SolverStats {
    /// Seconds spent in ordering and symbolic factorisation.
    pub symbolic_s: f64,
    /// Seconds spent in numeric factorisations (all of them).
    pub numeric_s: f64,
    /// Seconds spent in forward/back substitution.
    pub solve_s: f64,
    /// Number of numeric factorisations.
    pub factorisations: usize,
    /// Stored values of the factor.
    pub factor_nnz: usize,
}

/// Sparse symmetric positive-definite solver with a reusable symbolic factorisation.
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    factored: bool,
    /// Accumulated timings.
    pub stats: SolverStats,
}

impl SparseCholesky {
    /// Ordering (AMD) and symbolic analysis of `pattern`; done once per pattern.
    pub fn new(pattern: &LowerPattern) -> Result<Self, SolverError> {
        let t = std::time::Instant::now();
        let symbolic = factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SolverError::Internal(format!("{e:?}")))?;
        let req = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let mem = MemBuffer::try_new(req).map_err(|e| SolverError::Internal(format!("{e:?}")))?;
        let l_values = vec![0.0; symbolic.len_val()];
        let stats = SolverStats {
            symbolic_s: t.elapsed().as_secs_f64(),
            factor_nnz: symbolic.len_val(),
            ..Default::default()
        };
        Ok(Self {
            symbolic,
            l_values,
            mem,
            factored: false,
            stats,
        })
    }

    /// Numeric factorisation of the matrix with the analysed pattern and these values.
    pub fn factorize(&mut self, pattern: &LowerPattern, values: &[f64]) -> Result<(), SolverError> {
        let t = std::time::Instant::now();
        self.factored = false;
        let a = SparseColMatRef::new(pattern.symbolic(), values);
        let stack = MemStack::new(&mut self.mem);
        let res = self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            a,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        );
        self.stats.numeric_s += t.elapsed().as_secs_f64();
        self.stats.factorisations += 1;
        match res {
            Ok(_) => {
                self.factored = true;
                Ok(())
            }
            Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => {
                // faer reports simplicial pivots 1-based and supernodal ones 0-based, in the
                // permuted order; map back to the original equation.
                let index = match self.symbolic.raw() {
                    SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                    SymbolicCholeskyRaw::Supernodal(_) => index,
                }
                .min(pattern.n.saturating_sub(1));
                let equation = match self.symbolic.perm() {
                    Some(p) => p.arrays().0[index],
                    None => index,
                };
                Err(SolverError::NotPositiveDefinite { equation })
            }
        }
    }

    /// Solve A x = b in place (b is overwritten by x). Requires a successful `factorize`.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        assert!(self.factored, "solve called without a valid factorisation");
        let t = std::time::Instant::now();
        let n = b.len();
        let llt = LltRef::new(&self.symbolic, &self.l_values);
        let stack = MemStack::new(&mut self.mem);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, n, 1),
            Par::Seq,
            stack,
        );
        self.stats.solve_s += t.elapsed().as_secs_f64();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1-D Laplacian (tridiagonal 2, −1): solution of A x = e checked through the residual.
    #[test]
    fn solves_a_tridiagonal_system() {
        let n = 50;
        let mut col_ptr = vec![0];
        let mut row_idx = vec![];
        let mut vals = vec![];
        for j in 0..n {
            row_idx.push(j);
            vals.push(2.0);
            if j + 1 < n {
                row_idx.push(j + 1);
                vals.push(-1.0);
            }
            col_ptr.push(row_idx.len());
        }
        let p = LowerPattern {
            n,
            col_ptr,
            row_idx,
        };
        let mut s = SparseCholesky::new(&p).unwrap();
        s.factorize(&p, &vals).unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        let mut ax = vec![0.0; n];
        p.sym_mul(&vals, &x, &mut ax);
        // Condition number ~ n², so round-off residual ~1e-12 is generous.
        for i in 0..n {
            assert!((ax[i] - b[i]).abs() < 1e-10);
        }
    }

    /// A singular matrix (zero row) is reported, not solved.
    #[test]
    fn reports_non_positive_pivot() {
        let p = LowerPattern {
            n: 2,
            col_ptr: vec![0, 1, 2],
            row_idx: vec![0, 1],
        };
        let mut s = SparseCholesky::new(&p).unwrap();
        let err = s.factorize(&p, &[1.0, 0.0]).unwrap_err();
        assert_eq!(err, SolverError::NotPositiveDefinite { equation: 1 });
    }
}
