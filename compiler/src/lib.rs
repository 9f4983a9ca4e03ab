//! The signorini weak-form compiler: `.wf` text → checked AST → scalar expression DAG with
//! automatic tangents → Rust kernels. Every stage is printable (`signorini emit`).

pub mod diagnostic;
pub mod source;
pub mod syntax;

pub use diagnostic::{Diagnostic, Severity};
pub use source::{FileId, FsLoader, Loader, MemLoader, SourceMap, Span};
pub mod check;
pub mod ir;
