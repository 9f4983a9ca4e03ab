//! What a name is: a local, a param, a coef, a let, a built-in value, or an unknown name
//! (with the closest known one).

use super::{Checker, Ty};
use crate::check::builtins::{self, BUILTIN_VALUES};
use crate::check::{Global, suggest_name};
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::{Ident, Shape};

impl Checker<'_> {
    pub(super) fn unknown(&mut self, id: &Ident) {
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
            .chain(builtins::function_names().map(|n| n as &str))
            .chain(scope_names.iter().map(String::as_str));
        let mut d = Diagnostic::error("E0101", format!("unknown name `{}`", id.name), id.span, "not defined");
        if let Some(s) = suggest_name(&id.name, candidates) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.error(d);
    }

    pub(super) fn name_ty(&mut self, id: &Ident) -> Option<Ty> {
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
                _ if builtins::function(&id.name).is_some() => {
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
}
