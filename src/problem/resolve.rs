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
    bind_files(&pf, &mut methods, opts.chosen)?;
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
    for (group, law) in methods.pairs.iter().enumerate().filter(|(_, g)| g.own) {
        let pair = &p.pairs[law.pairs[0]];
        let mut own = Vec::new();
        for s in &pair.sets {
            own.push((s.name.name.as_str(), ex.scalar(&s.value).map_err(|e| pf.render(*e))?));
        }
        if !own.is_empty() {
            in_use.set_pair(&methods, group, &own, &|a| unmatched(&pf, &pair.sets, a))?;
        }
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
        Unnamed::SchemeParam(_) => Diagnostic::error(
            "E0101",
            format!("`{}` is the scheme's", a.name),
            span,
            "the problem's, not a body's or a pair's",
        )
        .with_note(a.message()),
        Unnamed::NotTheLaw { law, .. } => {
            Diagnostic::error("E0101", format!("`{}` is not a param of `{law}`", a.name), span, "not the pair law's")
                .with_note(a.message())
        }
    })
}

/// The problem's `bind` lines, for the roles the user did not choose; a path is relative to the
/// problem file. With contact pairs, each contact law goes where its kind does (the user's
/// choice first, then the file's): a pair law to the pairs (a pair's own block over the
/// problem's `bind`), an obstacle's law to the obstacle.
fn bind_files(pf: &ProblemFile, methods: &mut Methods, chosen: Chosen) -> Result<(), CaseError> {
    let user_contact = chosen.contact.then(|| methods.contact.clone());
    let mut file_contact = None;
    for b in &pf.problem().binds {
        let target = bound_target(pf, b);
        match b.role.name.as_str() {
            "scheme" if !chosen.scheme => methods.scheme = target,
            "contact" => file_contact = Some((target, b)),
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
    if pf.problem().pairs.is_empty() {
        if let (None, Some((target, _))) = (&user_contact, file_contact) {
            methods.contact = target;
        }
        return Ok(());
    }
    contact_with_pairs(pf, methods, user_contact, file_contact)
}

/// A `bind` line's target: a library name, or a path relative to the problem file.
fn bound_target(pf: &ProblemFile, b: &crate::compiler::syntax::ast::Bind) -> String {
    if b.is_path { pf.dir.join(&b.target).display().to_string() } else { b.target.clone() }
}

/// The laws of a problem with contact pairs (and perhaps an obstacle): the run's pair law (the
/// user's, the file's, else the library's default), each pair's (the user's, its block's, else
/// the run's), and the obstacle's (the user's, the file's, else the run's default).
fn contact_with_pairs(
    pf: &ProblemFile,
    methods: &mut Methods,
    user: Option<String>,
    file: Option<(String, &crate::compiler::syntax::ast::Bind)>,
) -> Result<(), CaseError> {
    use crate::compiler::Diagnostic;
    use crate::driver::pairs::{PairLaw, names_pair_law};
    let p = pf.problem();
    let obstacle = !super::bind::contact_free(pf);
    let user = match user {
        Some(law) => Some((names_pair_law(methods, &law)?, law)),
        None => None,
    };
    let file = match file {
        Some((law, b)) => Some((names_pair_law(methods, &law).map_err(|e| located(pf, b, e))?, law, b)),
        None => None,
    };
    let user_pair = user.as_ref().filter(|(pair, _)| *pair).map(|(_, law)| law.clone());
    let file_pair = file.as_ref().filter(|(pair, ..)| *pair).map(|(_, law, _)| law.clone());
    let run_pair = user_pair.clone().or(file_pair).unwrap_or_else(|| crate::settings::get().defaults.pair.clone());
    // An obstacle's law where no obstacle is: the pairs would be left without a law.
    let stray = |law: &str, at: Option<&crate::compiler::syntax::ast::Bind>, to: &str| {
        let message = format!("contact law `{law}` is an obstacle's, bound to {to}");
        let help = format!("a pair law reads the facing side (`opposite`): {}", crate::driver::pair_names().join(", "));
        match at {
            Some(b) => pf.render(
                Diagnostic::error("E0103", message, b.span, "an obstacle's law")
                    .with_note("a pair needs a pair law: an obstacle's law would leave it without force")
                    .with_help(help),
            ),
            None => CaseError::Option(format!("--contact: {message}; {help}")),
        }
    };
    if !obstacle {
        if let Some((false, law)) = &user {
            return Err(stray(law, None, "a problem whose contact is its pairs"));
        }
        if let (None, Some((false, law, b))) = (&user, &file) {
            return Err(stray(law, Some(b), "a problem whose contact is its pairs"));
        }
    }
    if obstacle {
        let user_obstacle = user.as_ref().filter(|(pair, _)| !*pair).map(|(_, law)| law.clone());
        let file_obstacle = file.as_ref().filter(|(pair, ..)| !*pair).map(|(_, law, _)| law.clone());
        if let Some(law) = user_obstacle.or(file_obstacle) {
            methods.contact = law;
        }
    }
    let mut groups = Vec::new();
    let shared: Vec<usize> =
        (0..p.pairs.len()).filter(|&k| p.pairs[k].binds.is_empty() && p.pairs[k].sets.is_empty()).collect();
    if !shared.is_empty() {
        let label = "the problem's pairs".to_string();
        groups.push(PairLaw { label, pairs: shared, law: run_pair.clone(), own: false });
    }
    for (k, pair) in p.pairs.iter().enumerate().filter(|(_, pair)| !pair.binds.is_empty() || !pair.sets.is_empty()) {
        let law = match (&user_pair, pair.binds.first()) {
            (Some(law), _) => law.clone(),
            (None, Some(b)) => {
                let law = bound_target(pf, b);
                if !names_pair_law(methods, &law).map_err(|e| located(pf, b, e))? {
                    return Err(stray(&law, Some(b), &format!("pair `{} with {}`", pair.own.name, pair.facing.name)));
                }
                law
            }
            (None, None) => run_pair.clone(),
        };
        let label = format!("{} with {}", pair.own.name, pair.facing.name);
        groups.push(PairLaw { label, pairs: vec![k], law, own: true });
    }
    if obstacle || groups.len() > 1 || groups.first().is_some_and(|g| g.own) {
        if !obstacle {
            methods.contact = groups[0].law.clone();
        }
        methods.pairs = groups;
    } else {
        // Every pair bound to the run's pair law: one law over all of them, as `contact`.
        methods.contact = run_pair;
    }
    Ok(())
}

/// An error about the law a `bind` line names, at that line.
fn located(pf: &ProblemFile, b: &crate::compiler::syntax::ast::Bind, e: CaseError) -> CaseError {
    use crate::compiler::Diagnostic;
    match e {
        CaseError::Option(message) => {
            pf.render(Diagnostic::error("E0101", "unknown contact law", b.span, "no such law").with_note(message))
        }
        other => other,
    }
}
