//! Compile-time constants: numbers, arithmetic, `sqrt`, `abs`, `min`, `max`, `pi` and `inf`.

use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, ExprKind};

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
