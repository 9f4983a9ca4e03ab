//! Square sparse matrices in compressed-column form over a shared [`Pattern`], and the errors
//! of linear algebra.

use std::sync::Arc;

use crate::linalg::pattern::Pattern;

/// The relative asymmetry |a_ij − a_ji| ≤ tol·max|a| below which a matrix is taken as
/// symmetric: factored by Cholesky, multiplied from its lower half.
pub const SYMMETRY_TOLERANCE: f64 = 1e-12;

/// Stored entries from which a matrix–vector product is split over threads.
const PARALLEL_NNZ: usize = 1 << 20;

/// A square sparse matrix in compressed-column form over a shared pattern.
#[derive(Clone, Debug)]
pub struct Matrix {
    pub pattern: Arc<Pattern>,
    pub values: Vec<f64>,
}

impl Matrix {
    pub fn zeros(pattern: Arc<Pattern>) -> Self {
        let values = vec![0.0; pattern.nnz()];
        Matrix { pattern, values }
    }

    pub fn size(&self) -> usize {
        self.pattern.size()
    }

    /// `y = A x` (whole in a split run: collective there, as every product).
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let p = &self.pattern;
        for (j, &xj) in x.iter().enumerate() {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                y[p.row_idx[k]] += self.values[k] * xj;
            }
        }
        p.complete(y);
    }

    /// xᵀ A y, as (Aᵀ x)ᵀ y: the column-gathering product reads half the bytes.
    pub fn quad(&self, x: &[f64], y: &[f64]) -> f64 {
        let mut atx = vec![0.0; x.len()];
        self.mul_vec_transposed(x, &mut atx);
        atx.iter().zip(y).map(|(p, q)| p * q).sum()
    }

    /// `y = Aᵀ x`, which is `A x` for a symmetric matrix: each entry of y is one column's dot
    /// product with x, read in node blocks (one index per d×d block), on rayon's threads in
    /// fixed chunks (the same bits for any number of threads).
    pub fn mul_vec_transposed(&self, x: &[f64], y: &mut [f64]) {
        match self.pattern.dim() {
            1 => self.gather::<1>(x, y),
            2 => self.gather::<2>(x, y),
            _ => self.gather::<3>(x, y),
        }
        // An owned node's columns are whole, as its rows are.
        self.pattern.complete(y);
    }

    fn gather<const D: usize>(&self, x: &[f64], y: &mut [f64]) {
        use rayon::prelude::*;
        const NODES_PER_TASK: usize = 512;
        let p = &self.pattern;
        let values = &self.values;
        let task = |t: usize, ys: &mut [f64]| {
            for (jj, yj) in ys.chunks_exact_mut(D).enumerate() {
                let j = t * NODES_PER_TASK + jj;
                let neighbours = p.neighbours(j);
                let columns: [&[f64]; D] =
                    std::array::from_fn(|m| &values[p.col_ptr[j * D + m]..p.col_ptr[j * D + m + 1]]);
                // D² independent sums (one per block entry) instead of one chain of dependent
                // additions per column: 1.4 times faster on P2 plane strain (benches/linalg.rs).
                let mut acc = [[0.0f64; D]; D];
                for (n, &i) in neighbours.iter().enumerate() {
                    let xi = &x[i as usize * D..][..D];
                    for m in 0..D {
                        let a = &columns[m][n * D..][..D];
                        for k in 0..D {
                            acc[m][k] += a[k] * xi[k];
                        }
                    }
                }
                for (ym, row) in yj.iter_mut().zip(&acc) {
                    *ym = row.iter().sum();
                }
            }
        };
        // Threads pay off only on large matrices; each entry is one task's sum either way.
        if values.len() < PARALLEL_NNZ || rayon::current_num_threads() == 1 {
            y.chunks_mut(NODES_PER_TASK * D).enumerate().for_each(|(t, ys)| task(t, ys));
        } else {
            y.par_chunks_mut(NODES_PER_TASK * D).enumerate().for_each(|(t, ys)| task(t, ys));
        }
    }

    /// `self += alpha * other` (same pattern).
    pub fn add_scaled(&mut self, alpha: f64, other: &Matrix) {
        debug_assert!(Arc::ptr_eq(&self.pattern, &other.pattern) || self.pattern.nnz() == other.pattern.nnz());
        for (a, b) in self.values.iter_mut().zip(&other.values) {
            *a += alpha * b;
        }
    }

    /// Entry (i, j), zero outside the pattern.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let p = &self.pattern;
        let rows = &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]];
        rows.binary_search(&i).map_or(0.0, |k| self.values[p.col_ptr[j] + k])
    }

    /// ‖A‖∞, the largest row sum of |a_ij|.
    pub fn norm_inf(&self) -> f64 {
        let mut rows = vec![0.0f64; self.size()];
        for (&i, v) in self.pattern.row_idx.iter().zip(&self.values) {
            rows[i] += v.abs();
        }
        rows.into_iter().fold(0.0, f64::max)
    }

    /// [`Matrix::is_symmetric`] on every process of a split run (collective there): each
    /// holds a part of the matrix.
    pub fn is_symmetric_everywhere(&self, tol: f64) -> bool {
        let here = self.is_symmetric(tol);
        match self.pattern.ownership() {
            Some(o) => !o.any(!here),
            None => here,
        }
    }

    /// Whether |a_ij − a_ji| ≤ tol·max|a| for every stored entry (one pass, through the
    /// pattern's transposed positions).
    pub fn is_symmetric(&self, tol: f64) -> bool {
        let scale = self.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let t = self.pattern.transposed();
        self.values.iter().zip(t).all(|(a, &k)| (a - self.values[k]).abs() <= tol * scale)
    }

    /// A with each pair a_ij, a_ji that differ by more than tol·max|a| replaced by their
    /// mean: the symmetric part of A where A is not symmetric to the tolerance
    /// [`Matrix::is_symmetric`] takes, and A itself bit for bit elsewhere (a Cholesky
    /// factorization reads one triangle of it).
    pub fn symmetrized(&self, tol: f64) -> Matrix {
        let scale = self.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let t = self.pattern.transposed();
        let values = (self.values.iter().zip(t))
            .map(|(&a, &k)| {
                let b = self.values[k];
                if (a - b).abs() > tol * scale { 0.5 * (a + b) } else { a }
            })
            .collect();
        Matrix { pattern: self.pattern.clone(), values }
    }

    /// Frobenius norm.
    pub fn frobenius(&self) -> f64 {
        self.values.iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// Imposes `x_i = given` on the listed dofs: zeroes their rows and columns and puts `diag`
    /// on the diagonal, keeping the matrix symmetric (the right-hand side is the caller's).
    /// Touches only the listed dofs' columns and rows (the pattern is symmetric).
    pub fn constrain(&mut self, dofs: &[usize], diag: f64) {
        let p = self.pattern.clone();
        for &i in dofs {
            for k in p.col_ptr[i]..p.col_ptr[i + 1] {
                let j = p.row_idx[k];
                self.values[k] = if i == j { diag } else { 0.0 };
                if i != j {
                    let rows = &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]];
                    let at = rows.binary_search(&i).expect("symmetric pattern");
                    self.values[p.col_ptr[j] + at] = 0.0;
                }
            }
        }
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinalgError {
    #[error("the matrix is not positive definite (pivot {index} is not positive)")]
    NotPositiveDefinite { index: usize },
    #[error("the matrix is singular{}", index.map(|i| format!(" (no pivot at column {i})")).unwrap_or_default())]
    Singular { index: Option<usize> },
    #[error("the linear solver failed: {0}")]
    Other(String),
    #[error("PETSc's {function} failed (error {code}): {message}")]
    Petsc { function: &'static str, code: i32, message: String },
    #[error("solve requested before a successful factorization")]
    NotFactored,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::structured::interval;

    #[test]
    fn symmetrized_averages_only_the_pairs_that_differ_and_is_symmetric_sees_them() {
        let mesh = interval(4, 0.0, 1.0);
        let pattern = Arc::new(Pattern::new(&mesh.connectivity()));
        let mut a = Matrix::zeros(pattern.clone());
        let t = pattern.transposed();
        for (k, v) in a.values.iter_mut().enumerate() {
            *v = 1.0 + (k.min(t[k]) as f64).sqrt();
        }
        assert!(t.iter().enumerate().all(|(k, &kt)| t[kt] == k), "an involution");
        // One pair made nonsymmetric, one by less than the tolerance.
        let off = (0..t.len()).filter(|&k| t[k] != k).collect::<Vec<_>>();
        a.values[off[0]] += 0.5;
        a.values[off[2]] += 1e-15;
        let s = a.symmetrized(1e-12);
        assert!(!a.is_symmetric(1e-12) && s.is_symmetric(1e-12) && !s.is_symmetric(1e-16));
        for k in 0..t.len() {
            let expected = if k == off[0] || k == t[off[0]] {
                0.5 * (a.values[off[0]] + a.values[t[off[0]]])
            } else {
                a.values[k]
            };
            assert_eq!(s.values[k].to_bits(), expected.to_bits(), "entry {k}");
        }
    }
}
