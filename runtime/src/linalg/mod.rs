//! Sparse linear algebra, the only layer that imports faer (faer 0.x: its API changes land
//! here): matrices over a sparsity pattern, reusable factorizations (faer's sparse Cholesky and
//! LU, and a copy of the Cholesky factor in node blocks for the solves), products with a
//! symmetric matrix's lower half, block-Jacobi Krylov solvers, and low-rank corrections of a
//! factorization by element matrices kept apart.

pub mod block_factor;
pub mod element_matrices;
pub mod factorization;
pub mod krylov;
pub mod lower_half;
pub mod lowrank;
pub mod matrix;
pub mod norms;
pub mod pattern;

pub use factorization::{AUTO_ITERATIVE_DOFS, Counters, Factorization, Solver, Structure};
pub use matrix::{LinalgError, Matrix};
