//! Finite-element building blocks: quadrature, shape functions, dof numbering and assembly.

pub mod assembly;
pub mod dofs;
pub mod quadrature;
pub mod shape;
