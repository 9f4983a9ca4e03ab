//! `sin`, `cos`, `tan`, `atan2`, `exp` and `ln` in forms: at random points in 1D, 2D and 3D,
//! each form's test-function coefficients are the function's values (computed here with f64's
//! own functions), its automatic tangent (value and gradient of the field) matches central
//! finite differences of those coefficients, and `grad` of a function of x matches finite
//! differences in x of the function itself.

use std::path::Path;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use signorini_compiler::ir::eval::evaluate;
use signorini_compiler::ir::graph::Sym;
use signorini_compiler::{Compiled, MemLoader, compile_text};

use crate::points::{Point, check_tangent, close, coefficients, points};

/// One function: its name, the arguments of its two terms (of u, and of ∇u), the same
/// computed here, and the argument of its `grad` form (of s = x·x).
struct Case {
    name: &'static str,
    value_term: &'static str,
    grad_term: &'static str,
    value: fn(&Point) -> f64,
    grad: fn(&Point) -> f64,
    of_x: &'static str,
    of_s: fn(f64) -> f64,
}

const CASES: &[Case] = &[
    Case {
        name: "sin",
        value_term: "sin(dot(u, a))",
        grad_term: "sin(div(u))",
        value: |p| ua(p).sin(),
        grad: |p| div(p).sin(),
        of_x: "sin(2*dot(x, x) + 0.3)",
        of_s: |s| (2.0 * s + 0.3).sin(),
    },
    Case {
        name: "cos",
        value_term: "cos(dot(u, a))",
        grad_term: "cos(div(u))",
        value: |p| ua(p).cos(),
        grad: |p| div(p).cos(),
        of_x: "cos(2*dot(x, x) + 0.3)",
        of_s: |s| (2.0 * s + 0.3).cos(),
    },
    // |u·a| ≤ 1.5 and |div u| ≤ 1.5 keep away from tan's poles at ±π/2.
    Case {
        name: "tan",
        value_term: "tan(dot(u, a))",
        grad_term: "tan(div(u))",
        value: |p| ua(p).tan(),
        grad: |p| div(p).tan(),
        of_x: "tan(dot(x, x) + 0.3)",
        of_s: |s| (s + 0.3).tan(),
    },
    Case {
        name: "exp",
        value_term: "exp(dot(u, a))",
        grad_term: "exp(div(u))",
        value: |p| ua(p).exp(),
        grad: |p| div(p).exp(),
        of_x: "exp(2*dot(x, x) - 1)",
        of_s: |s| (2.0 * s - 1.0).exp(),
    },
    Case {
        name: "ln",
        value_term: "ln(0.1 + dot(u, u))",
        grad_term: "ln(2 + div(u))",
        value: |p| (0.1 + uu(p)).ln(),
        grad: |p| (2.0 + div(p)).ln(),
        of_x: "ln(dot(x, x) + 0.05)",
        of_s: |s| (s + 0.05).ln(),
    },
    // Around the whole circle (the first term), and off the cut x < 0, y = 0 (the second).
    Case {
        name: "atan2",
        value_term: "atan2(dot(u, a), dot(u, b))",
        grad_term: "atan2(div(u), 2 + dot(u, b))",
        value: |p| ua(p).atan2(ub(p)),
        grad: |p| div(p).atan2(2.0 + ub(p)),
        // From about 10° to 150° as x·x grows, in the upper half plane (off the cut).
        of_x: "atan2(dot(x, x) + 0.05, 0.3 - 2*dot(x, x))",
        of_s: |s| (s + 0.05).atan2(0.3 - 2.0 * s),
    },
];

/// form f_NAME(u; v) = F(.. u ..) * dot(v, b) + F(.. ∇u ..) * div(v), and
/// form g_NAME(; v) = dot(grad(F(x·x)), v) per case.
fn source() -> String {
    let mut s = String::from("coef a: vector\ncoef b: vector\n");
    for c in CASES {
        s.push_str(&format!(
            "form f_{}(u; v) = int(Omega) {} * dot(v, b) + {} * div(v)\n",
            c.name, c.value_term, c.grad_term
        ));
        s.push_str(&format!("form g_{}(; v) = int(Omega) dot(grad({}), v)\n", c.name, c.of_x));
    }
    s
}

/// u·a, u·b, u·u and div u at a point: the functions' arguments.
fn ua(p: &Point) -> f64 {
    Point::dot(&p.u, &p.a)
}
fn ub(p: &Point) -> f64 {
    Point::dot(&p.u, &p.b)
}
fn uu(p: &Point) -> f64 {
    Point::dot(&p.u, &p.u)
}
fn div(p: &Point) -> f64 {
    (0..p.d).map(|k| p.at(k, k)).sum()
}

/// The coefficients f0 (of v) and f1 (of ∇v) of form `f_NAME`, and its four tangents, match
/// the function's values and finite differences of them.
fn check_form(compiled: &Compiled, c: &Case, p: &Point) -> Result<(), TestCaseError> {
    let d = p.d;
    let form = format!("f_{}", c.name);
    // f0[k] = F(value) b_k, f1[k*d + l] = F(grad) δ_kl.
    let got = coefficients(compiled.ir(d), &form, p);
    let (fv, fg) = ((c.value)(p), (c.grad)(p));
    for k in 0..d {
        prop_assert!(close(got[k], fv * p.b[k], 1e-14), "{} f0[{k}] {} against {}", c.name, got[k], fv * p.b[k]);
        for l in 0..d {
            let want = if k == l { fg } else { 0.0 };
            let g = got[d + k * d + l];
            prop_assert!(close(g, want, 1e-14), "{} f1[{k}][{l}] {g} against {want}", c.name);
        }
    }
    // ∂/∂u_m and ∂/∂(∂_n u_m), by central differences of the coefficients.
    check_tangent(compiled, &form, p)
}

/// `grad(F(x·x))`, the coefficient of v in form `g_NAME`, against central differences in x of
/// F(x·x) computed here.
fn check_grad(compiled: &Compiled, c: &Case, p: &Point) -> Result<(), TestCaseError> {
    let d = p.d;
    let ir = compiled.ir(d);
    let form = ir.forms.iter().find(|f| f.name == format!("g_{}", c.name)).expect("the form is lowered");
    let got = evaluate(&ir.graph, &form.integrals[0].f0, |s| p.leaf(s));
    let e = 1e-6;
    for k in 0..d {
        let (mut plus, mut minus) = (p.x.clone(), p.x.clone());
        plus[k] += e;
        minus[k] -= e;
        let f = |x: &[f64]| (c.of_s)(Point::dot(x, x));
        let fd = (f(&plus) - f(&minus)) / (2.0 * e);
        prop_assert!(close(got[k], fd, 1e-6), "{} {d}D: ∂_{k} {} against {fd} at x = {:?}", c.name, got[k], p.x);
    }
    Ok(())
}

#[test]
fn transcendental_functions_have_their_values_and_exact_tangents() {
    let compiled = compile_text(Path::new("transcendental.wf"), &source(), &MemLoader::default())
        .unwrap_or_else(|e| panic!("the forms compile:\n{e}"));
    let mut runner = TestRunner::new(Config { cases: 300, ..Config::default() });
    runner
        .run(&points(0.5, &[]), |p| {
            // atan2's first term: keep off the origin (its derivative grows as 1/r there) and the
            // cut (x < 0, y = 0), where the angle jumps by 2π and differences measure the jump.
            let (y, x) = (ua(&p), ub(&p));
            prop_assume!(x.hypot(y) > 0.1 && (x > 0.0 || y.abs() > 0.05));
            for c in CASES {
                check_form(&compiled, c, &p)?;
                check_grad(&compiled, c, &p)?;
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
}

/// The checker folds the functions on numbers as f64 does, and the lowering folds a constant
/// argument to a constant node (no operation left in the graph).
#[test]
fn functions_of_numbers_fold_to_numbers() {
    let text = "param c = cos(pi/3) in [0, sin(pi/2)]\nform f(u; v) = int(Omega) c * exp(ln(2)) * dot(u, v)\n";
    let compiled = compile_text(Path::new("fold.wf"), text, &MemLoader::default()).expect("it compiles");
    let param = &compiled.program.params[0];
    assert_eq!(param.default.to_bits(), (std::f64::consts::PI / 3.0).cos().to_bits());
    assert_eq!(param.range.expect("a range").hi, 1.0);
    let ir = compiled.ir(1);
    let f0 = ir.forms[0].integrals[0].f0[0];
    // f0 = c · exp(ln 2) · u: exp(ln 2) is the constant it folds to, c a param.
    let value = evaluate(&ir.graph, &[f0], |s| match s {
        Sym::Param(0) => 1.0,
        Sym::Field { .. } => 1.0,
        other => panic!("no {other:?}"),
    });
    assert_eq!(value[0], 2f64.ln().exp());
}
