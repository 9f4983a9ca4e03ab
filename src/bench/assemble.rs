//! `signorini bench assemble`: assembly and factorization timings of the P2 plane-strain
//! benchmark (issue 3). Assembly on one thread and on all of them (`--threads`), whose
//! matrices must have the same bits; the factorization on one thread. The unit square is cut into N×N squares along the
//! (i,j)–(i+1,j+1) diagonals (2N² cells); stiffness with the 3-point rule (degree 2), mass
//! with the 6-point rule (degree 4), E = 1, ν = 0.3, ρ = 1. Pattern building is timed apart
//! from assembly. Then M/(β dt²) + K at one N (β = 1/4, dt = 1e-3) is factored by sparse
//! Cholesky and solved with a right-hand side of ones. Medians of repeated runs.

use std::time::Instant;

use serde::Serialize;

use crate::forms::elasticity::{Coefficients, Mass, Params, Stiffness};
use crate::resources::median;
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::structured::{self, Diagonal};
use crate::runtime::linalg::{Factorization, Structure};

#[derive(Clone, Debug, Serialize)]
pub struct AssemblyTiming {
    pub n: usize,
    pub cells: usize,
    pub dofs: usize,
    pub nnz: usize,
    pub pattern_seconds: f64,
    /// One thread.
    pub stiffness_us_per_cell: f64,
    pub mass_us_per_cell: f64,
    /// `threads` threads, and the speedups over one.
    pub threads: usize,
    pub stiffness_us_per_cell_threaded: f64,
    pub mass_us_per_cell_threaded: f64,
    pub stiffness_speedup: f64,
    pub mass_speedup: f64,
    pub stiffness_frobenius: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FactorTiming {
    pub n: usize,
    pub dofs: usize,
    pub symbolic_seconds: f64,
    pub numeric_seconds: f64,
    pub solve_seconds: f64,
    /// ‖A x − b‖∞ / ‖b‖∞.
    pub relative_residual: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub assembly: Vec<AssemblyTiming>,
    pub factor: Option<FactorTiming>,
    pub repeats: usize,
}

fn forms() -> (Stiffness, Mass) {
    let p = Params::default()
        .with("E", 1.0)
        .and_then(|p| p.with("nu", 0.3))
        .and_then(|p| p.with("rho", 1.0))
        .expect("valid parameters");
    let c = Coefficients { f: Coef::constant(vec![0.0, 0.0]) };
    (Stiffness::new(&p, &c), Mass::new(&p, &c))
}

/// Times assembly at each N and the factorization at `factor_n` (if any).
pub fn assemble(sizes: &[usize], factor_n: Option<usize>, repeats: usize, progress: &mut dyn FnMut(&str)) -> Report {
    let repeats = repeats.max(1);
    let (k, m) = forms();
    let mut assembly = Vec::new();
    for &n in sizes {
        let mesh = structured::rectangle(n, n, [0.0, 1.0], [0.0, 1.0], Diagonal::Right, 2);
        let cells = mesh.num_cells();
        let mut pattern_times = Vec::new();
        let mut asm = None;
        for _ in 0..repeats.min(3) {
            let t = Instant::now();
            asm = Some(Assembler::new(&mesh));
            pattern_times.push(t.elapsed().as_secs_f64());
        }
        let asm = asm.expect("at least one repeat");
        let zero = vec![0.0; asm.size()];
        // Medians of the stiffness and mass assembly times on a pool of `threads`, and K.
        let time = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
            pool.install(|| {
                let mut kmat = asm.zero_matrix();
                let mut mmat = asm.zero_matrix();
                let (mut tk, mut tm) = (Vec::new(), Vec::new());
                for _ in 0..repeats {
                    kmat.values.iter_mut().for_each(|v| *v = 0.0);
                    let t = Instant::now();
                    asm.cell_tangent(&k, Quadrature { cell: Some(2), facet: None }, &[&zero], 0, 0.0, &mut kmat);
                    tk.push(t.elapsed().as_secs_f64());
                    mmat.values.iter_mut().for_each(|v| *v = 0.0);
                    let t = Instant::now();
                    asm.cell_tangent(&m, Quadrature { cell: Some(4), facet: None }, &[&zero], 0, 0.0, &mut mmat);
                    tm.push(t.elapsed().as_secs_f64());
                }
                (median(tk), median(tm), kmat)
            })
        };
        let threads = rayon::current_num_threads();
        let (k1, m1, kmat) = time(1);
        let (kt, mt, kmat_threaded) = time(threads);
        assert!(
            kmat.values.iter().zip(&kmat_threaded.values).all(|(a, b)| a.to_bits() == b.to_bits()),
            "threaded assembly changed the bits"
        );
        let timing = AssemblyTiming {
            n,
            cells,
            dofs: asm.size(),
            nnz: asm.pattern().nnz(),
            pattern_seconds: median(pattern_times),
            stiffness_us_per_cell: k1 * 1e6 / cells as f64,
            mass_us_per_cell: m1 * 1e6 / cells as f64,
            threads,
            stiffness_us_per_cell_threaded: kt * 1e6 / cells as f64,
            mass_us_per_cell_threaded: mt * 1e6 / cells as f64,
            stiffness_speedup: k1 / kt,
            mass_speedup: m1 / mt,
            stiffness_frobenius: kmat.frobenius(),
        };
        progress(&format!(
            "N = {n:4}: {cells:8} cells, pattern {:.3} s, K {:.3} µs/cell, M {:.3} µs/cell; {threads} threads: K {:.3} µs/cell (×{:.2}), M {:.3} µs/cell (×{:.2}), same bits; ‖K‖_F = {:.6}",
            timing.pattern_seconds,
            timing.stiffness_us_per_cell,
            timing.mass_us_per_cell,
            timing.stiffness_us_per_cell_threaded,
            timing.stiffness_speedup,
            timing.mass_us_per_cell_threaded,
            timing.mass_speedup,
            timing.stiffness_frobenius
        ));
        assembly.push(timing);
    }
    let factor = factor_n.map(|n| {
        let mesh = structured::rectangle(n, n, [0.0, 1.0], [0.0, 1.0], Diagonal::Right, 2);
        let asm = Assembler::new(&mesh);
        let zero = vec![0.0; asm.size()];
        let mut a = asm.zero_matrix();
        let mut mmat = asm.zero_matrix();
        asm.cell_tangent(&k, Quadrature { cell: Some(2), facet: None }, &[&zero], 0, 0.0, &mut a);
        asm.cell_tangent(&m, Quadrature { cell: Some(4), facet: None }, &[&zero], 0, 0.0, &mut mmat);
        let (beta, dt) = (0.25, 1e-3);
        a.add_scaled(1.0 / (beta * dt * dt), &mmat);
        let (mut ts, mut tn, mut tsol) = (Vec::new(), Vec::new(), Vec::new());
        let mut residual = f64::NAN;
        for _ in 0..repeats.min(3) {
            let mut f = Factorization::new(Structure::SymmetricPositiveDefinite);
            // The first factor call does the symbolic analysis and the numeric factorization;
            // the second reuses the analysis, so their difference is the analysis.
            let t = Instant::now();
            f.factor(&a).expect("SPD");
            let first = t.elapsed().as_secs_f64();
            let t = Instant::now();
            f.factor(&a).expect("SPD");
            let numeric = t.elapsed().as_secs_f64();
            ts.push((first - numeric).max(0.0));
            tn.push(numeric);
            let b = vec![1.0; asm.size()];
            let mut x = b.clone();
            let t = Instant::now();
            f.solve_in_place(&mut x).expect("factored");
            tsol.push(t.elapsed().as_secs_f64());
            let mut ax = vec![0.0; x.len()];
            a.mul_vec(&x, &mut ax);
            residual = ax.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        }
        let t = FactorTiming {
            n,
            dofs: asm.size(),
            symbolic_seconds: median(ts),
            numeric_seconds: median(tn),
            solve_seconds: median(tsol),
            relative_residual: residual,
        };
        progress(&format!(
            "N = {n}: {} dofs, symbolic {:.3} s, numeric Cholesky {:.3} s, solve {:.3} s, residual {:.1e}",
            t.dofs, t.symbolic_seconds, t.numeric_seconds, t.solve_seconds, t.relative_residual
        ));
        t
    });
    Report { assembly, factor, repeats }
}
