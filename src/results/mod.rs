//! Results: monitors recorded at converged increments, field recovery, and writers.

pub mod atomic;
pub mod fields;
pub mod recorder;
pub mod vtu;
pub mod joints;
