//! Checks of a `problem` item that need no mesh and no bound files: its params, one mesh, a
//! known generator or obstacle helper with its arguments, distinct names, the run and
//! quadrature settings, and the shape of every expression with the names its place allows
//! (`x` and `t` in coefs and fields, `n` in region predicates). What depends on the mesh (its
//! groups, empty regions, the dimension) or on the files bound to the slots (unset coefs,
//! observables) is checked when the problem is bound (`signorini check` does both).

use std::collections::HashMap;

use super::types::Checker;
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{
    Defined, Dirichlet, Expr, HeldAt, Ident, MeshSource, NamedCall, Problem, RegionSource, Shape,
};

/// A built-in mesh generator or obstacle helper: its name, its dimension (0: any) and its
/// arguments with their shapes (`true`: optional).
pub struct Builtin {
    pub name: &'static str,
    pub dim: usize,
    pub args: &'static [(&'static str, Shape, bool)],
    pub doc: &'static str,
}

use Shape::{Scalar, Vector};

/// The mesh generators a problem may name.
pub const GENERATORS: &[Builtin] = &[
    Builtin {
        name: "interval",
        dim: 1,
        args: &[("length", Scalar, false), ("cells", Scalar, false), ("start", Scalar, true)],
        doc: "P1 segments of [start, start + length]",
    },
    Builtin {
        name: "rectangle",
        dim: 2,
        args: &[
            ("width", Scalar, false),
            ("height", Scalar, false),
            ("nx", Scalar, false),
            ("ny", Scalar, false),
            ("degree", Scalar, true),
            ("origin", Vector, true),
        ],
        doc: "triangles of [0, width] × [0, height] (from `origin`, default [0, 0]), P1 or P2",
    },
    Builtin {
        name: "box",
        dim: 3,
        args: &[
            ("size", Vector, false),
            ("nx", Scalar, false),
            ("ny", Scalar, false),
            ("nz", Scalar, false),
            ("degree", Scalar, true),
            ("origin", Vector, true),
        ],
        doc: "tetrahedra of [0, size[0]] × [0, size[1]] × [0, size[2]] (from `origin`, default 0), P1 or P2",
    },
    Builtin {
        name: "disc",
        dim: 2,
        args: &[("radius", Scalar, false), ("centre", Vector, false), ("h", Scalar, false)],
        doc: "curved P2 triangles of a disc, edge length about h",
    },
    Builtin {
        name: "ball",
        dim: 3,
        args: &[("radius", Scalar, false), ("centre", Vector, false), ("h", Scalar, false)],
        doc: "curved P2 tetrahedra of a ball, edge length about h",
    },
];

/// The obstacle helpers: each sets the gap `g` and the obstacle normal `nc` on its region.
pub const OBSTACLES: &[Builtin] = &[
    Builtin {
        name: "plane",
        dim: 0,
        args: &[("point", Vector, false), ("normal", Vector, false)],
        doc: "the half-space below the plane through `point` with unit outward `normal`: g = (x − point)·normal, nc = −normal",
    },
    Builtin {
        name: "sphere",
        dim: 0,
        args: &[("centre", Vector, false), ("radius", Scalar, false)],
        doc: "a rigid disc (2D) or ball (3D), possibly moving with t: g = |x − centre| − radius, nc = (centre − x)/|x − centre|",
    },
    Builtin {
        name: "cylinder",
        dim: 0,
        args: &[("point", Vector, false), ("radius", Scalar, false), ("axis", Vector, true)],
        doc: "a rigid circular cylinder through `point` along `axis` (3D; in 2D its section, a disc, with no axis), possibly moving with t: g = |d| − radius, nc = −d/|d| for d the part of x − point across the axis",
    },
];

/// Run settings a problem may give defaults for (each overridable from the command line).
pub const RUN_SETTINGS: &[(&str, &str)] = &[
    ("dt", "the time step"),
    ("t_end", "the end time"),
    ("t_start", "the start time (initial fields are evaluated there)"),
];

/// The roles a problem binds files to (`bind scheme = hybrid`): the scheme, the contact law,
/// the material, and extra form files (repeatable).
pub const ROLES: &[(&str, &str)] = &[
    ("scheme", "the time scheme (forms/schemes/ by name, or a .wf file)"),
    ("contact", "the contact law (`nitsche`, `penalty`, ..., or a .wf file)"),
    ("material", "the material's form file"),
    ("forms", "an extra form file whose slots the scheme applies (repeatable)"),
];

/// Quadrature settings: degrees of the cell and contact-facet rules.
pub const QUADRATURE_SETTINGS: &[&str] = &["cell", "facet"];

/// What a series column may read at every row besides other columns: a name and its meaning.
pub const ROW_VALUES: &[(&str, &str)] = &[
    ("t", "the row's time"),
    ("energy", "½uᵀKu + ½vᵀMv − Fᵀu, with the mass the scheme steps with"),
    ("kinetic", "½vᵀMv, with the mass the scheme steps with (0 without a velocity)"),
    ("newton", "Newton iterations of the step (0 at the initial row and at stages)"),
    ("active_points", "contact quadrature points whose switch is on (the active set)"),
];

/// The reducers of a series column: name, arguments as written, meaning.
pub const ROW_REDUCERS: &[(&str, &str, &str)] = &[
    ("mean", "mean(u[k])", "mass-weighted mean of a component of u or v over the body (the centre of mass's)"),
    ("nodal_mean", "nodal_mean(u[k])", "plain mean of a component of u or v over the nodes"),
    ("at_min", "at_min(u[k], EXPR)", "a component of u or v at the node where EXPR (of x) is least"),
    (
        "force",
        "force(SLOT[, REGION])",
        "the resultant of a slot's residual on the body, or at a region's nodes (a vector): force(contact), force(stiffness, Gamma_D)",
    ),
    (
        "inner_mass",
        "inner_mass(A, B)",
        "aᵀ M b with the mass the scheme steps with, for vector fields A and B of x, t, u, v at the nodes (∫ρ A·B)",
    ),
    ("measure", "measure(REGION, EXPR)", "the measure of the region's quadrature points where EXPR ≥ 0"),
    (
        "peak",
        "peak(REGION, EXPR)",
        "the largest value of EXPR over the region's quadrature points, or 0 if none is positive",
    ),
    (
        "density_min",
        "density_min(NAME(u))",
        "the least value of a boundary functional's integrand over 16 points per edge of its region: -density_min(contact_pressure(u)) is the peak contact pressure",
    ),
    (
        "density_support",
        "density_support(NAME(u))",
        "the measure of the points of a boundary functional's region where its integrand is not zero: the contact zone's, of contact_pressure(u)",
    ),
];

/// Any other call in a series column, `NAME(u)`, is a functional of the files in use or of the
/// problem's reference (checked when the problem is bound).
pub const FUNCTIONAL_CALL: &str = "NAME(u)";

/// The states a functional is evaluated at: a name and its meaning.
pub const FUNCTIONAL_STATES: &[(&str, &str)] = &[
    ("u", "the row's displacement, at the row's time"),
    (
        "u_mid",
        "the step's midpoint (uⁿ + uⁿ⁺¹)/2 at t − Δt/2, where the midpoint and hybrid schemes impose contact (NaN at the initial row and at stages)",
    ),
];

/// The reducers of a summary key, over the rows of the series. Their argument is an expression
/// of the row (columns, `t`, earlier summary keys, params); rows where it is NaN (undefined, as
/// a `u_mid` value at the initial row) are left out of `min`, `max` and `sum`.
pub const SUMMARY_REDUCERS: &[(&str, &str, &str)] = &[
    ("initial", "initial(EXPR)", "the first row's value"),
    ("final", "final(EXPR)", "the last row's value"),
    ("min", "min(EXPR)", "the least value"),
    ("max", "max(EXPR)", "the largest value"),
    ("sum", "sum(EXPR)", "the sum over the rows, in order"),
    ("first", "first(EXPR, WHEN)", "EXPR at the first row where WHEN > 0 (null if none)"),
    ("at_max", "at_max(EXPR, OF)", "EXPR at the first row where OF is largest"),
];

/// Functions of one number a series column or a summary key may apply (in a summary, inside or
/// outside its reducers).
pub const SUMMARY_FUNCTIONS: &[&str] = &["sqrt", "abs", "pos"];

/// Fields whose initial value a problem may give.
pub const INITIAL_FIELDS: &[&str] = &["u", "v"];

pub(super) fn check(c: &mut Checker, p: &Problem, diags: &mut Vec<Diagnostic>) {
    let mut names: Vec<(String, Shape)> = p.params.iter().map(|q| (q.name.name.clone(), Scalar)).collect();
    distinct(p.params.iter().map(|q| &q.name), "parameter", diags);
    // A param named like a built-in value would hide it (`n`, the normal in region predicates).
    // `h` stays a param's name: problems read no cell size.
    for q in p.params.iter().map(|q| &q.name).chain(p.lets.iter().map(|l| &l.name)) {
        if ["x", "t", "n", "pi"].contains(&q.name.as_str()) {
            diags.push(
                Diagnostic::error("E0106", format!("`{}` is a built-in name", q.name), q.span, "would hide it")
                    .with_note("x is the position, t the time, n the facet normal, pi is π")
                    .with_help("give it another name"),
            );
        }
    }
    // Params are constants with a default in their range (as a scheme's).
    for q in &p.params {
        c.problem_ty(&q.default, &[]);
    }
    // Lets in order, each seeing the ones before.
    distinct(p.lets.iter().map(|d| &d.name), "let", diags);
    for d in &p.lets {
        let shape = expression(c, &d.value, &names.clone(), diags, false).unwrap_or(Scalar);
        names.push((d.name.name.clone(), shape));
    }
    let constants = names.clone();
    match p.mesh.as_slice() {
        [] => diags.push(
            Diagnostic::error("E0901", format!("problem `{}` has no mesh", p.name.name), p.name.span, "no `mesh` line")
                .with_help("add `mesh \"body.msh\"` (a Gmsh file beside the problem) or a generator such as `mesh disc(radius = 10, centre = [0, 12], h = 1)`"),
        ),
        [MeshSource::Generator(call)] => builtin_call(c, call, GENERATORS, "mesh generator", &constants, diags),
        [_] => {}
        [_, second, ..] => {
            let span = match second {
                MeshSource::File { span, .. } => *span,
                MeshSource::Generator(call) => call.span,
            };
            diags.push(Diagnostic::error("E0102", "a problem has one mesh", span, "second `mesh`"));
        }
    }
    distinct(p.regions.iter().map(|r| &r.name), "region", diags);
    // `x` and `t` are built-in names; `n` too, but it means something only on a facet.
    let facet = constants.clone();
    for r in &p.regions {
        for s in &r.sources {
            let (RegionSource::Boundary { conditions, .. } | RegionSource::Group { conditions, .. }) = s;
            for cmp in conditions {
                for side in [&cmp.lhs, &cmp.rhs] {
                    scalar(c, side, &facet, diags, true);
                }
            }
        }
    }
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
    // A reference's arguments are numbers of the params (the reference checks their names).
    distinct(p.reference_args.iter().map(|a| &a.name), "argument", diags);
    for a in &p.reference_args {
        scalar(c, &a.value, &constants, diags, false);
    }
    settings(&p.run, RUN_SETTINGS.iter().map(|(n, _)| *n), "run setting", c, &constants, diags);
    if let (Some(at), Some(first)) = (p.run_static, p.run.first()) {
        diags.push(
            Diagnostic::error("E0103", "`run static` with time settings", first.name.span, "a time setting")
                .with_label(at, "one equilibrium")
                .with_help("a static problem has no time: drop `run dt = ...`, or `run static` for a time run"),
        );
    }
    settings(&p.quadrature, QUADRATURE_SETTINGS.iter().copied(), "quadrature setting", c, &constants, diags);
    let fields = &constants;
    distinct(p.coefs.iter().map(|d| &d.name), "coef", diags);
    for d in &p.coefs {
        expression(c, &d.value, fields, diags, false);
    }
    distinct(p.initial.iter().map(|d| &d.name), "initial field", diags);
    for d in &p.initial {
        if !INITIAL_FIELDS.contains(&d.name.name.as_str()) {
            diags.push(unknown_among(&d.name, INITIAL_FIELDS.iter().copied(), "initial field"));
        }
        vector(c, &d.value, fields, diags);
    }
    let regions: Vec<&str> = p.regions.iter().map(|r| r.name.name.as_str()).collect();
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
    let mut pointwise = constants.clone();
    pointwise.extend([("u".to_string(), Vector), ("v".to_string(), Vector)]);
    for d in &p.coefs {
        let shape = c.problem_ty(&d.value, &constants).map_or(Scalar, |t| t.shape);
        pointwise.push((d.name.name.clone(), shape));
    }
    if !p.obstacles.is_empty() {
        pointwise.extend([("g".to_string(), Scalar), ("nc".to_string(), Vector)]);
    }
    let mut earlier: Vec<&str> = Vec::new();
    for (d, _) in &p.series {
        let scope = RowScope { constants: &constants, pointwise: &pointwise, regions: &regions, earlier: &earlier };
        row(c, &d.value, &scope, diags);
        earlier.push(&d.name.name);
    }
    // Every row has its time.
    earlier.push("t");
    let mut keys: Vec<&str> = Vec::new();
    for d in &p.summary {
        let scope = SummaryScope { columns: &earlier, keys: &keys, constants: &constants };
        summary(&d.value, &scope, false, diags);
        keys.push(&d.name.name);
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

fn scalar(c: &mut Checker, e: &Expr, names: &[(String, Shape)], diags: &mut Vec<Diagnostic>, facet: bool) {
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

fn vector(c: &mut Checker, e: &Expr, names: &[(String, Shape)], diags: &mut Vec<Diagnostic>) {
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

fn distinct<'a>(names: impl Iterator<Item = &'a Ident>, what: &str, diags: &mut Vec<Diagnostic>) {
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
    if let Some(s) = super::suggest_name(&id.name, known.clone()) {
        d = d.with_help(format!("did you mean `{s}`?"));
    }
    let list: Vec<&str> = known.collect();
    if list.is_empty() {
        return d.with_note(format!("there is no {what}"));
    }
    d.with_note(format!("the {what}s: {}", list.join(", ")))
}

/// What a series column may name.
struct RowScope<'a> {
    constants: &'a [(String, Shape)],
    pointwise: &'a [(String, Shape)],
    regions: &'a [&'a str],
    earlier: &'a [&'a str],
}

/// A series column: arithmetic of numbers, params, row values, earlier columns, reducers and
/// functionals.
fn row(c: &mut Checker, e: &Expr, s: &RowScope, diags: &mut Vec<Diagnostic>) {
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
    let reducers: Vec<&str> = ROW_REDUCERS.iter().map(|(_, w, _)| *w).collect();
    format!(
        "a column reads the row values ({}), earlier columns, params, and reducers: {}, or a functional `{FUNCTIONAL_CALL}` (also at {}), with arithmetic and {}",
        values.join(", "),
        reducers.join(", "),
        FUNCTIONAL_STATES.iter().skip(1).map(|(s, _)| *s).collect::<Vec<_>>().join(", "),
        SUMMARY_FUNCTIONS.join(", ")
    )
}

fn reducer(c: &mut Checker, e: &Expr, f: &Ident, args: &[Expr], s: &RowScope, diags: &mut Vec<Diagnostic>) {
    use crate::syntax::ast::ExprKind as K;
    let arity = |want: usize, diags: &mut Vec<Diagnostic>| {
        if args.len() != want {
            let usage = ROW_REDUCERS.iter().find(|(n, _, _)| *n == f.name).map_or(FUNCTIONAL_CALL, |(_, u, _)| u);
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
    match f.name.as_str() {
        name if SUMMARY_FUNCTIONS.contains(&name) => {
            if arity(1, diags) {
                row(c, &args[0], s, diags);
            }
        }
        "mean" | "nodal_mean" => {
            if arity(1, diags) {
                component(&args[0], diags);
            }
        }
        "at_min" => {
            if arity(2, diags) {
                component(&args[0], diags);
                scalar(c, &args[1], s.constants, diags, false);
            }
        }
        "force" => {
            // force(SLOT) over the body, force(SLOT, REGION) over the region's nodes.
            if args.len() == 2 {
                region(&args[1], diags);
            } else if !arity(1, diags) {
                return;
            }
            if !matches!(&args[0].kind, K::Name(_)) {
                diags.push(Diagnostic::error("E0301", "shape mismatch", args[0].span, "a slot's name is needed here"));
            }
        }
        "inner_mass" => {
            if arity(2, diags) {
                vector(c, &args[0], s.pointwise, diags);
                vector(c, &args[1], s.pointwise, diags);
            }
        }
        "measure" | "peak" => {
            if arity(2, diags) {
                region(&args[0], diags);
                scalar(c, &args[1], s.pointwise, diags, false);
            }
        }
        "density_min" | "density_support" => {
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
        _ => {
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
struct SummaryScope<'a> {
    /// The series' columns and `t`: read per row, inside a reducer.
    columns: &'a [&'a str],
    /// The summary keys before this one.
    keys: &'a [&'a str],
    constants: &'a [(String, Shape)],
}

/// A summary key: arithmetic of numbers, params, earlier keys, functions and reducers, whose
/// arguments (`in_row`) read the row's columns too.
fn summary(e: &Expr, s: &SummaryScope, in_row: bool, diags: &mut Vec<Diagnostic>) {
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
            let (want, usage) = match SUMMARY_REDUCERS.iter().find(|(n, _, _)| *n == f.name) {
                Some((name, usage, _)) => (if matches!(*name, "first" | "at_max") { 2 } else { 1 }, *usage),
                None if SUMMARY_FUNCTIONS.contains(&f.name.as_str()) => (1, ""),
                None => {
                    let known = SUMMARY_REDUCERS.iter().map(|(n, _, _)| *n).chain(SUMMARY_FUNCTIONS.iter().copied());
                    diags.push(unknown_among(f, known, "summary function"));
                    return;
                }
            };
            let reducer = !usage.is_empty();
            if reducer && in_row {
                diags.push(
                    Diagnostic::error("E0201", format!("`{}` inside a reducer", f.name), e.span, "a reducer of a row")
                        .with_help("a reducer's argument is a value of one row: reduce it once"),
                );
            } else if args.len() != want {
                let usage = if reducer { usage.to_string() } else { format!("{}(EXPR)", f.name) };
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
    let reducers: Vec<&str> = SUMMARY_REDUCERS.iter().map(|(_, u, _)| *u).collect();
    format!(
        "a summary reduces expressions of the columns: {}; it may apply {} and read the keys before it",
        reducers.join(", "),
        SUMMARY_FUNCTIONS.join(", ")
    )
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
