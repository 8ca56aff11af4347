//! Finite-element building blocks: quadrature, shape functions, dof numbering, sparse pattern and assembly.

pub mod assembly;
pub mod dofs;
pub mod kinds;
pub mod numbering;
pub mod quadrature;
pub mod shape;
