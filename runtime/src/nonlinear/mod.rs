//! Nonlinear solves: semi-smooth Newton and the static problems solved with it.

pub mod newton;
pub mod problem;
mod reuse;
pub mod statics;
