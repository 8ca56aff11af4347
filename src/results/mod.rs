//! Results: monitors recorded at converged increments, field recovery, and writers.

pub mod atomic;
pub mod checkpoint;
pub mod design;
pub mod fields;
pub mod gauss_points;
pub mod joints;
pub mod lock;
pub mod plausibility;
pub mod prepare;
pub mod recorder;
pub mod stages;
pub mod strength;
pub mod sustained;
pub mod ultimate;
pub mod vtu;
