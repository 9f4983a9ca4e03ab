//! `run`: a problem by name or file with the options of the command line, every scheme ×
//! contact law × mass matrix of it (`--all`), or a case file.

use std::path::Path;
use std::process::ExitCode;

use super::args::ProblemArgs;
use super::summary::{all_header, all_row, finish};
use super::{fail, out_dir};
use crate::driver::{Methods, Setting};
use crate::simulation::MassChoice;

pub(super) fn problem(problem: &str, a: ProblemArgs) -> ExitCode {
    if !a.all {
        return match options(problem, a, super::force()) {
            Ok(opts) => finish(crate::problem::run::run(&opts)),
            Err(e) => fail(e),
        };
    }
    let methods = match a.methods.to_methods() {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    if a.checkpoint.checkpoint_every > 0 || a.checkpoint.resume.is_some() {
        return fail("--all runs many cases: it takes no --checkpoint-every or --resume");
    }
    let mut opts = crate::problem::run::Options::new(problem);
    opts.mesh = a.mesh;
    opts.dt = a.dt;
    opts.t_start = a.t_start;
    opts.t_end = a.t_end;
    opts.steps = a.steps.options();
    opts.cell_size = a.methods.cell_size;
    opts.newton.solver = a.solver;
    opts.petsc_options = a.petsc_options;
    opts.newton.line_search = a.methods.line_search;
    opts.vtu_every = a.vtu_every;
    opts.chosen.material = a.methods.material.is_some();
    opts.out = match out_dir(a.out) {
        Ok(dir) => dir,
        Err(e) => return fail(e),
    };
    all(opts, methods)
}

/// The options of one run of `problem` (not `--all`) as the command line asks for them, its
/// output directory to be prepared with `force` when the run starts.
pub(super) fn options(problem: &str, a: ProblemArgs, force: bool) -> Result<crate::problem::run::Options, String> {
    let methods = a.methods.to_methods()?;
    let (out, fresh) = a.checkpoint.out(a.out)?;
    Ok(crate::problem::run::Options {
        problem: problem.to_string(),
        methods,
        mass: a.mass,
        cell_size: a.methods.cell_size,
        mesh: a.mesh,
        dt: a.dt,
        t_start: a.t_start,
        t_end: a.t_end,
        steps: a.steps.options(),
        newton: crate::runtime::nonlinear::newton::NewtonOptions {
            solver: a.solver,
            line_search: a.methods.line_search,
            chord: a.methods.chord,
            ..Default::default()
        },
        petsc_options: a.petsc_options,
        out,
        out_fresh: fresh.then_some(force),
        vtu_every: a.vtu_every,
        progress: true,
        checkpoint_every: a.checkpoint.checkpoint_every,
        resume: a.checkpoint.resume.is_some(),
        chosen: crate::problem::run::Chosen {
            scheme: a.methods.scheme.is_some(),
            contact: a.methods.contact.is_some(),
            material: a.methods.material.is_some(),
        },
        keep_fields: false,
    })
}

/// `run PROBLEM --all`: every scheme × contact law × mass matrix, one line each with the
/// problem's own summary keys.
fn all(base: crate::problem::run::Options, methods: Methods) -> ExitCode {
    // The masses of the implicit schemes' comparison (lumped is for explicit ones).
    let masses = [MassChoice::Consistent, MassChoice::Redistributed].map(|m| (m, m.name()));
    // The problem's own params (`ne`, or `bar.ne`) apply to every run: checked once.
    let rest = match crate::problem::load(&base.problem).and_then(|pf| crate::problem::params(&pf, &methods.params)) {
        Ok((_, rest)) => rest,
        Err(e) => return fail(e),
    };
    // A file's param applies to the runs whose files declare it (alpha to hht, not newmark);
    // one that no run takes is misspelt or out of range everywhere: an error, not a silent drop.
    let combinations: Vec<(&str, &str)> = crate::driver::all_schemes()
        .into_iter()
        .flat_map(|s| crate::driver::contact_names().into_iter().map(move |c| (s, c)))
        .collect();
    let takes = |scheme: &str, contact: &str, p: &Setting| {
        let probe =
            Methods { scheme: scheme.into(), contact: contact.into(), params: vec![p.clone()], ..methods.clone() };
        crate::driver::FilesInUse::resolve(&probe, &[])
    };
    for p in &rest {
        let results: Vec<_> = combinations.iter().map(|(s, c)| takes(s, c, p)).collect();
        if results.iter().all(Result::is_err) {
            // Out of range where it is declared says more than unknown where it is not.
            let errors: Vec<String> = results.into_iter().filter_map(Result::err).map(|e| e.to_string()).collect();
            let why = errors.iter().find(|e| !e.contains("unknown param")).or(errors.last());
            return fail(format!("{} applies to none of the runs: {}", p.origin, why.map_or("", |e| e.as_str())));
        }
    }
    let mut header: Option<Vec<String>> = None;
    let mut failed = false;
    for (scheme, contact) in combinations.iter().copied() {
        for (mass, mass_name) in masses {
            let params: Vec<Setting> = methods
                .params
                .iter()
                .filter(|p| !rest.contains(p) || takes(scheme, contact, p).is_ok())
                .cloned()
                .collect();
            let label = format!("{scheme}_{contact}_{mass_name}");
            let opts = crate::problem::run::Options {
                methods: Methods { scheme: scheme.into(), contact: contact.into(), params, ..methods.clone() },
                mass,
                out: base.out.as_ref().map(|d| d.join(&label)),
                chosen: crate::problem::run::Chosen { scheme: true, contact: true, ..base.chosen },
                ..base.clone()
            };
            match crate::problem::run::run(&opts) {
                Ok(r) => {
                    let keys = header.get_or_insert_with(|| all_header(&r.summary));
                    println!("{}", all_row(&r.summary, keys, scheme, contact, mass_name));
                }
                // A frictional law on a 1D problem: no combination to run.
                Err(crate::error::CaseError::NoTangentSpace(_)) => {}
                Err(e) => {
                    println!("{scheme:<15} {contact:<16} {mass_name:<13} failed: {e}");
                    failed = true;
                }
            }
        }
    }
    if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

pub(super) fn case_file(file: &Path) -> ExitCode {
    match case_options(file, super::force()) {
        Ok(opts) => finish(crate::problem::run::run(&opts)),
        Err(e) => {
            super::print_error(e);
            ExitCode::FAILURE
        }
    }
}

/// A case file's options; its output directory (`results/STEM` unless it names one) is
/// prepared with `force` when the run starts (a refused case writes nothing).
pub(super) fn case_options(file: &Path, force: bool) -> Result<crate::problem::run::Options, crate::error::CaseError> {
    use crate::cases::file;
    let mut opts = file::read(file)?;
    opts.out = Some(opts.out.take().unwrap_or_else(|| file::default_out(file)));
    opts.out_fresh = Some(force);
    opts.progress = true;
    Ok(opts)
}
