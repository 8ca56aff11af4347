//! Prestressing: tendon geometry, friction losses and equivalent forces.

pub mod friction;
pub mod posttension;
