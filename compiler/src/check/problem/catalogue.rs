//! The vocabulary of a problem: the mesh generators and obstacle helpers with their
//! arguments, the run and quadrature settings, the roles files are bound to, and what series
//! columns and summaries may read and reduce.

use crate::syntax::ast::{Expr, NamedCall, Shape};

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
    ("adaptive", "adaptive steps: the local error allowed per step, relative to the largest displacement"),
    ("dt_min", "the smallest adaptive step (default: dt × 1e-6)"),
    ("dt_max", "the largest adaptive step (default: a tenth of the run)"),
    ("event_dt", "an adaptive run lands on a first contact or a release to within this (default: dt / 20)"),
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

/// A reducer of a series column: what a column measures of a state (or of the rows so far).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowReducer {
    Mean,
    NodalMean,
    AtMin,
    Force,
    InnerMass,
    Measure,
    Peak,
    DensityMin,
    DensityMax,
    DensitySupport,
    Work,
    Cumulative,
    Initial,
}

/// A series reducer's row of the catalogue: what it is, its name, how it is written, its
/// meaning.
pub struct RowReducerInfo {
    pub kind: RowReducer,
    pub name: &'static str,
    pub usage: &'static str,
    pub doc: &'static str,
}

/// The reducers of a series column.
pub const ROW_REDUCERS: &[RowReducerInfo] = {
    use RowReducer::*;
    const fn r(kind: RowReducer, name: &'static str, usage: &'static str, doc: &'static str) -> RowReducerInfo {
        RowReducerInfo { kind, name, usage, doc }
    }
    &[
        r(
            Mean,
            "mean",
            "mean(u[k][, BODY])",
            "mass-weighted mean of a component of u or v over the bodies, or over one (the centre of mass's)",
        ),
        r(
            NodalMean,
            "nodal_mean",
            "nodal_mean(u[k][, BODY])",
            "plain mean of a component of u or v over the nodes (of a body)",
        ),
        r(AtMin, "at_min", "at_min(u[k], EXPR)", "a component of u or v at the node where EXPR (of x) is least"),
        r(
            Force,
            "force",
            "force(SLOT[, REGION or BODY])",
            "the resultant of a slot's residual on the mesh, at a region's nodes or on a body's (a vector): force(contact), force(stiffness, Gamma_D), force(contact, block)",
        ),
        r(
            InnerMass,
            "inner_mass",
            "inner_mass(A, B)",
            "aᵀ M b with the mass the scheme steps with, for vector fields A and B of x, t, u, v at the nodes (∫ρ A·B)",
        ),
        r(Measure, "measure", "measure(REGION, EXPR)", "the measure of the region's quadrature points where EXPR ≥ 0"),
        r(
            Peak,
            "peak",
            "peak(REGION, EXPR)",
            "the largest value of EXPR over the region's quadrature points, or 0 if none is positive",
        ),
        r(
            DensityMin,
            "density_min",
            "density_min(NAME(u))",
            "the least value of a boundary functional's integrand over 16 points per edge of its region: -density_min(contact_pressure(u)) is the peak contact pressure",
        ),
        r(
            DensityMax,
            "density_max",
            "density_max(NAME(u))",
            "the largest value of a boundary functional's integrand over those points: with density_min, the spread of a stress that should be one value",
        ),
        r(
            DensitySupport,
            "density_support",
            "density_support(NAME(u))",
            "the measure of the points of a boundary functional's region where its integrand is not zero: the contact zone's, of contact_pressure(u)",
        ),
        r(
            Work,
            "work",
            "work(SLOT)",
            "the work of a slot's residual over the step by the trapezoidal rule, ½(r(uⁿ) + r(uⁿ⁺¹))·(uⁿ⁺¹ − uⁿ), each end with its own previous level: Crank–Nicolson's E changes by −work(contact) (NaN at the initial row and at stages)",
        ),
        r(
            Cumulative,
            "cumulative",
            "cumulative(COLUMN)",
            "the sum of an earlier column over the rows so far, this one included (NaN values left out; a stage reads the sum at its step's start): cumulative(dissipated) is the frictional work since the start",
        ),
        r(
            Initial,
            "initial",
            "initial(COLUMN)",
            "an earlier column's value at the first row: the balance energy_aug + cumulative(dissipated) - initial(energy_aug)",
        ),
    ]
};

/// The series reducer of this name.
pub fn row_reducer(name: &str) -> Option<&'static RowReducerInfo> {
    ROW_REDUCERS.iter().find(|r| r.name == name)
}

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

/// A reducer of a summary key over the rows of the series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SummaryReducer {
    Initial,
    Final,
    Min,
    Max,
    Sum,
    /// The first argument at the first row where the second is positive.
    First,
    /// The first argument at the first row where the second is largest (NaN rows left out).
    AtMax,
    /// The trapezoidal rule over the rows in t.
    Integral,
    /// The largest value, refined by the parabola through its row and the two beside it in t.
    Crest,
}

/// A summary reducer's row of the catalogue: what it is, its name, how it is written, its
/// meaning, and how many arguments it takes (least, most).
pub struct Reducer {
    pub reducer: SummaryReducer,
    pub name: &'static str,
    pub usage: &'static str,
    pub doc: &'static str,
    pub arity: (usize, usize),
}

/// The reducers of a summary key, over the rows of the series. Their argument is an expression
/// of the row (columns, `t`, earlier summary keys, params); rows where it is NaN (undefined, as
/// a `u_mid` value at the initial row) are left out of `min`, `max` and `sum`.
pub const SUMMARY_REDUCERS: &[Reducer] = {
    use SummaryReducer::*;
    const fn r(
        reducer: SummaryReducer,
        name: &'static str,
        usage: &'static str,
        doc: &'static str,
        arity: (usize, usize),
    ) -> Reducer {
        Reducer { reducer, name, usage, doc, arity }
    }
    &[
        r(Initial, "initial", "initial(EXPR)", "the first row's value", (1, 1)),
        r(Final, "final", "final(EXPR)", "the last row's value", (1, 1)),
        r(Min, "min", "min(EXPR[, WHEN])", "the least value (over the rows where WHEN > 0)", (1, 2)),
        r(Max, "max", "max(EXPR[, WHEN])", "the largest value (over the rows where WHEN > 0)", (1, 2)),
        r(Sum, "sum", "sum(EXPR)", "the sum over the rows, in order", (1, 1)),
        r(First, "first", "first(EXPR, WHEN)", "EXPR at the first row where WHEN > 0 (null if none)", (2, 2)),
        r(AtMax, "at_max", "at_max(EXPR, OF)", "EXPR at the first row where OF is largest", (2, 2)),
        r(
            Integral,
            "integral",
            "integral(EXPR)",
            "the integral over t by the trapezoidal rule on the rows (an L² norm that steps of any size weigh alike)",
            (1, 1),
        ),
        r(
            Crest,
            "crest",
            "crest(EXPR)",
            "the largest value, refined by the parabola through its row and the rows beside it in t (a peak between rows)",
            (1, 1),
        ),
    ]
};

/// The summary reducer of this name.
pub fn summary_reducer(name: &str) -> Option<&'static Reducer> {
    SUMMARY_REDUCERS.iter().find(|r| r.name == name)
}

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

/// A mesh generator's call, typed: the catalogue's one match on a generator's name. Its
/// arguments are the expressions written (`None`: an optional one left out).
pub enum Generator<'a> {
    Interval {
        length: &'a Expr,
        cells: &'a Expr,
        start: Option<&'a Expr>,
    },
    Rectangle {
        width: &'a Expr,
        height: &'a Expr,
        nx: &'a Expr,
        ny: &'a Expr,
        degree: Option<&'a Expr>,
        origin: Option<&'a Expr>,
    },
    Box {
        size: &'a Expr,
        nx: &'a Expr,
        ny: &'a Expr,
        nz: &'a Expr,
        degree: Option<&'a Expr>,
        origin: Option<&'a Expr>,
    },
    Disc {
        radius: &'a Expr,
        centre: &'a Expr,
        h: &'a Expr,
    },
    Ball {
        radius: &'a Expr,
        centre: &'a Expr,
        h: &'a Expr,
    },
}

/// An obstacle helper's call, typed (see [`OBSTACLES`]).
pub enum ObstacleShape<'a> {
    Plane { point: &'a Expr, normal: &'a Expr },
    Sphere { centre: &'a Expr, radius: &'a Expr },
    Cylinder { point: &'a Expr, radius: &'a Expr, axis: Option<&'a Expr> },
}

/// The argument `name` of a call.
fn argument<'a>(call: &'a NamedCall, name: &str) -> Option<&'a Expr> {
    call.args.iter().find(|a| a.name.name == name).map(|a| &a.value)
}

/// `call` as a generator, or why not: an unknown name, or a required argument missing (the
/// checker reports both at the call; a caller that did not check gets the message).
pub fn generator(call: &NamedCall) -> Result<Generator<'_>, String> {
    let need = |name: &str| argument(call, name).ok_or_else(|| format!("`{}` needs `{name}`", call.name.name));
    let optional = |name: &str| argument(call, name);
    Ok(match call.name.name.as_str() {
        "interval" => Generator::Interval { length: need("length")?, cells: need("cells")?, start: optional("start") },
        "rectangle" => Generator::Rectangle {
            width: need("width")?,
            height: need("height")?,
            nx: need("nx")?,
            ny: need("ny")?,
            degree: optional("degree"),
            origin: optional("origin"),
        },
        "box" => Generator::Box {
            size: need("size")?,
            nx: need("nx")?,
            ny: need("ny")?,
            nz: need("nz")?,
            degree: optional("degree"),
            origin: optional("origin"),
        },
        "disc" => Generator::Disc { radius: need("radius")?, centre: need("centre")?, h: need("h")? },
        "ball" => Generator::Ball { radius: need("radius")?, centre: need("centre")?, h: need("h")? },
        other => return Err(format!("no mesh generator `{other}`")),
    })
}

/// `call` as an obstacle, or why not (as [`generator`]).
pub fn obstacle(call: &NamedCall) -> Result<ObstacleShape<'_>, String> {
    let need = |name: &str| argument(call, name).ok_or_else(|| format!("`{}` needs `{name}`", call.name.name));
    Ok(match call.name.name.as_str() {
        "plane" => ObstacleShape::Plane { point: need("point")?, normal: need("normal")? },
        "sphere" => ObstacleShape::Sphere { centre: need("centre")?, radius: need("radius")? },
        "cylinder" => {
            ObstacleShape::Cylinder { point: need("point")?, radius: need("radius")?, axis: argument(call, "axis") }
        }
        other => return Err(format!("no obstacle `{other}`")),
    })
}

#[cfg(test)]
mod typed {
    use super::*;

    /// Every generator and obstacle of the tables has its typed call, with every argument the
    /// table lists as required, and no other name is one.
    #[test]
    fn the_tables_and_the_typed_calls_agree() {
        use crate::source::Span;
        use crate::syntax::ast::{ExprKind, Ident, NamedArg};
        let id = |name: &str| Ident { name: name.to_string(), span: Span::new(0, 0, 0) };
        let call = |b: &Builtin, with_optional: bool| NamedCall {
            name: id(b.name),
            args: b
                .args
                .iter()
                .filter(|(_, _, optional)| with_optional || !optional)
                .map(|(n, _, _)| NamedArg {
                    name: id(n),
                    value: Expr { kind: ExprKind::Number(1.0), span: Span::new(0, 0, 0) },
                })
                .collect(),
            span: Span::new(0, 0, 0),
        };
        for b in GENERATORS {
            assert!(generator(&call(b, false)).is_ok(), "{}", b.name);
            assert!(generator(&call(b, true)).is_ok(), "{}", b.name);
        }
        for b in OBSTACLES {
            assert!(obstacle(&call(b, false)).is_ok(), "{}", b.name);
        }
        let unknown = NamedCall { name: id("torus"), args: Vec::new(), span: Span::new(0, 0, 0) };
        assert!(generator(&unknown).is_err() && obstacle(&unknown).is_err());
    }
}
