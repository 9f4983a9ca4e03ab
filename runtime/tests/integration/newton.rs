//! Semi-smooth Newton through the runtime alone: a membrane −u″ = f on (0, 1), u(0) = u(1) = 0,
//! pushed onto the obstacle u ≥ ψ by a nodal penalty ε[u − ψ]₋. R is the gradient of the convex
//! J(u) = ½uᵀKu − Fᵀu + ½ε Σ [u_i − ψ]₋², so Newton's answer must minimise J; it must also be
//! symmetric, touch the obstacle in the middle and nowhere near the ends, and not depend on
//! whether the Jacobian is reused while the active set is unchanged, nor on whether active-set
//! changes are solved by a low-rank correction of the factorization or by refactoring.

use crate::common::{MassStiffness, pseudo_random};
use signorini_runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
use signorini_runtime::fem::mesh::structured::interval;
use signorini_runtime::linalg::{Counters, Matrix, Solver, Structure};
use signorini_runtime::nonlinear::newton::{Newton, NewtonOptions};
use signorini_runtime::nonlinear::problem::NonlinearProblem;
use signorini_runtime::nonlinear::statics::Constraints;

const EPS: f64 = 1e4;
const PSI: f64 = -0.25;

struct Membrane {
    k: Matrix,
    f: Vec<f64>,
    constraints: Constraints,
    /// Report the active set (reuse the factorization) or not (refactor every iteration).
    piecewise: bool,
    /// The dofs the obstacle acts on, and its penalty.
    contact: std::ops::Range<usize>,
    eps: f64,
    /// Evaluate R on `contact` only when Newton asks (`residual_on_support`), and how often
    /// it did.
    on_support: bool,
    support_residuals: usize,
    /// A drag pulling each active dof towards its right neighbour, `drag (w_{i+1} − w_i)`:
    /// the Jacobian is nonsymmetric on the contact zone only, as a frictional law's is.
    drag: f64,
}

impl Membrane {
    fn energy(&self, u: &[f64]) -> f64 {
        let mut ku = vec![0.0; u.len()];
        self.k.mul_vec(u, &mut ku);
        let quad: f64 = u.iter().zip(&ku).map(|(a, b)| a * b).sum();
        let load: f64 = u.iter().zip(&self.f).map(|(a, b)| a * b).sum();
        0.5 * quad - load
            + 0.5 * self.eps * u[self.contact.clone()].iter().map(|x| (x - PSI).min(0.0).powi(2)).sum::<f64>()
    }
}

fn diagonal_index(m: &Matrix, i: usize) -> usize {
    let p = &m.pattern;
    let rows = &p.row_idx[p.col_ptr[i]..p.col_ptr[i + 1]];
    p.col_ptr[i] + rows.binary_search(&i).expect("the diagonal is in the pattern")
}

impl NonlinearProblem for Membrane {
    fn residual(&mut self, w: &[f64], r: &mut [f64]) {
        self.k.mul_vec(w, r);
        for (i, ri) in r.iter_mut().enumerate() {
            *ri -= self.f[i];
        }
        for i in self.contact.clone() {
            r[i] += self.eps * (w[i] - PSI).min(0.0);
            if w[i] < PSI && i + 1 < w.len() {
                r[i] += self.drag * (w[i + 1] - w[i]);
            }
        }
        self.constraints.zero(r);
    }
    fn residual_on_support(&mut self, w: &[f64], r: &mut [f64]) -> bool {
        if !self.on_support {
            return false;
        }
        self.support_residuals += 1;
        let mut full = vec![0.0; r.len()];
        self.residual(w, &mut full);
        r.fill(0.0);
        r[self.contact.clone()].copy_from_slice(&full[self.contact.clone()]);
        true
    }
    fn magnitude(&self) -> f64 {
        self.f.iter().fold(0.0, |m, x| m.max(x.abs()))
    }
    fn active_set(&mut self, w: &[f64], out: &mut Vec<bool>) -> bool {
        out.extend(w[self.contact.clone()].iter().map(|x| *x < PSI));
        self.piecewise
    }
    fn jacobian(&mut self, w: &[f64], j: &mut Matrix) {
        j.add_scaled(1.0, &self.k);
        for (i, x) in w.iter().enumerate().filter(|(i, _)| self.contact.contains(i)) {
            if *x < PSI {
                let k = diagonal_index(j, i);
                j.values[k] += self.eps - self.drag;
                if self.drag != 0.0 && i + 1 < j.size() {
                    let p = &j.pattern;
                    let rows = &p.row_idx[p.col_ptr[i + 1]..p.col_ptr[i + 2]];
                    let right = p.col_ptr[i + 1] + rows.binary_search(&i).expect("neighbours in the pattern");
                    j.values[right] += self.drag;
                }
            }
        }
        self.constraints.apply(j);
    }
    fn jacobian_matrix(&self) -> Matrix {
        Matrix::zeros(self.k.pattern.clone())
    }
    fn structure(&self) -> Structure {
        if self.drag == 0.0 { Structure::SymmetricPositiveDefinite } else { Structure::General }
    }
}

fn solve(piecewise: bool) -> (Vec<f64>, usize, Membrane) {
    let (u, iterations, problem, _) = solve_with(piecewise, NewtonOptions::default());
    (u, iterations, problem)
}

fn solve_with(piecewise: bool, options: NewtonOptions) -> (Vec<f64>, usize, Membrane, Counters) {
    let (u, iterations, problem, (counters, _)) = solve_on(piecewise, options, None, false, 0.0);
    (u, iterations, problem, counters)
}

/// With the obstacle on `contact` only (everywhere if None; else under half the load and then
/// the whole), its residual evaluated there alone when Newton asks if `on_support`, with a
/// `drag` on the active dofs. Returns Newton's counters and its Cholesky factor's size, if its
/// last factor is one.
fn solve_on(
    piecewise: bool,
    options: NewtonOptions,
    contact: Option<std::ops::Range<usize>>,
    on_support: bool,
    drag: f64,
) -> (Vec<f64>, usize, Membrane, (Counters, Option<usize>)) {
    let n_el = 64;
    let mesh = interval(n_el, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let zero = vec![0.0; n];
    let mut k = asm.zero_matrix();
    asm.cell_tangent(
        CellIntegral::all(&MassStiffness { rho: 0.0, k: 1.0 }, Quadrature::default()),
        &[&zero],
        0,
        0.0,
        &mut k,
    );
    // F = M (−8): a uniform load pushing the membrane down (alone it would reach −1).
    let mut f = vec![0.0; n];
    asm.cell_residual(
        CellIntegral::all(&MassStiffness { rho: 1.0, k: 0.0 }, Quadrature::default()),
        &[&vec![-8.0; n]],
        0.0,
        &mut f,
    );
    let mut constraints = Constraints::none(n);
    constraints.fix(0);
    constraints.fix(n_el);
    constraints.zero(&mut f);
    let twice = contact.is_some();
    let contact = contact.unwrap_or(0..n);
    // A milder penalty in the two-load runs: its solves are accurate enough to be trusted.
    let eps = if twice { 1e2 } else { EPS };
    let mut problem = Membrane { k, f, constraints, piecewise, contact, eps, on_support, support_residuals: 0, drag };
    if twice {
        problem.f.iter_mut().for_each(|x| *x *= 0.5);
    }
    let mut u = vec![0.0; n];
    let mut newton = Newton::new(options);
    let report = newton.solve(&mut problem, &mut u).unwrap();
    let mut iterations = report.iterations();
    // Then the load doubled, from there with the same Newton (its solves trusted by then):
    // the active set grows from the last one, as in a time step.
    if twice {
        problem.f.iter_mut().for_each(|x| *x *= 2.0);
        iterations += newton.solve(&mut problem, &mut u).unwrap().iterations();
    }
    (u, iterations, problem, (newton.counters(), newton.factor_nnz()))
}

#[test]
fn newton_minimises_the_penalised_energy() {
    let (u, iterations, problem) = solve(true);
    let n = u.len();
    // From u = 0 (no contact) the active set grows by a few nodes per iteration: 13 measured.
    assert!(iterations <= 20, "{iterations} iterations");
    // Symmetric, in contact in the middle, free near the ends.
    for i in 0..n {
        assert!((u[i] - u[n - 1 - i]).abs() < 1e-10, "asymmetric at node {i}");
    }
    assert!(u[n / 2] < PSI && u[n / 2] > PSI - 1e-3, "centre {}", u[n / 2]);
    assert!(u[n / 8] > PSI, "near the end {}", u[n / 8]);
    // A minimum of J: no perturbation (zero at the fixed ends) lowers it.
    let j0 = problem.energy(&u);
    for seed in 0..20 {
        let mut d = pseudo_random(n, seed);
        d[0] = 0.0;
        d[n - 1] = 0.0;
        for t in [1e-3, -1e-3, 1e-5] {
            let v: Vec<f64> = u.iter().zip(&d).map(|(a, b)| a + t * b).collect();
            assert!(problem.energy(&v) >= j0 - 1e-12 * j0.abs(), "seed {seed}, t = {t}");
        }
    }
}

#[test]
fn reusing_the_factorization_does_not_change_the_answer() {
    let (a, _, _) = solve(true);
    let (b, _, _) = solve(false);
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9 * scale));
}

#[test]
fn low_rank_corrections_replace_refactorizations_without_changing_the_answer() {
    let direct = NewtonOptions { solver: Solver::Direct, ..NewtonOptions::default() };
    let (a, ia, _, with) = solve_with(true, direct);
    let (b, ib, _, without) = solve_with(true, NewtonOptions { max_rank: 0, ..direct });
    assert_eq!(ia, ib, "the same Newton iterates");
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(diff < 1e-12 * scale, "the answers differ by {diff:.1e}");
    assert_eq!(without.updates, 0);
    assert!(with.updates > 0, "{with:?}");
    assert_eq!(with.numeric + with.updates, without.numeric, "each change of the active set: one or the other");
    assert!(with.numeric < without.numeric / 2, "{with:?} against {without:?}");
}

#[test]
fn a_nonsymmetric_tangent_is_solved_by_correcting_its_factored_symmetric_part() {
    // The drag makes J nonsymmetric where the membrane touches: the symmetric part of J is
    // factored by Cholesky at the first iterate (J = K there) and every later operator is that
    // factor corrected, nonsymmetric part included; without corrections every one is an LU.
    let direct = NewtonOptions { solver: Solver::Direct, ..NewtonOptions::default() };
    let (a, ia, problem, (with, cholesky)) = solve_on(true, direct, Some(24..41), false, 1.0);
    let (b, ib, _, (without, _)) = solve_on(true, NewtonOptions { max_rank: 0, ..direct }, Some(24..41), false, 1.0);
    assert_eq!(ia, ib, "the same Newton iterates");
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(diff < 1e-12 * scale, "the answers differ by {diff:.1e}");
    let active = a.iter().filter(|x| **x < PSI).count();
    assert!(active > 2 && problem.drag > 0.0, "in contact on {active} dofs");
    assert_eq!(with.numeric, 1, "one factorization, corrected since: {with:?}");
    assert!(cholesky.is_some(), "a Cholesky factor");
    assert_eq!(with.updates, without.numeric, "a correction for each LU: {with:?} against {without:?}");
}

/// R(w) = (cM + K) w − (cM w̃ + f), an implicit step with c = 1/(βΔt²) for Δt ≈ 1e-7: the
/// right-hand side is 10¹³ times the force balance M a + K w − f that Newton must satisfy.
struct InertiaDominated {
    a: Matrix,
    rhs: Vec<f64>,
    magnitude: f64,
}

impl NonlinearProblem for InertiaDominated {
    fn residual(&mut self, w: &[f64], r: &mut [f64]) {
        self.a.mul_vec(w, r);
        self.magnitude = r.iter().chain(&self.rhs).fold(0.0, |m, x| m.max(x.abs()));
        r.iter_mut().zip(&self.rhs).for_each(|(ri, b)| *ri -= b);
    }
    fn magnitude(&self) -> f64 {
        self.magnitude
    }
    fn active_set(&mut self, _: &[f64], _: &mut Vec<bool>) -> bool {
        true
    }
    fn jacobian(&mut self, _: &[f64], j: &mut Matrix) {
        j.values.copy_from_slice(&self.a.values);
    }
    fn jacobian_matrix(&self) -> Matrix {
        Matrix::zeros(self.a.pattern.clone())
    }
    fn structure(&self) -> Structure {
        Structure::SymmetricPositiveDefinite
    }
}

#[test]
fn an_inertial_right_hand_side_does_not_set_the_stopping_scale() {
    let mesh = interval(64, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let zero = vec![0.0; n];
    let c = 1e15;
    let (mut m, mut k) = (asm.zero_matrix(), asm.zero_matrix());
    asm.cell_tangent(
        CellIntegral::all(&MassStiffness { rho: 1.0, k: 0.0 }, Quadrature::default()),
        &[&zero],
        0,
        0.0,
        &mut m,
    );
    asm.cell_tangent(
        CellIntegral::all(&MassStiffness { rho: 0.0, k: 1.0 }, Quadrature::default()),
        &[&zero],
        0,
        0.0,
        &mut k,
    );
    let mut a = k.clone();
    a.add_scaled(c, &m);
    // A rough predictor w̃ (so K w̃ is not small) and a unit load.
    let predictor: Vec<f64> = pseudo_random(n, 7).iter().map(|x| 1.0 + x).collect();
    let mut f = vec![0.0; n];
    m.mul_vec(&vec![1.0; n], &mut f);
    let mut rhs = vec![0.0; n];
    m.mul_vec(&predictor, &mut rhs);
    rhs.iter_mut().zip(&f).for_each(|(r, fi)| *r = c * *r + fi);
    let mut problem = InertiaDominated { a, rhs, magnitude: 0.0 };
    let mut w = predictor.clone();
    let report = Newton::new(NewtonOptions::default()).solve(&mut problem, &mut w).unwrap();
    assert!(report.iterations() >= 1, "no iteration from a residual of {:.2e}", report.initial_residual);
    // The force balance M a + K w = f with a = c (w − w̃), to the precision w − w̃ ≈ 1e-11
    // keeps against w ≈ 1 (about 1e-5).
    let accel: Vec<f64> = w.iter().zip(&predictor).map(|(x, p)| c * (x - p)).collect();
    let (mut ma, mut kw) = (vec![0.0; n], vec![0.0; n]);
    m.mul_vec(&accel, &mut ma);
    k.mul_vec(&w, &mut kw);
    let defect = (0..n).map(|i| (ma[i] + kw[i] - f[i]).abs()).fold(0.0, f64::max);
    let scale = (0..n).map(|i| (kw[i] - f[i]).abs()).fold(0.0, f64::max);
    assert!(defect < 1e-3 * scale, "force balance off by {defect:.2e} of {scale:.2e}");
}

#[test]
fn a_residual_on_the_contact_dofs_alone_gives_the_same_answer() {
    // The obstacle on the middle half, under a load and then twice that: where the set changes
    // after a trusted solve, Newton evaluates R there only and carries that solve's error
    // elsewhere in its bounds.
    let direct = NewtonOptions { solver: Solver::Direct, ..NewtonOptions::default() };
    let contact = Some(16..49);
    let (a, ia, mut problem, _) = solve_on(true, direct, contact.clone(), true, 0.0);
    assert!(problem.support_residuals > 0, "residuals on the contact dofs were asked for");
    problem.on_support = false;
    let (b, ib, _, _) = solve_on(true, direct, contact, false, 0.0);
    assert_eq!(ia, ib, "the same Newton iterations");
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(diff < 1e-12 * scale, "the answers differ by {diff:.1e}");
    // The answer's whole residual meets Newton's tolerance (relative to the first residual).
    let mut r = vec![0.0; a.len()];
    problem.residual(&a, &mut r);
    let mut r0 = vec![0.0; a.len()];
    problem.residual(&vec![0.0; a.len()], &mut r0);
    assert!(a.iter().any(|x| *x < PSI), "in contact");
    let tol = NewtonOptions::default().tol;
    assert!(norm(&r) <= tol * norm(&r0), "‖R‖ = {:.1e} against {:.1e}", norm(&r), tol * norm(&r0));
}

fn norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Inexact Newton: under loads growing step by step, as in a run through an impact, each solve's
/// active set grows from the last one's. The iterative solves whose iteration is expected to
/// change the set are loose, the ones that end Newton tight; the answers still meet Newton's
/// tolerance and agree with the direct solver's.
#[test]
fn iterative_solves_are_as_loose_as_their_newton_iteration_allows() {
    let run = |solver| {
        let options = NewtonOptions { solver, ..NewtonOptions::default() };
        let (_, _, mut problem, _) = solve_on(true, options, Some(16..49), false, 0.0);
        let full = problem.f.clone();
        let mut u = vec![0.0; full.len()];
        let mut newton = Newton::new(options);
        let mut out = Vec::new();
        for scale in [0.5, 0.7, 0.9, 1.1, 1.3] {
            problem.f.iter_mut().zip(&full).for_each(|(f, g)| *f = scale * g);
            let mut r0 = vec![0.0; u.len()];
            problem.residual(&u, &mut r0);
            let report = newton.solve(&mut problem, &mut u).unwrap();
            let mut r = vec![0.0; u.len()];
            problem.residual(&u, &mut r);
            assert!(norm(&r) <= options.tol * norm(&r0), "‖R‖ = {:.1e} from {:.1e}", norm(&r), norm(&r0));
            out.push((u.clone(), report));
        }
        out
    };
    let (direct, iterative) = (run(Solver::Direct), run(Solver::Iterative));
    let mut loose = 0;
    for ((a, d), (b, i)) in direct.iter().zip(&iterative) {
        assert!(d.history.iter().all(|it| it.tolerance.is_none()), "direct solves have no tolerance");
        let tolerances: Vec<f64> = i.history.iter().map(|it| it.tolerance.expect("an iterative solve")).collect();
        assert!(*tolerances.last().unwrap() <= 1e-8, "the last solve is tight: {tolerances:?}");
        loose += tolerances.iter().filter(|t| **t >= 1e-4).count();
        assert!(a.iter().any(|x| *x < PSI), "in contact");
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-9 * scale, "the answers differ by {diff:.1e} of {scale:.1e}");
    }
    assert!(loose > 0, "solves expected to change the active set are loose");
}
