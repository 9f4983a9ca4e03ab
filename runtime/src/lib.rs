//! The signorini runtime: element catalogue, quadrature, the interface compiled kernels
//! implement, and (later) meshes, assembly, solvers and time loops.

pub mod assembly;
pub mod element;
pub mod geometry;
pub mod kernel;
pub mod linalg;
pub mod mesh;
pub mod quadrature;
