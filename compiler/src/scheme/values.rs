//! What a scheme's expression means: a scalar of the coefficient graph (parameters, lets, dt,
//! t and arithmetic of them, `sqrt`, `abs`), or an affine combination of time levels with
//! scalar coefficients. Anything else is refused where it is written.

use super::compiler::{Compiler, Value};
use crate::check::schemes;
use crate::diagnostic::Diagnostic;
use crate::ir::graph::NodeId;
use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, ExprKind, Ident};

impl Compiler<'_> {
    pub(super) fn scalar(&mut self, e: &Expr) -> Option<NodeId> {
        match self.value(e)? {
            Value::Scalar(n) => Some(n),
            Value::Vector(_) => {
                self.error(Diagnostic::error("E0301", "expected a scalar", e.span, "a combination of time levels"));
                None
            }
        }
    }

    /// A scalar, or an affine combination of time levels; a division by zero or a non-finite
    /// constant is refused where it is written.
    pub(super) fn value(&mut self, e: &Expr) -> Option<Value> {
        let v = self.value_inner(e)?;
        if let Value::Scalar(n) = v
            && let Some(x) = self.g.as_const(n).filter(|x| !x.is_finite())
        {
            self.error(not_finite(e.span, &format!("evaluates to {x}")));
            return None;
        }
        Some(v)
    }

    fn value_inner(&mut self, e: &Expr) -> Option<Value> {
        match &e.kind {
            ExprKind::Vector(_) | ExprKind::Index(..) => {
                self.error(crate::check::problem_only(e.span));
                None
            }
            ExprKind::Number(v) => Some(Value::Scalar(self.g.constant(*v))),
            ExprKind::Name(id) => self.name(id),
            ExprKind::Neg(a) => Some(match self.value(a)? {
                Value::Scalar(n) => Value::Scalar(self.g.neg(n)),
                Value::Vector(v) => {
                    let m = self.g.constant(-1.0);
                    Value::Vector(v.scale(&mut self.g, m))
                }
            }),
            ExprKind::Binary(op, a, b) => self.binary(e, *op, a, b),
            ExprKind::Call(f, args) => self.call(e, f, args),
        }
    }

    /// A name in scope, or E0101.
    fn name(&mut self, id: &Ident) -> Option<Value> {
        if let Some(v) = self.scope.get(&id.name) {
            return Some(v.clone());
        }
        let visible = self.visible_names();
        self.error(schemes::unknown_name(self.prog, self.def, id, &visible));
        None
    }

    /// `a op b`: arithmetic of scalars, and the affine operations on levels (E0814 for the
    /// others).
    fn binary(&mut self, e: &Expr, op: BinOp, a: &Expr, b: &Expr) -> Option<Value> {
        let (x, y) = (self.value(a)?, self.value(b)?);
        if let (BinOp::Div, Value::Scalar(q)) = (op, &y)
            && self.g.is_zero(*q)
        {
            self.error(not_finite(e.span, "divides by zero"));
            return None;
        }
        match (op, x, y) {
            (BinOp::Add, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.add(p, q))),
            (BinOp::Sub, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.sub(p, q))),
            (BinOp::Mul, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.mul(p, q))),
            (BinOp::Div, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.div(p, q))),
            (BinOp::Pow, Value::Scalar(p), Value::Scalar(_)) => match crate::check::const_value(b) {
                Some(k) if k.fract() == 0.0 && k.abs() <= 64.0 => Some(Value::Scalar(self.g.powi(p, k as i32))),
                _ => {
                    self.error(Diagnostic::error(
                        "E0303",
                        "exponent must be a constant integer",
                        b.span,
                        "not a constant integer",
                    ));
                    None
                }
            },
            (BinOp::Add, Value::Vector(p), Value::Vector(q)) => Some(Value::Vector(p.add(&mut self.g, &q))),
            (BinOp::Sub, Value::Vector(p), Value::Vector(q)) => Some(Value::Vector(p.sub(&mut self.g, &q))),
            (BinOp::Mul, Value::Scalar(s), Value::Vector(v)) | (BinOp::Mul, Value::Vector(v), Value::Scalar(s)) => {
                Some(Value::Vector(v.scale(&mut self.g, s)))
            }
            (BinOp::Div, Value::Vector(v), Value::Scalar(s)) => {
                let one = self.g.one();
                let inv = self.g.div(one, s);
                Some(Value::Vector(v.scale(&mut self.g, inv)))
            }
            (op, _, _) => {
                let why = match op {
                    BinOp::Add | BinOp::Sub => "adds a scalar to a time level",
                    BinOp::Mul => "multiplies two time levels",
                    BinOp::Div => "divides by a time level",
                    BinOp::Pow => "raises a time level to a power",
                };
                self.error(
                    Diagnostic::error(
                        "E0814",
                        "not an affine relation between time levels",
                        e.span,
                        format!("this {why}"),
                    )
                    .with_note("relations and form arguments are combinations Σ cₖ·levelₖ with scalar coefficients"),
                );
                None
            }
        }
    }

    /// `sqrt(x)` and `abs(x)` of a scalar; a slot here is E0813, anything else E0101.
    fn call(&mut self, e: &Expr, f: &Ident, args: &[Expr]) -> Option<Value> {
        if schemes::is_slot(self.def, &f.name) {
            self.error(Diagnostic::error(
                "E0813",
                format!("slot `{}` applied outside a residual", f.name),
                e.span,
                "forms belong in `residual` lines",
            ));
            return None;
        }
        let vals: Vec<NodeId> = args.iter().map(|a| self.scalar(a)).collect::<Option<_>>()?;
        let node = match (f.name.as_str(), vals.as_slice()) {
            ("sqrt", [x]) => self.g.sqrt(*x),
            ("abs", [x]) => {
                let h = self.g.heaviside(*x);
                let m = self.g.neg(*x);
                let hm = self.g.heaviside(m);
                let s = self.g.sub(h, hm);
                self.g.mul(*x, s)
            }
            _ => {
                self.error(Diagnostic::error(
                    "E0101",
                    format!("`{}` is not available in schemes", f.name),
                    f.span,
                    "schemes use arithmetic, sqrt and abs",
                ));
                return None;
            }
        };
        Some(Value::Scalar(node))
    }
}

fn not_finite(span: Span, label: &str) -> Diagnostic {
    Diagnostic::error("E0004", "constant arithmetic is not finite", span, label)
        .with_note("a division by zero or an overflow of double precision, after simplification")
}
