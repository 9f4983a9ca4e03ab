//! Abstract evaluation of expressions: shape, linearity in the test function, use of facet
//! geometry, differentiability and compile-time constant value.

use std::collections::{HashMap, HashSet};

use super::builtins::{self, BUILTIN_FUNCTIONS, BUILTIN_VALUES, NONLINEAR};
use super::{CELL_REGION, Global, ParamRange, ParamSet, Unit};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, ExprKind, Ident, Shape};

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

    /// Param defaults and ranges are constant expressions; the default must lie in its range.
    pub fn check_params(&mut self) -> Vec<(Option<f64>, Option<ParamRange>)> {
        let n = self.prog.params.len();
        let mut values = Vec::with_capacity(n);
        for i in 0..n {
            let p = &self.prog.params[i];
            let default = self.constant(&p.default_expr, "a param default").filter(|v| {
                let finite = v.is_finite();
                if !finite {
                    self.error(Diagnostic::error(
                        "E0603",
                        "a param default must be finite",
                        p.default_expr.span,
                        format!("evaluates to {v}"),
                    ));
                }
                finite
            });
            let range = p.range_expr.as_ref().and_then(|r| {
                let lo = self.constant(&r.lo, "a range bound")?;
                let hi = self.constant(&r.hi, "a range bound")?;
                let range = ParamRange { lo, lo_closed: r.lo_closed, hi, hi_closed: r.hi_closed };
                if lo > hi || (lo == hi && !(r.lo_closed && r.hi_closed)) {
                    self.error(Diagnostic::error(
                        "E0602",
                        "empty parameter range",
                        r.span,
                        format!("no value lies in {}", range.describe()),
                    ));
                    return None;
                }
                Some(range)
            });
            if let (Some(v), Some(r)) = (default, range)
                && !r.contains(v)
            {
                let name = &self.prog.params[i].name;
                self.error(
                    Diagnostic::error(
                        "E0601",
                        format!("default of `{name}` is outside its range"),
                        p.default_expr.span,
                        format!("{v} is not in {}", r.describe()),
                    )
                    .with_label(p.range_expr.as_ref().map_or(p.span, |r| r.span), "the declared range"),
                );
            }
            values.push((default, range));
        }
        values
    }

    /// A constant expression (numbers, arithmetic, `sqrt`, `pi`, `inf`).
    fn constant(&mut self, e: &Expr, what: &str) -> Option<f64> {
        match const_eval(e) {
            Ok(v) => Some(v),
            Err(span) => {
                self.error(
                    Diagnostic::error("E0603", format!("{what} must be a constant"), span, "not a constant")
                        .with_help("use numbers, arithmetic, sqrt, pi and inf"),
                );
                None
            }
        }
    }

    /// Lets are checked once, whether used or not; fns are checked at their uses, and on their own
    /// with plain arguments so that a mistake in an unused fn is still reported.
    pub fn check_lets_and_fns(&mut self) {
        let mut names: Vec<(&String, &Global)> = self.prog.globals.iter().collect();
        names.sort_by_key(|(_, g)| g.span(&self.prog.params, &self.prog.coefs, &self.prog.forms));
        for (name, g) in names {
            match g {
                Global::Let { .. } => {
                    let saved = std::mem::take(&mut self.used_params);
                    self.let_ty(name, Span::new(0, 0, 0));
                    self.used_params = saved;
                }
                Global::Fn { params, body, .. } => {
                    let saved = std::mem::take(&mut self.used_params);
                    let scope = params.iter().map(|p| (p.name.clone(), Ty::plain(Shape::Vector))).collect();
                    let old = std::mem::replace(&mut self.scope, scope);
                    // Shapes of parameters are unknown here: check names only.
                    self.names_only(body, params);
                    self.scope = old;
                    self.used_params = saved;
                }
                _ => {}
            }
        }
    }

    /// The type of a problem's expression, with `names` (the problem's params and lets, and
    /// the fields of the context) visible and vectors allowed.
    pub(super) fn problem_ty(&mut self, e: &Expr, names: &[(String, Shape)]) -> Option<Ty> {
        let old = std::mem::take(&mut self.scope);
        self.scope = names.iter().map(|(n, s)| (n.clone(), Ty::plain(*s))).collect();
        self.vectors_allowed = true;
        let ty = self.ty(e);
        self.vectors_allowed = false;
        self.scope = old;
        ty
    }

    /// Reports unknown names in an expression whose argument shapes are not known.
    fn names_only(&mut self, e: &Expr, params: &[Ident]) {
        match &e.kind {
            ExprKind::Number(_) => {}
            ExprKind::Name(id) => {
                if !params.iter().any(|p| p.name == id.name)
                    && !self.prog.globals.contains_key(&id.name)
                    && !BUILTIN_VALUES.contains(&id.name.as_str())
                {
                    self.unknown(id);
                }
            }
            ExprKind::Call(f, args) => {
                if !self.prog.globals.contains_key(&f.name) && !BUILTIN_FUNCTIONS.contains(&f.name.as_str()) {
                    self.unknown(f);
                }
                for a in args {
                    self.names_only(a, params);
                }
            }
            ExprKind::Neg(a) => self.names_only(a, params),
            ExprKind::Binary(_, a, b) | ExprKind::Index(a, b) => {
                self.names_only(a, params);
                self.names_only(b, params);
            }
            ExprKind::Vector(items) => items.iter().for_each(|a| self.names_only(a, params)),
        }
    }

    pub fn check_forms(&mut self) {
        for form in &self.prog.forms {
            let mut scope: Vec<(String, Ty)> =
                form.fields.iter().map(|f| (f.name.clone(), Ty::plain(Shape::Vector))).collect();
            if let Some(test) = &form.test {
                scope.push((test.name.clone(), Ty { test: true, ..Ty::plain(Shape::Vector) }));
            }
            self.scope = scope;
            for integral in &form.integrals {
                let Some(ty) = self.ty(&integral.integrand) else {
                    continue;
                };
                let span = integral.integrand.span;
                if ty.shape != Shape::Scalar {
                    // The help names the form's own test function.
                    let help = match (&form.test, ty.shape) {
                        (Some(w), Shape::Tensor) => format!("take inner(..., grad({})) with the test function", w.name),
                        (Some(w), _) => format!("take dot(..., {}) with the test function", w.name),
                        (None, _) => "a functional integrates a scalar: take a dot or inner product".to_string(),
                    };
                    self.error(
                        Diagnostic::error(
                            "E0304",
                            "integrand is not a scalar",
                            span,
                            format!("this is a {}", ty.shape.name()),
                        )
                        .with_help(help),
                    );
                } else if let Some(test) = form.test.as_ref().filter(|_| !ty.test) {
                    self.error(
                        Diagnostic::error(
                            "E0401",
                            format!("integrand does not depend on the test function `{}`", test.name),
                            span,
                            "no test function here",
                        )
                        .with_note("a form is linear in its test function: every term must contain it exactly once"),
                    );
                }
                if integral.region.name == CELL_REGION
                    && let Some(g) = ty.facet
                {
                    let what = self.prog.sources.slice(g).to_string();
                    self.error(
                        Diagnostic::error(
                            "E0501",
                            format!("`{what}` used in a volume integral"),
                            g,
                            "only defined on boundary facets",
                        )
                        .with_label(integral.region.span, "this integral is over cells")
                        .with_help("`n` and `h` belong in integrals over a boundary region, e.g. int(Gamma_C)"),
                    );
                }
            }
            self.scope.clear();
        }
    }

    fn unknown(&mut self, id: &Ident) {
        if self.broken.contains(&id.name) {
            return; // its declaration has a syntax error, already reported
        }
        let scope_names: Vec<String> = self.scope.iter().map(|(n, _)| n.clone()).collect();
        let candidates = self
            .prog
            .globals
            .keys()
            .map(String::as_str)
            .chain(BUILTIN_VALUES.iter().copied())
            .chain(BUILTIN_FUNCTIONS.iter().copied())
            .chain(scope_names.iter().map(String::as_str));
        let mut d = Diagnostic::error("E0101", format!("unknown name `{}`", id.name), id.span, "not defined");
        if let Some(s) = super::suggest_name(&id.name, candidates) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.error(d);
    }

    fn let_ty(&mut self, name: &str, use_span: Span) -> Option<Ty> {
        match self.lets.get(name) {
            Some(LetState::Done(ty, params)) => {
                self.used_params.extend(params.iter().copied());
                return *ty;
            }
            Some(LetState::InProgress) => {
                let Some(Global::Let { span, .. }) = self.prog.globals.get(name) else {
                    return None;
                };
                self.error(
                    Diagnostic::error(
                        "E0104",
                        format!("`{name}` is defined in terms of itself"),
                        use_span,
                        "used here",
                    )
                    .with_label(*span, "in this definition"),
                );
                return None;
            }
            None => {}
        }
        let Some(Global::Let { value, .. }) = self.prog.globals.get(name) else {
            return None;
        };
        self.lets.insert(name.to_string(), LetState::InProgress);
        let saved_scope = std::mem::take(&mut self.scope);
        let saved_used = std::mem::take(&mut self.used_params);
        let saved_calls = std::mem::take(&mut self.calls);
        let ty = self.ty(value);
        self.calls = saved_calls;
        self.scope = saved_scope;
        let used = std::mem::replace(&mut self.used_params, saved_used);
        self.used_params.extend(used.iter().copied());
        self.lets.insert(name.to_string(), LetState::Done(ty, used));
        ty
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
            self.error(
                Diagnostic::error("E0004", "constant arithmetic is not finite", e.span, format!("evaluates to {v}"))
                    .with_note("a division by zero or an overflow of double precision"),
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

    fn name_ty(&mut self, id: &Ident) -> Option<Ty> {
        if let Some((_, ty)) = self.scope.iter().rev().find(|(n, _)| *n == id.name) {
            return Some(*ty);
        }
        match self.prog.globals.get(&id.name) {
            Some(Global::Param(i)) => {
                self.used_params.insert(*i);
                Some(Ty::plain(Shape::Scalar))
            }
            Some(Global::Coef(i)) => Some(Ty { smooth: false, ..Ty::plain(self.prog.coefs[*i].shape) }),
            Some(Global::Let { .. }) => self.let_ty(&id.name, id.span),
            Some(g @ (Global::Fn { .. } | Global::Form(_) | Global::Scheme(_) | Global::Problem(_))) => {
                let kind = g.kind();
                self.error(
                    Diagnostic::error(
                        "E0205",
                        format!("`{}` is a {kind}, not a value", id.name),
                        id.span,
                        "used as a value",
                    )
                    .with_help(format!("call it: `{}(...)`", id.name)),
                );
                None
            }
            None => match id.name.as_str() {
                "I" => Some(Ty::plain(Shape::Tensor)),
                "x" => Some(Ty::plain(Shape::Vector)),
                "t" => Some(Ty::plain(Shape::Scalar)),
                "pi" => Some(Ty::constant(std::f64::consts::PI)),
                "n" => Some(Ty { facet: Some(id.span), smooth: false, ..Ty::plain(Shape::Vector) }),
                "h" => Some(Ty { facet: Some(id.span), ..Ty::plain(Shape::Scalar) }),
                "inf" => {
                    self.error(Diagnostic::error(
                        "E0206",
                        "`inf` is only allowed in parameter ranges",
                        id.span,
                        "not a finite value",
                    ));
                    None
                }
                _ if BUILTIN_FUNCTIONS.contains(&id.name.as_str()) => {
                    self.error(
                        Diagnostic::error(
                            "E0205",
                            format!("`{}` is a function, not a value", id.name),
                            id.span,
                            "used as a value",
                        )
                        .with_help(format!("call it: `{}(...)`", id.name)),
                    );
                    None
                }
                _ => {
                    self.unknown(id);
                    None
                }
            },
        }
    }

    fn binary_ty(&mut self, op: BinOp, e: &Expr, a: &Expr, b: &Expr, ta: Ty, tb: Ty) -> Option<Ty> {
        use Shape::*;
        let mismatch = |this: &mut Self, msg: String, help: Option<&str>| {
            let mut d = Diagnostic::error("E0301", "shape mismatch", e.span, msg)
                .with_label(a.span, ta.shape.name())
                .with_label(b.span, tb.shape.name());
            if let Some(h) = help {
                d = d.with_help(h);
            }
            this.error(d);
            None
        };
        match op {
            BinOp::Add | BinOp::Sub => {
                if ta.shape != tb.shape {
                    return mismatch(
                        self,
                        format!(
                            "cannot {} a {} and a {}",
                            if op == BinOp::Add { "add" } else { "subtract" },
                            ta.shape.name(),
                            tb.shape.name()
                        ),
                        None,
                    );
                }
                if ta.test != tb.test {
                    let (without, with) = if ta.test { (b, a) } else { (a, b) };
                    self.error(
                        Diagnostic::error(
                            "E0405",
                            "form is not linear in the test function",
                            without.span,
                            "this term does not contain the test function",
                        )
                        .with_label(with.span, "this one does")
                        .with_note("a form is linear in its test function: every term must contain it exactly once"),
                    );
                    return None;
                }
                let konst = match (ta.konst, tb.konst) {
                    (Some(x), Some(y)) => Some(if op == BinOp::Add { x + y } else { x - y }),
                    _ => None,
                };
                Some(Ty { konst, ..Ty::join(&ta, &tb, ta.shape) })
            }
            BinOp::Mul => {
                let shape = match (ta.shape, tb.shape) {
                    (Scalar, s) | (s, Scalar) => s,
                    (Tensor, Vector) | (Vector, Tensor) => Vector,
                    (Tensor, Tensor) => Tensor,
                    (Vector, Vector) => {
                        return mismatch(
                            self,
                            "cannot multiply two vectors".into(),
                            Some("use dot(a, b) for the scalar product, or outer(a, b)"),
                        );
                    }
                };
                if ta.test && tb.test {
                    self.self_product(e.span, a.span, b.span);
                    return None;
                }
                let konst = ta.konst.zip(tb.konst).map(|(x, y)| x * y);
                Some(Ty { konst, ..Ty::join(&ta, &tb, shape) })
            }
            BinOp::Div => {
                if tb.shape != Scalar {
                    return mismatch(self, format!("cannot divide by a {}", tb.shape.name()), None);
                }
                if tb.test {
                    self.error(
                        Diagnostic::error(
                            "E0403",
                            "test function in a denominator",
                            b.span,
                            "depends on the test function",
                        )
                        .with_note("a form must be linear in its test function"),
                    );
                    return None;
                }
                let konst = ta.konst.zip(tb.konst).map(|(x, y)| x / y);
                Some(Ty { konst, ..Ty::join(&ta, &tb, ta.shape) })
            }
            BinOp::Pow => {
                if ta.shape != Scalar {
                    return mismatch(
                        self,
                        format!("cannot raise a {} to a power", ta.shape.name()),
                        Some("powers apply to scalars; use dot or inner for products"),
                    );
                }
                // A real constant exponent: a^p, differentiated as p a^(p−1) (NaN where a < 0;
                // its derivative infinite at a = 0 for p < 1).
                if let Some(k) = tb.konst.filter(|k| k.fract() != 0.0 && k.is_finite())
                    && !ta.test
                {
                    return Some(Ty { konst: ta.konst.map(|x| x.powf(k)), ..ta });
                }
                let k = match tb.konst {
                    Some(k) if k.fract() == 0.0 && k.abs() <= 64.0 && !tb.test => k,
                    _ => {
                        self.error(
                            Diagnostic::error("E0303", "exponent must be a constant", b.span, "not a constant")
                                .with_help(
                                    "`^` takes a number written in the file (integers from -64 to 64, or a real such as 3/2); a param's value is not known when the form is compiled",
                                ),
                        );
                        return None;
                    }
                };
                if ta.test && k != 1.0 {
                    if k < 0.0 {
                        self.error(Diagnostic::error(
                            "E0403",
                            "test function in a denominator",
                            e.span,
                            "negative power of the test function",
                        ));
                    } else {
                        self.self_product(e.span, a.span, b.span);
                    }
                    return None;
                }
                Some(Ty { konst: ta.konst.map(|x| x.powi(k as i32)), ..ta })
            }
        }
    }

    fn self_product(&mut self, span: Span, a: Span, b: Span) {
        self.error(
            Diagnostic::error("E0404", "test function multiplied by itself", span, "quadratic in the test function")
                .with_label(a, "contains the test function")
                .with_label(b, "contains it too")
                .with_note("a form must be linear in its test function"),
        );
    }

    fn call_ty(&mut self, e: &Expr, f: &Ident, args: &[Expr]) -> Option<Ty> {
        if let Some((_, _)) = self.scope.iter().find(|(n, _)| *n == f.name) {
            self.error(Diagnostic::error(
                "E0204",
                format!("`{}` is not a function", f.name),
                f.span,
                "a value, not a function",
            ));
            return None;
        }
        let arg_tys: Vec<Option<Ty>> = args.iter().map(|a| self.ty(a)).collect();
        match self.prog.globals.get(&f.name) {
            Some(Global::Fn { params, body, .. }) => {
                if params.len() != args.len() {
                    self.arity_error(e, f, params.len(), args.len());
                    return None;
                }
                let arg_tys: Vec<Ty> = arg_tys.into_iter().collect::<Option<_>>()?;
                let key = (f.name.clone(), arg_tys.iter().map(Ty::key).collect::<Vec<_>>());
                if let Some((ty, used)) = self.memo.get(&key) {
                    self.used_params.extend(used.iter().copied());
                    return *ty;
                }
                if self.calls.iter().any(|(n, _)| *n == f.name) {
                    self.error(
                        Diagnostic::error("E0105", format!("`{}` calls itself", f.name), f.span, "recursive call")
                            .with_note("functions are inlined, so they cannot be recursive"),
                    );
                    return None;
                }
                if self.calls.len() >= MAX_INLINE_DEPTH {
                    self.error(Diagnostic::error(
                        "E0105",
                        "functions nested too deeply",
                        f.span,
                        format!("more than {MAX_INLINE_DEPTH} nested calls"),
                    ));
                    return None;
                }
                self.expansions += 1;
                if self.expansions > MAX_EXPANSIONS {
                    if self.expansions == MAX_EXPANSIONS + 1 {
                        self.error(
                            Diagnostic::error(
                                "E0002",
                                "functions expand too far",
                                e.span,
                                format!("more than {MAX_EXPANSIONS} inlined calls with distinct arguments"),
                            )
                            .with_help("functions are inlined at every call: compute shared values once with `let`"),
                        );
                    }
                    return None;
                }
                let scope = params.iter().zip(arg_tys).map(|(p, t)| (p.name.clone(), t)).collect();
                let saved = std::mem::replace(&mut self.scope, scope);
                let saved_used = std::mem::take(&mut self.used_params);
                self.calls.push((f.name.clone(), e.span));
                let ty = self.ty(body);
                self.calls.pop();
                self.scope = saved;
                let used = std::mem::replace(&mut self.used_params, saved_used);
                self.used_params.extend(used.iter().copied());
                self.memo.insert(key, (ty, used));
                ty
            }
            Some(g) => {
                if let Global::Param(i) = g {
                    self.used_params.insert(*i);
                }
                let kind = g.kind();
                let mut d = Diagnostic::error(
                    "E0204",
                    format!("`{}` is a {kind}, not a function", f.name),
                    f.span,
                    "cannot be called",
                );
                if kind == "form" {
                    d = d.with_note("forms are applied to time levels in schemes, not called inside expressions");
                }
                self.error(d);
                None
            }
            // A problem's numbers round up or down (the lowering checks that they are numbers).
            None if self.vectors_allowed && builtins::NUMBER_FUNCTIONS.contains(&f.name.as_str()) => {
                if args.len() != 1 {
                    self.arity_error(e, f, 1, args.len());
                    return None;
                }
                let ty = arg_tys.into_iter().next().flatten()?;
                if ty.shape != Shape::Scalar {
                    self.error(Diagnostic::error(
                        "E0301",
                        "shape mismatch",
                        args[0].span,
                        format!("`{}` takes a scalar", f.name),
                    ));
                    return None;
                }
                let round = if f.name == "ceil" { f64::ceil } else { f64::floor };
                Some(Ty { konst: ty.konst.map(round), ..ty })
            }
            None if BUILTIN_FUNCTIONS.contains(&f.name.as_str()) => {
                let want = builtins::arity(&f.name);
                if want != args.len() {
                    self.arity_error(e, f, want, args.len());
                    return None;
                }
                let tys: Vec<Ty> = arg_tys.into_iter().collect::<Option<_>>()?;
                self.builtin_ty(e, f, args, &tys)
            }
            None if BUILTIN_VALUES.contains(&f.name.as_str()) => {
                self.error(Diagnostic::error(
                    "E0204",
                    format!("`{}` is a built-in value, not a function", f.name),
                    f.span,
                    "cannot be called",
                ));
                None
            }
            None => {
                self.unknown(f);
                None
            }
        }
    }

    fn arity_error(&mut self, e: &Expr, f: &Ident, want: usize, got: usize) {
        let plural = |n: usize| if n == 1 { "argument" } else { "arguments" };
        let mut d = Diagnostic::error(
            "E0201",
            format!(
                "`{}` takes {want} {}, but {got} {} given",
                f.name,
                plural(want),
                if got == 1 { "was" } else { "were" }
            ),
            e.span,
            format!("{got} {}", plural(got)),
        );
        if let Some(Global::Fn { span, .. }) = self.prog.globals.get(&f.name) {
            d = d.with_label(*span, "defined here");
        }
        self.error(d);
    }

    fn builtin_ty(&mut self, e: &Expr, f: &Ident, args: &[Expr], tys: &[Ty]) -> Option<Ty> {
        let name = f.name.as_str();
        let shapes: Vec<Shape> = tys.iter().map(|t| t.shape).collect();
        let shape = match builtins::result_shape(name, &shapes) {
            Ok(s) => s,
            Err(msg) => {
                let mut d = Diagnostic::error("E0301", "shape mismatch", e.span, msg);
                for (a, t) in args.iter().zip(tys) {
                    d = d.with_label(a.span, t.shape.name());
                }
                self.error(d);
                return None;
            }
        };
        if NONLINEAR.contains(&name)
            && let Some((a, _)) = args.iter().zip(tys).find(|(_, t)| t.test)
        {
            self.error(
                Diagnostic::error(
                    "E0402",
                    format!("test function inside `{name}`"),
                    a.span,
                    "depends on the test function",
                )
                .with_note(format!("`{name}` is not linear, and a form must be linear in its test function")),
            );
            return None;
        }
        if matches!(name, "dot" | "inner" | "outer") && tys[0].test && tys[1].test {
            self.self_product(e.span, args[0].span, args[1].span);
            return None;
        }
        let mut ty = tys.iter().skip(1).fold(tys[0], |acc, t| Ty::join(&acc, t, shape));
        ty.shape = shape;
        ty.konst = None;
        match name {
            "grad" | "div" => {
                if !tys[0].smooth {
                    let reason = if tys[0].facet.is_some() { "the normal" } else { "case data or a derivative" };
                    self.error(
                        Diagnostic::error("E0502", format!("cannot take `{name}` of this expression"), args[0].span, format!("depends on {reason}"))
                            .with_note("derivatives are available for fields, test functions, x, and smooth functions of them, once"),
                    );
                    return None;
                }
                ty.smooth = false;
            }
            "sqrt" => ty.konst = tys[0].konst.map(f64::sqrt),
            "abs" => ty.konst = tys[0].konst.map(f64::abs),
            "min" => ty.konst = tys[0].konst.zip(tys[1].konst).map(|(a, b)| a.min(b)),
            "max" => ty.konst = tys[0].konst.zip(tys[1].konst).map(|(a, b)| a.max(b)),
            _ => {}
        }
        Some(ty)
    }
}

/// Evaluates a constant expression; on failure returns the span of the first non-constant part.
pub fn const_eval(e: &Expr) -> Result<f64, Span> {
    Ok(match &e.kind {
        ExprKind::Number(v) => *v,
        ExprKind::Name(id) => match id.name.as_str() {
            "pi" => std::f64::consts::PI,
            "inf" => f64::INFINITY,
            _ => return Err(e.span),
        },
        ExprKind::Neg(a) => -const_eval(a)?,
        ExprKind::Binary(op, a, b) => {
            let (x, y) = (const_eval(a)?, const_eval(b)?);
            match op {
                BinOp::Add => x + y,
                BinOp::Sub => x - y,
                BinOp::Mul => x * y,
                BinOp::Div => x / y,
                BinOp::Pow => x.powf(y),
            }
        }
        ExprKind::Vector(_) | ExprKind::Index(..) => return Err(e.span),
        ExprKind::Call(f, args) => match (f.name.as_str(), args.as_slice()) {
            ("sqrt", [a]) => const_eval(a)?.sqrt(),
            ("abs", [a]) => const_eval(a)?.abs(),
            ("min", [a, b]) => const_eval(a)?.min(const_eval(b)?),
            ("max", [a, b]) => const_eval(a)?.max(const_eval(b)?),
            _ => return Err(e.span),
        },
    })
}
