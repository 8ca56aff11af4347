//! Design checks against code limits (docs/theory-design.md): the code formulas and the
//! joint as a cross-section. The checks of a run read its results (`results::design`).

pub mod formulas;
pub mod joint_section;
