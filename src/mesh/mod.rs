//! Meshes: nodes, elements and regions; generators and readers.

pub mod banded;
pub mod gmsh;
pub mod segmental;
