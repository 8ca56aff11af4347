//! Finite-element building blocks: quadrature, shape functions, dof numbering and assembly.

pub mod quadrature;
pub mod shape;
