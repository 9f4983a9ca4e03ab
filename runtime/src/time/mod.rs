//! Time integration: what a compiled scheme gives the stepper, the stepper that runs it step by
//! step, and the nonlinear problem of one of its stages.

pub mod scheme;
pub mod stage;
pub mod stepper;
