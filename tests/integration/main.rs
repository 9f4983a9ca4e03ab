//! The facade's integration tests, in one binary (a binary per file spent most of `cargo
//! test` linking): the CLI, problems, schemes, references and the report, end to end.

mod adaptive;
mod assembly;
mod bad_inputs;
mod bar;
mod bodies;
mod case_files;
mod checkpoint;
mod cli;
mod convergence;
mod deformed_contact;
mod disc;
mod elements;
mod energy_guard;
mod energy_identity;
mod finite_strain;
mod friction;
mod friction_laws;
mod genalpha;
mod hertz;
mod import_circles;
mod interpreted_forms;
mod interpreted_schemes;
#[cfg(feature = "petsc")]
mod mpi;
mod pair_laws;
mod pairs;
#[cfg(feature = "petsc")]
mod petsc;
mod previous_level;
mod problems;
mod readme;
mod redistribution;
mod schemes;
mod settings;
mod sphere;
mod static_contact;
mod sweep;
mod tangents;
mod time_dependence;
mod tutorial;
mod verify;
mod verify_scheme;
mod vtu;
