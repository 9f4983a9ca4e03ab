//! Space orders: manufactured solutions of linear elasticity through the library's compiled
//! elasticity forms, P1 and P2 in 1D, 2D (straight meshes and the curved isoparametric P2
//! disc) and 3D.
//!
//! With u₁ = Πₖ sin(π xₖ) and u_j = 0 for j > 1, −div σ(u) = f with
//! f₁ = π²(dμ + λ + μ) u₁ and f_j = −(λ + μ) π² cos(π x₁) cos(π x_j) Π_{k≠1,j} sin(π xₖ).
//! The exact solution is imposed on the boundary; errors in L2 and the H1 seminorm.

use std::f64::consts::PI;

use serde::Serialize;

use crate::error::CaseError;
use crate::forms::elasticity;
use crate::runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
use crate::runtime::fem::evaluate::errors;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::structured::{self, Diagonal};
use crate::runtime::fem::mesh::{Mesh, disc::disc};
use crate::runtime::linalg::Structure;
use crate::runtime::nonlinear::statics::{Constraints, solve_linear};

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
fn solve(mesh: &Mesh, boundary: &[&str], nu: f64) -> Result<(f64, f64), CaseError> {
    let d = mesh.dim();
    let e = 1.0;
    let (lambda, mu) = (e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu)));
    let p = elasticity::Params::default()
        .with("E", e)
        .and_then(|p| p.with("nu", nu))
        .map_err(|e| CaseError::Option(e.to_string()))?;
    let c = elasticity::Coefficients { f: Coef::function(d, move |x, _, out| body_force(x, lambda, mu, out)) };
    let asm = Assembler::new(mesh);
    let n = asm.size();
    let degree = mesh.kind.degree();
    let quad = Quadrature { cell: Some(2 * degree + 2), facet: None };
    let mut k = asm.zero_matrix();
    asm.cell_tangent(CellIntegral::all(&elasticity::Stiffness::new(&p, &c), quad), &[&vec![0.0; n]], 0, 0.0, &mut k);
    let mut b = vec![0.0; n];
    asm.cell_residual(CellIntegral::all(&elasticity::Load::new(&p, &c), quad), &[], 0.0, &mut b);
    let mut dirichlet = Constraints::none(n);
    let all: Vec<usize> = (0..d).collect();
    for region in boundary {
        dirichlet.fix_region(mesh, region, &all, |x| exact(x).0)?;
    }
    let u = solve_linear(&k, &b, &dirichlet, Structure::SymmetricPositiveDefinite)
        .map_err(|e| CaseError::Option(format!("manufactured solution: {e}")))?;
    Ok(errors(mesh, &u, 2 * degree + 3, &exact))
}

/// One family of meshes, each twice as fine as the last.
#[derive(Clone, Debug, Serialize)]
pub struct SpaceRow {
    pub case: String,
    pub degree: u32,
    /// (h, L2 error, H1 error) per mesh.
    pub errors: Vec<(f64, f64, f64)>,
    /// Observed rates between the two finest meshes.
    pub l2_order: f64,
    pub h1_order: f64,
}

fn row(case: String, degree: u32, meshes: Vec<(f64, Mesh)>, boundary: &[&str], nu: f64) -> Result<SpaceRow, CaseError> {
    let errors: Vec<(f64, f64, f64)> = meshes
        .iter()
        .map(|(h, mesh)| {
            let (l2, h1) = solve(mesh, boundary, nu)?;
            Ok((*h, l2, h1))
        })
        .collect::<Result<_, CaseError>>()?;
    let l2: Vec<(f64, f64)> = errors.iter().map(|e| (e.0, e.1)).collect();
    let h1: Vec<(f64, f64)> = errors.iter().map(|e| (e.0, e.2)).collect();
    Ok(SpaceRow {
        case,
        degree,
        l2_order: super::time::last_order(&l2),
        h1_order: super::time::last_order(&h1),
        errors,
    })
}

/// Every family: 1D P1; 2D P1 and P2 with both diagonals; the curved P2 disc; 3D P1 and P2.
pub fn orders(progress: &mut dyn FnMut(&str)) -> Result<Vec<SpaceRow>, CaseError> {
    let mut rows = Vec::new();
    progress("space order 1D");
    let meshes = [8, 16, 32].iter().map(|&n| (1.0 / n as f64, structured::interval(n, 0.0, 1.0))).collect();
    rows.push(row("1D interval".into(), 1, meshes, &["left", "right"], 0.0)?);
    let square = ["left", "right", "bottom", "top"];
    for degree in [1, 2] {
        for diagonal in [Diagonal::Right, Diagonal::Left] {
            progress(&format!("space order 2D P{degree} {diagonal:?}"));
            let meshes = [4, 8, 16]
                .iter()
                .map(|&n| (1.0 / n as f64, structured::rectangle(n, n, [0.0, 1.0], [0.0, 1.0], diagonal, degree)))
                .collect();
            let name = format!("2D square, {} diagonals", format!("{diagonal:?}").to_lowercase());
            rows.push(row(name, degree, meshes, &square, 0.3)?);
        }
    }
    // Off-centre, so the solution has no symmetry the mesh could exploit.
    progress("space order 2D curved disc");
    let meshes = [0.5, 0.25, 0.125].iter().map(|&h| (h, disc(1.0, [0.3, 0.2], h))).collect();
    rows.push(row("2D curved disc".into(), 2, meshes, &["boundary"], 0.3)?);
    let cube = ["left", "right", "front", "back", "bottom", "top"];
    let unit = [0.0, 1.0];
    for (degree, sizes) in [(1, [4, 8, 16]), (2, [2, 4, 8])] {
        progress(&format!("space order 3D P{degree}"));
        let meshes =
            sizes.iter().map(|&n| (1.0 / n as f64, structured::cuboid([n; 3], unit, unit, unit, degree))).collect();
        rows.push(row("3D cube".into(), degree, meshes, &cube, 0.3)?);
    }
    Ok(rows)
}
