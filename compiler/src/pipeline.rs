//! The compiler as one pipeline: load and parse the unit, check it, compile its schemes, lower
//! its forms to IR (per dimension, on demand) and generate Rust. The CLI (`check`, `emit`), the
//! `forms!` macro and the helpers below all go through [`compile`].

use std::path::{Path, PathBuf};

use crate::check::{self, SchemeDef, load};
use crate::codegen;
use crate::diagnostic::{self, Diagnostic, Located, render_all};
use crate::ir::{self, DimIr};
use crate::program::Program;
use crate::scheme::{self, SchemeIr};
use crate::source::{Loader, SourceMap, display_name, module_name};
use crate::syntax::ast;

/// Why a unit did not compile: rendered diagnostics, or an I/O problem with the root file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    /// Human-readable, with file:line:col and carets.
    pub rendered: String,
    /// The diagnostics behind it, located (none for an I/O problem).
    pub diagnostics: Vec<Located>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.rendered)
    }
}

impl Failure {
    fn internal(e: impl std::fmt::Display) -> Failure {
        Failure { rendered: format!("error: {e}\n"), diagnostics: Vec::new() }
    }

    /// The diagnostics, rendered and located.
    pub fn of(diags: &[Diagnostic], sources: &SourceMap) -> Failure {
        Failure { rendered: render_all(diags, sources), diagnostics: diags.iter().map(|d| d.locate(sources)).collect() }
    }
}

/// A stage of the compilation, as [`Compiled::print`] shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The root file's syntax tree.
    Ast,
    /// The forms' IR for one dimension.
    Ir,
    /// The time schemes, their relations solved (coefficients simplified for reading).
    Scheme,
    /// The generated Rust module, formatted.
    Rust,
    /// Each scheme's discrete energy identity, and what it proves.
    Energy,
}

/// Every stage of a unit that compiled.
pub struct Compiled {
    /// The checked program, schemes compiled.
    pub program: Program,
    /// The root file's syntax tree (imports have their own).
    pub ast: ast::File,
    /// The warnings, rendered (empty if none).
    pub warnings: String,
}

impl Compiled {
    /// The IR of every form for dimension `d` (1, 2 or 3; panics otherwise).
    pub fn ir(&self, d: usize) -> &DimIr {
        assert!(ir::DIMS.contains(&d), "dimension {d} is not one of {:?}", ir::DIMS);
        &self.program.irs[d - 1]
    }

    /// The IR for every dimension of [`ir::DIMS`], in order.
    pub fn irs(&self) -> Vec<&DimIr> {
        ir::DIMS.iter().map(|&d| self.ir(d)).collect()
    }

    /// The compiled time schemes.
    pub fn schemes(&self) -> &[SchemeIr] {
        &self.program.schemes
    }

    /// Every file of the unit (the root and its imports), as loaded.
    pub fn source_paths(&self) -> Vec<PathBuf> {
        let sources = &self.program.sources;
        (0..sources.len()).map(|f| sources.path(f).to_path_buf()).collect()
    }

    /// The generated Rust: one `pub mod`.
    pub fn rust(&self, opts: &codegen::Options) -> Result<syn::File, Failure> {
        codegen::generate(&self.program, &self.irs(), opts).map_err(Failure::internal)
    }

    /// The generated Rust formatted for reading, with its line count in a header comment.
    pub fn rust_pretty(&self, opts: &codegen::Options) -> Result<String, Failure> {
        codegen::pretty(&self.program, &self.irs(), opts).map_err(Failure::internal)
    }

    /// A stage as text, the one way every tool shows it (`signorini emit`, the snapshots):
    /// the AST, the IR of dimension `dim` (1, 2 or 3), the schemes, or the Rust module named
    /// after the root file, for the runtime at [`codegen::DEFAULT_RUNTIME`]. `dim` matters to
    /// the IR only.
    pub fn print(&self, stage: Stage, dim: usize) -> Result<String, Failure> {
        let prog = &self.program;
        match stage {
            Stage::Ast => Ok(crate::syntax::print::print_file(&self.ast, &prog.sources)),
            Stage::Ir => {
                if !ir::DIMS.contains(&dim) {
                    return Err(Failure::internal(format!("dimension {dim} is not one of {:?}", ir::DIMS)));
                }
                let params: Vec<String> = prog.params.iter().map(|p| p.name.clone()).collect();
                let coefs: Vec<String> = prog.coefs.iter().map(|c| c.name.clone()).collect();
                Ok(ir::print::print(self.ir(dim), &params, &coefs))
            }
            Stage::Scheme => Ok(self.schemes().iter().map(scheme::print::print).collect::<Vec<_>>().join("\n")),
            Stage::Energy => {
                if self.schemes().is_empty() {
                    return Err(Failure::internal(format!(
                        "{} defines no scheme: the energy stage is a scheme's",
                        display_name(prog.sources.path(prog.root))
                    )));
                }
                let mut out = Vec::new();
                for s in self.schemes() {
                    match scheme::energy::print::print(s) {
                        Ok(text) => out.push(text),
                        Err(why) => {
                            let message = format!("no energy identity for scheme `{}`", s.name);
                            let d = Diagnostic::error("E0822", message, s.span, why);
                            return Err(Failure::of(&[d], &prog.sources));
                        }
                    }
                }
                Ok(out.join("\n"))
            }
            Stage::Rust => {
                let root = prog.sources.path(prog.root);
                let opts = codegen::Options {
                    runtime: codegen::DEFAULT_RUNTIME.to_string(),
                    module: module_name(root),
                    source_name: display_name(root),
                };
                self.rust_pretty(&opts)
            }
        }
    }
}

/// Result of the front end (loading, checking, schemes): the program with its warnings, or
/// every diagnostic in source order with the sources needed to render them.
pub type Checked = Result<Program, (Vec<Diagnostic>, SourceMap)>;

/// Compiles the unit rooted at `path` (imports resolve through `loader`).
pub fn compile(path: &Path, loader: &dyn Loader) -> Result<Compiled, Failure> {
    let mut diags = Vec::new();
    let loaded = load::load(path, loader, &mut diags).map_err(Failure::internal)?;
    finish(front(loaded, diags))
}

/// Compiles `text` as if it were the file `path` (imports resolve through `loader`).
pub fn compile_text(path: &Path, text: &str, loader: &dyn Loader) -> Result<Compiled, Failure> {
    let mut diags = Vec::new();
    let loaded = load::load_text(path, text, loader, &mut diags);
    finish(front(loaded, diags))
}

/// The front end of [`compile`], with the diagnostics as values (for tests and tools).
pub fn check_file(path: &Path, loader: &dyn Loader) -> Result<Checked, String> {
    let mut diags = Vec::new();
    let loaded = load::load(path, loader, &mut diags)?;
    Ok(front(loaded, diags).map(|(prog, _)| prog))
}

/// The front end of [`compile_text`], with the diagnostics as values.
pub fn check_text(path: &Path, text: &str, loader: &dyn Loader) -> Checked {
    let mut diags = Vec::new();
    let loaded = load::load_text(path, text, loader, &mut diags);
    front(loaded, diags).map(|(prog, _)| prog)
}

/// Checks a unit; on success returns the program and its rendered warnings.
pub fn check_path(path: &Path, loader: &dyn Loader) -> Result<(Program, String), Failure> {
    compile(path, loader).map(|c| (c.program, c.warnings))
}

/// Compiles a unit to formatted Rust (the module named after the file stem).
pub fn compile_to_rust(path: &Path, loader: &dyn Loader, runtime: &str) -> Result<String, Failure> {
    let opts =
        codegen::Options { runtime: runtime.to_string(), module: module_name(path), source_name: display_name(path) };
    compile(path, loader)?.rust_pretty(&opts)
}

/// What `forms!` expands to: the generated module, and every file it was compiled from (for
/// rebuild tracking).
pub struct Expansion {
    pub file: syn::File,
    pub sources: Vec<PathBuf>,
}

/// The `forms!` macro without the macro: the module generated from `path`, or the rendered
/// diagnostics.
pub fn expand(path: &Path, loader: &dyn Loader, opts: &codegen::Options) -> Result<Expansion, String> {
    let compiled = compile(path, loader).map_err(|f| f.rendered)?;
    let file = compiled.rust(opts).map_err(|f| f.rendered)?;
    Ok(Expansion { file, sources: compiled.source_paths() })
}

/// Checks a loaded unit and compiles its schemes; returns the program and the root's AST.
fn front(loaded: load::Loaded, diags: Vec<Diagnostic>) -> Result<(Program, ast::File), (Vec<Diagnostic>, SourceMap)> {
    let load::Loaded { sources, mut files, root, roles } = loaded;
    let (mut unit, mut diags) = check::check(sources, root, &files, diags);
    unit.roles = roles;
    let checked = !diags.iter().any(Diagnostic::is_error);
    // The schemes need nothing the forms' errors break: their mistakes are shown in the same
    // run. A scheme whose declaration has a syntax error is not compiled.
    let broken = check::broken_names(&files);
    let defs: Vec<&SchemeDef> = unit.scheme_defs.iter().filter(|d| !broken.contains(&d.name.name)).collect();
    let schemes = scheme::compile(&unit, &defs, &mut diags);
    if !checked {
        diagnostic::normalize(&mut diags);
        return Err((diags, unit.sources));
    }
    let mut irs = Vec::new();
    for &d in &ir::DIMS {
        match ir::build(&unit, d) {
            Ok(ir) => {
                // The first dimension's only: the others repeat them.
                if irs.is_empty() {
                    diags.extend(ir::vanishing_denominators(&unit, &ir));
                }
                irs.push(ir)
            }
            // The first dimension's errors only: the others mostly repeat them.
            Err(mut e) => {
                diags.append(&mut e);
                break;
            }
        }
    }
    diagnostic::normalize(&mut diags);
    if diags.iter().any(Diagnostic::is_error) {
        return Err((diags, unit.sources));
    }
    unit.warnings = diags;
    let ast = match files.iter().position(|(id, _)| *id == root) {
        Some(i) => files.swap_remove(i).1,
        None => ast::File::default(),
    };
    Ok((Program { unit, schemes, irs }, ast))
}

fn finish(front: Result<(Program, ast::File), (Vec<Diagnostic>, SourceMap)>) -> Result<Compiled, Failure> {
    match front {
        Err((diags, sources)) => Err(Failure::of(&diags, &sources)),
        Ok((program, ast)) => {
            let warnings = render_all(&program.warnings, &program.sources);
            Ok(Compiled { program, ast, warnings })
        }
    }
}
