//! The compiler's property tests, in one binary: random inputs never make it panic, random
//! schemes compile to stages that satisfy their relations, and the built-ins' tangents are
//! their derivatives (the tensor functions also their identities).

mod derivative;
mod energy_identity;
mod friction_builtins;
mod no_panic;
mod points;
mod scheme_properties;
mod tensor_builtins;
mod transcendental;
