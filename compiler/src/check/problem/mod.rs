//! Checks of a `problem` item that need no mesh and no bound files: its params, one mesh, a
//! known generator or obstacle helper with its arguments, distinct names, the run and
//! quadrature settings, and the shape of every expression with the names its place allows
//! (`x` and `t` in coefs and fields, `n` in region predicates). What depends on the mesh (its
//! groups, empty regions, the dimension) or on the files bound to the slots (unset coefs,
//! observables) is checked when the problem is bound (`signorini check` does both).
//!
//! `catalogue` is the vocabulary a problem may use, `measures` the checks of its series and
//! summary.

mod bodies;
mod catalogue;
mod fns;
mod measures;
mod pairs;

use std::collections::HashMap;

pub use catalogue::*;
pub(in crate::check) use fns::expand as expand_fns;
use measures::{RowScope, SummaryScope, row, summary};

use super::types::Checker;
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{
    Defined, Dirichlet, Expr, HeldAt, Ident, MeshSource, NamedCall, Problem, RegionSource, Shape,
};

use Shape::{Scalar, Vector};

/// Names with their shapes, as an expression of the problem sees them.
type Names = [(String, Shape)];

pub(in crate::check) fn check(c: &mut Checker, p: &Problem, diags: &mut Vec<Diagnostic>) {
    let constants = params_and_lets(c, p, diags);
    mesh(c, p, &constants, diags);
    bodies::check(c, p, &constants, diags);
    region_predicates(c, p, &constants, diags);
    bindings(p, diags);
    settings_of_the_run(c, p, &constants, diags);
    let fields = &constants;
    distinct(p.coefs.iter().map(|d| &d.name), "coef", diags);
    for d in &p.coefs {
        expression(c, &d.value, fields, diags, false);
    }
    initial_fields(c, &p.initial, fields, true, diags);
    let regions: Vec<&str> = p.regions.iter().map(|r| r.name.name.as_str()).collect();
    dirichlet(c, p, fields, &regions, diags);
    neumann(c, p, fields, &regions, diags);
    obstacles(c, p, fields, &regions, diags);
    pairs::check(c, p, &constants, diags);
    measures(c, p, &constants, &regions, diags);
}

/// `initial u = ...`, `initial v = ...`: known fields, each once, vectors of `x` and `t`; the
/// displacement may be `settled(GUESS)` where `settles` (the problem's, not a body's).
fn initial_fields(c: &mut Checker, list: &[Defined], fields: &Names, settles: bool, diags: &mut Vec<Diagnostic>) {
    distinct(list.iter().map(|d| &d.name), "initial field", diags);
    for d in list {
        if !INITIAL_FIELDS.contains(&d.name.name.as_str()) {
            diags.push(unknown_among(&d.name, INITIAL_FIELDS.iter().copied(), "initial field"));
        }
        match catalogue::settled_guess(&d.value) {
            Some(_) if !settles => diags.push(
                Diagnostic::error("E0301", "a body's displacement does not settle alone", d.value.span, "in a body")
                    .with_help("write `initial u = settled(GUESS)` at the problem's level: the bodies settle together"),
            ),
            Some([guess]) if d.name.name == "u" => vector(c, guess, fields, diags),
            Some(args) if d.name.name == "u" => diags.push(
                Diagnostic::error(
                    "E0201",
                    "`settled` takes 1 argument(s)",
                    d.value.span,
                    format!("{} given", args.len()),
                )
                .with_help("write `initial u = settled([0, -1e-4])`: the guess Newton starts from"),
            ),
            Some(_) => diags.push(
                Diagnostic::error("E0301", "only the displacement settles", d.value.span, "not a displacement")
                    .with_help("write `initial u = settled(GUESS)`; the velocity is given as it is"),
            ),
            None => vector(c, &d.value, fields, diags),
        }
    }
}

/// The params (constants with a default in their range, as a scheme's) and the lets, in order,
/// each seeing the ones before: the names every later expression sees.
fn params_and_lets(c: &mut Checker, p: &Problem, diags: &mut Vec<Diagnostic>) -> Vec<(String, Shape)> {
    let mut names: Vec<(String, Shape)> = p.params.iter().map(|q| (q.name.name.clone(), Scalar)).collect();
    distinct(p.params.iter().map(|q| &q.name), "parameter", diags);
    // A param named like a built-in value would hide it (`n`, the normal in region predicates).
    // `h` stays a param's name: problems read no cell size.
    for q in p.params.iter().map(|q| &q.name).chain(p.lets.iter().map(|l| &l.name)) {
        if ["x", "t", "n", "pi"].contains(&q.name.as_str()) || crate::check::builtins::builtin(&q.name).is_some() {
            diags.push(
                Diagnostic::error("E0106", format!("`{}` is a built-in name", q.name), q.span, "would hide it")
                    .with_note("x is the position, t the time, n the facet normal, pi is π; the functions (sin, max, ...) are the language's")
                    .with_help("give it another name"),
            );
        }
    }
    for q in &p.params {
        c.problem_ty(&q.default, &[]);
    }
    distinct(p.lets.iter().map(|d| &d.name), "let", diags);
    for d in &p.lets {
        let shape = expression(c, &d.value, &names.clone(), diags, false).unwrap_or(Scalar);
        names.push((d.name.name.clone(), shape));
    }
    names
}

/// One mesh: a file, or a known generator with its arguments (or none, when every body is a
/// generator's).
fn mesh(c: &mut Checker, p: &Problem, constants: &Names, diags: &mut Vec<Diagnostic>) {
    match p.mesh.as_slice() {
        // A body that is a group needs a file: the bodies' check says so.
        [] if !p.bodies.is_empty() => {}
        [] => diags.push(
            Diagnostic::error("E0901", format!("problem `{}` has no mesh", p.name.name), p.name.span, "no `mesh` line")
                .with_help("add `mesh \"body.msh\"` (a Gmsh file beside the problem) or a generator such as `mesh disc(radius = 10, centre = [0, 12], h = 1)`"),
        ),
        [MeshSource::Generator(call)] => builtin_call(c, call, GENERATORS, "mesh generator", constants, diags),
        [_] => {}
        [_, second, ..] => {
            let span = match second {
                MeshSource::File { span, .. } => *span,
                MeshSource::Generator(call) => call.span,
            };
            diags.push(Diagnostic::error("E0102", "a problem has one mesh", span, "second `mesh`"));
        }
    }
}

/// Distinct region names; their predicates are scalars that may read `n`.
fn region_predicates(c: &mut Checker, p: &Problem, constants: &Names, diags: &mut Vec<Diagnostic>) {
    distinct(p.regions.iter().map(|r| &r.name), "region", diags);
    // `x` and `t` are built-in names; `n` too, but it means something only on a facet.
    for (i, r) in p.regions.iter().enumerate() {
        let earlier: Vec<&str> = p.regions[..i].iter().map(|r| r.name.name.as_str()).collect();
        for s in &r.sources {
            region_source(c, s, constants, &earlier, diags);
        }
    }
}

/// A region's source: its predicates' comparisons are scalars of `x` and `n`; a region it names
/// is an earlier one.
fn region_source(c: &mut Checker, s: &RegionSource, constants: &Names, earlier: &[&str], diags: &mut Vec<Diagnostic>) {
    match s {
        RegionSource::Boundary { condition, .. } | RegionSource::Group { condition, .. } => {
            for cmp in condition.iter().flat_map(|c| c.comparisons()) {
                for side in [&cmp.lhs, &cmp.rhs] {
                    // A region's name in a predicate: the union's `+` was read as arithmetic.
                    if let Some(id) = names_in(side).into_iter().find(|id| earlier.contains(&id.name.as_str())) {
                        diags.push(
                            Diagnostic::error(
                                "E0301",
                                format!("region `{}` inside a predicate", id.name),
                                id.span,
                                "a region, not a number",
                            )
                            .with_help(format!(
                                "to join it, parenthesise the part before: `(boundary where ...) + {}`",
                                id.name
                            )),
                        );
                        continue;
                    }
                    scalar(c, side, constants, diags, true);
                }
            }
        }
        RegionSource::Region(id) => {
            if !earlier.contains(&id.name.as_str()) {
                diags.push(
                    unknown_among(id, earlier.iter().copied(), "region")
                        .with_help("a union names regions defined above it"),
                );
            }
        }
        RegionSource::Union(parts, _) => {
            for part in parts {
                region_source(c, part, constants, earlier, diags);
            }
        }
    }
}

/// Known roles, each bound once (but `forms`).
fn bindings(p: &Problem, diags: &mut Vec<Diagnostic>) {
    let mut bound: HashMap<&str, Span> = HashMap::new();
    for b in &p.binds {
        if !ROLES.iter().any(|(r, _)| *r == b.role.name) {
            diags.push(unknown_among(&b.role, ROLES.iter().map(|(r, _)| *r), "role"));
        } else if b.role.name != "forms"
            && let Some(prev) = bound.insert(&b.role.name, b.role.span)
        {
            diags.push(
                Diagnostic::error("E0103", format!("`{}` bound twice", b.role.name), b.role.span, "again here")
                    .with_label(prev, "first here"),
            );
        }
    }
}

/// The reference's arguments, the run settings (or `run static`) and the quadrature settings.
fn settings_of_the_run(c: &mut Checker, p: &Problem, constants: &Names, diags: &mut Vec<Diagnostic>) {
    // A reference's arguments are numbers of the params (the reference checks their names).
    distinct(p.reference_args.iter().map(|a| &a.name), "argument", diags);
    for a in &p.reference_args {
        scalar(c, &a.value, constants, diags, false);
    }
    settings(&p.run, RUN_SETTINGS.iter().map(|(n, _)| *n), "run setting", c, constants, diags);
    if let (Some(at), Some(first)) = (p.run_static, p.run.first()) {
        diags.push(
            Diagnostic::error("E0103", "`run static` with time settings", first.name.span, "a time setting")
                .with_label(at, "one equilibrium")
                .with_help("a static problem has no time: drop `run dt = ...`, or `run static` for a time run"),
        );
    }
    settings(&p.quadrature, QUADRATURE_SETTINGS.iter().copied(), "quadrature setting", c, constants, diags);
    // The files' params: numbers of the problem's; which file declares each is known when the
    // problem is bound to the files in use.
    distinct(p.sets.iter().map(|d| &d.name), "`set` of a param", diags);
    for d in &p.sets {
        scalar(c, &d.value, constants, diags, false);
    }
}

/// Dirichlet conditions: on `u`, on a known region that is not a contact region, or at the
/// node nearest a point.
fn dirichlet(c: &mut Checker, p: &Problem, fields: &Names, regions: &[&str], diags: &mut Vec<Diagnostic>) {
    for d in &p.dirichlet {
        if d.field.name != "u" {
            diags.push(unknown_among(&d.field, ["u"].into_iter(), "Dirichlet field"));
        }
        let region = match &d.on {
            HeldAt::Region(r) => r,
            HeldAt::Nearest { point, .. } => {
                // A point: a constant vector (the node is found once, on the mesh).
                vector(c, point, fields, diags);
                held_value(c, d, fields, diags);
                continue;
            }
        };
        if !regions.contains(&region.name.as_str()) {
            diags.push(unknown_among(region, regions.iter().copied(), "region"));
        }
        // An obstacle's region is where contact is imposed: a displacement held there too
        // leaves the contact nothing to decide.
        if let Some(o) =
            p.obstacles.iter().find(|o| o.region.as_ref().map_or("Gamma_C", |r| r.name.as_str()) == region.name)
        {
            diags.push(
                Diagnostic::error(
                    "E0905",
                    "a Dirichlet condition on a contact region",
                    region.span,
                    "contact is imposed here",
                )
                .with_label(o.span, "the obstacle faces this region")
                .with_help("hold another part of the boundary: a region of its own (`region Gamma_D = ...`)"),
            );
        }
        held_value(c, d, fields, diags);
    }
}

/// Loads on regions: a traction `t` (a vector of `x` and `t`) or a pressure `p` (a scalar), on
/// a known region that no Dirichlet condition holds and no obstacle faces.
fn neumann(c: &mut Checker, p: &Problem, fields: &Names, regions: &[&str], diags: &mut Vec<Diagnostic>) {
    for b in &p.neumann {
        match b.kind.name.as_str() {
            "t" => vector(c, &b.value, fields, diags),
            "p" => scalar(c, &b.value, fields, diags, false),
            _ => diags.push(
                unknown_among(&b.kind, NEUMANN_KINDS.iter().map(|(k, _)| *k), "boundary load")
                    .with_help("`t = [..]` is a traction, `p = ..` a pressure (the traction −p n)"),
            ),
        }
        let region = &b.region;
        if !regions.contains(&region.name.as_str()) {
            diags.push(unknown_among(region, regions.iter().copied(), "region"));
            continue;
        }
        let held = p.dirichlet.iter().find(|d| d.on.region().is_some_and(|r| r.name == region.name));
        let faced =
            p.obstacles.iter().find(|o| o.region.as_ref().map_or("Gamma_C", |r| r.name.as_str()) == region.name);
        let clash = held
            .map(|d| (d.span, "held by this Dirichlet condition"))
            .or(faced.map(|o| (o.span, "the obstacle faces it")));
        if let Some((at, why)) = clash {
            diags.push(
                Diagnostic::error("E0907", "a load on a region whose displacement is decided elsewhere", region.span, "loaded here")
                    .with_label(at, why)
                    .with_help("a Dirichlet region takes no load (its reaction is `force(stiffness, REGION)`); a contact region's traction is the contact law's: load another region"),
            );
        }
    }
}

/// Obstacles: a known helper with its arguments, facing a known region.
fn obstacles(c: &mut Checker, p: &Problem, fields: &Names, regions: &[&str], diags: &mut Vec<Diagnostic>) {
    for o in &p.obstacles {
        builtin_call(c, &o.shape, OBSTACLES, "obstacle", fields, diags);
        // The contact law imposes it on its region: `on REGION`, or `Gamma_C`.
        match &o.region {
            Some(r) if !regions.contains(&r.name.as_str()) => {
                diags.push(unknown_among(r, regions.iter().copied(), "region"))
            }
            // The contact law's `Gamma_C` is bound to the obstacle's region: a region of that
            // name besides would be hidden.
            Some(r) if r.name != "Gamma_C" && regions.contains(&"Gamma_C") => diags.push(
                Diagnostic::error("E0103", "two contact regions", r.span, "the contact law's `Gamma_C` is bound here")
                    .with_label(
                        p.regions.iter().find(|x| x.name.name == "Gamma_C").map_or(r.span, |x| x.name.span),
                        "and a region `Gamma_C` is defined here",
                    )
                    .with_help("name the obstacle's region `Gamma_C`, or rename the other region"),
            ),
            None if !regions.contains(&"Gamma_C") => diags.push(
                Diagnostic::error("E0101", "an obstacle without its region", o.span, "faces `Gamma_C`, not defined")
                    .with_help("add `on REGION`, or `region Gamma_C = group \"NAME\"` (or `boundary where ...`)"),
            ),
            _ => {}
        }
    }
}

/// Series columns and summary keys, each named once; the columns' and keys' expressions; the
/// plots' columns.
fn measures(c: &mut Checker, p: &Problem, constants: &Names, regions: &[&str], diags: &mut Vec<Diagnostic>) {
    let mut columns: HashMap<&str, Span> = HashMap::new();
    for d in p.series.iter().map(|(d, _)| d).chain(&p.summary) {
        if let Some(prev) = columns.insert(&d.name.name, d.name.span) {
            diags.push(
                Diagnostic::error("E0102", format!("`{}` is measured twice", d.name.name), d.name.span, "again here")
                    .with_label(prev, "first here"),
            );
        }
    }
    // Pointwise expressions see the fields, the problem's coefs and the obstacles' g and nc.
    let mut pointwise = constants.to_vec();
    pointwise.extend([("u".to_string(), Vector), ("v".to_string(), Vector)]);
    for d in &p.coefs {
        let shape = c.problem_ty(&d.value, constants).map_or(Scalar, |t| t.shape);
        pointwise.push((d.name.name.clone(), shape));
    }
    if !p.obstacles.is_empty() {
        pointwise.extend([("g".to_string(), Scalar), ("nc".to_string(), Vector)]);
    }
    let mut earlier: Vec<&str> = Vec::new();
    let bodies: Vec<&str> = p.bodies.iter().map(|b| b.name.name.as_str()).collect();
    for (d, _) in &p.series {
        let scope = RowScope { constants, pointwise: &pointwise, regions, bodies: &bodies, earlier: &earlier };
        row(c, &d.value, &scope, diags);
        earlier.push(&d.name.name);
    }
    // Every row has its time.
    earlier.push("t");
    let mut keys: Vec<&str> = Vec::new();
    for d in &p.summary {
        let scope = SummaryScope { columns: &earlier, keys: &keys, constants };
        summary(&d.value, &scope, false, diags);
        keys.push(&d.name.name);
    }
    // An expectation names a key; its value is an expression as a key's (params, keys, reducers).
    let mut expected: HashMap<&str, Span> = HashMap::new();
    for x in &p.expects {
        if !keys.contains(&x.key.name.as_str()) {
            diags.push(unknown_among(&x.key, keys.iter().copied(), "summary key"));
        } else if let Some(first) = expected.get(x.key.name.as_str()) {
            diags.push(
                Diagnostic::error("E0102", format!("`{}` is expected twice", x.key.name), x.key.span, "again here")
                    .with_label(*first, "first here"),
            );
        } else {
            expected.insert(&x.key.name, x.key.span);
        }
        let scope = SummaryScope { columns: &earlier, keys: &keys, constants };
        summary(&x.value, &scope, false, diags);
        if !crate::check::const_value(&x.within).is_some_and(|w| w > 0.0) {
            diags.push(
                Diagnostic::error("E0301", "a tolerance is a positive number", x.within.span, "not one")
                    .with_help("a relative tolerance: `within 0.03` for 3 %"),
            );
        }
    }
    for pl in &p.plots {
        for col in &pl.columns {
            if !p.series.iter().any(|(d, _)| d.name.name == col.name) {
                diags.push(unknown_among(col, p.series.iter().map(|(d, _)| d.name.name.as_str()), "series column"));
            }
        }
    }
}

fn settings<'a>(
    list: &[Defined],
    known: impl Iterator<Item = &'a str> + Clone,
    what: &str,
    c: &mut Checker,
    names: &[(String, Shape)],
    diags: &mut Vec<Diagnostic>,
) {
    distinct(list.iter().map(|d| &d.name), what, diags);
    for d in list {
        if !known.clone().any(|k| k == d.name.name) {
            diags.push(unknown_among(&d.name, known.clone(), what));
        }
        scalar(c, &d.value, names, diags, false);
    }
}

/// A Dirichlet condition's component and value: a scalar for `u[k]`, a vector for `u`.
fn held_value(c: &mut Checker, d: &Dirichlet, fields: &[(String, Shape)], diags: &mut Vec<Diagnostic>) {
    match &d.component {
        Some(k) => {
            if !crate::check::const_value(k).is_some_and(|k| k >= 0.0 && k.fract() == 0.0 && k < 3.0) {
                diags.push(Diagnostic::error("E0302", "a component index must be 0, 1 or 2", k.span, "not one"));
            }
            scalar(c, &d.value, fields, diags, false);
        }
        None => vector(c, &d.value, fields, diags),
    }
}

fn builtin_call(
    c: &mut Checker,
    call: &NamedCall,
    catalogue: &[Builtin],
    what: &str,
    names: &[(String, Shape)],
    diags: &mut Vec<Diagnostic>,
) {
    let Some(b) = catalogue.iter().find(|b| b.name == call.name.name) else {
        diags.push(unknown_among(&call.name, catalogue.iter().map(|b| b.name), what));
        return;
    };
    distinct(call.args.iter().map(|a| &a.name), "argument", diags);
    for a in &call.args {
        match b.args.iter().find(|(n, _, _)| *n == a.name.name) {
            Some((_, Scalar, _)) => scalar(c, &a.value, names, diags, false),
            Some(_) => vector(c, &a.value, names, diags),
            None => diags.push(unknown_among(
                &a.name,
                b.args.iter().map(|(n, _, _)| *n),
                &format!("argument of `{}`", b.name),
            )),
        }
    }
    for (n, _, optional) in b.args {
        if !optional && !call.args.iter().any(|a| a.name.name == *n) {
            diags.push(
                Diagnostic::error("E0201", format!("`{}` needs `{n}`", b.name), call.span, format!("no `{n} = ...`"))
                    .with_note(format!("{}: {}", b.name, b.doc)),
            );
        }
    }
}

fn expression(
    c: &mut Checker,
    e: &Expr,
    names: &[(String, Shape)],
    diags: &mut Vec<Diagnostic>,
    facet: bool,
) -> Option<Shape> {
    let ty = c.problem_ty(e, names)?;
    if !facet && let Some(at) = ty.facet {
        diags.push(Diagnostic::error("E0501", "`n` or `h` outside a region predicate", at, "no facet here").with_help(
            "a problem's coefs and fields are functions of `x` and `t`; the normal is known in `boundary where ...`",
        ));
    }
    Some(ty.shape)
}

pub(super) fn scalar(c: &mut Checker, e: &Expr, names: &[(String, Shape)], diags: &mut Vec<Diagnostic>, facet: bool) {
    if let Some(s) = expression(c, e, names, diags, facet)
        && s != Scalar
    {
        diags.push(Diagnostic::error(
            "E0301",
            "shape mismatch",
            e.span,
            format!("a scalar is needed here, not a {}", s.name()),
        ));
    }
}

pub(super) fn vector(c: &mut Checker, e: &Expr, names: &[(String, Shape)], diags: &mut Vec<Diagnostic>) {
    if let Some(s) = expression(c, e, names, diags, false)
        && s != Vector
    {
        diags.push(Diagnostic::error(
            "E0301",
            "shape mismatch",
            e.span,
            format!("a vector is needed here, not a {}", s.name()),
        ));
    }
}

pub(super) fn distinct<'a>(names: impl Iterator<Item = &'a Ident>, what: &str, diags: &mut Vec<Diagnostic>) {
    let mut seen: HashMap<&str, Span> = HashMap::new();
    for n in names {
        if let Some(prev) = seen.insert(&n.name, n.span) {
            diags.push(
                Diagnostic::error("E0103", format!("duplicate {what} `{}`", n.name), n.span, "repeated here")
                    .with_label(prev, "first here"),
            );
        }
    }
}

/// E0101 for `id`, which is none of `known`, with the closest and the list.
pub fn unknown_among<'a>(id: &Ident, known: impl Iterator<Item = &'a str> + Clone, what: &str) -> Diagnostic {
    let mut d = Diagnostic::error("E0101", format!("unknown {what} `{}`", id.name), id.span, "not one of them");
    if let Some(s) = crate::check::suggest_name(&id.name, known.clone()) {
        d = d.with_help(format!("did you mean `{s}`?"));
    }
    let list: Vec<&str> = known.collect();
    if list.is_empty() {
        return d.with_note(format!("there is no {what}"));
    }
    // `body` → `bodies`, `key` → `keys`.
    let plural = match what.strip_suffix('y') {
        Some(stem) if !stem.ends_with(['a', 'e', 'i', 'o', 'u']) => format!("{stem}ies"),
        _ => format!("{what}s"),
    };
    d.with_note(format!("the {plural}: {}", list.join(", ")))
}

/// W0004: coef `name` of a problem is read by none of `files` (the files of the run).
pub fn unread_coef(name: &Ident, files: &[&str]) -> Diagnostic {
    Diagnostic::warning(
        "W0004",
        format!("coef `{}` is set, but no file in use reads it", name.name),
        name.span,
        "not read",
    )
    .with_note(format!("the files in use: {}", files.join(", ")))
    .with_help("check its name against the forms' `coef` lines, or add the file that reads it (--forms, --material)")
}

/// The names an expression reads (not the functions it calls), in order.
pub fn names_in(e: &Expr) -> Vec<&Ident> {
    use crate::syntax::ast::ExprKind as K;
    match &e.kind {
        K::Name(id) => vec![id],
        K::Number(_) => Vec::new(),
        K::Neg(a) => names_in(a),
        K::Binary(_, a, b) | K::Index(a, b) => names_in(a).into_iter().chain(names_in(b)).collect(),
        K::Call(_, args) | K::Vector(args) => args.iter().flat_map(names_in).collect(),
    }
}

/// E0906: `name` (a `set`, or a param a `when` reads) answers to several params of the files
/// in use; `choices` are their qualified names with their declarations.
pub fn ambiguous_param(name: &Ident, choices: &[String]) -> Diagnostic {
    Diagnostic::error(
        "E0906",
        format!("`{}` is ambiguous", name.name),
        name.span,
        "more than one file in use declares it",
    )
    .with_note(format!("write {}", choices.join(" or ")))
    .with_help("qualify it by a role or a file's name, as listed (`material.rho`, `scheme.rho`)")
}
