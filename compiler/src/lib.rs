//! The signorini weak-form compiler: `.wf` text → checked AST → scalar expression DAG with
//! automatic tangents → Rust kernels. Every stage is printable (`signorini emit`).

pub mod check;
pub mod codegen;
pub mod diagnostic;
pub mod docs;
pub mod ir;
pub mod scheme;
pub mod source;
pub mod syntax;

use std::path::Path;

pub use check::{Program, check_file, check_text};
pub use diagnostic::{Diagnostic, Severity, render_all};
pub use source::{FileId, FsLoader, Loader, MemLoader, SourceMap, Span};

/// Why a unit did not compile: rendered diagnostics, or an I/O problem with the root file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    /// Human-readable, with file:line:col and carets.
    pub rendered: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.rendered)
    }
}

/// Checks a unit; on success returns the program and its rendered warnings.
pub fn check_path(path: &Path, loader: &dyn Loader) -> Result<(Program, String), Failure> {
    match check_file(path, loader) {
        Err(io) => Err(Failure { rendered: format!("error: {io}\n") }),
        Ok(Err((diags, sources))) => Err(Failure { rendered: render_all(&diags, &sources) }),
        Ok(Ok(prog)) => {
            let warnings = render_all(&prog.warnings, &prog.sources);
            Ok((prog, warnings))
        }
    }
}

/// Compiles a unit to formatted Rust (the module named after the file stem).
pub fn compile_to_rust(path: &Path, loader: &dyn Loader, runtime: &str) -> Result<String, Failure> {
    let (prog, _) = check_path(path, loader)?;
    let opts =
        codegen::Options { runtime: runtime.to_string(), module: module_name(path), source_name: display_name(path) };
    codegen::generate_pretty(&prog, &opts).map_err(|e| Failure { rendered: format!("error: {e}\n") })
}

/// The default module name of a .wf file: its stem.
pub fn module_name(path: &Path) -> String {
    path.file_stem().map_or_else(|| "forms".to_string(), |s| s.to_string_lossy().into_owned())
}

/// The file name shown in generated documentation (no machine-specific directories).
pub fn display_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned())
}
