//! Meshes: nodes, elements and regions; generators and readers; bar paths cut through a mesh.

pub mod banded;
pub mod embed;
pub mod gmsh;
pub mod segmental;
