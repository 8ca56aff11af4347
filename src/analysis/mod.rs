//! Analysis: state, assembly, the Newton loop and the step drivers (the linear algebra they
//! call is [`crate::linalg`]).

pub mod bonded_time;
pub mod committed;
mod context;
pub mod displacements;
mod driver;
pub mod failure;
pub mod families;
mod increments;
pub mod influence;
pub mod loads;
mod newton;
pub mod one_way;
pub mod path;
mod responses;
mod scatter;
pub mod staged;
pub mod stages;
pub mod state;
pub mod steps;
pub mod system;
pub mod tendon_time;
pub mod thermal;
pub mod time;
