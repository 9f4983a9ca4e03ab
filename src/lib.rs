//! signorini: dynamic contact mechanics from weak forms.
//!
//! `signorini::forms!("forms/contact_nitsche.wf")` compiles a `.wf` file at build time into a
//! module of kernels (see `signorini-compiler`); the kernels run on `signorini::runtime`.

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
