//! The compiler's property tests, in one binary: random inputs never make it panic, and random
//! schemes compile to stages that satisfy their relations.

mod friction_builtins;
mod no_panic;
mod scheme_properties;
