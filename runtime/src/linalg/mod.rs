//! Sparse linear algebra, the only layer that imports faer (faer 0.x: its API changes land
//! here): matrices over a sparsity pattern, reusable factorizations (faer's sparse Cholesky and
//! LU, and a copy of the Cholesky factor in node blocks for the solves), products with a
//! symmetric matrix's lower half, block-Jacobi Krylov solvers, and low-rank corrections of a
//! factorization by element matrices kept apart; with the feature `petsc`, PETSc's Krylov
//! solvers (block Jacobi or algebraic multigrid) behind the same `Factorization`.

pub mod block_factor;
pub mod element_matrices;
pub mod factorization;
pub mod krylov;
pub mod lower_half;
pub mod lowrank;
pub mod matrix;
pub mod norms;
pub mod ownership;
pub mod pattern;
#[cfg(feature = "petsc")]
pub mod petsc;
pub mod ranks;

pub use factorization::{AUTO_ITERATIVE_DOFS, Counters, Factorization, Solver, Structure};
pub use matrix::{LinalgError, Matrix};

/// Options for every PETSc solver of this process, in PETSc's syntax (`-ksp_type gmres
/// -pc_type hypre`), applied over their defaults as `PETSC_OPTIONS` is; an error in a build
/// without the `petsc` feature.
pub fn set_petsc_options(options: &str) -> Result<(), LinalgError> {
    #[cfg(feature = "petsc")]
    return petsc::set_options(options);
    #[cfg(not(feature = "petsc"))]
    Err(LinalgError::Other(format!(
        "PETSc options `{options}` given, but this signorini was built without PETSc (`--features petsc`)"
    )))
}

/// Ends PETSc if it was used (it then writes what options like `-log_view` asked for); a
/// no-op without the `petsc` feature. Call it last: no PETSc solver may be used afterwards.
pub fn finalize_petsc() -> Result<(), LinalgError> {
    #[cfg(feature = "petsc")]
    return petsc::finalize();
    #[cfg(not(feature = "petsc"))]
    Ok(())
}
