//! The runtime's integration tests, in one binary (a binary per file spent most of `cargo
//! test` linking): through the runtime alone, with hand-written forms and no compiler.

mod assembly;
mod common;
mod gmsh;
mod mesh_integrity;
mod meshes;
mod newton;
#[cfg(feature = "petsc")]
mod petsc;
mod solvers;
mod stepper;
