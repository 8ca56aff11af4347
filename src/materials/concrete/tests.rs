//! Material-point tests of the concrete model.
