//! signorini: dynamic contact mechanics from weak forms.
//!
//! `signorini::forms!("forms/contact_nitsche.wf")` compiles a `.wf` file at build time into a
//! module of kernels (see `signorini-compiler`); the kernels run on `signorini::runtime`.
//!
//! The modules in layers, each importing only from those below it:
//! - [`cli`], the command line;
//! - [`report`], which reads [`verify`] and [`bench`];
//! - [`cases`], typed views of the library's bar and falling-body runs, and case files;
//! - [`problem`], problem files bound and run by the one loop;
//! - [`simulation`], the operators bound on a mesh, the stepper's time loop and the energy guard;
//! - [`checkpoint`], what a run writes to resume from;
//! - [`driver`], the scheme and form files in use with every param's value ([`interpret`] for
//!   the files given by path, [`forms`] for the compiled library, [`settings`] for
//!   forms/library.toml);
//! - the run's error ([`error`]), its step guard ([`guard`]), [`references`], and the outputs
//!   ([`output`], [`numbers`], [`plot`], [`vtu`], [`progress`], [`interrupt`], [`resources`]), and where the library's files are ([`library_dir`]).

// Generated code names the runtime `::signorini::runtime`, also inside this crate.
extern crate self as signorini;

pub use signorini_compiler as compiler;
pub use signorini_macros::forms;
pub use signorini_runtime as runtime;

pub mod bench;
pub mod cases;
pub mod checkpoint;
pub mod cli;
pub mod driver;
pub mod error;
pub mod forms;
pub mod guard;
pub mod interpret;
pub mod interrupt;
pub mod library_dir;
pub mod numbers;
pub mod output;
pub mod plot;
pub mod problem;
pub mod progress;
pub mod references;
pub mod report;
pub mod resources;
pub mod settings;
pub mod simulation;
pub mod verify;
pub mod vtu;
