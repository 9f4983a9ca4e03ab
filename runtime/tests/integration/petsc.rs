//! PETSc's solvers (feature `petsc`) against a plain factorization of the same matrix: CG with
//! block Jacobi on a symmetric step matrix, GMRES on one whose contact blocks are unsymmetric,
//! on every element kind; a matrix block Jacobi cannot precondition gets algebraic multigrid;
//! new values of the same pattern keep the solver, and its preconditioner while it serves; a
//! failure is an error.

use crate::common::pseudo_random;
use crate::solvers::{meshes, relative_difference, step_matrix};
use signorini_runtime::linalg::{Factorization, LinalgError, Matrix, Solver, Structure};

fn petsc(structure: Structure, mesh: &signorini_runtime::fem::mesh::Mesh) -> Factorization {
    Factorization::new(structure).with_solver(Solver::Petsc).with_coordinates(Some(mesh.coords.as_slice().into()))
}

fn solve(f: &mut Factorization, a: &Matrix, b: &[f64]) -> Result<Vec<f64>, LinalgError> {
    f.factor(a)?;
    let mut x = b.to_vec();
    f.solve_in_place(&mut x)?;
    Ok(x)
}

fn direct(a: &Matrix, structure: Structure, b: &[f64]) -> Vec<f64> {
    solve(&mut Factorization::new(structure), a, b).expect("a direct solve")
}

#[test]
fn conjugate_gradients_match_the_cholesky_solution() {
    for mesh in meshes() {
        let a = step_matrix(&mesh);
        let b = pseudo_random(a.size(), 3);
        let mut f = petsc(Structure::SymmetricPositiveDefinite, &mesh);
        let x = solve(&mut f, &a, &b).expect("PETSc solves");
        let err = relative_difference(&x, &direct(&a, Structure::SymmetricPositiveDefinite, &b));
        let iterations = f.counters.iterations;
        assert!(err < 1e-10, "{}: differs by {err:.1e} after {iterations} iterations", mesh.kind.name());
        // ILU(0) of the interval's banded matrix is its exact factorization; not elsewhere.
        assert!(mesh.dim() == 1 || iterations > 1, "a real iteration");
        assert_eq!(f.counters.numeric, 1, "one preconditioner: block Jacobi serves a step matrix");
    }
}

/// A stiffness with a trace of mass, nearly singular along the rigid-body modes: block Jacobi
/// reaches its limit (8 iterations per digit, 96 to 1e-12) within the first solve, which is
/// taken again with GAMG, whose near-null space is those modes; the next solve keeps GAMG and
/// needs a fraction of the iterations.
#[test]
fn a_matrix_block_jacobi_cannot_precondition_gets_multigrid() {
    let mesh = signorini_runtime::fem::mesh::structured::cuboid([8, 8, 8], [0.0, 1.0], [0.0, 1.0], [0.0, 1.0], 2);
    let asm = signorini_runtime::fem::assembly::Assembler::new(&mesh);
    let zero = vec![0.0; asm.size()];
    let mut a = asm.zero_matrix();
    let form = crate::common::MassStiffness { rho: 1e-6, k: 1.0 };
    let whole = signorini_runtime::fem::assembly::CellIntegral::all(&form, Default::default());
    asm.cell_tangent(whole, &[&zero], 0, 0.0, &mut a);
    let b = pseudo_random(a.size(), 11);
    let mut f = petsc(Structure::SymmetricPositiveDefinite, &mesh);
    let reference = direct(&a, Structure::SymmetricPositiveDefinite, &b);
    let x = solve(&mut f, &a, &b).expect("solved after the switch");
    let first = f.counters.iterations;
    assert_eq!(f.counters.numeric, 2, "block Jacobi, then GAMG, within the first solve");
    assert!(first > 96, "{first} iterations: block Jacobi's 96, then GAMG's");
    assert!(relative_difference(&x, &reference) < 1e-6, "the first solution");
    let x = solve(&mut f, &a, &b).expect("GAMG solves");
    let multigrid = f.counters.iterations - first;
    assert_eq!(f.counters.numeric, 2, "GAMG kept");
    assert!(3 * multigrid < 96, "GAMG took {multigrid} iterations, where block Jacobi's 96 did not do");
    assert!(relative_difference(&x, &reference) < 1e-6, "GAMG's solution");
}

#[test]
fn gmres_matches_the_lu_solution_of_a_nonsymmetric_matrix() {
    for mesh in meshes() {
        // The contact blocks of the first tenth of the nodes (a "contact surface") made
        // unsymmetric, as Nitsche's θ ≠ 1 makes a contact tangent.
        let mut a = step_matrix(&mesh);
        let d = mesh.dim();
        for j in 0..a.size() {
            for k in a.pattern.col_ptr[j]..a.pattern.col_ptr[j + 1] {
                let i = a.pattern.row_idx[k];
                if i < j && i / d == j / d && (j / d) % 3 == 0 && j < a.size() / 10 {
                    a.values[k] *= 1.3;
                }
            }
        }
        assert!(d == 1 || !a.is_symmetric(1e-3));
        let b = pseudo_random(a.size(), 5);
        let x = solve(&mut petsc(Structure::General, &mesh), &a, &b).expect("PETSc solves");
        let err = relative_difference(&x, &direct(&a, Structure::General, &b));
        assert!(err < 1e-10, "{}: GMRES differs by {err:.1e}", mesh.kind.name());
    }
}

#[test]
fn new_values_of_the_same_pattern_keep_the_preconditioner_while_it_serves() {
    let mesh = &meshes()[1];
    let mut a = step_matrix(mesh);
    let b = pseudo_random(a.size(), 7);
    let mut f = petsc(Structure::SymmetricPositiveDefinite, mesh);
    solve(&mut f, &a, &b).expect("first solve");
    let first = f.counters.iterations;
    // A's diagonal 1 % larger on the first tenth of the unknowns, as a contact term changes a
    // few rows: A's preconditioner serves.
    let n = a.size();
    for j in 0..n / 10 {
        for k in a.pattern.col_ptr[j]..a.pattern.col_ptr[j + 1] {
            if a.pattern.row_idx[k] == j {
                a.values[k] *= 1.01;
            }
        }
    }
    let x = solve(&mut f, &a, &b).expect("second solve");
    assert_eq!((f.counters.symbolic, f.counters.numeric), (1, 1), "one solver, one preconditioner");
    let second = f.counters.iterations - first;
    assert!(second <= 2 * first, "{second} iterations with the kept preconditioner, {first} with a new one");
    let err = relative_difference(&x, &direct(&a, Structure::SymmetricPositiveDefinite, &b));
    assert!(err < 1e-10, "the second solve is of the new matrix: differs by {err:.1e}");
    // D A D with D = 10⁴ on the first half of the nodes: A's preconditioner no longer serves,
    // and one for these values is set up within the solve.
    let d = mesh.dim();
    let half = a.size() / d / 2;
    let scale = |i: usize| if i / d < half { 1e4 } else { 1.0 };
    for j in 0..a.size() {
        for k in a.pattern.col_ptr[j]..a.pattern.col_ptr[j + 1] {
            a.values[k] *= scale(a.pattern.row_idx[k]) * scale(j);
        }
    }
    let x = solve(&mut f, &a, &b).expect("third solve");
    assert_eq!(f.counters.numeric, 2, "a new preconditioner");
    let err = relative_difference(&x, &direct(&a, Structure::SymmetricPositiveDefinite, &b));
    assert!(err < 1e-10, "the third solve is of the scaled matrix: differs by {err:.1e}");
}

#[test]
fn a_matrix_petsc_cannot_solve_is_an_error_with_its_reason() {
    let mesh = &meshes()[1];
    let mut a = step_matrix(mesh);
    a.values.iter_mut().for_each(|v| *v = 0.0);
    let b = pseudo_random(a.size(), 9);
    let err = solve(&mut petsc(Structure::SymmetricPositiveDefinite, mesh), &a, &b).expect_err("no solution");
    assert!(!err.to_string().is_empty());
    // PETSc still works after the failure.
    let a = step_matrix(mesh);
    assert!(solve(&mut petsc(Structure::SymmetricPositiveDefinite, mesh), &a, &b).is_ok());
}
