//! Forms of a `.wf` file given at run time, evaluated by interpreting their IR instead of
//! compiling Rust: a [`Library`] checks the file and lowers every form for dimensions 1, 2
//! and 3; [`Library::form`] binds one form to parameter and coef values as an
//! [`InterpretedForm`], which implements the runtime's `Form`, `FormKernel` and
//! `FunctionalKernel` with the semantics of the generated kernels (so it works with
//! `runtime::fem::bound::Bound` and the `Assembler`).
//!
//! ```no_run
//! use signorini::interpret::Library;
//! use signorini::runtime::fem::kernel::Coef;
//!
//! let lib = Library::load("forms/contact_nitsche.wf".as_ref())?;
//! let coefs = [
//!     ("f", Coef::constant(vec![0.0, -9.81])),
//!     ("g", Coef::function(1, |x, _, out| out[0] = x[1])),
//!     ("nc", Coef::constant(vec![0.0, -1.0])),
//! ];
//! let contact = lib.form("contact", 2, &[("gamma0", 10.0)], &coefs)?;
//! # Ok::<(), signorini::interpret::InterpretError>(())
//! ```

mod form;
mod kernels;
mod pair;

use std::path::Path;
use std::sync::Arc;

use signorini_compiler::ir::{DimIr, plan};
use signorini_compiler::{FsLoader, Program, Span};
use signorini_runtime::descriptors::ParamRange;
use signorini_runtime::fem::kernel::{Coef, FormMeta};

pub use form::InterpretedForm;

/// Why a form could not be loaded or bound.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InterpretError {
    /// The file does not compile: the compiler's rendered diagnostics.
    #[error("{0}")]
    Compile(String),
    #[error("`{file}` has no form or functional `{name}` (available: {})", list(.available))]
    UnknownForm { name: String, file: String, available: Vec<String> },
    #[error("unknown parameter `{name}` (known: {})", list(.known))]
    UnknownParam { name: String, known: Vec<String> },
    #[error("parameter `{name}` = {value} is outside its range {range} (declared at {at})")]
    OutOfRange { name: String, value: f64, range: String, at: String },
    #[error("missing coef `{name}` (declared at {at})")]
    MissingCoef { name: String, at: String },
    #[error("unknown coef `{name}` (declared: {})", list(.known))]
    UnknownCoef { name: String, known: Vec<String> },
    /// A coef with the wrong number of components for its shape (`runtime::fem::kernel::check_coef`).
    #[error("{0}")]
    CoefShape(String),
    #[error("interpreted forms exist in dimensions 1, 2 and 3, not {0}")]
    Dimension(usize),
}

fn list(names: &[String]) -> String {
    if names.is_empty() { "none".into() } else { names.join(", ") }
}

/// A checked `.wf` unit, lowered and ready to bind its forms.
#[derive(Clone)]
pub struct Library {
    unit: Arc<Unit>,
    warnings: String,
}

impl std::fmt::Debug for Library {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Library").field("file", &self.unit.file).field("forms", &self.forms()).finish()
    }
}

/// What every form of a unit shares.
struct Unit {
    file: String,
    params: Vec<ParamDecl>,
    coefs: Vec<CoefDecl>,
    forms: Vec<FormEntry>,
}

struct ParamDecl {
    name: String,
    default: f64,
    range: Option<ParamRange>,
    /// `file:line` of the declaration.
    at: String,
}

impl ParamDecl {
    /// The value if it is accepted, as generated `Params::set` decides (finite, in range).
    fn check(&self, value: f64) -> Result<f64, InterpretError> {
        let range = self.range.unwrap_or(ParamRange::UNBOUNDED);
        if range.contains(value) {
            return Ok(value);
        }
        Err(InterpretError::OutOfRange {
            name: self.name.clone(),
            value,
            range: range.to_string(),
            at: self.at.clone(),
        })
    }
}

struct CoefDecl {
    name: String,
    /// 0, 1, 2 for scalar, vector, tensor.
    rank: u32,
    at: String,
}

struct FormEntry {
    meta: FormMeta,
    /// Kernels for dimensions 1, 2, 3.
    dims: Vec<plan::FormPlan>,
    /// A contact pair's law: its pointwise programs for dimensions 1, 2, 3.
    pairs: Option<Vec<Vec<signorini_compiler::ir::pair::PairIntegral>>>,
    /// A pair law integrated over each surface of its pair in turn (`both_sides`).
    both_sides: bool,
}

impl Library {
    /// Checks and lowers the file at `path` (imports resolve on the filesystem).
    pub fn load(path: &Path) -> Result<Library, InterpretError> {
        let (prog, warnings) =
            signorini_compiler::check_path(path, &FsLoader).map_err(|f| InterpretError::Compile(f.rendered))?;
        let mut lib = Library::new(&prog);
        lib.warnings = warnings;
        Ok(lib)
    }

    /// Lowers every form declared in the root file of a checked program.
    pub fn new(prog: &Program) -> Library {
        let irs = &prog.irs;
        let at = |span: Span| {
            let (line, _) = prog.sources.line_col(span.file, span.start);
            format!("{}:{line}", prog.sources.path(span.file).display())
        };
        let params = prog
            .params
            .iter()
            .map(|p| ParamDecl { name: p.name.clone(), default: p.default, range: p.range, at: at(p.span) })
            .collect();
        let coefs = prog
            .coefs
            .iter()
            .map(|c| {
                let rank = c.shape.rank();
                CoefDecl { name: c.name.clone(), rank, at: at(c.span) }
            })
            .collect();
        // The forms declared in the file itself, as a generated module has them: imported
        // files provide their own.
        let forms = (0..prog.forms.len())
            .filter(|&fi| prog.forms[fi].span.file == prog.root)
            .map(|fi| FormEntry {
                meta: meta(prog, irs, fi),
                dims: irs.iter().map(|ir| plan::form(prog, ir, &ir.forms[fi])).collect(),
                pairs: irs.iter().map(|ir| signorini_compiler::ir::pair::plan(ir, &ir.forms[fi])).collect(),
                both_sides: irs.iter().any(|ir| ir.forms[fi].both_sides),
            })
            .collect();
        let file = prog.sources.path(prog.root).display().to_string();
        Library { unit: Arc::new(Unit { file, params, coefs, forms }), warnings: String::new() }
    }

    /// The checker's rendered warnings (empty for [`Library::new`]).
    pub fn warnings(&self) -> &str {
        &self.warnings
    }

    /// Whether the file is a contact pair's law (it reads `opposite`).
    pub fn is_pair_law(&self) -> bool {
        self.unit.forms.iter().any(|f| f.pairs.is_some())
    }

    /// Names of the forms and functionals, in declaration order.
    pub fn forms(&self) -> Vec<&str> {
        self.unit.forms.iter().map(|f| &*f.meta.name).collect()
    }

    /// The metadata of a form, as a generated form's `META`.
    pub fn meta(&self, name: &str) -> Option<&FormMeta> {
        self.unit.forms.iter().find(|f| f.meta.name == name).map(|f| &f.meta)
    }

    /// Parameters with their defaults, in declaration order.
    pub fn params(&self) -> Vec<(&str, f64)> {
        self.unit.params.iter().map(|p| (p.name.as_str(), p.default)).collect()
    }

    /// Names of the coefs, in declaration order.
    pub fn coefs(&self) -> Vec<&str> {
        self.unit.coefs.iter().map(|c| c.name.as_str()).collect()
    }

    /// The coefs with their tensor ranks (0 scalar, 1 vector, 2 tensor).
    pub fn coef_ranks(&self) -> Vec<(String, u32)> {
        self.unit.coefs.iter().map(|c| (c.name.clone(), c.rank)).collect()
    }

    /// Binds form `name` for cells of dimension `dim`: parameters not in `params` take their
    /// defaults; `coefs` gives a value for every coef of the unit (as a generated
    /// `Coefficients` does), with the components its shape needs in `dim`.
    pub fn form(
        &self,
        name: &str,
        dim: usize,
        params: &[(&str, f64)],
        coefs: &[(&str, Coef)],
    ) -> Result<InterpretedForm, InterpretError> {
        InterpretedForm::new(self.unit.clone(), name, dim, params, coefs)
    }
}

/// `FormMeta` as codegen builds `META`: degrees from the 2D lowering, `linear` and
/// `piecewise` over every dimension.
fn meta(prog: &Program, irs: &[DimIr], fi: usize) -> FormMeta {
    let f2 = &irs[1].forms[fi];
    let facets = f2.integrals.iter().filter(|i| !i.cell);
    FormMeta {
        name: f2.name.clone().into(),
        fields: f2.fields.iter().map(|f| f.clone().into()).collect(),
        test: f2.test.clone().unwrap_or_default().into(),
        linear: irs.iter().all(|ir| ir.forms[fi].linear),
        piecewise: irs.iter().all(|ir| ir.forms[fi].integrals.iter().all(|i| i.tangents.iter().all(|t| t.piecewise))),
        previous: irs.iter().any(|ir| ir.forms[fi].previous),
        cell_degree: f2.integrals.iter().find(|i| i.cell).map(|i| i.degree),
        facets: facets.clone().map(|i| (i.region.clone().into(), i.degree)).collect(),
        facet_sites: facets.map(|i| signorini_compiler::docs::region_site(prog, &f2.name, &i.region).into()).collect(),
        tangential: signorini_compiler::docs::tangential_site(prog, &f2.name).map(Into::into),
    }
}
