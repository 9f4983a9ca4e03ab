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
use crate::runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
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

/// The finite-strain material of forms/library.toml `[bench]` on the same mesh (its largest N):
/// its stiffness's residual and tangent at a small random state, per cell, one thread, at a
/// quadrature degree of the triangle.
#[derive(Clone, Debug, Serialize)]
pub struct MaterialTiming {
    pub material: String,
    pub n: usize,
    pub cells: usize,
    pub degree: u32,
    pub residual_us_per_cell: f64,
    pub tangent_us_per_cell: f64,
    /// The tangent's Frobenius norm (for comparing runs, as `stiffness_frobenius`).
    pub tangent_frobenius: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub assembly: Vec<AssemblyTiming>,
    pub material: Vec<MaterialTiming>,
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
                    asm.cell_tangent(
                        CellIntegral::all(&k, Quadrature { cell: Some(2), facet: None }),
                        &[&zero],
                        0,
                        0.0,
                        &mut kmat,
                    );
                    tk.push(t.elapsed().as_secs_f64());
                    mmat.values.iter_mut().for_each(|v| *v = 0.0);
                    let t = Instant::now();
                    asm.cell_tangent(
                        CellIntegral::all(&m, Quadrature { cell: Some(4), facet: None }),
                        &[&zero],
                        0,
                        0.0,
                        &mut mmat,
                    );
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
        asm.cell_tangent(CellIntegral::all(&k, Quadrature { cell: Some(2), facet: None }), &[&zero], 0, 0.0, &mut a);
        asm.cell_tangent(CellIntegral::all(&m, Quadrature { cell: Some(4), facet: None }), &[&zero], 0, 0.0, &mut mmat);
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
    let material = match sizes.iter().max() {
        Some(&n) => material_timings(n, repeats, progress),
        None => Vec::new(),
    };
    Report { assembly, material, factor, repeats }
}

/// The stiffness of forms/library.toml's `[bench] assemble_material` (with `assemble_params`) on the N×N mesh at the state u = 0.01 ξ / N, ξ uniform in [−1/2, 1/2)
/// per dof (a random field whose gradient is of order 0.01: J > 0 everywhere), at each of
/// `[bench] assemble_degrees`. Medians of `repeats` assemblies each.
fn material_timings(n: usize, repeats: usize, progress: &mut dyn FnMut(&str)) -> Vec<MaterialTiming> {
    use crate::runtime::library::{Binding, SlotForm};
    let bench = &crate::settings::get().bench;
    let name = &bench.assemble_material;
    let Some(forms) = crate::forms::LIBRARY.iter().find(|u| u.name == name.as_str()).and_then(|u| u.forms) else {
        progress(&format!("bench assemble: no form file `{name}` in the library: its stiffness is not timed"));
        return Vec::new();
    };
    if let Some(unknown) = bench.assemble_params.keys().find(|k| !forms.params.iter().any(|p| *p.name == **k)) {
        progress(&format!("bench assemble: `{name}` declares no param `{unknown}` (forms/library.toml [bench])"));
        return Vec::new();
    }
    let values: Vec<f64> =
        forms.params.iter().map(|p| bench.assemble_params.get(&*p.name).copied().unwrap_or(p.default)).collect();
    let mesh = structured::rectangle(n, n, [0.0, 1.0], [0.0, 1.0], Diagonal::Right, 2);
    let asm = Assembler::new(&mesh);
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let u: Vec<f64> = (0..asm.size())
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            0.01 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) / n as f64
        })
        .collect();
    let coefs = |name: &str| (name == "f").then(|| Coef::constant(vec![0.0, 0.0]));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a thread pool");
    let mut out = Vec::new();
    for &degree in &bench.assemble_degrees {
        let binding = Binding::new(Quadrature { cell: Some(degree), facet: None }, Vec::new(), 2);
        // Made in the one-thread pool: a bound form is not shared between threads.
        let timed = pool.install(|| {
            let made = (forms.make)(&values, &coefs, &binding).map_err(|e| e.to_string())?;
            let form = made
                .into_iter()
                .find_map(|(slot, f)| match f {
                    SlotForm::Form(f) if slot == "stiffness" => Some(f),
                    _ => None,
                })
                .ok_or("provides no `stiffness`")?;
            let mut r = vec![0.0; asm.size()];
            let mut m = asm.zero_matrix();
            let (mut tr, mut tt) = (Vec::new(), Vec::new());
            for _ in 0..repeats {
                r.fill(0.0);
                let t = Instant::now();
                form.residual(&asm, &[&u], 0.0, &mut r);
                tr.push(t.elapsed().as_secs_f64());
                m.values.fill(0.0);
                let t = Instant::now();
                form.tangent(&asm, &[&u], 0, 0.0, &mut m);
                tt.push(t.elapsed().as_secs_f64());
            }
            Ok::<_, String>((median(tr), median(tt), m.frobenius()))
        });
        let (residual, tangent, frobenius) = match timed {
            Ok(t) => t,
            Err(e) => {
                progress(&format!("bench assemble: `{name}`: {e}"));
                return out;
            }
        };
        let cells = mesh.num_cells();
        let t = MaterialTiming {
            material: name.clone(),
            n,
            cells,
            degree,
            residual_us_per_cell: residual * 1e6 / cells as f64,
            tangent_us_per_cell: tangent * 1e6 / cells as f64,
            tangent_frobenius: frobenius,
        };
        progress(&format!(
            "N = {n}: {name} stiffness at degree {degree}, one thread: residual {:.3} µs/cell, tangent {:.3} µs/cell; ‖K_T‖_F = {:.6}",
            t.residual_us_per_cell, t.tangent_us_per_cell, t.tangent_frobenius
        ));
        out.push(t);
    }
    out
}
