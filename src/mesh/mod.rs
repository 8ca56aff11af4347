//! Meshes: nodes, elements and regions; generators and readers.
pub mod gmsh;
