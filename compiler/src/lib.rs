//! The signorini weak-form compiler: `.wf` text → checked AST → scalar expression DAG with
//! automatic tangents → Rust kernels. Every stage is printable (`signorini emit`).
//!
//! [`compile`] runs the whole pipeline and returns every stage ([`Compiled`]); the CLI, the
//! `forms!` macro and the helpers here all use it. Modules, lowest first: `syntax`, `check`,
//! `ir`, `scheme`, `program`, `describe`, `codegen`, `pipeline`.

#![forbid(unsafe_code)]

pub mod check;
pub mod codegen;
pub mod describe;
pub mod diagnostic;
pub mod docs;
pub mod ir;
pub mod pipeline;
pub mod program;
pub mod scheme;
pub mod source;
pub mod syntax;

pub use diagnostic::{Diagnostic, Located, Severity, render_all};
pub use pipeline::{
    Checked, Compiled, Expansion, Failure, Stage, check_file, check_path, check_text, compile, compile_text,
    compile_to_rust, expand,
};
pub use program::Program;
pub use source::{FileId, FsLoader, Loader, MemLoader, SourceMap, Span, display_name, module_name};
