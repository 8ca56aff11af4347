//! Meshes: nodes, elements and regions; generators and readers.
