//! What a problem measures: series columns (row values, earlier columns, params, reducers over
//! regions, functionals) and summaries (reductions of the columns).

use super::catalogue::*;
use super::{scalar, unknown_among, vector};
use crate::check::types::Checker;
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::{Expr, Ident, Shape};

/// What a series column may name.
pub(super) struct RowScope<'a> {
    pub(super) constants: &'a [(String, Shape)],
    pub(super) pointwise: &'a [(String, Shape)],
    pub(super) regions: &'a [&'a str],
    pub(super) bodies: &'a [&'a str],
    pub(super) earlier: &'a [&'a str],
}

/// A series column: arithmetic of numbers, params, row values, earlier columns, reducers and
/// functionals.
pub(super) fn row(c: &mut Checker, e: &Expr, s: &RowScope, diags: &mut Vec<Diagnostic>) {
    use crate::syntax::ast::ExprKind as K;
    match &e.kind {
        K::Number(_) => {}
        K::Name(id) => {
            let known = s
                .constants
                .iter()
                .map(|(n, _)| n.as_str())
                .chain(ROW_VALUES.iter().map(|(n, _)| *n))
                .chain(s.earlier.iter().copied())
                .chain(["pi"]);
            if !known.clone().any(|n| n == id.name) {
                diags.push(unknown_among(id, known, "row value").with_note(row_help()));
            }
        }
        K::Neg(a) => row(c, a, s, diags),
        K::Binary(_, a, b) => {
            row(c, a, s, diags);
            row(c, b, s, diags);
        }
        K::Index(a, i) => {
            let is_force = matches!(&a.kind, K::Call(f, _) if f.name == "force");
            if !is_force {
                diags.push(Diagnostic::error("E0301", "shape mismatch", a.span, "only `force(SLOT)` is a vector here"));
            } else if !crate::check::const_value(i).is_some_and(|k| k >= 0.0 && k.fract() == 0.0 && k < 3.0) {
                diags.push(Diagnostic::error("E0302", "a component index must be 0, 1 or 2", i.span, "not one"));
            }
            row(c, a, s, diags);
        }
        K::Vector(_) => diags.push(Diagnostic::error("E0301", "shape mismatch", e.span, "a series column is a number")),
        K::Call(f, args) => reducer(c, e, f, args, s, diags),
    }
}

/// E0201: call `e` of `f` with `given` arguments, not `want`; `usage` shows how to write it.
fn arity_error(f: &Ident, e: &Expr, want: usize, given: usize, usage: &str) -> Diagnostic {
    Diagnostic::error("E0201", format!("`{}` takes {want} argument(s)", f.name), e.span, format!("{given} given"))
        .with_help(format!("write `{usage}`"))
}

fn row_help() -> String {
    let values: Vec<&str> = ROW_VALUES.iter().map(|(n, _)| *n).collect();
    let reducers: Vec<&str> = ROW_REDUCERS.iter().map(|r| r.usage).collect();
    format!(
        "a column reads the row values ({}), earlier columns, params, and reducers: {}, or a functional `{FUNCTIONAL_CALL}` (also at {}), with arithmetic and {}",
        values.join(", "),
        reducers.join(", "),
        FUNCTIONAL_STATES.iter().skip(1).map(|(s, _)| *s).collect::<Vec<_>>().join(", "),
        row_function_names().join(", ")
    )
}

fn reducer(c: &mut Checker, e: &Expr, f: &Ident, args: &[Expr], s: &RowScope, diags: &mut Vec<Diagnostic>) {
    use crate::syntax::ast::ExprKind as K;
    let arity = |want: usize, diags: &mut Vec<Diagnostic>| {
        if args.len() != want {
            let usage = row_reducer(&f.name).map_or(FUNCTIONAL_CALL, |r| r.usage);
            diags.push(arity_error(f, e, want, args.len(), usage));
            return false;
        }
        true
    };
    // `u[k]` or `v[k]`.
    let component = |a: &Expr, diags: &mut Vec<Diagnostic>| {
        let ok = matches!(&a.kind, K::Index(b, i) if matches!(&b.kind, K::Name(n) if n.name == "u" || n.name == "v")
            && crate::check::const_value(i).is_some_and(|k| k >= 0.0 && k.fract() == 0.0 && k < 3.0));
        if !ok {
            diags.push(
                Diagnostic::error("E0301", "shape mismatch", a.span, "a component of a field is needed here")
                    .with_help("write `u[1]` or `v[0]`"),
            );
        }
    };
    let region = |a: &Expr, diags: &mut Vec<Diagnostic>| match &a.kind {
        K::Name(id) if s.regions.contains(&id.name.as_str()) => {}
        K::Name(id) => diags.push(unknown_among(id, s.regions.iter().copied(), "region")),
        _ => diags.push(Diagnostic::error("E0301", "shape mismatch", a.span, "a region's name is needed here")),
    };
    use RowReducer as R;
    match row_reducer(&f.name).map(|r| r.kind) {
        None if let Some(b) = row_function(&f.name) => {
            if arity(b.arity, diags) {
                args.iter().for_each(|a| row(c, a, s, diags));
            }
        }
        Some(R::Mean | R::NodalMean) => {
            // mean(u[k]) over every body, mean(u[k], BODY) over one.
            if args.len() == 2 {
                match &args[1].kind {
                    K::Name(id) if s.bodies.contains(&id.name.as_str()) => {}
                    K::Name(id) => diags.push(unknown_among(id, s.bodies.iter().copied(), "body")),
                    _ => diags.push(Diagnostic::error(
                        "E0301",
                        "shape mismatch",
                        args[1].span,
                        "a body's name is needed here",
                    )),
                }
                component(&args[0], diags);
            } else if arity(1, diags) {
                component(&args[0], diags);
            }
        }
        Some(R::AtMin) => {
            if arity(2, diags) {
                component(&args[0], diags);
                scalar(c, &args[1], s.constants, diags, false);
            }
        }
        Some(R::Force) => {
            // force(SLOT) over the mesh, force(SLOT, REGION) over the region's nodes,
            // force(SLOT, BODY) over the body's.
            if args.len() == 2 {
                match &args[1].kind {
                    K::Name(id) if s.bodies.contains(&id.name.as_str()) => {}
                    _ => region(&args[1], diags),
                }
            } else if !arity(1, diags) {
                return;
            }
            if !matches!(&args[0].kind, K::Name(_)) {
                diags.push(Diagnostic::error("E0301", "shape mismatch", args[0].span, "a slot's name is needed here"));
            }
        }
        Some(R::Work) => {
            if arity(1, diags) && !matches!(&args[0].kind, K::Name(_)) {
                diags.push(Diagnostic::error("E0301", "shape mismatch", args[0].span, "a slot's name is needed here"));
            }
        }
        Some(R::InnerMass) => {
            if arity(2, diags) {
                vector(c, &args[0], s.pointwise, diags);
                vector(c, &args[1], s.pointwise, diags);
            }
        }
        Some(R::Measure | R::Peak) => {
            if arity(2, diags) {
                region(&args[0], diags);
                scalar(c, &args[1], s.pointwise, diags, false);
            }
        }
        Some(R::Cumulative | R::Initial) => {
            if arity(1, diags) {
                match &args[0].kind {
                    K::Name(id) if s.earlier.contains(&id.name.as_str()) => {}
                    K::Name(id) => diags.push(unknown_among(id, s.earlier.iter().copied(), "earlier column")),
                    _ => diags.push(
                        Diagnostic::error(
                            "E0301",
                            "shape mismatch",
                            args[0].span,
                            "an earlier column's name is needed here",
                        )
                        .with_help(format!(
                            "name the column: `series dissipated = friction_work(u, u_prev)`, then `{}(dissipated)`",
                            f.name
                        )),
                    ),
                }
            }
        }
        Some(R::DensityMin | R::DensityMax | R::DensitySupport) => {
            let functional = |a: &Expr| {
                matches!(&a.kind, K::Call(_, xs) if xs.len() == 1
                && matches!(&xs[0].kind, K::Name(n) if n.name == "u"))
            };
            if arity(1, diags) && !functional(&args[0]) {
                diags.push(
                    Diagnostic::error("E0301", "shape mismatch", args[0].span, "a functional of u is needed here")
                        .with_help(format!("write `{}(contact_pressure(u))`", f.name)),
                );
            }
        }
        None => {
            let state = |n: &str| FUNCTIONAL_STATES.iter().any(|(s, _)| *s == n);
            let fields = args.iter().all(|a| matches!(&a.kind, K::Name(n) if state(&n.name)));
            if args.is_empty() || !fields {
                diags.push(
                    Diagnostic::error(
                        "E0201",
                        format!("`{}` is not a reducer", f.name),
                        e.span,
                        "nor a functional of u",
                    )
                    .with_help(row_help()),
                );
            }
        }
    }
}

/// What a summary key may name.
pub(super) struct SummaryScope<'a> {
    /// The series' columns and `t`: read per row, inside a reducer.
    pub(super) columns: &'a [&'a str],
    /// The summary keys before this one.
    pub(super) keys: &'a [&'a str],
    pub(super) constants: &'a [(String, Shape)],
}

/// A summary key: arithmetic of numbers, params, earlier keys, functions and reducers, whose
/// arguments (`in_row`) read the row's columns too.
pub(super) fn summary(e: &Expr, s: &SummaryScope, in_row: bool, diags: &mut Vec<Diagnostic>) {
    use crate::syntax::ast::ExprKind as K;
    match &e.kind {
        K::Number(_) => {}
        K::Name(id) => {
            let columns = s.columns.iter().copied().filter(|_| in_row);
            let known =
                s.constants.iter().map(|(n, _)| n.as_str()).chain(s.keys.iter().copied()).chain(columns).chain(["pi"]);
            if !known.clone().any(|n| n == id.name) {
                let mut d = unknown_among(id, known, if in_row { "column" } else { "name" });
                d = if s.columns.contains(&id.name.as_str()) {
                    d.with_help(format!("a column is read through a reducer: `max({})`", id.name))
                } else {
                    d.with_note(summary_help())
                };
                diags.push(d);
            }
        }
        K::Neg(a) => summary(a, s, in_row, diags),
        K::Binary(_, a, b) => {
            summary(a, s, in_row, diags);
            summary(b, s, in_row, diags);
        }
        K::Call(f, args) => {
            // Inside a reducer's argument (a value of one row) `min` and `max` of two are
            // functions; of one, the reducer nested.
            let nested = in_row && args.len() == 1;
            let reducer = summary_reducer(&f.name).filter(|_| nested || !in_row || row_function(&f.name).is_none());
            let (want, usage) = match (reducer, row_function(&f.name)) {
                (Some(r), _) => (args.len().clamp(r.arity.0, r.arity.1), r.usage),
                (None, Some(b)) => (b.arity, ""),
                (None, None) => {
                    let mut known: Vec<&str> = SUMMARY_REDUCERS.iter().map(|r| r.name).collect();
                    for n in row_function_names() {
                        if !known.contains(&n) {
                            known.push(n);
                        }
                    }
                    diags.push(unknown_among(f, known.into_iter(), "summary function"));
                    return;
                }
            };
            let reducer = !usage.is_empty();
            if reducer && in_row {
                let mut d =
                    Diagnostic::error("E0201", format!("`{}` inside a reducer", f.name), e.span, "a reducer of a row")
                        .with_help("a reducer's argument is a value of one row: reduce it once");
                if row_function(&f.name).is_some() {
                    d = d.with_note(format!("inside a reducer, `{}(a, b)` of two values is the function", f.name));
                }
                diags.push(d);
            } else if args.len() != want {
                let usage = if reducer {
                    usage.to_string()
                } else {
                    row_function(&f.name).map_or(String::new(), |b| b.doc.split(':').next().unwrap_or("").to_string())
                };
                diags.push(arity_error(f, e, want, args.len(), &usage));
            } else {
                args.iter().for_each(|a| summary(a, s, in_row || reducer, diags));
            }
        }
        K::Index(..) | K::Vector(_) => diags.push(
            Diagnostic::error("E0301", "shape mismatch", e.span, "a summary value is a number")
                .with_help(summary_help()),
        ),
    }
}

fn summary_help() -> String {
    let reducers: Vec<&str> = SUMMARY_REDUCERS.iter().map(|r| r.usage).collect();
    format!(
        "a summary reduces expressions of the columns: {}; it may apply {} and read the keys before it",
        reducers.join(", "),
        row_function_names().join(", ")
    )
}
