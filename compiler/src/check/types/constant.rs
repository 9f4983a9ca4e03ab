//! Compile-time constants: numbers, arithmetic, the built-in functions that fold on numbers
//! (`sqrt`, `min`, `sin`, `atan2`, ...: the table's `fold`), `pi` and `inf`.

use crate::check::builtins;
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
        ExprKind::Call(f, args) => {
            let Some(b) = builtins::function(&f.name) else { return Err(e.span) };
            let values = args.iter().map(const_eval).collect::<Result<Vec<f64>, Span>>()?;
            b.fold.apply(&values).ok_or(e.span)?
        }
    })
}
