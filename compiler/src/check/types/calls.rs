//! Calls: a user's `fn`, inlined with the types of its arguments (memoised, bounded), and the
//! built-in functions with their arities and shapes.

use super::{Checker, MAX_EXPANSIONS, MAX_INLINE_DEPTH, Ty};
use crate::check::Global;
use crate::check::builtins::{self, BUILTIN_VALUES, Builtin};
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::{Expr, ExprKind, Ident, Shape};

impl Checker<'_> {
    pub(super) fn call_ty(&mut self, e: &Expr, f: &Ident, args: &[Expr]) -> Option<Ty> {
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
            Some(Global::Fn { params, body, .. }) => self.inline_call(e, f, params, body, arg_tys),
            Some(Global::Coef(i)) => {
                let i = *i;
                self.coef_at_ty(e, f, i, args, arg_tys)
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
            None if let Some(b) = builtins::builtin(&f.name).filter(|b| b.numbers_only && self.vectors_allowed) => {
                if args.len() != b.arity {
                    self.arity_error(e, f, b.arity, args.len());
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
                Some(Ty { konst: ty.konst.and_then(|x| b.fold.apply(&[x])), ..ty })
            }
            None if f.name == "derivative" => self.derivative_ty(e, f, args, arg_tys),
            None if let Some(b) = builtins::function(&f.name) => {
                if b.arity != args.len() {
                    self.arity_error(e, f, b.arity, args.len());
                    return None;
                }
                let tys: Vec<Ty> = arg_tys.into_iter().collect::<Option<_>>()?;
                self.builtin_ty(e, b, args, &tys)
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

    /// A call of the user's `fn` with these parameters and body, inlined: its body checked with
    /// the argument types (once per distinct types), not recursive, not nested or expanded
    /// past the limits.
    fn inline_call(
        &mut self,
        e: &Expr,
        f: &Ident,
        params: &[Ident],
        body: &Expr,
        arg_tys: Vec<Option<Ty>>,
    ) -> Option<Ty> {
        if params.len() != arg_tys.len() {
            self.arity_error(e, f, params.len(), arg_tys.len());
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

    /// A coef evaluated at a point (`g(x + u)`, contact on the deformed configuration): one
    /// vector argument that does not hold the test function; the value has the coef's shape,
    /// and a gradient where the point has one.
    fn coef_at_ty(&mut self, e: &Expr, f: &Ident, i: usize, args: &[Expr], arg_tys: Vec<Option<Ty>>) -> Option<Ty> {
        if args.len() != 1 {
            self.arity_error(e, f, 1, args.len());
            return None;
        }
        let point = arg_tys.into_iter().next().flatten()?;
        if point.shape != Shape::Vector {
            self.error(
                Diagnostic::error(
                    "E0301",
                    "shape mismatch",
                    args[0].span,
                    format!("coef `{}` is read at a point: a vector, not a {}", f.name, point.shape.name()),
                )
                .with_help(format!("`{}(x + u)` reads it at the displaced point", f.name)),
            );
            return None;
        }
        if point.test {
            self.error(Diagnostic::error(
                "E0402",
                format!("test function in the point coef `{}` is read at", f.name),
                args[0].span,
                "depends on the test function",
            ));
            return None;
        }
        let shape = self.prog.coefs[i].shape;
        Some(Ty { shape, konst: None, height: point.height.saturating_add(1), ..point })
    }

    /// `derivative(e, u, d)`: `u` a name of the scope (a field, or an argument of the function
    /// the call is written in), `d` a direction of its shape; `e` is differentiated, so it must
    /// not hold the test function, and the result is linear in `d`.
    fn derivative_ty(&mut self, e: &Expr, f: &Ident, args: &[Expr], arg_tys: Vec<Option<Ty>>) -> Option<Ty> {
        if args.len() != 3 {
            self.arity_error(e, f, 3, args.len());
            return None;
        }
        let tys: Vec<Ty> = arg_tys.into_iter().collect::<Option<_>>()?;
        let (te, tu, td) = (tys[0], tys[1], tys[2]);
        let named = matches!(&args[1].kind, ExprKind::Name(id) if self.scope.iter().any(|(n, _)| *n == id.name));
        if !named {
            self.error(
                Diagnostic::error(
                    "E0407",
                    "`derivative` with respect to something that is not an argument",
                    args[1].span,
                    "not a field of the form or an argument of the function",
                )
                .with_help("`derivative(e, u, v)` varies a name: a field of the form, or an argument of the `fn` it is written in (`fn dpn(u, v) = derivative(pn(u), u, v)`)"),
            );
            return None;
        }
        if tu.test {
            self.error(Diagnostic::error(
                "E0402",
                "`derivative` with respect to the test function",
                args[1].span,
                "the test function",
            ));
            return None;
        }
        if te.test {
            self.error(
                Diagnostic::error("E0402", "test function inside `derivative`", args[0].span, "depends on the test function")
                    .with_note("the expression is differentiated, and a form must be linear in its test function: give the test function as the direction, `derivative(e, u, v)`"),
            );
            return None;
        }
        if td.shape != tu.shape {
            self.error(
                Diagnostic::error(
                    "E0301",
                    "shape mismatch",
                    args[2].span,
                    format!(
                        "the direction of `derivative` must have the shape of what it varies, a {}, not a {}",
                        tu.shape.name(),
                        td.shape.name()
                    ),
                )
                .with_label(args[1].span, tu.shape.name()),
            );
            return None;
        }
        if tu.smooth && !td.smooth {
            self.error(
                Diagnostic::error("E0502", "the direction of `derivative` has no gradient", args[2].span, "no gradient")
                    .with_note("what it varies has one, which the expression may read: the direction must be a field, a test function, or a smooth expression of them"),
            );
            return None;
        }
        Some(Ty {
            shape: te.shape,
            test: td.test,
            facet: te.facet.or(td.facet),
            smooth: te.smooth && td.smooth,
            konst: None,
            height: te.height.max(td.height).saturating_add(1),
        })
    }

    pub(super) fn arity_error(&mut self, e: &Expr, f: &Ident, want: usize, got: usize) {
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

    pub(super) fn builtin_ty(&mut self, e: &Expr, b: &Builtin, args: &[Expr], tys: &[Ty]) -> Option<Ty> {
        let name = b.name;
        let shapes: Vec<Shape> = tys.iter().map(|t| t.shape).collect();
        let shape = match b.result_shape(&shapes) {
            Ok(s) => s,
            Err(msg) => {
                let mut d = Diagnostic::error("E0301", "shape mismatch", e.span, msg);
                for (a, t) in args.iter().zip(tys) {
                    d = d.with_label(a.span, t.shape.name());
                }
                if let Some(help) = b.shape_help(&shapes) {
                    d = d.with_help(help);
                }
                self.error(d);
                return None;
            }
        };
        if b.nonlinear
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
        if name == "prev" && tys[0].test {
            self.error(
                Diagnostic::error("E0402", "test function inside `prev`", args[0].span, "depends on the test function")
                    .with_note("`prev(e)` is `e` at the previous time level: the test function has none"),
            );
            return None;
        }
        if name == "tangential" && tys[1].test {
            self.error(
                Diagnostic::error("E0402", "test function in the normal of `tangential`", args[1].span, "depends on the test function")
                    .with_note("`tangential(a, nc)` = a − (a·nc) nc is linear in `a` only, and a form must be linear in its test function"),
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
            _ => {
                // A function of numbers is a number (`cos(alpha)` of a problem's param).
                let konst: Option<Vec<f64>> = tys.iter().map(|t| t.konst).collect();
                ty.konst = konst.and_then(|k| b.fold.apply(&k));
            }
        }
        Some(ty)
    }
}
