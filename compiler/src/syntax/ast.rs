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
