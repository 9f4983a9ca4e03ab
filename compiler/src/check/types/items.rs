//! The unit's declarations checked: param defaults and ranges, lets (once, whether used or
//! not), fns (on their own, by names only), forms' integrands, and a problem's expressions.

use signorini_descriptors::ParamRange;

use super::{Checker, LetState, Ty};
use crate::check::builtins::{self, BUILTIN_VALUES};
use crate::check::{CELL_REGION, Global, const_eval, range_written};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{Expr, ExprKind, Ident, Shape};

impl Checker<'_> {
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
                        format!("no value lies in {}", range_written(&self.prog.sources, r)),
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
                        format!(
                            "{v} is not in {}",
                            range_written(&self.prog.sources, p.range_expr.as_ref().expect("a range"))
                        ),
                    )
                    .with_label(p.range_expr.as_ref().map_or(p.span, |r| r.span), "the declared range"),
                );
            }
            values.push((default, range));
        }
        values
    }

    /// A constant expression (numbers, arithmetic, `sqrt`, `pi`, `inf`).
    pub(super) fn constant(&mut self, e: &Expr, what: &str) -> Option<f64> {
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
    pub(in crate::check) fn problem_ty(&mut self, e: &Expr, names: &[(String, Shape)]) -> Option<Ty> {
        let old = std::mem::take(&mut self.scope);
        self.scope = names.iter().map(|(n, s)| (n.clone(), Ty::plain(*s))).collect();
        self.vectors_allowed = true;
        let ty = self.ty(e);
        self.vectors_allowed = false;
        self.scope = old;
        ty
    }

    /// Reports unknown names in an expression whose argument shapes are not known.
    pub(super) fn names_only(&mut self, e: &Expr, params: &[Ident]) {
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
                if !self.prog.globals.contains_key(&f.name) && builtins::function(&f.name).is_none() {
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

    pub(super) fn let_ty(&mut self, name: &str, use_span: Span) -> Option<Ty> {
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
}
