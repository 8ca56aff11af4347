//! Element kinds: plane-stress continuum, embedded bars, joint interfaces and external tendons.
pub mod bar;
