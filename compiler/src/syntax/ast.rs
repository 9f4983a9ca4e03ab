//! Abstract syntax tree of a .wf file. Every node keeps its span.

use crate::source::Span;

#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl BinOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Pow => "^",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Number(f64),
    Name(Ident),
    Call(Ident, Vec<Expr>),
    Neg(Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `[a, b, c]`: a vector of components (problems only, where the dimension is known).
    Vector(Vec<Expr>),
    /// `a[i]`: component `i` (from 0) of a vector (problems only).
    Index(Box<Expr>, Box<Expr>),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Shape {
    Scalar,
    Vector,
    Tensor,
}

impl Shape {
    /// Tensor rank: 0 scalar, 1 vector, 2 tensor (a coef has dim^rank components).
    pub fn rank(self) -> u32 {
        match self {
            Shape::Scalar => 0,
            Shape::Vector => 1,
            Shape::Tensor => 2,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Shape::Scalar => "scalar",
            Shape::Vector => "vector",
            Shape::Tensor => "tensor",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Range {
    pub lo: Expr,
    pub lo_closed: bool,
    pub hi: Expr,
    pub hi_closed: bool,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Integral {
    /// +1 or -1: the sign written before `int`.
    pub sign: f64,
    pub region: Ident,
    /// `int(REGION, degree = k)`: the quadrature degree the author sets, and where.
    pub degree: Option<(f64, Span)>,
    /// `int(REGION, both_sides)`: a pair law integrated over each surface of its pair in turn,
    /// and where.
    pub both_sides: Option<Span>,
    pub integrand: Expr,
    pub span: Span,
}

/// A parameter of a scheme: `alpha = 0.05 in [0, 1/3]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SchemeParam {
    pub name: Ident,
    pub default: Expr,
    pub range: Option<Range>,
    pub span: Span,
}

/// One stage: an unknown, affine relations for the other new quantities, a residual.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Stage {
    pub name: Option<Ident>,
    /// Time of the stage (`at t + dt` when omitted).
    pub at: Option<Expr>,
    pub lets: Vec<(Ident, Expr)>,
    pub unknown: Option<Ident>,
    /// Declared auxiliary quantities (`new abar`): determined by the relations.
    pub news: Vec<Ident>,
    pub relates: Vec<Relate>,
    pub residual: Option<Residual>,
    pub span: Option<Span>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Relate {
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

/// `lhs == rhs`, both sums of scalar multiples of form applications.
#[derive(Clone, Debug, PartialEq)]
pub struct Residual {
    pub lhs: Expr,
    pub rhs: Expr,
    pub span: Span,
}

/// `initial a: mass(a) + ... == load(t)`: solves for a state at t = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Initial {
    pub unknown: Ident,
    pub residual: Residual,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Import {
        path: String,
        span: Span,
        /// `import material = elasticity`: a role the run may bind to another file (`path` is
        /// the default).
        role: Option<Ident>,
    },
    Param {
        name: Ident,
        default: Expr,
        range: Option<Range>,
        span: Span,
    },
    Coef {
        name: Ident,
        shape: Shape,
        span: Span,
    },
    Let {
        name: Ident,
        value: Expr,
        span: Span,
    },
    Fn {
        name: Ident,
        params: Vec<Ident>,
        body: Expr,
        span: Span,
    },
    Form {
        name: Ident,
        fields: Vec<Ident>,
        test: Option<Ident>,
        integrals: Vec<Integral>,
        span: Span,
    },
    Problem(Box<Problem>),
    Scheme {
        name: Ident,
        params: Vec<SchemeParam>,
        /// Slots (`uses mass, stiffness, contact, load`): the forms the scheme applies.
        uses: Vec<Ident>,
        states: Vec<Ident>,
        /// Scalar lets shared by the stages.
        lets: Vec<(Ident, Expr)>,
        initial: Option<Initial>,
        /// `claim NAME = EXPR`: properties the author states (`order`, `rho_inf`).
        claims: Vec<(Ident, Expr)>,
        /// `estimate EXPR`: the step's local error (one per scheme; more is E0823).
        estimates: Vec<Expr>,
        stages: Vec<Stage>,
        span: Span,
    },
}

impl Item {
    /// The name the item declares, if any.
    pub fn name(&self) -> Option<&Ident> {
        match self {
            Item::Import { .. } => None,
            Item::Param { name, .. }
            | Item::Coef { name, .. }
            | Item::Let { name, .. }
            | Item::Fn { name, .. }
            | Item::Form { name, .. }
            | Item::Scheme { name, .. } => Some(name),
            Item::Problem(p) => Some(&p.name),
        }
    }

    pub fn span(&self) -> Span {
        match self {
            Item::Import { span, .. }
            | Item::Param { span, .. }
            | Item::Coef { span, .. }
            | Item::Let { span, .. }
            | Item::Fn { span, .. }
            | Item::Form { span, .. }
            | Item::Scheme { span, .. } => *span,
            Item::Problem(p) => p.span,
        }
    }
}

/// A parsed file: the items that parsed, and the names of items that did not (so that later
/// checks do not report them a second time as unknown).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct File {
    pub items: Vec<Item>,
    pub broken_names: Vec<String>,
}

/// `name = value`, in a call with named arguments or a list of settings.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedArg {
    pub name: Ident,
    pub value: Expr,
}

/// `name(a = 1, b = [0, 2])`: a mesh generator or an obstacle helper.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedCall {
    pub name: Ident,
    pub args: Vec<NamedArg>,
    pub span: Span,
}

/// Where a problem's mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    /// A Gmsh file, relative to the problem file.
    File { path: String, span: Span },
    /// A built-in generator.
    Generator(NamedCall),
}

/// `lhs < rhs` and the like, in a region predicate or an expectation's `when`.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub lhs: Expr,
    pub op: Compare,
    pub rhs: Expr,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Less,
    LessEqual,
    Greater,
    GreaterEqual,
    Equal,
    NotEqual,
}

impl Compare {
    pub fn symbol(self) -> &'static str {
        match self {
            Compare::Less => "<",
            Compare::LessEqual => "<=",
            Compare::Greater => ">",
            Compare::GreaterEqual => ">=",
            Compare::Equal => "==",
            Compare::NotEqual => "!=",
        }
    }

    /// Whether `a op b` holds.
    pub fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Compare::Less => a < b,
            Compare::LessEqual => a <= b,
            Compare::Greater => a > b,
            Compare::GreaterEqual => a >= b,
            Compare::Equal => a == b,
            Compare::NotEqual => a != b,
        }
    }
}

/// Comparisons joined by `and`, `or` and `not`.
#[derive(Clone, Debug, PartialEq)]
pub enum Condition {
    Compare(Comparison),
    All(Vec<Condition>),
    Any(Vec<Condition>),
    Not(Box<Condition>),
}

impl Condition {
    /// Every comparison, in the order written.
    pub fn comparisons(&self) -> Vec<&Comparison> {
        match self {
            Condition::Compare(c) => vec![c],
            Condition::All(parts) | Condition::Any(parts) => parts.iter().flat_map(Condition::comparisons).collect(),
            Condition::Not(c) => c.comparisons(),
        }
    }

    /// Whether it holds, given whether each comparison (in [`Condition::comparisons`]'s order)
    /// holds. Every comparison is consumed, whatever short-circuits.
    pub fn holds(&self, comparisons: &mut impl Iterator<Item = bool>) -> bool {
        match self {
            Condition::Compare(_) => comparisons.next().unwrap_or(false),
            Condition::All(parts) => parts.iter().map(|c| c.holds(comparisons)).fold(true, |a, b| a & b),
            Condition::Any(parts) => parts.iter().map(|c| c.holds(comparisons)).fold(false, |a, b| a | b),
            Condition::Not(c) => !c.holds(comparisons),
        }
    }
}

/// One way to find a region's facets.
#[derive(Clone, Debug, PartialEq)]
pub enum RegionSource {
    /// A Gmsh physical group, by name; with a condition, its facets that satisfy it.
    Group { name: String, condition: Option<Condition>, span: Span },
    /// The boundary facets whose outward normal `n` and centroid `x` satisfy the condition
    /// (all of the boundary without one).
    Boundary { condition: Option<Condition>, span: Span },
    /// An earlier region, by name.
    Region(Ident),
    /// The facets of every part, in the order written, each once.
    Union(Vec<RegionSource>, Span),
}

impl RegionSource {
    pub fn span(&self) -> Span {
        match self {
            RegionSource::Group { span, .. } | RegionSource::Boundary { span, .. } | RegionSource::Union(_, span) => {
                *span
            }
            RegionSource::Region(id) => id.span,
        }
    }
}

/// `region NAME = SOURCE else SOURCE ...`: the first source that names anything.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionDecl {
    pub name: Ident,
    pub sources: Vec<RegionSource>,
    /// Declared in a body: the region is on that body's facets only (`boundary` is its
    /// boundary).
    pub body: Option<Ident>,
    pub span: Span,
}

/// `body NAME = group "g" { ... }` or `body NAME = GENERATOR(...) { ... }`: a part of the
/// problem's cells with param values and initial fields of its own (its regions are in
/// `Problem::regions`, with their body).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub name: Ident,
    pub source: BodySource,
    /// `set` in the body: its values of the files' params, over the problem's.
    pub sets: Vec<Defined>,
    /// `initial u = ...`, `initial v = ...` in the body: at its nodes, over the problem's.
    pub initial: Vec<Defined>,
    pub span: Span,
}

/// Where a body's cells come from.
#[derive(Clone, Debug, PartialEq)]
pub enum BodySource {
    /// A physical group of cells of the problem's mesh file.
    Group { name: String, span: Span },
    /// A generator's mesh, placed beside the other bodies'.
    Generator(NamedCall),
}

/// A file bound to a role of the run: `scheme = hybrid`, `contact = "my_law.wf"`.
#[derive(Clone, Debug, PartialEq)]
pub struct Bind {
    pub role: Ident,
    /// A library name, or a path (relative to the problem file) when written as a string.
    pub target: String,
    pub is_path: bool,
    pub span: Span,
}

/// `name = expr` with its span, for the problem's field-like declarations.
#[derive(Clone, Debug, PartialEq)]
pub struct Defined {
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

/// `dirichlet REGION: FIELD = EXPR`, or `FIELD[k] = EXPR` for one component.
#[derive(Clone, Debug, PartialEq)]
pub struct Dirichlet {
    pub on: HeldAt,
    pub field: Ident,
    pub component: Option<Expr>,
    pub value: Expr,
    pub span: Span,
}

/// Where a Dirichlet condition holds the displacement.
#[derive(Clone, Debug, PartialEq)]
pub enum HeldAt {
    /// The nodes of a facet region.
    Region(Ident),
    /// `nearest(POINT)`: the one mesh node nearest to a point (a pin that removes a rigid mode).
    Nearest { point: Expr, span: Span },
}

impl HeldAt {
    /// The region's name (`None` for a node).
    pub fn region(&self) -> Option<&Ident> {
        match self {
            HeldAt::Region(r) => Some(r),
            HeldAt::Nearest { .. } => None,
        }
    }

    pub fn span(&self) -> Span {
        match self {
            HeldAt::Region(r) => r.span,
            HeldAt::Nearest { span, .. } => *span,
        }
    }
}

/// `obstacle plane(point = [0, 0], normal = [0, 1]) on Gamma_C`.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    pub shape: NamedCall,
    /// The contact region it faces (`Gamma_C` when omitted).
    pub region: Option<Ident>,
    pub span: Span,
}

/// `contact Gamma_a with Gamma_b within 2 by segments { bind contact = LAW  set p = v }`: the
/// pair's law (its block's, else the run's) integrates over `own`, facing `facing`, looking
/// for facing points as far as `reach`, facet by facet or (`by segments`) piece by piece.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPair {
    pub own: Ident,
    pub facing: Ident,
    pub reach: Option<Expr>,
    /// `by segments` or `by elements` (the default).
    pub by: Option<Ident>,
    /// Its block's `bind contact = LAW`: the pair's own law.
    pub binds: Vec<Bind>,
    /// Its block's `set`: params of the pair's law, for this pair only.
    pub sets: Vec<Defined>,
    pub span: Span,
}

/// `plot "title": col, col`.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    pub title: String,
    pub columns: Vec<Ident>,
    pub span: Span,
}

/// `expect KEY = VALUE within TOL`: summary key KEY is expected to be VALUE (an expression of
/// the params and the keys) within the relative tolerance TOL.
#[derive(Clone, Debug, PartialEq)]
pub struct Expect {
    pub key: Ident,
    pub value: Expr,
    pub within: Expr,
    /// `when CONDITION`: of params; the runs where it does not hold do not check it.
    pub when: Option<Condition>,
    pub span: Span,
}

/// A problem: the body, its mesh and regions, the files bound to the run's roles, every coef,
/// obstacles, Dirichlet data, initial fields, what is measured, and the run's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub name: Ident,
    pub params: Vec<SchemeParam>,
    pub mesh: Vec<MeshSource>,
    /// The bodies, when the problem has more than one part (none: its mesh is one body).
    pub bodies: Vec<Body>,
    pub regions: Vec<RegionDecl>,
    pub binds: Vec<Bind>,
    /// Param values of the scheme and form files (`set E = 50`).
    pub sets: Vec<Defined>,
    pub coefs: Vec<Defined>,
    pub obstacles: Vec<Obstacle>,
    /// Contact between two bodies' regions.
    pub pairs: Vec<ContactPair>,
    pub initial: Vec<Defined>,
    pub dirichlet: Vec<Dirichlet>,
    /// Loads on regions: tractions and pressures.
    pub neumann: Vec<Neumann>,
    /// Series columns (written) and observed values (not written), in order.
    pub series: Vec<(Defined, bool)>,
    /// The columns marked `required`: one that reads a functional no file in use provides is
    /// an error, not left out.
    pub required: Vec<Ident>,
    pub summary: Vec<Defined>,
    /// `expect KEY = VALUE within TOL`: what a summary key should be, to a relative tolerance.
    pub expects: Vec<Expect>,
    pub plots: Vec<Plot>,
    /// Run settings: `dt`, `t_end`, `t_start`.
    pub run: Vec<Defined>,
    /// `run static`: the problem is one equilibrium (K u + C(u) = F), not a time run.
    pub run_static: Option<Span>,
    /// Quadrature degrees: `cell`, `facet`.
    pub quadrature: Vec<Defined>,
    /// An analytic reference solution provided by the runtime, by name.
    pub reference: Option<Ident>,
    /// Its arguments (`reference hertz(radius = 10, force = F)`).
    pub reference_args: Vec<NamedArg>,
    pub lets: Vec<Defined>,
    /// `fn NAME(ARGS) = EXPR`: functions of the problem, expanded where they are called.
    pub fns: Vec<ProblemFn>,
    pub span: Span,
}

/// `neumann REGION: t = EXPR` (a traction) or `neumann REGION: p = EXPR` (a pressure, the
/// traction −p n).
#[derive(Clone, Debug, PartialEq)]
pub struct Neumann {
    pub region: Ident,
    /// `t` or `p`.
    pub kind: Ident,
    pub value: Expr,
    pub span: Span,
}

/// `fn NAME(ARGS) = EXPR` in a problem.
#[derive(Clone, Debug, PartialEq)]
pub struct ProblemFn {
    pub name: Ident,
    pub params: Vec<Ident>,
    pub body: Expr,
    pub span: Span,
}
