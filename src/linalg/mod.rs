//! Sparse linear algebra below the analysis: the symmetric solver (faer Cholesky LLᵀ with
//! symbolic reuse, LDLᵀ with its negative-pivot count), the factorisation by halves on two
//! cores, and the fill-reducing orderings by geometric nested dissection. Knows nothing of
//! the analysis, its states or its drivers: it takes matrices in lower compressed columns,
//! coordinates and element node lists.

pub mod ordering;
pub mod pattern;
pub mod solver;
mod split;
