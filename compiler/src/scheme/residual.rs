//! A residual `lhs == rhs` as a list of terms `coef · slot(levels)` at a time: sums and scalar
//! multiples of slot applications, a load being a slot applied to a time (or to nothing).

use super::compiler::{Compiler, Value};
use super::ir::Term;
use crate::check::schemes::{self, SCHEME_FUNCTIONS};
use crate::diagnostic::Diagnostic;
use crate::ir::graph::NodeId;
use crate::syntax::ast::{self, BinOp, Expr, ExprKind, Ident};

impl Compiler<'_> {
    /// A residual `lhs == rhs` as a list of terms (rhs with flipped signs).
    pub(super) fn residual(&mut self, r: &ast::Residual, time: NodeId) -> Option<Vec<Term>> {
        let mut lhs = self.form_sum(&r.lhs, time)?;
        let rhs = self.form_sum(&r.rhs, time)?;
        let minus = self.g.constant(-1.0);
        for mut t in rhs {
            t.coef = self.g.mul(minus, t.coef);
            lhs.push(t);
        }
        Some(lhs)
    }

    /// A sum of scalar multiples of form applications.
    fn form_sum(&mut self, e: &Expr, time: NodeId) -> Option<Vec<Term>> {
        match &e.kind {
            ExprKind::Call(f, _)
                if !schemes::is_slot(self.def, &f.name) && !SCHEME_FUNCTIONS.contains(&f.name.as_str()) =>
            {
                let d = schemes::unknown_slot(self.prog, self.def, f);
                self.error(d);
                None
            }
            ExprKind::Call(f, args) if schemes::is_slot(self.def, &f.name) => self.application(e, f, args, time),
            ExprKind::Binary(op @ (BinOp::Add | BinOp::Sub), a, b) => {
                let mut x = self.form_sum(a, time)?;
                let y = self.form_sum(b, time)?;
                let sign = self.g.constant(if *op == BinOp::Add { 1.0 } else { -1.0 });
                for mut t in y {
                    t.coef = self.g.mul(sign, t.coef);
                    x.push(t);
                }
                Some(x)
            }
            ExprKind::Neg(a) => {
                let mut x = self.form_sum(a, time)?;
                let m = self.g.constant(-1.0);
                x.iter_mut().for_each(|t| t.coef = self.g.mul(m, t.coef));
                Some(x)
            }
            ExprKind::Binary(BinOp::Mul, a, b) => {
                let (scalar, sum) = if self.is_form_sum(a) { (b, a) } else { (a, b) };
                let s = self.scalar(scalar)?;
                let mut x = self.form_sum(sum, time)?;
                x.iter_mut().for_each(|t| t.coef = self.g.mul(s, t.coef));
                Some(x)
            }
            ExprKind::Binary(BinOp::Div, a, b) => {
                let s = self.scalar(b)?;
                let mut x = self.form_sum(a, time)?;
                x.iter_mut().for_each(|t| t.coef = self.g.div(t.coef, s));
                Some(x)
            }
            _ => {
                self.error(
                    Diagnostic::error(
                        "E0813",
                        "a residual side is a sum of forms applied to time levels",
                        e.span,
                        "not a form application",
                    )
                    .with_help(schemes::residual_help(self.def, e)),
                );
                None
            }
        }
    }

    /// Slot `f` applied to time levels, or to a time (a load: one scalar argument, or none for
    /// the stage's time).
    fn application(&mut self, e: &Expr, f: &Ident, args: &[Expr], time: NodeId) -> Option<Vec<Term>> {
        let one = self.g.one();
        // A slot applied to nothing or to one scalar is a load (a function of time).
        let first = match args.first() {
            Some(a) => Some(self.value(a)?),
            None => None,
        };
        let is_load = args.len() <= 1 && !matches!(first, Some(Value::Vector(_)));
        if let Err(d) = self.applied.record(self.def, f, if is_load { 0 } else { args.len() }, e.span) {
            self.error(*d);
            return None;
        }
        if is_load {
            let at = self.load_time(e, f, args, time)?;
            return Some(vec![Term { coef: one, form: f.name.clone(), args: Vec::new(), time: at }]);
        }
        let mut affine_args = Vec::new();
        for a in args {
            match self.value(a)? {
                Value::Vector(v) => affine_args.push(v),
                Value::Scalar(_) => {
                    self.error(Diagnostic::error(
                        "E0301",
                        format!("`{}` is applied to time levels", f.name),
                        a.span,
                        "this is a scalar",
                    ));
                    return None;
                }
            }
        }
        Some(vec![Term { coef: one, form: f.name.clone(), args: affine_args, time }])
    }

    /// The time a load is applied at: its argument, or the stage's time.
    fn load_time(&mut self, e: &Expr, f: &Ident, args: &[Expr], time: NodeId) -> Option<NodeId> {
        match args {
            [] => Some(time),
            [a] => match self.value(a)? {
                Value::Scalar(n) => Some(n),
                Value::Vector(_) => {
                    self.error(Diagnostic::error(
                        "E0301",
                        format!("`{}` takes the time, not a time level", f.name),
                        a.span,
                        "a combination of time levels",
                    ));
                    None
                }
            },
            _ => {
                self.error(Diagnostic::error(
                    "E0201",
                    format!("`{}` takes at most one argument (the time)", f.name),
                    e.span,
                    format!("{} arguments", args.len()),
                ));
                None
            }
        }
    }

    fn is_form_sum(&self, e: &Expr) -> bool {
        match &e.kind {
            ExprKind::Call(f, _) => schemes::is_slot(self.def, &f.name) || !SCHEME_FUNCTIONS.contains(&f.name.as_str()),
            ExprKind::Neg(a) => self.is_form_sum(a),
            ExprKind::Binary(BinOp::Add | BinOp::Sub, a, b) => self.is_form_sum(a) || self.is_form_sum(b),
            ExprKind::Binary(BinOp::Mul, a, b) => self.is_form_sum(a) || self.is_form_sum(b),
            ExprKind::Binary(BinOp::Div, a, _) => self.is_form_sum(a),
            _ => false,
        }
    }
}
