//! Nonlinear solves: semi-smooth Newton and the static problems solved with it.

pub mod newton;
mod reuse;
pub mod statics;
