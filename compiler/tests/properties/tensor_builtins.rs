//! `det`, `inv`, `cofac`, `dev`, `skew` and `outer` in forms, at random points in 1D, 2D and 3D:
//! each form's automatic tangent matches central finite differences of its coefficients; a
//! neo-Hookean stress written with `inv` and `cofac` is the derivative of its energy density
//! written with `det`; and on random well-conditioned matrices the functions satisfy their
//! identities (inv(A) A = I, cofac(A) = det(A) inv(A)ᵀ, det(I + a⊗b) = 1 + a·b, tr dev(A) = 0,
//! skew(A) + sym(A) = A, det(AᵀA) = det(A)², det(AB) = det(A) det(B)), with `det` against
//! Leibniz's formula computed here.

use std::path::Path;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use signorini_compiler::ir::eval::evaluate;
use signorini_compiler::{Compiled, MemLoader, compile_text};

use crate::points::{Point, check_tangent, close, coefficients, differences, points};

/// F = I + ∇u near the identity; W the compressible neo-Hookean energy density and P its first
/// Piola stress ∂W/∂F = mu (F − F⁻ᵀ) + lam ln(J) F⁻ᵀ, with F⁻ᵀ written once through `inv` and
/// once through `cofac`. The `t_*` forms mix the functions with u's value and gradient, so that
/// every block of their tangents is exercised; the `i_*` forms read A = ∇u as a general matrix.
/// Their quadrature degree is set: the estimate of a quotient of high products (`inv` of a
/// tensor of u's value) passes the cap, and it is not what these tests are about.
const SOURCE: &str = "
coef a: vector
coef b: vector
param mu = 1.3 in (0, inf)
param lam = 0.7 in [0, inf)
fn F(u) = I + grad(u)
fn J(u) = det(F(u))
functional energy(u) = int(Omega) mu/2*(tr(transpose(F(u))*F(u)) - tr(I)) - mu*ln(J(u)) + lam/2*ln(J(u))^2
form nh(u; v) = int(Omega) inner(mu*(F(u) - transpose(inv(F(u)))) + lam*ln(J(u))*cofac(F(u))/J(u), grad(v))
form t_det(u; v) = int(Omega, degree = 2) det(F(u) + outer(u, a)) * dot(b, v) + det(grad(u)) * div(v)
form t_inv(u; v) = int(Omega, degree = 2) dot(inv(F(u))*u, v) + inner(inv(F(u) + outer(u, a)), grad(v))
form t_cofac(u; v) = int(Omega, degree = 2) dot(cofac(F(u))*a, v) + inner(cofac(grad(u) + outer(u, b)), grad(v))
form t_dev(u; v) = int(Omega, degree = 2) inner(dev(transpose(grad(u))*F(u) + outer(u, u)), grad(v))
form t_skew(u; v) = int(Omega, degree = 2) dot(skew(grad(u)*grad(u) + outer(u, a))*u, v) + inner(skew(F(u)*grad(u)), grad(v))
form t_outer(u; v) = int(Omega, degree = 2) dot(outer(u, a)*u, v) + inner(outer(grad(u)*u, b), grad(v))
form i_inv(u; v) = int(Omega, degree = 2) inner(inv(grad(u))*grad(u), grad(v)) + dot(grad(u)*inv(grad(u))*a, v)
form i_cofac(u; v) = int(Omega, degree = 2) inner(cofac(grad(u)) - det(grad(u))*transpose(inv(grad(u))), grad(v)) + det(grad(u))*dot(b, v)
form i_outer(u; v) = int(Omega, degree = 2) det(outer(u, a) + I)*dot(b, v) + inner(outer(u, a), grad(v))
form i_dev(u; v) = int(Omega, degree = 2) tr(dev(grad(u)))*dot(b, v) + inner(dev(grad(u)), grad(v))
form i_skew(u; v) = int(Omega, degree = 2) dot((skew(grad(u)) + transpose(skew(grad(u))))*a, v) + inner(skew(grad(u)) + sym(grad(u)), grad(v))
form i_det(u; v) = int(Omega, degree = 2) (det(transpose(grad(u))*grad(u)) - det(grad(u))^2)*dot(b, v) + inner(det(grad(u)*(I + outer(u, a)))*I, grad(v))
";

const TANGENT_FORMS: &[&str] = &["nh", "t_det", "t_inv", "t_cofac", "t_dev", "t_skew", "t_outer"];
const MU: f64 = 1.3;
const LAM: f64 = 0.7;

/// The determinant by Leibniz's formula (a sum over the d! permutations), independent of the
/// compiler's cofactor expansion.
fn leibniz(p: &Point) -> f64 {
    let perms: &[(&[usize], f64)] = match p.d {
        1 => &[(&[0], 1.0)],
        2 => &[(&[0, 1], 1.0), (&[1, 0], -1.0)],
        _ => &[
            (&[0, 1, 2], 1.0),
            (&[1, 2, 0], 1.0),
            (&[2, 0, 1], 1.0),
            (&[0, 2, 1], -1.0),
            (&[2, 1, 0], -1.0),
            (&[1, 0, 2], -1.0),
        ],
    };
    perms.iter().map(|(s, sign)| sign * s.iter().enumerate().map(|(i, &j)| p.at(i, j)).product::<f64>()).sum()
}

/// The neo-Hookean stress (form `nh`, of `inv` and `cofac`) is ∂W/∂F, the central differences
/// of the energy density (functional `energy`, of `det`), and no force of u's value.
fn check_energy(compiled: &Compiled, p: &Point) -> Result<(), TestCaseError> {
    let d = p.d;
    let ir = compiled.ir(d);
    let w = ir.forms.iter().find(|f| f.name == "energy").expect("the functional is lowered").integrals[0]
        .value
        .expect("a functional's integrand");
    let by_grad = differences(p, d * d, |q, mn, e| q.gu[mn] += e, |q| evaluate(&ir.graph, &[w], |s| q.leaf(s)));
    let got = coefficients(ir, "nh", p);
    for k in 0..d {
        prop_assert!(got[k] == 0.0, "nh {d}D: f0[{k}] = {}", got[k]);
    }
    for (mn, fd) in by_grad.iter().enumerate() {
        prop_assert!(close(got[d + mn], fd[0], 1e-6), "nh {d}D: P[{mn}] {} against ∂W {} at {p:?}", got[d + mn], fd[0]);
    }
    Ok(())
}

#[test]
fn tensor_functions_have_exact_tangents_and_the_stress_is_the_energy_derivative() {
    let compiled = compile_text(Path::new("tensor.wf"), SOURCE, &MemLoader::default())
        .unwrap_or_else(|e| panic!("the forms compile:\n{e}"));
    let mut runner = TestRunner::new(Config { cases: 150, ..Config::default() });
    // |∂_l u_k| < 0.25: ‖∇u‖ < 0.75, so F = I + ∇u has singular values above 1/4 and J > 0.
    runner
        .run(&points(0.25, &[MU, LAM]), |p| {
            for form in TANGENT_FORMS {
                check_tangent(&compiled, form, &p)?;
            }
            check_energy(&compiled, &p)
        })
        .unwrap_or_else(|e| panic!("{e}"));
}

/// Each `i_*` form's coefficients (f0, then f1) as the identity says they are, computed here.
fn expected(form: &str, p: &Point) -> Vec<f64> {
    let d = p.d;
    let ua: f64 = p.u.iter().zip(&p.a).map(|(x, y)| x * y).sum();
    let det = leibniz(p);
    let delta = |k: usize| if k / d == k % d { 1.0 } else { 0.0 };
    let tr: f64 = (0..d).map(|i| p.at(i, i)).sum();
    let (f0, f1): (Vec<f64>, Vec<f64>) = match form {
        "i_inv" => (p.a.clone(), (0..d * d).map(delta).collect()),
        "i_cofac" => (p.b.iter().map(|b| det * b).collect(), vec![0.0; d * d]),
        "i_outer" => {
            (p.b.iter().map(|b| (1.0 + ua) * b).collect(), (0..d * d).map(|k| p.u[k / d] * p.a[k % d]).collect())
        }
        "i_dev" => (vec![0.0; d], (0..d * d).map(|k| p.gu[k] - tr / d as f64 * delta(k)).collect()),
        "i_skew" => (vec![0.0; d], p.gu.clone()),
        "i_det" => (vec![0.0; d], (0..d * d).map(|k| det * (1.0 + ua) * delta(k)).collect()),
        _ => unreachable!("no identity form `{form}`"),
    };
    f0.into_iter().chain(f1).collect()
}

#[test]
fn tensor_functions_satisfy_their_identities_on_random_matrices() {
    let compiled = compile_text(Path::new("tensor.wf"), SOURCE, &MemLoader::default())
        .unwrap_or_else(|e| panic!("the forms compile:\n{e}"));
    let mut runner = TestRunner::new(Config { cases: 400, ..Config::default() });
    runner
        .run(&points(1.0, &[MU, LAM]), |p| {
            // Entries in (−1, 1) and |det A| > 0.1 bound ‖A⁻¹‖ by about 20: well-conditioned.
            prop_assume!(leibniz(&p).abs() > 0.1);
            let ir = compiled.ir(p.d);
            for form in ["i_inv", "i_cofac", "i_outer", "i_dev", "i_skew", "i_det"] {
                let (got, want) = (coefficients(ir, form, &p), expected(form, &p));
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    prop_assert!(close(*g, *w, 1e-10), "{form} {}D: coef[{i}] {g} against {w} at {p:?}", p.d);
                }
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
}
