//! `derivative(e, u, d)` at random points in 1D, 2D and 3D: its coefficients are the central
//! differences of `e` in u's value and gradient; it is so also where `u` is a function's
//! argument bound to an expression (the midpoint of u and x); the stress of the neo-Hookean
//! energy density written as `derivative(W(u), u, v)` is the one written out by hand; and the
//! automatic tangent of a form written with `derivative` (a second derivative) matches
//! central differences of its coefficients.

use std::path::Path;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use signorini_compiler::ir::eval::evaluate;
use signorini_compiler::{Compiled, MemLoader, compile_text};

use crate::points::{Point, check_tangent, close, coefficients, differences, points};

const SOURCE: &str = "
coef a: vector
coef b: vector
param mu = 1.3 in (0, inf)
param lam = 0.7 in [0, inf)
fn F(u) = I + grad(u)
fn J(u) = det(F(u))
fn W(u) = mu/2*(inner(F(u), F(u)) - tr(I)) - mu*ln(J(u)) + lam/2*ln(J(u))^2
fn E(u) = sin(dot(u, a)) * det(F(u) + outer(u, b)) + exp(dot(grad(u)*a, b)) + dot(x, u)^2
fn dE(w, v) = derivative(E(w), w, v)
functional energy(u) = int(Omega, degree = 2) E(u)
functional midpoint_energy(u) = int(Omega, degree = 2) E((u + x)/2)
form by_derivative(u; v) = int(Omega, degree = 2) derivative(E(u), u, v)
form at_midpoint(u; v) = int(Omega, degree = 2) dE((u + x)/2, v)/2
form nh(u; v) = int(Omega) inner(mu*(F(u) - transpose(inv(F(u)))) + lam*ln(J(u))*transpose(inv(F(u))), grad(v))
form nh_derived(u; v) = int(Omega) derivative(W(u), u, v)
form nonlinear(u; v) = int(Omega, degree = 2) dot(u, b) * derivative(W(u) * dot(u, a), u, v)
";

const MU: f64 = 1.3;
const LAM: f64 = 0.7;

/// The form's coefficients (f0 of v, f1 of ∇v) against central differences of the functional
/// in u's value and gradient.
fn check_variation(compiled: &Compiled, form: &str, functional: &str, p: &Point) -> Result<(), TestCaseError> {
    let d = p.d;
    let ir = compiled.ir(d);
    let e = ir.forms.iter().find(|f| f.name == functional).expect("the functional is lowered").integrals[0]
        .value
        .expect("a functional's integrand");
    let value = |q: &Point| evaluate(&ir.graph, &[e], |s| q.leaf(s));
    let by_value = differences(p, d, |q, m, e| q.u[m] += e, value);
    let by_grad = differences(p, d * d, |q, mn, e| q.gu[mn] += e, value);
    let got = coefficients(ir, form, p);
    for (i, fd) in by_value.iter().chain(&by_grad).enumerate() {
        prop_assert!(close(got[i], fd[0], 1e-6), "{form} {d}D: coef[{i}] {} against {} at {p:?}", got[i], fd[0]);
    }
    Ok(())
}

#[test]
fn derivative_is_the_variation_of_its_expression() {
    let compiled = compile_text(Path::new("derivative.wf"), SOURCE, &MemLoader::default())
        .unwrap_or_else(|e| panic!("the forms compile:\n{e}"));
    let mut runner = TestRunner::new(Config { cases: 150, ..Config::default() });
    runner
        .run(&points(0.25, &[MU, LAM]), |p| {
            check_variation(&compiled, "by_derivative", "energy", &p)?;
            check_variation(&compiled, "at_midpoint", "midpoint_energy", &p)?;
            let ir = compiled.ir(p.d);
            let (derived, by_hand) = (coefficients(ir, "nh_derived", &p), coefficients(ir, "nh", &p));
            for (i, (x, y)) in derived.iter().zip(&by_hand).enumerate() {
                prop_assert!(close(*x, *y, 1e-13), "nh {}D: coef[{i}] derived {x}, by hand {y} at {p:?}", p.d);
            }
            check_tangent(&compiled, "nh_derived", &p)?;
            check_tangent(&compiled, "nonlinear", &p)
        })
        .unwrap_or_else(|e| panic!("{e}"));
}
