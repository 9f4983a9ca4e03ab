//! The built-in names of the language and the shape rules of the built-in functions.

use crate::syntax::ast::Shape;

/// Built-in values: identity, outward normal, cell diameter, position, time, constants.
pub const BUILTIN_VALUES: &[&str] = &["I", "n", "h", "x", "t", "pi", "inf"];

/// Built-in functions.
pub const BUILTIN_FUNCTIONS: &[&str] = &[
    "grad",
    "div",
    "sym",
    "tr",
    "transpose",
    "dot",
    "inner",
    "outer",
    "pos",
    "neg",
    "H",
    "min",
    "max",
    "abs",
    "sqrt",
    "norm",
    "proj_ball",
    "tangential",
    "prev",
];

/// Functions of a problem's numbers (params, `let`s of them), not of values that vary.
pub const NUMBER_FUNCTIONS: &[&str] = &["ceil", "floor"];

/// Functions of one scalar that are not linear, so a test function must not appear inside.
pub const NONLINEAR: &[&str] = &["pos", "neg", "H", "min", "max", "abs", "sqrt", "norm", "proj_ball"];

pub fn arity(name: &str) -> usize {
    match name {
        "dot" | "inner" | "outer" | "min" | "max" | "proj_ball" | "tangential" => 2,
        _ => 1,
    }
}

/// Result shape of a built-in applied to arguments of the given shapes, or a message that
/// says what was expected.
pub fn result_shape(name: &str, args: &[Shape]) -> Result<Shape, String> {
    use Shape::*;
    match (name, args) {
        ("grad", [Scalar]) => Ok(Vector),
        ("grad", [Vector]) => Ok(Tensor),
        ("grad", [Tensor]) => Err("grad of a tensor (a third-order tensor) is not supported".into()),
        ("div", [Vector]) => Ok(Scalar),
        ("div", [Tensor]) => Ok(Vector),
        ("div", [s]) => Err(format!("div takes a vector or a tensor, not a {}", s.name())),
        ("sym" | "transpose", [Tensor]) => Ok(Tensor),
        ("tr", [Tensor]) => Ok(Scalar),
        ("sym" | "transpose" | "tr", [s]) => Err(format!("{name} takes a tensor, not a {}", s.name())),
        ("dot", [Vector, Vector]) => Ok(Scalar),
        ("dot", [Tensor, Vector] | [Vector, Tensor]) => Ok(Vector),
        ("dot", [Tensor, Tensor]) => Ok(Tensor),
        ("dot", [a, b]) => Err(format!("dot takes vectors or tensors, not a {} and a {}", a.name(), b.name())),
        ("inner", [a, b]) if a == b => Ok(Scalar),
        ("inner", [a, b]) => {
            Err(format!("inner takes two arguments of the same shape, not a {} and a {}", a.name(), b.name()))
        }
        ("outer", [Vector, Vector]) => Ok(Tensor),
        ("outer", [a, b]) => Err(format!("outer takes two vectors, not a {} and a {}", a.name(), b.name())),
        ("pos" | "neg" | "H" | "abs" | "sqrt", [Scalar]) => Ok(Scalar),
        ("norm", [Vector | Tensor]) => Ok(Scalar),
        ("norm", [Scalar]) => Err("norm takes a vector or a tensor; the size of a scalar is `abs`".into()),
        ("proj_ball", [a @ (Scalar | Vector), Scalar]) => Ok(*a),
        ("proj_ball", [a, b]) => Err(format!(
            "proj_ball takes a vector (or a scalar) and a scalar radius, not a {} and a {}",
            a.name(),
            b.name()
        )),
        ("tangential", [Vector, Vector]) => Ok(Vector),
        ("prev", [a]) => Ok(*a),
        ("tangential", [a, b]) => {
            Err(format!("tangential takes a vector and a unit normal, not a {} and a {}", a.name(), b.name()))
        }
        ("min" | "max", [Scalar, Scalar]) => Ok(Scalar),
        (_, shapes) => {
            let got: Vec<_> = shapes.iter().map(|s| s.name()).collect();
            Err(format!("{name} takes scalars, not {}", got.join(" and ")))
        }
    }
}
