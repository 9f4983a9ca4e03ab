//! A scheme's discrete energy identity (`emit --stage energy`), built on exact algebra: the
//! scheme's scalars as rational functions of its params, dt and t ([`exact`]), over
//! polynomials kept expanded ([`poly`]) so that a coefficient is zero exactly when it is the
//! zero polynomial ([`ratfn`]). The derivation of the identity from a compiled scheme comes on
//! top of these.

pub mod exact;
pub mod poly;
pub mod ratfn;
