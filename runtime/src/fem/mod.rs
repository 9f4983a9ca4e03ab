//! The finite-element layer: the element catalogue, quadrature and isoparametric geometry,
//! the interface compiled kernels implement, meshes, and the assembly of compiled forms (with
//! the mass operations built on it: lumping and redistribution).

pub mod assembly;
pub mod bound;
pub mod element;
pub mod evaluate;
pub mod facing;
pub mod geometry;
pub mod kernel;
pub mod lumping;
pub mod mesh;
pub mod pair;
pub mod quadrature;
pub mod redistribute;
pub mod search_cost;
pub mod summed;
pub mod test_matrices;
