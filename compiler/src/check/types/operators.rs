//! Arithmetic: the shapes `+ - * / ^` accept, linearity in the test function, and constant
//! folding.

use super::{Checker, Ty};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, Shape};

impl Checker<'_> {
    pub(super) fn binary_ty(&mut self, op: BinOp, e: &Expr, a: &Expr, b: &Expr, ta: Ty, tb: Ty) -> Option<Ty> {
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
            BinOp::Pow => self.power_ty(e, a, b, ta, tb),
        }
    }

    /// `a ^ b`: a scalar to a constant power (an integer up to 64, or a real constant of a value
    /// without the test function); the test function only to the power 1.
    fn power_ty(&mut self, e: &Expr, a: &Expr, b: &Expr, ta: Ty, tb: Ty) -> Option<Ty> {
        if ta.shape != Shape::Scalar {
            self.error(
                Diagnostic::error(
                    "E0301",
                    "shape mismatch",
                    e.span,
                    format!("cannot raise a {} to a power", ta.shape.name()),
                )
                .with_label(a.span, ta.shape.name())
                .with_label(b.span, tb.shape.name())
                .with_help("powers apply to scalars; use dot or inner for products"),
            );
            return None;
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

    pub(super) fn self_product(&mut self, span: Span, a: Span, b: Span) {
        self.error(
            Diagnostic::error("E0404", "test function multiplied by itself", span, "quadratic in the test function")
                .with_label(a, "contains the test function")
                .with_label(b, "contains it too")
                .with_note("a form must be linear in its test function"),
        );
    }
}
