//! Abstract evaluation of expressions: shape, linearity in the test function, use of facet
//! geometry, differentiability and compile-time constant value.
//!
//! The checker walks every expression once per context (`items`: params, lets, fns, forms);
//! a name is looked up in `names`, arithmetic follows `operators`, calls `calls` (a user's
//! `fn` is inlined with the types of its arguments); `constant` evaluates what must be a
//! number.

mod calls;
mod constant;
mod items;
mod names;
mod operators;

use std::collections::{HashMap, HashSet};

pub use constant::const_eval;

use super::{ParamSet, Unit};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{Expr, ExprKind, Shape};

/// What the checker knows about a value.
#[derive(Clone, Copy, Debug)]
pub struct Ty {
    pub shape: Shape,
    /// Linear in the test function (otherwise independent of it).
    pub test: bool,
    /// Where `n` or `h` was first used, if the value depends on facet geometry.
    pub facet: Option<Span>,
    /// Whether `grad` may be applied (fields, position and what is built from them).
    pub smooth: bool,
    /// The value, when it is a compile-time constant.
    pub konst: Option<f64>,
    /// Depth of the expression tree, `let`s and inlined `fn`s included: what the later
    /// stages recurse through.
    pub height: u32,
}

impl Ty {
    /// What an inlined call's result depends on (the argument types of a memoised call).
    fn key(&self) -> FnKey {
        (self.shape, self.test, self.facet, self.smooth, self.konst.map(f64::to_bits), self.height)
    }

    fn plain(shape: Shape) -> Ty {
        Ty { shape, test: false, facet: None, smooth: true, konst: None, height: 0 }
    }

    fn constant(v: f64) -> Ty {
        Ty { konst: Some(v), ..Ty::plain(Shape::Scalar) }
    }

    fn join(a: &Ty, b: &Ty, shape: Shape) -> Ty {
        Ty {
            shape,
            test: a.test || b.test,
            facet: a.facet.or(b.facet),
            smooth: a.smooth && b.smooth,
            konst: None,
            height: a.height.max(b.height),
        }
    }
}

enum LetState {
    InProgress,
    Done(Option<Ty>, ParamSet),
}

pub(super) struct Checker<'p> {
    prog: &'p Unit,
    broken: &'p HashSet<String>,
    pub diags: Vec<Diagnostic>,
    pub used_params: ParamSet,
    lets: HashMap<String, LetState>,
    /// Inlined function calls: (name, call span).
    calls: Vec<(String, Span)>,
    /// Whether a global fn is being checked on its own (its parameters have unknown use).
    scope: Vec<(String, Ty)>,
    /// Inlined calls already checked: (fn, argument types) → result and params used. A chain
    /// of functions that each call the previous twice is then checked in linear time.
    memo: HashMap<(String, Vec<FnKey>), (Option<Ty>, ParamSet)>,
    /// Function bodies checked (memo misses), bounded by [`MAX_EXPANSIONS`].
    expansions: usize,
    /// Current recursion depth of [`Checker::ty`].
    depth: u32,
    /// Inside a problem, whose dimension is known: vector literals and components allowed.
    pub vectors_allowed: bool,
}

/// E0301 at `span`: `what`, found `shape`.
fn shape_error(span: Span, what: &str, shape: Shape) -> Diagnostic {
    Diagnostic::error("E0301", "shape mismatch", span, format!("{what}, not a {}", shape.name()))
}

type FnKey = (Shape, bool, Option<Span>, bool, Option<u64>, u32);

const MAX_INLINE_DEPTH: usize = 32;
/// Deepest expression accepted, through `let`s and inlined `fn`s: every later stage walks
/// expressions recursively, and this bound keeps them within a thread's default stack.
pub const MAX_DEPTH: u32 = 1024;
/// Most function bodies checked with distinct argument types in one unit.
const MAX_EXPANSIONS: usize = 100_000;

impl<'p> Checker<'p> {
    pub fn new(prog: &'p Unit, broken: &'p HashSet<String>) -> Self {
        Checker {
            prog,
            broken,
            diags: Vec::new(),
            used_params: ParamSet::new(),
            lets: HashMap::new(),
            calls: Vec::new(),
            scope: Vec::new(),
            memo: HashMap::new(),
            expansions: 0,
            depth: 0,
            vectors_allowed: false,
        }
    }

    fn error(&mut self, mut d: Diagnostic) {
        if let Some((name, span)) = self.calls.last() {
            d = d.with_label(*span, format!("in this call of `{name}`"));
        }
        self.diags.push(d);
    }

    /// The type of `e`; also enforces [`MAX_DEPTH`] (going down, for this walk's own stack, and
    /// coming up, for the heights of `let`s already checked) and that constants are finite.
    pub fn ty(&mut self, e: &Expr) -> Option<Ty> {
        if self.depth >= MAX_DEPTH {
            self.too_deep(e.span);
            return None;
        }
        self.depth += 1;
        let ty = self.ty_inner(e);
        self.depth -= 1;
        let mut ty = ty?;
        ty.height += 1;
        if ty.height > MAX_DEPTH {
            self.too_deep(e.span);
            return None;
        }
        if let Some(v) = ty.konst.filter(|v| !v.is_finite()) {
            let note = match &e.kind {
                ExprKind::Call(f, _) => format!("a number outside the domain of `{}`, or an overflow", f.name),
                _ => "a division by zero or an overflow of double precision".into(),
            };
            self.error(
                Diagnostic::error("E0004", "constant arithmetic is not finite", e.span, format!("evaluates to {v}"))
                    .with_note(note),
            );
            return None;
        }
        Some(ty)
    }

    fn too_deep(&mut self, span: Span) {
        self.error(
            Diagnostic::error(
                "E0002",
                format!("expression nests deeper than {MAX_DEPTH} levels"),
                span,
                format!("more than {MAX_DEPTH} levels deep, counting the `let`s and `fn`s it uses"),
            )
            .with_help("compute it in fewer nested steps: sum terms in balanced groups"),
        );
    }

    fn ty_inner(&mut self, e: &Expr) -> Option<Ty> {
        match &e.kind {
            ExprKind::Number(v) => Some(Ty::constant(*v)),
            ExprKind::Name(id) => self.name_ty(id),
            ExprKind::Neg(a) => {
                let a = self.ty(a)?;
                Some(Ty { konst: a.konst.map(|v| -v), ..a })
            }
            ExprKind::Binary(op, a, b) => {
                let (ta, tb) = (self.ty(a), self.ty(b));
                let (ta, tb) = (ta?, tb?);
                let height = ta.height.max(tb.height);
                self.binary_ty(*op, e, a, b, ta, tb).map(|t| Ty { height, ..t })
            }
            ExprKind::Call(f, args) => self.call_ty(e, f, args),
            ExprKind::Vector(items) => {
                let tys: Vec<Option<Ty>> = items.iter().map(|a| self.ty(a)).collect();
                let mut out = Ty { shape: Shape::Vector, ..Ty::plain(Shape::Vector) };
                for (a, t) in items.iter().zip(tys) {
                    let t = t?;
                    if t.shape != Shape::Scalar {
                        self.error(shape_error(a.span, "a component of a vector must be a scalar", t.shape));
                        return None;
                    }
                    out = Ty::join(&out, &t, Shape::Vector);
                }
                if !self.vectors_allowed {
                    self.error(super::problem_only(e.span));
                    return None;
                }
                Some(Ty { height: out.height + 1, ..out })
            }
            ExprKind::Index(a, i) => {
                let ta = self.ty(a)?;
                if !self.vectors_allowed {
                    self.error(super::problem_only(e.span));
                    return None;
                }
                if ta.shape != Shape::Vector {
                    self.error(shape_error(a.span, "only a vector has components", ta.shape));
                    return None;
                }
                match const_eval(i) {
                    Ok(k) if k >= 0.0 && k.fract() == 0.0 && k < 3.0 => {}
                    _ => {
                        self.error(
                            Diagnostic::error("E0302", "a component index must be 0, 1 or 2", i.span, "not one")
                                .with_help("components count from 0: `x[0]`, `x[1]`, `x[2]`"),
                        );
                        return None;
                    }
                }
                Some(Ty { shape: Shape::Scalar, konst: None, height: ta.height + 1, ..ta })
            }
        }
    }
}
