//! Material laws: plane-stress continuum points and uniaxial steel, each keeping committed
//! and trial state apart.

pub mod chain;
pub mod concrete;
pub mod elastic;
pub mod error;
pub mod mc90;
pub mod mc90_time;
pub mod point;
pub mod steel;
pub mod viscoplastic;
