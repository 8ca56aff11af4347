//! Analysis: steps, the Newton loop, and the linear-solver wrapper.

pub mod bonded_time;
mod driver;
pub mod failure;
pub mod families;
mod increments;
pub mod influence;
pub mod loads;
mod newton;
pub mod one_way;
pub mod ordering;
pub mod path;
mod responses;
pub mod solver;
mod split;
pub mod staged;
pub mod stages;
pub mod state;
pub mod steps;
pub mod system;
pub mod thermal;
pub mod time;
