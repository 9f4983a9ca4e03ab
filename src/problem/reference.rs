//! The analytic reference a problem names (`reference bar`, `reference hertz_ball(...)`): found
//! by name, checked against the problem's dimension, its arguments evaluated, and bound to the
//! run after it checked that the run is one it describes.

use super::ProblemFile;
use super::expr::Exprs;
use crate::driver::FilesInUse;
use crate::error::CaseError;

/// The problem's reference bound to this run, after it checked the run is one it describes.
pub(super) fn bound_reference(
    pf: &ProblemFile,
    ex: &mut Exprs,
    in_use: &FilesInUse,
    mesh: &crate::runtime::fem::mesh::Mesh,
    contact: &[crate::runtime::fem::mesh::Facet],
    t_start: f64,
) -> Result<Option<crate::references::Bound>, CaseError> {
    let Some(r) = reference(pf, mesh.dim())? else { return Ok(None) };
    let param = |name: &str| in_use.forms.params.get(name);
    let args = reference_args(pf, ex, r)?;
    let facts = crate::references::RunFacts { mesh, param: &param, t_start, args: &args, contact };
    let bound = r.bind(&facts).map_err(|why| {
        let at = pf.problem().reference.as_ref().map_or(pf.problem().name.span, |n| n.span);
        pf.render(
            crate::compiler::Diagnostic::error(
                "E0101",
                format!("reference `{}` does not describe this run", r.name()),
                at,
                "named here",
            )
            .with_note(why)
            .with_note(format!("{}: {}", r.name(), r.doc())),
        )
    })?;
    Ok(Some((r, bound)))
}

/// The problem's reference, if it names one, for a problem of dimension `d`.
pub(super) fn reference(
    pf: &ProblemFile,
    d: usize,
) -> Result<Option<&'static dyn crate::references::Reference>, CaseError> {
    use crate::compiler::Diagnostic;
    let Some(name) = &pf.problem().reference else { return Ok(None) };
    let names = crate::references::ALL.iter().map(|r| r.name());
    let r = crate::references::find(&name.name)
        .ok_or_else(|| pf.render(crate::compiler::check::problem::unknown_among(name, names, "reference")))?;
    if !r.dims().contains(&d) {
        let dims: Vec<String> = r.dims().iter().map(|d| format!("{d}D")).collect();
        return Err(pf.render(
            Diagnostic::error(
                "E0302",
                "wrong dimension",
                name.span,
                format!("reference `{}` is {}, the problem {d}D", r.name(), dims.join(" or ")),
            )
            .with_note(format!("{}: {}", r.name(), r.doc())),
        ));
    }
    Ok(Some(r))
}

/// The problem's arguments to its reference, evaluated; a name the reference does not take is
/// an error with its list.
fn reference_args(
    pf: &ProblemFile,
    ex: &mut Exprs,
    r: &dyn crate::references::Reference,
) -> Result<Vec<(String, f64)>, CaseError> {
    let known = r.args();
    let mut out = Vec::new();
    for a in &pf.problem().reference_args {
        if !known.iter().any(|(n, _)| *n == a.name.name) {
            return Err(pf.render(crate::compiler::check::problem::unknown_among(
                &a.name,
                known.iter().map(|(n, _)| *n),
                "reference argument",
            )));
        }
        out.push((a.name.name.clone(), ex.scalar(&a.value).map_err(|e| pf.render(*e))?));
    }
    Ok(out)
}
