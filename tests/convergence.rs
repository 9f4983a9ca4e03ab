//! Manufactured solutions for linear elasticity through the compiled forms: P1 and P2 in 1D,
//! 2D (straight meshes, and the curved isoparametric P2 disc) and 3D.
//!
//! With u_1 = Π_k sin(π x_k) and u_j = 0 for j > 1, −div σ(u) = f with
//! f_1 = π² (dμ + λ + μ) u_1 and f_j = −(λ + μ) π² cos(π x_1) cos(π x_j) Π_{k≠1,j} sin(π x_k).
//! Observed rates on the two finest meshes must reach p + 1 − 0.1 in L2 and p − 0.1 in H1.

use std::f64::consts::PI;

use signorini::runtime::assembly::{Assembler, Quadrature};
use signorini::runtime::evaluate::errors;
use signorini::runtime::kernel::Coef;
use signorini::runtime::linalg::Structure;
use signorini::runtime::mesh::structured::{self, Diagonal};
use signorini::runtime::mesh::{Mesh, disc::disc};
use signorini::runtime::problem::{Constraints, solve_linear};

signorini::forms!("forms/elasticity.wf");

/// Exact value and gradient (`[component][direction]`) at x.
fn exact(x: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let d = x.len();
    let s: Vec<f64> = x.iter().map(|v| (PI * v).sin()).collect();
    let c: Vec<f64> = x.iter().map(|v| (PI * v).cos()).collect();
    let mut u = vec![0.0; d];
    u[0] = s.iter().product();
    let mut g = vec![0.0; d * d];
    for l in 0..d {
        g[l] = PI * c[l] * (0..d).filter(|&k| k != l).map(|k| s[k]).product::<f64>();
    }
    (u, g)
}

fn body_force(x: &[f64], lambda: f64, mu: f64, out: &mut [f64]) {
    let d = x.len();
    let s: Vec<f64> = x.iter().map(|v| (PI * v).sin()).collect();
    let c: Vec<f64> = x.iter().map(|v| (PI * v).cos()).collect();
    out[0] = PI * PI * (d as f64 * mu + lambda + mu) * s.iter().product::<f64>();
    for j in 1..d {
        out[j] = -(lambda + mu) * PI * PI * c[0] * c[j] * (1..d).filter(|&k| k != j).map(|k| s[k]).product::<f64>();
    }
}

/// Solves on `mesh` with the exact solution imposed on `boundary`; returns (L2, H1) errors.
fn solve(mesh: &Mesh, boundary: &[&str], nu: f64) -> (f64, f64) {
    let d = mesh.dim();
    let e = 1.0;
    let (lambda, mu) = (e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu)));
    let p = elasticity::Params::default().with("nu", nu).unwrap();
    let c = elasticity::Coefficients { f: Coef::function(d, move |x, _, out| body_force(x, lambda, mu, out)) };
    let asm = Assembler::new(mesh);
    let n = asm.size();
    let degree = mesh.kind.degree();
    let quad = Quadrature { cell: Some(2 * degree + 2), facet: None };
    let mut k = asm.zero_matrix();
    asm.cell_tangent(&elasticity::Stiffness::new(&p, &c), quad, &[&vec![0.0; n]], 0, 0.0, &mut k);
    let mut b = vec![0.0; n];
    asm.cell_residual(&elasticity::Load::new(&p, &c), quad, &[], 0.0, &mut b);
    let mut dirichlet = Constraints::none(n);
    let all: Vec<usize> = (0..d).collect();
    for region in boundary {
        dirichlet.fix_region(mesh, region, &all, |x| exact(x).0).unwrap();
    }
    let u = solve_linear(&k, &b, &dirichlet, Structure::SymmetricPositiveDefinite).unwrap();
    errors(mesh, &u, 2 * degree + 3, &exact)
}

/// Rates between consecutive meshes (each twice as fine as the last).
fn rates(errs: &[(f64, f64)]) -> (f64, f64) {
    let [.., a, b] = errs else { panic!("need two meshes") };
    ((a.0 / b.0).log2(), (a.1 / b.1).log2())
}

fn check(what: &str, p: u32, errs: &[(f64, f64)]) {
    let (l2, h1) = rates(errs);
    eprintln!("{what}: errors {errs:?}, rates L2 {l2:.3} H1 {h1:.3}");
    assert!(l2 >= p as f64 + 1.0 - 0.1, "{what}: L2 rate {l2:.3} < {}", p as f64 + 0.9);
    assert!(h1 >= p as f64 - 0.1, "{what}: H1 rate {h1:.3} < {}", p as f64 - 0.1);
}

#[test]
fn one_dimensional_p1() {
    let errs: Vec<_> =
        [8, 16, 32].iter().map(|&n| solve(&structured::interval(n, 0.0, 1.0), &["left", "right"], 0.0)).collect();
    check("1D P1", 1, &errs);
}

#[test]
fn two_dimensional_p1_and_p2_on_straight_meshes() {
    let sides = ["left", "right", "bottom", "top"];
    for degree in [1, 2] {
        for diagonal in [Diagonal::Right, Diagonal::Left] {
            let errs: Vec<_> = [4, 8, 16]
                .iter()
                .map(|&n| solve(&structured::rectangle(n, n, [0.0, 1.0], [0.0, 1.0], diagonal, degree), &sides, 0.3))
                .collect();
            check(&format!("2D P{degree} {diagonal:?}"), degree, &errs);
        }
    }
}

#[test]
fn two_dimensional_p2_on_the_curved_disc() {
    // Off-centre, so the solution has no symmetry the mesh could exploit.
    let errs: Vec<_> =
        [0.5, 0.25, 0.125].iter().map(|&h| solve(&disc(1.0, [0.3, 0.2], h), &["boundary"], 0.3)).collect();
    check("2D P2 curved disc", 2, &errs);
}

#[test]
fn three_dimensional_p1_and_p2() {
    let sides = ["left", "right", "front", "back", "bottom", "top"];
    let unit = [0.0, 1.0];
    let p1: Vec<_> =
        [4, 8, 16].iter().map(|&n| solve(&structured::cuboid([n; 3], unit, unit, unit, 1), &sides, 0.3)).collect();
    check("3D P1", 1, &p1);
    let p2: Vec<_> =
        [2, 4, 8].iter().map(|&n| solve(&structured::cuboid([n; 3], unit, unit, unit, 2), &sides, 0.3)).collect();
    check("3D P2", 2, &p2);
}
