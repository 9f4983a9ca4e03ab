//! Static checks: names, arity, shapes, linearity in the test function, geometry in volume
//! integrals, parameter ranges, imports. All errors of a unit are collected; nothing panics.
//!
//! Checking evaluates every form abstractly: user functions are inlined at each call with the
//! abstract values of their arguments, so a mistake that depends on how a function is used
//! (a test function passed into `pos`) is reported inside the function, with the call site.

pub mod builtins;
pub mod load;
pub mod problem;
pub mod schemes;
mod types;

use std::collections::{BTreeSet, HashMap, HashSet};

use signorini_descriptors::ParamRange;

use crate::diagnostic::Diagnostic;
use crate::source::{FileId, SourceMap, Span};
use crate::syntax::ast::{self, Expr, Ident, Shape};

pub use builtins::{BUILTIN_VALUES, BUILTINS, Builtin, builtin};
pub use schemes::{CLAIMS, EnergyLaw, SchemeDef, SchemeParamInfo};
pub use types::{Ty, const_eval};

/// The value of a constant expression, if it is one.
pub fn const_value(e: &Expr) -> Option<f64> {
    const_eval(e).ok()
}

/// A checked compilation unit: the root file and its imports. Its schemes are declared, not
/// yet compiled (the pipeline compiles them; `crate::Program` holds the result).
pub struct Unit {
    pub sources: SourceMap,
    pub root: FileId,
    pub params: Vec<Param>,
    pub coefs: Vec<Coef>,
    pub forms: Vec<Form>,
    /// Time schemes as written (`Global::Scheme` indexes them).
    pub scheme_defs: Vec<SchemeDef>,
    /// Problems as written (`Global::Problem` indexes them).
    pub problems: Vec<ast::Problem>,
    pub globals: HashMap<String, Global>,
    /// Warnings (errors make `check` return `Err`).
    pub warnings: Vec<Diagnostic>,
    /// The roles its files import (`import material = elasticity`), each once, in the order
    /// of loading (set by the loader, which resolves them).
    pub roles: Vec<Role>,
}

/// A role a unit imports (`import material = elasticity`): the run may bind a file to it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Role {
    pub name: String,
    /// The stem of the file the import names, read when nothing is bound to the role.
    pub default: String,
    /// The stem of the file read for it in this unit.
    pub read: String,
}

#[derive(Clone, Debug)]
pub struct Param {
    pub name: String,
    pub default: f64,
    pub range: Option<ParamRange>,
    pub span: Span,
    pub name_span: Span,
    /// The default and range as written; `default` and `range` are their values.
    pub default_expr: Expr,
    pub range_expr: Option<ast::Range>,
}

#[derive(Clone, Debug)]
pub struct Coef {
    pub name: String,
    pub shape: Shape,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct Form {
    pub name: String,
    pub fields: Vec<Ident>,
    /// The test function; `None` for a functional.
    pub test: Option<Ident>,
    pub integrals: Vec<ast::Integral>,
    pub span: Span,
}

/// What a global name refers to.
#[derive(Clone, Debug)]
pub enum Global {
    Param(usize),
    Coef(usize),
    Let { value: Expr, span: Span },
    Fn { params: Vec<Ident>, body: Expr, span: Span },
    Form(usize),
    Scheme(usize),
    Problem(usize),
}

impl Global {
    pub(crate) fn span(&self, prog_params: &[Param], coefs: &[Coef], forms: &[Form]) -> Span {
        match self {
            Global::Param(i) => prog_params[*i].span,
            Global::Coef(i) => coefs[*i].span,
            Global::Let { span, .. } | Global::Fn { span, .. } => *span,
            Global::Form(i) => forms[*i].span,
            Global::Scheme(_) | Global::Problem(_) => Span::new(0, 0, 0),
        }
    }

    pub(crate) fn kind(&self) -> &'static str {
        match self {
            Global::Param(_) => "param",
            Global::Coef(_) => "coef",
            Global::Let { .. } => "let",
            Global::Fn { .. } => "fn",
            Global::Form(_) => "form",
            Global::Scheme(_) => "scheme",
            Global::Problem(_) => "problem",
        }
    }
}

/// E0207: a vector literal or a component outside a problem.
pub fn problem_only(span: Span) -> Diagnostic {
    Diagnostic::error(
        "E0207",
        "vector literals and components need a known dimension",
        span,
        "only a problem's expressions may write `[a, b]` or `x[1]`",
    )
    .with_help("a form serves every dimension: use `dot(a, b)`, `outer`, or a `coef: vector` the problem sets")
}

/// A declared range as written (`[0, 1/3]`, without its `in`), its runs of whitespace made
/// single spaces.
pub fn range_written(sources: &SourceMap, r: &ast::Range) -> String {
    let text = sources.slice(r.span).trim_start();
    let text = text.strip_prefix("in").unwrap_or(text);
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The region name of volume integrals.
pub const CELL_REGION: &str = "Omega";

/// The names whose declaration has a syntax error (already reported): uses of them are not
/// reported again, and a scheme among them is not compiled.
pub fn broken_names(files: &[(FileId, ast::File)]) -> HashSet<String> {
    files.iter().flat_map(|(_, f)| f.broken_names.iter().cloned()).collect()
}

/// Checks a loaded unit (`load::load`); `diags` holds what loading found (syntax errors,
/// missing imports). Returns the unit and every diagnostic found, errors and warnings, not
/// yet in source order (`diagnostic::normalize`). Schemes are declared, not compiled.
pub fn check(
    sources: SourceMap,
    root: FileId,
    files: &[(FileId, ast::File)],
    mut diags: Vec<Diagnostic>,
) -> (Unit, Vec<Diagnostic>) {
    let mut prog = Unit {
        sources,
        root,
        params: Vec::new(),
        coefs: Vec::new(),
        forms: Vec::new(),
        scheme_defs: Vec::new(),
        problems: Vec::new(),
        globals: HashMap::new(),
        warnings: Vec::new(),
        roles: Vec::new(),
    };
    let broken = broken_names(files);
    declare(&mut prog, files, &mut diags);
    shadowing(&prog, files, &mut diags);
    let used = {
        let mut c = types::Checker::new(&prog, &broken);
        let values = c.check_params();
        c.check_lets_and_fns();
        c.check_forms();
        let used = c.used_params.clone();
        for p in &prog.problems {
            problem::check(&mut c, p, &mut diags);
        }
        diags.append(&mut c.diags);
        for (p, (default, range)) in prog.params.iter_mut().zip(values) {
            p.default = default.unwrap_or(f64::NAN);
            p.range = range;
        }
        used
    };
    // Unused-parameter warnings only for a unit without errors: a form that failed to check
    // has not recorded what it uses.
    let has_errors = diags.iter().any(Diagnostic::is_error);
    for (i, p) in prog.params.iter().enumerate() {
        if !has_errors && p.span.file == prog.root && !used.contains(&i) {
            diags.push(
                Diagnostic::warning(
                    "W0001",
                    format!("unused param `{}`", p.name),
                    p.name_span,
                    "no form uses this parameter",
                )
                .with_help("remove it, or use it in a form"),
            );
        }
    }
    (prog, diags)
}

/// Arguments of a `fn` or a `form` named like a global of the unit (a param, a let, ...):
/// inside, the argument wins, which is rarely what was meant. A warning at both.
fn shadowing(prog: &Unit, files: &[(FileId, ast::File)], diags: &mut Vec<Diagnostic>) {
    for (file, ast) in files {
        if *file != prog.root {
            continue;
        }
        for item in &ast.items {
            let (what, args): (&str, Vec<&Ident>) = match item {
                ast::Item::Fn { params, .. } => ("fn", params.iter().collect()),
                ast::Item::Form { fields, test, .. } => ("form", fields.iter().chain(test).collect()),
                _ => continue,
            };
            for a in args {
                let Some(g) = prog.globals.get(&a.name) else { continue };
                let at = g.span(&prog.params, &prog.coefs, &prog.forms);
                let mut w = Diagnostic::warning(
                    "W0003",
                    format!("the {what} argument `{}` hides the {} `{}`", a.name, g.kind(), a.name),
                    a.span,
                    "this argument hides it",
                )
                .with_help(format!("rename the argument if `{}` should keep its meaning inside", a.name));
                if at.end > at.start {
                    w = w.with_label(at, "declared here");
                }
                diags.push(w);
            }
        }
    }
}

/// Builds the global name table; duplicate names and built-in names are errors.
fn declare(prog: &mut Unit, files: &[(FileId, ast::File)], diags: &mut Vec<Diagnostic>) {
    let mut first: HashMap<String, Span> = HashMap::new();
    for (_, file) in files {
        for item in &file.items {
            let Some(name) = item.name() else { continue };
            if BUILTIN_VALUES.iter().copied().chain(builtins::function_names()).any(|b| b == name.name)
                || name.name == CELL_REGION
            {
                diags.push(
                    Diagnostic::error(
                        "E0106",
                        format!("`{}` is a built-in name", name.name),
                        name.span,
                        "cannot be redefined",
                    )
                    .with_help("choose another name"),
                );
                continue;
            }
            if let Some(prev) = first.get(&name.name) {
                diags.push(
                    Diagnostic::error(
                        "E0102",
                        format!("`{}` is defined twice", name.name),
                        name.span,
                        "defined again here",
                    )
                    .with_label(*prev, "first defined here"),
                );
                continue;
            }
            first.insert(name.name.clone(), name.span);
            let global = match item {
                ast::Item::Param { name, default, range, span } => {
                    prog.params.push(Param {
                        name: name.name.clone(),
                        default: f64::NAN,
                        range: None,
                        span: *span,
                        name_span: name.span,
                        default_expr: default.clone(),
                        range_expr: range.clone(),
                    });
                    Global::Param(prog.params.len() - 1)
                }
                ast::Item::Coef { name, shape, span } => {
                    prog.coefs.push(Coef { name: name.name.clone(), shape: *shape, span: *span });
                    Global::Coef(prog.coefs.len() - 1)
                }
                ast::Item::Let { value, span, .. } => Global::Let { value: value.clone(), span: *span },
                ast::Item::Fn { params, body, span, .. } => {
                    check_distinct(params, "parameter", diags);
                    Global::Fn { params: params.clone(), body: body.clone(), span: *span }
                }
                ast::Item::Form { name, fields, test, integrals, span } => {
                    let mut args = fields.clone();
                    args.extend(test.clone());
                    check_distinct(&args, "argument", diags);
                    prog.forms.push(Form {
                        name: name.name.clone(),
                        fields: fields.clone(),
                        test: test.clone(),
                        integrals: integrals.clone(),
                        span: *span,
                    });
                    Global::Form(prog.forms.len() - 1)
                }
                ast::Item::Scheme { name, params, uses, states, lets, initial, claims, estimates, stages, span } => {
                    prog.scheme_defs.push(SchemeDef {
                        name: name.clone(),
                        params: params.clone(),
                        uses: uses.clone(),
                        states: states.clone(),
                        lets: lets.clone(),
                        initial: initial.clone(),
                        claims: claims.clone(),
                        estimates: estimates.clone(),
                        stages: stages.clone(),
                        span: *span,
                    });
                    Global::Scheme(prog.scheme_defs.len() - 1)
                }
                ast::Item::Problem(p) => {
                    // Its `fn`s expanded where they are called: the problem as checked and run.
                    prog.problems.push(problem::expand_fns(p, diags));
                    Global::Problem(prog.problems.len() - 1)
                }
                ast::Item::Import { .. } => continue,
            };
            prog.globals.insert(name.name.clone(), global);
        }
    }
}

fn check_distinct(names: &[Ident], what: &str, diags: &mut Vec<Diagnostic>) {
    let mut seen: HashMap<&str, Span> = HashMap::new();
    for n in names {
        if let Some(prev) = seen.get(n.name.as_str()) {
            diags.push(
                Diagnostic::error("E0103", format!("duplicate {what} `{}`", n.name), n.span, "repeated here")
                    .with_label(*prev, "first here"),
            );
        } else {
            seen.insert(&n.name, n.span);
        }
        if BUILTIN_VALUES.contains(&n.name.as_str()) {
            diags.push(
                Diagnostic::error(
                    "E0106",
                    format!("`{}` is a built-in name", n.name),
                    n.span,
                    "cannot be used as a name here",
                )
                .with_help("choose another name"),
            );
        }
    }
}

/// Names visible everywhere, for "did you mean" suggestions.
pub fn suggest_name<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<String> {
    // At equal distance, a name that differs only in case is the likelier one.
    candidates
        .filter(|c| *c != name)
        .map(|c| (strsim::damerau_levenshtein(name, c), !c.eq_ignore_ascii_case(name), c))
        .filter(|(d, _, c)| *d <= 1.max(name.len() / 3) && *d < c.len())
        .min()
        .map(|(_, _, c)| c.to_string())
}

/// Used params, as a set of indices.
pub type ParamSet = BTreeSet<usize>;
