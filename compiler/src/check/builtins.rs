//! The built-in names of the language, and one table of the built-in functions: every fact
//! the checker, the constant folding and the docs need about one (its arity, the shape of its
//! result, whether it is linear, what it folds to on numbers) is in its row.

use crate::syntax::ast::Shape;

/// Built-in values: identity, outward normal, cell diameter, position, time, constants.
pub const BUILTIN_VALUES: &[&str] = &["I", "n", "h", "x", "t", "pi", "inf"];

/// How a built-in's result shape follows from its arguments' shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeRule {
    /// Scalars to a scalar.
    Scalars,
    /// The shape of its argument (`prev`).
    Same,
    Grad,
    Div,
    /// A tensor to a tensor (`sym`, `transpose`, `inv`, ...).
    Tensor,
    /// A tensor to a scalar (`tr`, `det`).
    Trace,
    Dot,
    Inner,
    Outer,
    Norm,
    ProjBall,
    Tangential,
    /// `derivative(e, u, d)`: the shape of `e`.
    Derivative,
}

/// A built-in's value on constant arguments.
#[derive(Clone, Copy, Debug)]
pub enum Fold {
    /// Not folded: its value on numbers is no number (`grad`), or the checker leaves it to the
    /// lowering (`pos`, `H`, ...).
    No,
    Unary(fn(f64) -> f64),
    Binary(fn(f64, f64) -> f64),
}

impl Fold {
    /// The value on these arguments; `None` when it does not fold or the count is wrong.
    pub fn apply(self, args: &[f64]) -> Option<f64> {
        match (self, args) {
            (Fold::Unary(f), [a]) => Some(f(*a)),
            (Fold::Binary(f), [a, b]) => Some(f(*a, *b)),
            _ => None,
        }
    }
}

/// One built-in function.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    pub name: &'static str,
    pub arity: usize,
    pub shape: ShapeRule,
    /// Not linear in its arguments: a test function must not appear inside (E0402).
    pub nonlinear: bool,
    /// Its signature and meaning, in one line.
    pub doc: &'static str,
    pub fold: Fold,
    /// Only of a problem's numbers (params, `let`s of them), not of values that vary; elsewhere
    /// an unknown name, and no reserved one.
    pub numbers_only: bool,
}

const fn row(name: &'static str, arity: usize, shape: ShapeRule, nonlinear: bool, doc: &'static str) -> Builtin {
    Builtin { name, arity, shape, nonlinear, doc, fold: Fold::No, numbers_only: false }
}

const fn folds(b: Builtin, fold: Fold) -> Builtin {
    Builtin { fold, ..b }
}

/// A scalar function that is not linear and folds on numbers.
const fn scalar_fn(name: &'static str, fold: Fold, doc: &'static str) -> Builtin {
    let arity = if matches!(fold, Fold::Binary(_)) { 2 } else { 1 };
    folds(row(name, arity, ShapeRule::Scalars, true, doc), fold)
}

/// Every built-in function, in the order of the docs' table.
pub const BUILTINS: &[Builtin] = {
    use ShapeRule::*;
    &[
        row("grad", 1, Grad, false, "grad(a): the gradient of a scalar (a vector) or of a vector (a tensor)"),
        row("div", 1, Div, false, "div(a): the divergence of a vector, or row-wise of a tensor"),
        row("sym", 1, Tensor, false, "sym(A): the symmetric part of a tensor"),
        row("tr", 1, Trace, false, "tr(A): the trace of a tensor"),
        row("transpose", 1, Tensor, false, "transpose(A): the transpose of a tensor"),
        row("det", 1, Trace, true, "det(A): the determinant of a tensor"),
        row("inv", 1, Tensor, true, "inv(A): the inverse of a tensor, cofac(A)ᵀ/det(A)"),
        row("cofac", 1, Tensor, true, "cofac(A): the cofactor tensor, det(A) inv(A)ᵀ"),
        row("dev", 1, Tensor, false, "dev(A): the deviatoric part of a tensor, A − tr(A)/d I"),
        row("skew", 1, Tensor, false, "skew(A): the skew-symmetric part of a tensor, (A − Aᵀ)/2"),
        row("dot", 2, Dot, false, "dot(a, b): the contraction of the last index"),
        row("inner", 2, Inner, false, "inner(a, b): the full contraction"),
        row("outer", 2, Outer, false, "outer(a, b): the tensor product of two vectors"),
        row("pos", 1, Scalars, true, "pos(a): max(a, 0)"),
        row("neg", 1, Scalars, true, "neg(a): min(a, 0)"),
        row("H", 1, Scalars, true, "H(a): 1 if a > 0, else 0"),
        scalar_fn("min", Fold::Binary(f64::min), "min(a, b): the smaller"),
        scalar_fn("max", Fold::Binary(f64::max), "max(a, b): the larger"),
        scalar_fn("abs", Fold::Unary(f64::abs), "abs(a): |a|"),
        scalar_fn("sqrt", Fold::Unary(f64::sqrt), "sqrt(a): the square root, NaN for a < 0"),
        row("norm", 1, Norm, true, "norm(a): the Euclidean size of a vector, Frobenius of a tensor"),
        row("proj_ball", 2, ProjBall, true, "proj_ball(a, r): the projection of a onto the ball of radius r"),
        row("tangential", 2, Tangential, false, "tangential(a, nc): a − (a·nc) nc"),
        row("prev", 1, Same, false, "prev(e): e at the previous time level"),
        row(
            "opposite",
            1,
            Same,
            false,
            "opposite(e): e on the other surface of a contact pair, at the point facing the quadrature point",
        ),
        row(
            "derivative",
            3,
            Derivative,
            false,
            "derivative(e, u, d): the derivative of e with respect to u (a field or a function's argument) in the direction d",
        ),
        scalar_fn("sin", Fold::Unary(f64::sin), "sin(a): the sine, a in radians"),
        scalar_fn("cos", Fold::Unary(f64::cos), "cos(a): the cosine, a in radians"),
        scalar_fn("tan", Fold::Unary(f64::tan), "tan(a): the tangent, a in radians"),
        scalar_fn("atan2", Fold::Binary(f64::atan2), "atan2(y, x): the angle of the point (x, y), in (−π, π]"),
        scalar_fn("exp", Fold::Unary(f64::exp), "exp(a): the exponential"),
        scalar_fn("ln", Fold::Unary(f64::ln), "ln(a): the natural logarithm, NaN for a < 0, −∞ at 0"),
        Builtin { numbers_only: true, ..scalar_fn("ceil", Fold::Unary(f64::ceil), "ceil(a): a number rounded up") },
        Builtin {
            numbers_only: true,
            ..scalar_fn("floor", Fold::Unary(f64::floor), "floor(a): a number rounded down")
        },
    ]
};

/// The built-in function of this name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// The built-in function of this name that every expression may call (not `ceil`/`floor`).
pub fn function(name: &str) -> Option<&'static Builtin> {
    builtin(name).filter(|b| !b.numbers_only)
}

/// The names of the functions every expression may call: reserved, and suggested for a
/// misspelt name.
pub fn function_names() -> impl Iterator<Item = &'static str> {
    BUILTINS.iter().filter(|b| !b.numbers_only).map(|b| b.name)
}

impl Builtin {
    /// The result shape for arguments of the given shapes (as many as its arity), or a message
    /// that says what was expected.
    pub fn result_shape(&self, args: &[Shape]) -> Result<Shape, String> {
        use Shape::*;
        let name = self.name;
        match (self.shape, args) {
            (ShapeRule::Grad, [Scalar]) => Ok(Vector),
            (ShapeRule::Grad, [Vector]) => Ok(Tensor),
            (ShapeRule::Grad, [Tensor]) => Err("grad of a tensor (a third-order tensor) is not supported".into()),
            (ShapeRule::Div, [Vector]) => Ok(Scalar),
            (ShapeRule::Div, [Tensor]) => Ok(Vector),
            (ShapeRule::Div, [s]) => Err(format!("div takes a vector or a tensor, not a {}", s.name())),
            (ShapeRule::Tensor, [Tensor]) => Ok(Tensor),
            (ShapeRule::Trace, [Tensor]) => Ok(Scalar),
            (ShapeRule::Tensor | ShapeRule::Trace, [s]) => Err(format!("{name} takes a tensor, not a {}", s.name())),
            (ShapeRule::Dot, [Vector, Vector]) => Ok(Scalar),
            (ShapeRule::Dot, [Tensor, Vector] | [Vector, Tensor]) => Ok(Vector),
            (ShapeRule::Dot, [Tensor, Tensor]) => Ok(Tensor),
            (ShapeRule::Dot, [a, b]) => {
                Err(format!("dot takes vectors or tensors, not a {} and a {}", a.name(), b.name()))
            }
            (ShapeRule::Inner, [a, b]) if a == b => Ok(Scalar),
            (ShapeRule::Inner, [a, b]) => {
                Err(format!("inner takes two arguments of the same shape, not a {} and a {}", a.name(), b.name()))
            }
            (ShapeRule::Outer, [Vector, Vector]) => Ok(Tensor),
            (ShapeRule::Outer, [a, b]) => {
                Err(format!("outer takes two vectors, not a {} and a {}", a.name(), b.name()))
            }
            (ShapeRule::Norm, [Vector | Tensor]) => Ok(Scalar),
            (ShapeRule::Norm, [Scalar]) => Err("norm takes a vector or a tensor; the size of a scalar is `abs`".into()),
            (ShapeRule::ProjBall, [a @ (Scalar | Vector), Scalar]) => Ok(*a),
            (ShapeRule::ProjBall, [a, b]) => Err(format!(
                "proj_ball takes a vector (or a scalar) and a scalar radius, not a {} and a {}",
                a.name(),
                b.name()
            )),
            (ShapeRule::Tangential, [Vector, Vector]) => Ok(Vector),
            (ShapeRule::Tangential, [a, b]) => {
                Err(format!("tangential takes a vector and a unit normal, not a {} and a {}", a.name(), b.name()))
            }
            (ShapeRule::Same, [a]) => Ok(*a),
            (ShapeRule::Derivative, [e, _, _]) => Ok(*e),
            (ShapeRule::Scalars, shapes) if shapes.iter().all(|s| *s == Scalar) => Ok(Scalar),
            (_, shapes) => {
                let got: Vec<_> = shapes.iter().map(|s| s.name()).collect();
                Err(format!("{name} takes scalars, not {}", got.join(" and ")))
            }
        }
    }

    /// What to write instead, for arguments of shapes it does not take (after
    /// [`Builtin::result_shape`] refused them).
    pub fn shape_help(&self, args: &[Shape]) -> Option<String> {
        let name = self.name;
        match (self.shape, args) {
            (ShapeRule::Tensor | ShapeRule::Trace, [Shape::Vector]) => Some(format!(
                "`{name}` takes a d×d tensor, such as `grad(u)` of a vector field `u` or `outer(a, b)` of two vectors"
            )),
            (ShapeRule::Tensor | ShapeRule::Trace, [Shape::Scalar]) => {
                Some(format!("`{name}` takes a d×d tensor; a scalar `s` times the identity is `s*I`"))
            }
            (ShapeRule::Outer, _) => Some("`outer(a, b)` is the tensor a_i b_j of two vectors".into()),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_distinct_and_folds_match_arities() {
        for (i, b) in BUILTINS.iter().enumerate() {
            assert!(BUILTINS[..i].iter().all(|a| a.name != b.name), "`{}` twice", b.name);
            let args = vec![0.5; b.arity];
            assert_eq!(b.fold.apply(&args).is_some(), !matches!(b.fold, Fold::No), "`{}`", b.name);
            assert!(b.doc.starts_with(&format!("{}(", b.name)), "`{}`'s doc", b.name);
            assert!(!BUILTIN_VALUES.contains(&b.name));
        }
    }

    #[test]
    fn the_new_functions_fold_to_their_values() {
        let f = |name: &str, args: &[f64]| builtin(name).and_then(|b| b.fold.apply(args));
        assert_eq!(f("sin", &[std::f64::consts::FRAC_PI_2]), Some(1.0));
        assert_eq!(f("cos", &[0.0]), Some(1.0));
        assert_eq!(f("atan2", &[1.0, -1.0]), Some(3.0 * std::f64::consts::FRAC_PI_4));
        assert_eq!(f("exp", &[0.0]), Some(1.0));
        assert_eq!(f("ln", &[1.0]), Some(0.0));
        assert_eq!(f("ln", &[0.0]), Some(f64::NEG_INFINITY));
        assert_eq!(function("ceil").map(|b| b.name), None);
    }
}
