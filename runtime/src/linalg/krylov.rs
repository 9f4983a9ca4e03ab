//! Block-Jacobi-preconditioned Krylov solvers for the step matrices of large problems:
//! conjugate gradients for symmetric positive definite matrices, BiCGStab otherwise. A time
//! step's matrix is c·M + K + J_C with c = O(1/Δt²), mass-dominated on fine meshes, so the
//! inverse of each node's d×d diagonal block keeps the iteration count small and the memory
//! is that of the matrix.
//!
//! The work is memory-bound: the matrix–vector product (`Matrix::mul_vec_transposed`) reads
//! the values once and one index per d×d node block, and it, the vector updates and the dot
//! products are split over rayon's threads in fixed chunks whose partial sums are added in
//! order, so the iterates have the same bits for any number of threads.

use rayon::prelude::*;

use crate::linalg::matrix::{LinalgError, Matrix};

/// Relative residual ‖b − A x‖₂ ≤ TOLERANCE ‖b‖₂ at which a solve stops unless asked for
/// another (Newton asks each of its solves for what its iteration needs).
pub const TOLERANCE: f64 = 1e-12;

/// Entries per task of the vector operations (a fixed size: the reductions' bits depend on it).
const CHUNK: usize = 1 << 13;

/// The matrix and its inverted diagonal blocks.
pub struct Krylov {
    pub matrix: Matrix,
    /// Per node, the inverse of its d×d diagonal block, row-major.
    inv_blocks: Vec<f64>,
    symmetric: bool,
    /// Iterations of the last solve (`Factorization` counts them all).
    pub iterations: usize,
    /// The last solve's best residual and the iteration it was reached at (the stall test).
    best: (f64, usize),
    /// The current solve's relative tolerance.
    tolerance: f64,
}

/// Iterations without halving the best residual after which a solve has stalled: conjugate
/// gradients on the library's problems halve it every few tens (the 3D ball at 986k unknowns
/// converges to 1e-12 in 200 in all).
const STALL: usize = 250;

fn dot(a: &[f64], b: &[f64]) -> f64 {
    let partial: Vec<f64> =
        a.par_chunks(CHUNK).zip(b.par_chunks(CHUNK)).map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum()).collect();
    partial.iter().sum()
}

/// `y[i] = f(y[i], x[i])` over chunks in parallel.
fn update(y: &mut [f64], x: &[f64], f: impl Fn(f64, f64) -> f64 + Sync) {
    y.par_chunks_mut(CHUNK)
        .zip(x.par_chunks(CHUNK))
        .for_each(|(ys, xs)| ys.iter_mut().zip(xs).for_each(|(a, b)| *a = f(*a, *b)));
}

/// Inverts the d×d row-major block `a` in place (Gauss–Jordan with partial pivoting); false if
/// it is singular.
fn invert_block(a: &mut [f64], d: usize) -> bool {
    let mut inv = vec![0.0; d * d];
    (0..d).for_each(|i| inv[i * d + i] = 1.0);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for c in 0..d {
        let p = (c..d).max_by(|&i, &j| a[i * d + c].abs().total_cmp(&a[j * d + c].abs())).unwrap_or(c);
        let pivot = a[p * d + c].abs();
        if pivot.is_nan() || pivot <= 1e-300 + 1e-15 * scale {
            return false;
        }
        for k in 0..d {
            a.swap(c * d + k, p * d + k);
            inv.swap(c * d + k, p * d + k);
        }
        let piv = a[c * d + c];
        for k in 0..d {
            a[c * d + k] /= piv;
            inv[c * d + k] /= piv;
        }
        for r in (0..d).filter(|&r| r != c) {
            let f = a[r * d + c];
            for k in 0..d {
                a[r * d + k] -= f * a[c * d + k];
                inv[r * d + k] -= f * inv[c * d + k];
            }
        }
    }
    a.copy_from_slice(&inv);
    true
}

impl Krylov {
    pub fn new(matrix: Matrix, symmetric: bool) -> Result<Krylov, LinalgError> {
        let n = matrix.size();
        let p = matrix.pattern.clone();
        let d = p.dim();
        for i in 0..n {
            let a = matrix.get(i, i);
            if !a.is_finite() || a == 0.0 {
                return Err(LinalgError::Singular { index: Some(i) });
            }
            if symmetric && a < 0.0 {
                return Err(LinalgError::NotPositiveDefinite { index: i });
            }
        }
        let mut inv_blocks = vec![0.0; n * d];
        for (j, block) in inv_blocks.chunks_exact_mut(d * d).enumerate() {
            let pos = p.neighbours(j).binary_search(&(j as u32)).expect("a node is its own neighbour");
            for m in 0..d {
                let column = &matrix.values[p.col_ptr[j * d + m] + pos * d..][..d];
                column.iter().enumerate().for_each(|(k, v)| block[k * d + m] = *v);
            }
            if !invert_block(block, d) {
                return Err(LinalgError::Singular { index: Some(j * d) });
            }
        }
        Ok(Krylov { matrix, inv_blocks, symmetric, iterations: 0, best: (f64::INFINITY, 0), tolerance: TOLERANCE })
    }

    /// `y = A x`: for a symmetric matrix as `Aᵀ x` (threaded), otherwise the sequential column
    /// scatter.
    fn mul(&self, x: &[f64], y: &mut [f64]) {
        if self.symmetric { self.matrix.mul_vec_transposed(x, y) } else { self.matrix.mul_vec(x, y) }
    }

    /// Whether `method` has converged with residual `r`; an error once it never will: past the
    /// iteration limit, or stalled ([`STALL`] iterations without halving its best residual).
    fn converged(&mut self, method: &str, r: &[f64], norm_b: f64) -> Result<bool, LinalgError> {
        let res = dot(r, r).sqrt();
        if !res.is_finite() {
            return Err(LinalgError::Other(format!("{method} produced non-finite values")));
        }
        if res <= self.tolerance * norm_b {
            return Ok(true);
        }
        if self.iterations == 0 || res <= 0.5 * self.best.0 {
            self.best = (res, self.iterations);
        } else if self.iterations - self.best.1 >= STALL {
            return Err(LinalgError::Other(format!(
                "{method} stalled: its relative residual {:.1e} has not halved in {STALL} iterations (after {} in all; the tolerance is {:.0e}); the matrix is likely singular or indefinite, or too ill-conditioned for the block-Jacobi preconditioner: try --solver direct",
                res / norm_b,
                self.iterations,
                self.tolerance
            )));
        }
        let limit = 1000 + 20 * (r.len() as f64).sqrt() as usize;
        if self.iterations >= limit {
            return Err(LinalgError::Other(format!(
                "{method} did not converge in {} iterations (relative residual {:.1e})",
                self.iterations,
                res / norm_b
            )));
        }
        Ok(false)
    }

    /// out = D⁻¹ v, D the block diagonal.
    fn precondition(&self, v: &[f64], out: &mut [f64]) {
        let d = self.matrix.pattern.dim();
        let per_task = CHUNK / d * d;
        out.par_chunks_mut(per_task)
            .zip(v.par_chunks(per_task))
            .zip(self.inv_blocks.par_chunks(per_task * d))
            .for_each(|((os, vs), bs)| {
                for ((o, a), b) in os.chunks_exact_mut(d).zip(vs.chunks_exact(d)).zip(bs.chunks_exact(d * d)) {
                    for (k, ok) in o.iter_mut().enumerate() {
                        *ok = (0..d).map(|m| b[k * d + m] * a[m]).sum();
                    }
                }
            });
    }

    /// Solves A x = b in place to ‖b − A x‖₂ ≤ `rtol`·‖b‖₂, from x = 0: Newton's corrections
    /// shrink from one solve to the next, and the last one was the worse first guess (10 % more
    /// iterations on the 47k-unknown ball through impact).
    pub fn solve_in_place(&mut self, b: &mut [f64], rtol: f64) -> Result<(), LinalgError> {
        self.tolerance = rtol;
        let norm_b = dot(b, b).sqrt();
        if norm_b == 0.0 {
            b.iter_mut().for_each(|x| *x = 0.0);
            return Ok(());
        }
        let mut x = vec![0.0; b.len()];
        if self.symmetric { self.cg(b, &mut x, norm_b) } else { self.bicgstab(b, &mut x, norm_b) }?;
        b.copy_from_slice(&x);
        Ok(())
    }

    fn cg(&mut self, b: &[f64], x: &mut [f64], norm_b: f64) -> Result<(), LinalgError> {
        let n = b.len();
        // x = 0: the residual is b.
        let mut r = b.to_vec();
        let mut z = vec![0.0; n];
        self.precondition(&r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![0.0; n];
        self.iterations = 0;
        while !self.converged("conjugate gradients", &r, norm_b)? {
            self.mul(&p, &mut ap);
            let pap = dot(&p, &ap);
            if pap <= 0.0 || !pap.is_finite() {
                return Err(LinalgError::NotPositiveDefinite { index: 0 });
            }
            let alpha = rz / pap;
            update(x, &p, |xi, pi| xi + alpha * pi);
            update(&mut r, &ap, |ri, api| ri - alpha * api);
            self.precondition(&r, &mut z);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            update(&mut p, &z, |pi, zi| zi + beta * pi);
            self.iterations += 1;
        }
        Ok(())
    }

    fn bicgstab(&mut self, b: &[f64], x: &mut [f64], norm_b: f64) -> Result<(), LinalgError> {
        let n = b.len();
        let mut r = b.to_vec();
        let r0 = r.clone();
        let (mut rho, mut alpha, mut omega) = (1.0, 1.0, 1.0);
        let [mut v, mut p, mut t, mut y, mut s, mut zs] = std::array::from_fn(|_| vec![0.0; n]);
        self.iterations = 0;
        while !self.converged("BiCGStab", &r, norm_b)? {
            let rho_new = dot(&r0, &r);
            if rho_new == 0.0 || omega == 0.0 || !rho_new.is_finite() {
                return Err(LinalgError::Other("BiCGStab broke down".into()));
            }
            let beta = (rho_new / rho) * (alpha / omega);
            rho = rho_new;
            p.iter_mut().zip(r.iter().zip(&v)).for_each(|(pi, (ri, vi))| *pi = ri + beta * (*pi - omega * vi));
            self.precondition(&p, &mut y);
            self.mul(&y, &mut v);
            alpha = rho / dot(&r0, &v);
            s.iter_mut().zip(r.iter().zip(&v)).for_each(|(si, (ri, vi))| *si = ri - alpha * vi);
            self.precondition(&s, &mut zs);
            self.mul(&zs, &mut t);
            let tt = dot(&t, &t);
            omega = if tt > 0.0 { dot(&t, &s) / tt } else { 0.0 };
            x.iter_mut().zip(y.iter().zip(&zs)).for_each(|(xi, (yi, zi))| *xi += alpha * yi + omega * zi);
            r.iter_mut().zip(s.iter().zip(&t)).for_each(|(ri, (si, ti))| *ri = si - omega * ti);
            self.iterations += 1;
        }
        Ok(())
    }
}
