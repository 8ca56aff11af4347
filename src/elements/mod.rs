//! Element kinds: plane-stress continuum, embedded bars, joint interfaces and external tendons.

pub mod bar;
pub mod continuum;
pub mod incompatible;
pub mod interface;
pub mod tendon;
pub mod total_lagrangian;
