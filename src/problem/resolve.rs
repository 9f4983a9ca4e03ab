//! A problem resolved for a run: the file loaded, its params (the user's settings over its
//! defaults), the files in use bound to its roles with their params (its `set` values over the
//! files' defaults, the user's over them), and the checks the driver needs before it binds.

use super::ProblemFile;
use super::bind::{ReadMesh, unset_coefs};
use super::expr::Exprs;
use super::options::{Chosen, Options};
use crate::driver::{FilesInUse, Methods};
use crate::error::CaseError;

/// Loads the problem, resolves its params and the files in use (the problem's `set` values as
/// the case's overrides, the user's settings over them), checks what the driver needs of it,
/// and hands the bound pieces to `f`, with the mesh file read to learn the dimension.
pub(super) fn bound<R>(
    opts: &Options,
    f: impl FnOnce(&ProblemFile, &[super::ProblemParam], &mut Exprs, &FilesInUse, Option<ReadMesh>) -> Result<R, CaseError>,
) -> Result<R, CaseError> {
    let pf = super::load(&opts.problem)?;
    let (params, rest) = super::params(&pf, &opts.methods.params)?;
    let mut methods = Methods { params: rest, ..opts.methods.clone() };
    bind_files(&pf, &mut methods, opts.chosen);
    methods.generated.extend(super::neumann::forms(&pf));
    let values: Vec<(String, f64)> = params.iter().map(|p| (p.name.clone(), p.value)).collect();
    let (d, read_mesh) = super::bind::dimension(&pf, opts.mesh.as_deref(), &values)?;
    let p = pf.problem();
    let mut ex = Exprs::new(&pf.program.unit, d, &values, &p.lets).map_err(|e| pf.render(*e))?;
    let mut sets = Vec::new();
    for s in &p.sets {
        sets.push((s.name.name.clone(), ex.scalar(&s.value).map_err(|e| pf.render(*e))?));
    }
    let overrides: Vec<(&str, f64)> = sets.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    let mut in_use = FilesInUse::resolve_located(&methods, &overrides, &|a| unmatched(&pf, &p.sets, a))?;
    if !p.bodies.is_empty() {
        let mut bodies = Vec::new();
        for b in &p.bodies {
            let mut own = Vec::new();
            for s in &b.sets {
                own.push((s.name.name.as_str(), ex.scalar(&s.value).map_err(|e| pf.render(*e))?));
            }
            bodies.push((b.name.name.clone(), own));
        }
        let locate = |body: &str, a: &crate::driver::params::Unmatched| {
            let sets = p.bodies.iter().find(|b| b.name.name == body).map_or(&[][..], |b| b.sets.as_slice());
            unmatched(&pf, sets, a)
        };
        in_use.set_bodies(&methods, &overrides, &bodies, &locate)?;
    }
    unset_coefs(&pf, &in_use)?;
    f(&pf, &params, &mut ex, &in_use, read_mesh)
}

/// A `set` (of `sets`) that names no one param, located at its name.
fn unmatched(
    pf: &ProblemFile,
    sets: &[crate::compiler::syntax::ast::Defined],
    a: &crate::driver::params::Unmatched,
) -> CaseError {
    use crate::compiler::Diagnostic;
    use crate::driver::params::Unnamed;
    let name = &sets[a.index].name;
    let span = name.span;
    pf.render(match &a.why {
        Unnamed::Several(choices) => crate::compiler::check::problem::ambiguous_param(name, choices),
        Unnamed::UnknownQualifier(_) => {
            Diagnostic::error("E0101", format!("unknown qualifier in `{}`", a.name), span, "no such role or file")
                .with_note(a.message())
        }
        Unnamed::SchemeParam(_) => {
            Diagnostic::error("E0101", format!("`{}` is the scheme's", a.name), span, "not a param of a body")
                .with_note(a.message())
        }
    })
}

/// The problem's `bind` lines, for the roles the user did not choose; a path is relative to the
/// problem file.
fn bind_files(pf: &ProblemFile, methods: &mut Methods, chosen: Chosen) {
    // Contact between bodies takes a pair law unless the problem or the user names one.
    if !pf.problem().pairs.is_empty() && !chosen.contact {
        methods.contact = crate::settings::get().defaults.pair.clone();
    }
    for b in &pf.problem().binds {
        let target = if b.is_path { pf.dir.join(&b.target).display().to_string() } else { b.target.clone() };
        match b.role.name.as_str() {
            "scheme" if !chosen.scheme => methods.scheme = target,
            "contact" if !chosen.contact => methods.contact = target,
            "material" if !chosen.material => methods.material = target,
            "forms" => {
                let path = std::path::PathBuf::from(target);
                if !methods.forms.contains(&path) {
                    methods.forms.push(path);
                }
            }
            _ => {}
        }
    }
}
