//! Material laws: plane-stress continuum points and uniaxial steel, each keeping committed
//! and trial state apart.

pub mod elastic;
pub mod point;
