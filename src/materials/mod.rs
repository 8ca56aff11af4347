//! Material laws: plane-stress continuum points and uniaxial steel, each keeping committed
//! and trial state apart.

pub mod concrete;
pub mod error;
pub mod mc90;
pub mod steel;
