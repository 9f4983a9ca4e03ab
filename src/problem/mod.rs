//! Problems posed in `.wf` files (`problem NAME(...) { ... }`): the library's, in
//! `forms/problems/`, found by name, or a user's file by path. This module loads and checks
//! the file and resolves its params; [`expr`] evaluates its expressions, [`bind`] builds the
//! mesh, regions, coefs and initial fields (and checks the coefs against the files in use),
//! [`dirichlet`] its held displacements, [`neumann`] its loads on regions, [`reference`] the
//! analytic reference it names;
//! [`observe`] measures its series columns at every row and [`summary`] its summary keys over
//! the rows; [`run`] is the one loop that runs every problem, with [`options`] the choices over
//! the problem's own, [`outputs`] what a run writes and [`resume`] what its checkpoints keep.

pub mod bind;
mod bodies;
mod check;
mod dirichlet;
pub mod expr;
mod generate;
mod neumann;
pub mod observe;
pub mod options;
pub mod outputs;
mod pairs;
mod reference;
mod resolve;
mod resume;
pub mod run;
mod settle;
pub mod summary;

use std::path::{Path, PathBuf};

use crate::compiler::Program;
use crate::compiler::syntax::ast;
use crate::driver::Setting;
use crate::error::CaseError;

/// A checked problem file.
pub struct ProblemFile {
    /// The file as the user named it (`forms/problems/disc.wf` for the library's).
    pub file: String,
    /// Where a mesh file the problem names is looked for.
    pub dir: PathBuf,
    /// A hash of the file's text (checkpoints refuse another).
    pub text_hash: u64,
    pub program: Program,
}

impl ProblemFile {
    /// The file's problem (a problem file declares exactly one).
    pub fn problem(&self) -> &ast::Problem {
        &self.program.unit.problems[0]
    }

    pub fn name(&self) -> &str {
        &self.problem().name.name
    }

    /// Renders a diagnostic at the file's text.
    pub fn render(&self, d: crate::compiler::Diagnostic) -> CaseError {
        CaseError::Wf(crate::compiler::Failure::of(&[d], &self.program.unit.sources))
    }
}

/// The names of the library's problems.
pub fn library_names() -> Vec<&'static str> {
    crate::forms::PROBLEM_SOURCES.iter().map(|(n, _)| *n).collect()
}

/// A library problem by name (`static-block` finds `static_block`), or a file by path.
pub fn load(name: &str) -> Result<ProblemFile, CaseError> {
    use crate::compiler::{MemLoader, pipeline::check_text};
    let is_path = name.ends_with(".wf") || name.contains('/');
    let (file, dir, text) = if is_path {
        let path = Path::new(name);
        let text =
            crate::compiler::source::read_source(path).map_err(|e| CaseError::CaseFile(format!("{name}: {e}")))?;
        (name.to_string(), path.parent().map(Path::to_path_buf).unwrap_or_default(), text)
    } else {
        let stem = name.replace('-', "_");
        let Some((_, text)) = crate::forms::PROBLEM_SOURCES.iter().find(|(n, _)| *n == stem) else {
            let known = library_names();
            let hint = crate::compiler::check::suggest_name(&stem, known.iter().copied())
                .map_or(String::new(), |s| format!("; did you mean `{s}`?"));
            return Err(CaseError::Option(format!(
                "no problem `{name}` in the library (known: {}){hint}; or give a .wf file",
                known.join(", ")
            )));
        };
        let dir = crate::library_dir::forms().join("problems");
        (format!("forms/problems/{stem}.wf"), dir, text.to_string())
    };
    let checked = if is_path {
        check_text(Path::new(&file), &text, &crate::driver::sources::LibraryLoader)
    } else {
        check_text(Path::new(&file), &text, &MemLoader::default())
    };
    let unit = checked.map_err(|(diags, sources)| CaseError::Wf(crate::compiler::Failure::of(&diags, &sources)))?;
    let count = unit.unit.problems.len();
    if count != 1 {
        return Err(CaseError::CaseFile(format!("{file}: a problem file declares one problem, this one {count}")));
    }
    Ok(ProblemFile { file, dir, text_hash: crate::checkpoint::fnv(text.as_bytes()), program: unit })
}

/// A problem param in effect.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ProblemParam {
    pub name: String,
    pub value: f64,
    /// `file` (its default) or `user`.
    pub source: crate::driver::params::Source,
}

/// The problem's params: defaults, then the user's settings that name them (`h`, or
/// `disc.h`); the other settings are returned for the scheme and form files.
pub fn params(pf: &ProblemFile, settings: &[Setting]) -> Result<(Vec<ProblemParam>, Vec<Setting>), CaseError> {
    use crate::compiler::check::const_value;
    use crate::driver::params::Source;
    let p = pf.problem();
    let mut out = Vec::new();
    for q in &p.params {
        let value = const_value(&q.default).ok_or_else(|| {
            pf.render(crate::compiler::Diagnostic::error(
                "E0603",
                "param default not a finite constant",
                q.default.span,
                "not a constant",
            ))
        })?;
        out.push(ProblemParam { name: q.name.name.clone(), value, source: Source::File });
    }
    let mut rest = Vec::new();
    for s in settings {
        let bare = s.name.strip_prefix(&format!("{}.", p.name.name)).unwrap_or(&s.name);
        let Some(i) = p.params.iter().position(|q| q.name.name == bare) else {
            rest.push(s.clone());
            continue;
        };
        let q = &p.params[i];
        if let Some(r) = &q.range {
            let lo = const_value(&r.lo).unwrap_or(f64::NEG_INFINITY);
            let hi = const_value(&r.hi).unwrap_or(f64::INFINITY);
            let range =
                crate::runtime::descriptors::ParamRange { lo, lo_closed: r.lo_closed, hi, hi_closed: r.hi_closed };
            if !range.contains(s.value) {
                return Err(CaseError::Option(format!(
                    "{}: param {} of problem `{}` must be in {}, not {} ({})",
                    s.origin, q.name.name, p.name.name, range, s.value, pf.file
                )));
            }
        } else if !s.value.is_finite() {
            return Err(CaseError::Option(format!("{}: param {} must be finite", s.origin, q.name.name)));
        }
        out[i].value = s.value;
        out[i].source = Source::User;
    }
    Ok((out, rest))
}
