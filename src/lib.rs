//! segfem: finite element analysis of precast segmental concrete members with bonded and
//! external (unbonded) prestressing, in plane stress, from service load to failure and over
//! time. The method follows Ribeiro, Campos Filho & Pacheco, "Finite Element Model for
//! Segmental Structures", Rev. IBRACON Estrut. 2(2), 2006.
//!
//! Data flows one way: input → validated [`model`] → mesh and dofs → analysis → results →
//! writers.

#![warn(missing_docs)]

pub mod analysis;
pub mod design;
pub mod elements;
pub mod fem;
pub mod input;
pub mod linalg;
pub mod materials;
pub mod mesh;
pub mod model;
pub mod prestress;
pub mod results;
pub mod run;
pub mod traffic;
pub mod view;
