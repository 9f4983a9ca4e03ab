//! The vocabulary of a problem: the mesh generators and obstacle helpers with their
//! arguments, the run and quadrature settings, the roles files are bound to, and what series
//! columns and summaries may read and reduce.

use crate::syntax::ast::Shape;

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
    (
        "status_kept",
        "1 where the active set is the previous row's (every point's contact status kept over the step), else 0 (0 at the initial row)",
    ),
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
    (
        "work",
        "work(SLOT)",
        "the work of a slot's residual over the step by the trapezoidal rule, ½(r(uⁿ) + r(uⁿ⁺¹))·(uⁿ⁺¹ − uⁿ), each end with its own previous level: Crank–Nicolson's E changes by −work(contact) (NaN at the initial row and at stages)",
    ),
    (
        "cumulative",
        "cumulative(COLUMN)",
        "the sum of an earlier column over the rows so far, this one included (NaN values left out; a stage reads the sum at its step's start): cumulative(dissipated) is the frictional work since the start",
    ),
    (
        "initial",
        "initial(COLUMN)",
        "an earlier column's value at the first row: the balance energy_aug + cumulative(dissipated) - initial(energy_aug)",
    ),
];

/// The reducers of a series column that read an earlier column over the rows (not the state).
pub const OVER_ROWS: &[&str] = &["cumulative", "initial"];

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
    (
        "u_prev",
        "the step's start uⁿ, for a functional of two levels: friction_work(u, u_prev) (NaN at the initial row and at stages)",
    ),
];

/// The reducers of a summary key, over the rows of the series. Their argument is an expression
/// of the row (columns, `t`, earlier summary keys, params); rows where it is NaN (undefined, as
/// a `u_mid` value at the initial row) are left out of `min`, `max` and `sum`.
pub const SUMMARY_REDUCERS: &[(&str, &str, &str)] = &[
    ("initial", "initial(EXPR)", "the first row's value"),
    ("final", "final(EXPR)", "the last row's value"),
    ("min", "min(EXPR[, WHEN])", "the least value (over the rows where WHEN > 0)"),
    ("max", "max(EXPR[, WHEN])", "the largest value (over the rows where WHEN > 0)"),
    ("sum", "sum(EXPR)", "the sum over the rows, in order"),
    ("first", "first(EXPR, WHEN)", "EXPR at the first row where WHEN > 0 (null if none)"),
    ("at_max", "at_max(EXPR, OF)", "EXPR at the first row where OF is largest"),
];

/// The functions of numbers a series column or a summary key may apply: the language's scalar
/// built-ins (`sqrt`, `abs`, `pos`, `neg`, `H`, `min`, `max`, `sin`, ..., `ln`), the same as in
/// coefs and forms. In a summary, `min` and `max` of the rows are reducers; inside a reducer's
/// argument (a value of one row) they are these functions.
pub fn row_function(name: &str) -> Option<&'static crate::check::builtins::Builtin> {
    crate::check::builtins::function(name).filter(|b| b.shape == crate::check::builtins::ShapeRule::Scalars)
}

/// The names of [`row_function`]s, for messages.
pub fn row_function_names() -> Vec<&'static str> {
    crate::check::builtins::function_names().filter(|n| row_function(n).is_some()).collect()
}

/// The loads `neumann REGION: KIND = EXPR` applies: a kind and its meaning.
pub const NEUMANN_KINDS: &[(&str, &str)] = &[
    ("t", "a traction, a vector of x and t: ∫ t·v over the region"),
    ("p", "a pressure, a scalar of x and t: the traction −p n, ∫ −p n·v over the region"),
];

/// Fields whose initial value a problem may give.
pub const INITIAL_FIELDS: &[&str] = &["u", "v"];

/// `initial u = settled(GUESS)`: the displacement in static equilibrium with the loads and the
/// contact law, K u + C(u) = F, sought by Newton from GUESS (which should press the contact
/// region in): a body that starts at rest on an obstacle instead of bouncing on it.
pub const SETTLED: &str = "settled";

/// The argument of `settled(GUESS)` in `initial u = ...`, if the value is one.
pub fn settled_guess(value: &crate::syntax::ast::Expr) -> Option<&[crate::syntax::ast::Expr]> {
    match &value.kind {
        crate::syntax::ast::ExprKind::Call(f, args) if f.name == SETTLED => Some(args),
        _ => None,
    }
}
