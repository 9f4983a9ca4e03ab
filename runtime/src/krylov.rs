//! Jacobi-preconditioned Krylov solvers for the step matrices of large problems: conjugate
//! gradients for symmetric positive definite matrices, BiCGStab otherwise. A time step's
//! matrix is c·M + K + J_C with c = O(1/Δt²), mass-dominated on fine meshes, so the diagonal
//! preconditioner keeps the iteration count small and the memory is that of the matrix.

use crate::linalg::{LinalgError, Matrix};

/// Relative residual ‖b − A x‖₂ ≤ TOLERANCE ‖b‖₂ at which a solve stops.
pub const TOLERANCE: f64 = 1e-12;

/// The matrix, its inverted diagonal, and the last solution (the next solve's first guess).
pub struct Krylov {
    pub matrix: Matrix,
    inv_diag: Vec<f64>,
    symmetric: bool,
    last: Vec<f64>,
    /// Iterations of the last solve (`Factorization` counts them all).
    pub iterations: usize,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Krylov {
    pub fn new(matrix: Matrix, symmetric: bool) -> Result<Krylov, LinalgError> {
        let n = matrix.size();
        let inv_diag = (0..n)
            .map(|i| {
                let d = matrix.get(i, i);
                if d == 0.0 || !d.is_finite() { Err(LinalgError::Singular { index: Some(i) }) } else { Ok(1.0 / d) }
            })
            .collect::<Result<Vec<f64>, _>>()?;
        if symmetric && inv_diag.iter().any(|d| *d < 0.0) {
            let index = inv_diag.iter().position(|d| *d < 0.0).unwrap_or(0);
            return Err(LinalgError::NotPositiveDefinite { index });
        }
        Ok(Krylov { matrix, inv_diag, symmetric, last: vec![0.0; n], iterations: 0 })
    }

    /// Starts from `old`'s last solution (same size).
    pub fn inherit(&mut self, old: &Krylov) {
        if old.last.len() == self.last.len() {
            self.last.copy_from_slice(&old.last);
        }
    }

    /// b − A x.
    fn residual(&self, b: &[f64], x: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; b.len()];
        self.matrix.mul_vec(x, &mut r);
        r.iter_mut().zip(b).for_each(|(ri, bi)| *ri = bi - *ri);
        r
    }

    /// Whether `method` has converged with residual `r`; an error once it never will.
    fn converged(&self, method: &str, r: &[f64], norm_b: f64) -> Result<bool, LinalgError> {
        let res = dot(r, r).sqrt();
        if !res.is_finite() {
            return Err(LinalgError::Other(format!("{method} produced non-finite values")));
        }
        if res <= TOLERANCE * norm_b {
            return Ok(true);
        }
        let limit = 1000 + 20 * (self.inv_diag.len() as f64).sqrt() as usize;
        if self.iterations >= limit {
            return Err(LinalgError::Other(format!(
                "{method} did not converge in {} iterations (relative residual {:.1e})",
                self.iterations,
                res / norm_b
            )));
        }
        Ok(false)
    }

    /// out = D⁻¹ v.
    fn precondition(&self, v: &[f64], out: &mut [f64]) {
        out.iter_mut().zip(v.iter().zip(&self.inv_diag)).for_each(|(o, (a, d))| *o = a * d);
    }

    /// Solves A x = b in place, from the last solution.
    pub fn solve_in_place(&mut self, b: &mut [f64]) -> Result<(), LinalgError> {
        let norm_b = dot(b, b).sqrt();
        if norm_b == 0.0 {
            b.iter_mut().for_each(|x| *x = 0.0);
            return Ok(());
        }
        let mut x = self.last.clone();
        if self.symmetric { self.cg(b, &mut x, norm_b) } else { self.bicgstab(b, &mut x, norm_b) }?;
        self.last.copy_from_slice(&x);
        b.copy_from_slice(&x);
        Ok(())
    }

    fn cg(&mut self, b: &[f64], x: &mut [f64], norm_b: f64) -> Result<(), LinalgError> {
        let n = b.len();
        let mut r = self.residual(b, x);
        let mut z = vec![0.0; n];
        self.precondition(&r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![0.0; n];
        self.iterations = 0;
        while !self.converged("conjugate gradients", &r, norm_b)? {
            self.matrix.mul_vec(&p, &mut ap);
            let pap = dot(&p, &ap);
            if pap <= 0.0 || !pap.is_finite() {
                return Err(LinalgError::NotPositiveDefinite { index: 0 });
            }
            let alpha = rz / pap;
            x.iter_mut().zip(&p).for_each(|(xi, pi)| *xi += alpha * pi);
            r.iter_mut().zip(&ap).for_each(|(ri, api)| *ri -= alpha * api);
            self.precondition(&r, &mut z);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            p.iter_mut().zip(&z).for_each(|(pi, zi)| *pi = zi + beta * *pi);
            self.iterations += 1;
        }
        Ok(())
    }

    fn bicgstab(&mut self, b: &[f64], x: &mut [f64], norm_b: f64) -> Result<(), LinalgError> {
        let n = b.len();
        let mut r = self.residual(b, x);
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
            self.matrix.mul_vec(&y, &mut v);
            alpha = rho / dot(&r0, &v);
            s.iter_mut().zip(r.iter().zip(&v)).for_each(|(si, (ri, vi))| *si = ri - alpha * vi);
            self.precondition(&s, &mut zs);
            self.matrix.mul_vec(&zs, &mut t);
            let tt = dot(&t, &t);
            omega = if tt > 0.0 { dot(&t, &s) / tt } else { 0.0 };
            x.iter_mut().zip(y.iter().zip(&zs)).for_each(|(xi, (yi, zi))| *xi += alpha * yi + omega * zi);
            r.iter_mut().zip(s.iter().zip(&t)).for_each(|(ri, (si, ti))| *ri = si - omega * ti);
            self.iterations += 1;
        }
        Ok(())
    }
}
