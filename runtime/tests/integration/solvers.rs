//! The solvers against a plain factorization of the same matrix: CG (symmetric) and BiCGStab
//! (general) on a mass-dominated step matrix c·M + K with nodal couplings like a contact
//! tangent's, on every element kind; the block-Jacobi preconditioner is exact on a
//! block-diagonal matrix; the iterates have the same bits for one and two threads; a low-rank
//! correction of a factorization solves the changed matrix.

use crate::common::{MassStiffness, pseudo_random};
use signorini_runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
use signorini_runtime::fem::mesh::Mesh;
use signorini_runtime::fem::mesh::structured::{Diagonal, cuboid, interval, rectangle};
use signorini_runtime::linalg::lowrank::LowRank;
use signorini_runtime::linalg::{Factorization, Matrix, Solver, Structure};

pub(crate) fn meshes() -> Vec<Mesh> {
    let unit = [0.0, 1.0];
    vec![
        interval(40, 0.0, 1.0),
        rectangle(12, 10, unit, unit, Diagonal::Right, 2),
        cuboid([5, 4, 4], unit, unit, unit, 2),
    ]
}

/// Position of entry (i, j) in `m.values`.
fn index(m: &Matrix, i: usize, j: usize) -> usize {
    let p = &m.pattern;
    p.col_ptr[j] + p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]].binary_search(&i).expect("in the pattern")
}

/// c·M + K plus, on every third node, the symmetric positive block s·n nᵀ (n a unit vector
/// mixing the components, as a contact tangent does).
pub(crate) fn step_matrix(mesh: &Mesh) -> Matrix {
    let asm = Assembler::new(mesh);
    let zero = vec![0.0; asm.size()];
    let mut a = asm.zero_matrix();
    asm.cell_tangent(
        CellIntegral::all(&MassStiffness { rho: 400.0, k: 1.0 }, Quadrature::default()),
        &[&zero],
        0,
        0.0,
        &mut a,
    );
    let d = mesh.dim();
    let scale = (0..asm.size()).map(|i| a.get(i, i)).fold(0.0, f64::max);
    let n: Vec<f64> = (0..d).map(|k| 1.0 + k as f64).collect();
    let norm = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    for node in (0..mesh.num_nodes()).step_by(3) {
        for k in 0..d {
            for m in 0..d {
                let at = index(&a, node * d + k, node * d + m);
                a.values[at] += 50.0 * scale * n[k] * n[m] / (norm * norm);
            }
        }
    }
    a
}

fn solve(a: &Matrix, structure: Structure, solver: Solver, b: &[f64]) -> (Vec<f64>, usize) {
    let mut f = Factorization::new(structure).with_solver(solver);
    f.factor(a).expect("factors");
    let mut x = b.to_vec();
    f.solve_in_place(&mut x).expect("solves");
    (x, f.counters.iterations)
}

pub(crate) fn relative_difference(x: &[f64], y: &[f64]) -> f64 {
    let diff = x.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
    diff / y.iter().map(|v| v * v).sum::<f64>().sqrt()
}

#[test]
fn conjugate_gradients_match_the_cholesky_solution() {
    for mesh in meshes() {
        let a = step_matrix(&mesh);
        let b = pseudo_random(a.size(), 3);
        let (direct, _) = solve(&a, Structure::SymmetricPositiveDefinite, Solver::Direct, &b);
        let (cg, iterations) = solve(&a, Structure::SymmetricPositiveDefinite, Solver::Iterative, &b);
        let err = relative_difference(&cg, &direct);
        assert!(err < 1e-10, "{}: CG differs by {err:.1e} after {iterations} iterations", mesh.kind.name());
        assert!(iterations > 1, "a real iteration");
    }
}

#[test]
fn bicgstab_matches_the_lu_solution_of_a_nonsymmetric_matrix() {
    for mesh in meshes() {
        let mut a = step_matrix(&mesh);
        // A skew part off the diagonal, as Nitsche's θ ≠ 1 gives.
        let n = a.size();
        for j in 0..n {
            for k in a.pattern.col_ptr[j]..a.pattern.col_ptr[j + 1] {
                if a.pattern.row_idx[k] < j {
                    a.values[k] *= 1.3;
                }
            }
        }
        assert!(!a.is_symmetric(1e-3));
        let b = pseudo_random(n, 5);
        let (direct, _) = solve(&a, Structure::General, Solver::Direct, &b);
        let (krylov, iterations) = solve(&a, Structure::General, Solver::Iterative, &b);
        let err = relative_difference(&krylov, &direct);
        assert!(err < 1e-10, "{}: BiCGStab differs by {err:.1e} after {iterations} iterations", mesh.kind.name());
    }
}

#[test]
fn block_jacobi_solves_a_block_diagonal_matrix_at_once() {
    let mesh = cuboid([3, 3, 3], [0.0, 1.0], [0.0, 1.0], [0.0, 1.0], 2);
    let mut a = step_matrix(&mesh);
    let d = mesh.dim();
    let n = a.size();
    for j in 0..n {
        for k in a.pattern.col_ptr[j]..a.pattern.col_ptr[j + 1] {
            if a.pattern.row_idx[k] / d != j / d {
                a.values[k] = 0.0;
            }
        }
    }
    let b = pseudo_random(n, 9);
    let (x, iterations) = solve(&a, Structure::SymmetricPositiveDefinite, Solver::Iterative, &b);
    assert_eq!(iterations, 1, "the preconditioner is the inverse");
    let mut ax = vec![0.0; n];
    a.mul_vec(&x, &mut ax);
    assert!(relative_difference(&ax, &b) < 1e-13);
}

#[test]
fn iterates_do_not_depend_on_the_number_of_threads() {
    let mesh = cuboid([10, 10, 9], [0.0, 1.0], [0.0, 1.0], [0.0, 1.0], 2);
    let a = step_matrix(&mesh);
    let b = pseudo_random(a.size(), 11);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
        pool.install(|| solve(&a, Structure::SymmetricPositiveDefinite, Solver::Iterative, &b))
    };
    let (one, i1) = run(1);
    let (two, i2) = run(2);
    assert_eq!(i1, i2);
    assert!(one.iter().zip(&two).all(|(x, y)| x.to_bits() == y.to_bits()), "same bits");
}

#[test]
fn a_low_rank_correction_solves_the_changed_matrix() {
    // Dense columns J₀⁻¹U with an LU reference, sparse columns L⁻¹U with a Cholesky one.
    for (mesh, structure) in
        meshes().into_iter().flat_map(|m| [(m.clone(), Structure::General), (m, Structure::SymmetricPositiveDefinite)])
    {
        let reference = step_matrix(&mesh);
        let mut f = Factorization::new(structure);
        f.factor(&reference).expect("factors");
        let mut lr = LowRank::new(&reference);
        let d = mesh.dim();
        let b = pseudo_random(reference.size(), 13);
        // Two successive changes on a few nodes, as active sets switching on and off.
        for (round, nodes) in [vec![1usize, 2, 7], vec![2usize, 9]].into_iter().enumerate() {
            let mut changed = reference.clone();
            for &node in &nodes {
                for k in 0..d {
                    for m in 0..d {
                        let at = index(&changed, node * d + k, node * d + m);
                        changed.values[at] *= 1.0 + 0.5 * (round + 1) as f64 + 0.1 * (k + m) as f64;
                    }
                }
            }
            // A coupling between two changed nodes: symmetric, then (second round) not, as a
            // nonsymmetric contact tangent's change of a symmetric reference.
            let (i, j) = (nodes[0] * d, nodes[1] * d);
            if changed.pattern.row_idx[changed.pattern.col_ptr[j]..changed.pattern.col_ptr[j + 1]].contains(&i) {
                let c = 0.1 * changed.get(i, i).min(changed.get(j, j));
                let (a, b2) = (index(&changed, i, j), index(&changed, j, i));
                changed.values[a] += c;
                changed.values[b2] += c * (1.0 - round as f64);
            }
            let dofs = lr.changed_dofs(&changed, None);
            // Told where J can differ (the entries among the changed nodes), the same dofs.
            let mut flags = vec![false; changed.pattern.num_nodes()];
            nodes.iter().for_each(|&n| flags[n] = true);
            assert_eq!(lr.changed_dofs(&changed, Some(&changed.pattern.entries_among(&flags))), dofs);
            assert!(dofs.len() <= nodes.len() * d && !dofs.is_empty(), "changed dofs {dofs:?}");
            assert!(lr.update(&changed, dofs, &mut f, None, usize::MAX).expect("updates"), "within the limit");
            let mut x = b.clone();
            let defect = lr.solve(&mut f, &mut x, true).expect("solves");
            let (exact, _) = solve(&changed, Structure::General, Solver::Direct, &b);
            let err = relative_difference(&x, &exact);
            assert!(err < 1e-12, "{}: corrected solve differs by {err:.1e}", mesh.kind.name());
            // The correction's own residual is reported for a Cholesky reference in node blocks
            // (and is round-off here), not for columns of J₀⁻¹.
            match (structure, defect) {
                (Structure::SymmetricPositiveDefinite, Some(d)) => assert!(d < 1e-10, "defect {d:.1e}"),
                (Structure::SymmetricPositiveDefinite, None) => panic!("no defect for a Cholesky reference"),
                (_, defect) => assert_eq!(defect, None),
            }
        }
    }
}

/// The stiffness of a long free bar with a trace of mass is positive definite but so badly
/// conditioned (κ ~ 1e15) that Jacobi-preconditioned conjugate gradients need ~1e4 iterations
/// per halving of the residual: the solve gives up once the residual stops halving, after a
/// few hundred iterations rather than the iteration cap, with the cause and the way out.
#[test]
fn a_stalled_solve_gives_up_with_its_cause() {
    let mesh = interval(4000, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let zero = vec![0.0; asm.size()];
    let mut k = asm.zero_matrix();
    asm.cell_tangent(
        CellIntegral::all(&MassStiffness { rho: 1e-9, k: 1.0 }, Quadrature::default()),
        &[&zero],
        0,
        0.0,
        &mut k,
    );
    let mut f = Factorization::new(Structure::SymmetricPositiveDefinite).with_solver(Solver::Iterative);
    f.factor(&k).expect("the preconditioner's blocks invert");
    let mut x = pseudo_random(k.size(), 5);
    let e = f.solve_in_place(&mut x).expect_err("no solution").to_string();
    assert!(e.contains("stalled") && e.contains("--solver direct"), "{e}");
    let n: usize = e.split("after ").nth(1).and_then(|s| s.split(' ').next()).and_then(|s| s.parse().ok()).unwrap();
    let cap = 1000 + 20 * (k.size() as f64).sqrt() as usize;
    assert!(n < cap / 2, "gave up after {n} iterations (the cap is {cap})");
}
