//! Material laws: plane-stress continuum points and uniaxial steel, each keeping committed
//! and trial state apart.

pub mod chain;
pub mod elastic;
pub mod mc90_time;
pub mod point;
pub mod viscoplastic;
