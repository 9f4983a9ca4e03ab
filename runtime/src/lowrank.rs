//! Solves with a matrix that differs from a factored reference on a few dofs, without
//! refactoring (the Woodbury identity): J = J₀ + U E Uᵀ, with U the identity's columns at the
//! dofs D where J − J₀ has entries and E = (J − J₀)[D, D] dense. With Z = J₀⁻¹ U and
//! G = Uᵀ Z,
//!
//!   x₀ = J₀⁻¹ b,  (I + G E) y = x₀[D],  x = x₀ − Z E y,
//!
//! so J x = b + U E (x₀[D] − (I + G E) y) = b. A contact tangent changes only on the cells of
//! facets whose active set changed, so D stays small while the reference is the operator at
//! an active set near the current one. The columns of Z are kept per dof until the reference
//! changes: a dof that switches again costs nothing.

use crate::linalg::{Factorization, LinalgError, Matrix};

/// The correction of a factored reference J₀ towards the current matrix.
pub struct LowRank {
    /// J₀'s entries.
    reference: Vec<f64>,
    /// Z's column of each dof computed so far (J₀⁻¹ e_d).
    columns: Vec<Option<Box<[f64]>>>,
    /// The current correction: D, E (row-major), and the LU factors of I + G E.
    dofs: Vec<usize>,
    e: Vec<f64>,
    lu: DenseLu,
}

impl LowRank {
    /// A correction of nothing, for the factored `reference`.
    pub fn new(reference: &Matrix) -> LowRank {
        LowRank {
            reference: reference.values.clone(),
            columns: vec![None; reference.size()],
            dofs: Vec::new(),
            e: Vec::new(),
            lu: DenseLu::default(),
        }
    }

    /// Columns computed so far.
    pub fn cached(&self) -> usize {
        self.columns.iter().filter(|c| c.is_some()).count()
    }

    /// How many of `dofs` have no column yet.
    pub fn missing(&self, dofs: &[usize]) -> usize {
        dofs.iter().filter(|&&d| self.columns[d].is_none()).count()
    }

    /// Size of the current correction.
    pub fn rank(&self) -> usize {
        self.dofs.len()
    }

    /// The dofs on which `j` differs from the reference (rows and columns), sorted.
    pub fn changed_dofs(&self, j: &Matrix) -> Vec<usize> {
        let p = &j.pattern;
        let mut changed = vec![false; j.size()];
        for col in 0..j.size() {
            for k in p.col_ptr[col]..p.col_ptr[col + 1] {
                if j.values[k] != self.reference[k] {
                    changed[col] = true;
                    changed[p.row_idx[k]] = true;
                }
            }
        }
        (0..j.size()).filter(|&i| changed[i]).collect()
    }

    /// Makes the correction the one from the reference to `j`, whose differing dofs are `dofs`
    /// (from [`LowRank::changed_dofs`]); `reference` is J₀'s factorization.
    pub fn update(&mut self, j: &Matrix, dofs: Vec<usize>, reference: &mut Factorization) -> Result<(), LinalgError> {
        let n = j.size();
        let missing: Vec<usize> = dofs.iter().copied().filter(|&d| self.columns[d].is_none()).collect();
        if !missing.is_empty() {
            let mut block = vec![0.0; n * missing.len()];
            for (c, &d) in missing.iter().enumerate() {
                block[c * n + d] = 1.0;
            }
            reference.solve_many_in_place(&mut block, missing.len())?;
            for (c, &d) in missing.iter().enumerate() {
                self.columns[d] = Some(block[c * n..(c + 1) * n].into());
            }
        }
        let k = dofs.len();
        let mut position = vec![usize::MAX; n];
        dofs.iter().enumerate().for_each(|(a, &d)| position[d] = a);
        let mut e = vec![0.0; k * k];
        let p = &j.pattern;
        for (b, &col) in dofs.iter().enumerate() {
            for idx in p.col_ptr[col]..p.col_ptr[col + 1] {
                let a = position[p.row_idx[idx]];
                if a != usize::MAX {
                    e[a * k + b] = j.values[idx] - self.reference[idx];
                }
            }
        }
        // I + G E, G[a][c] = Z[dofs[a]][c] = (J₀⁻¹ e_{dofs[c]})[dofs[a]].
        let mut m = vec![0.0; k * k];
        for a in 0..k {
            for c in 0..k {
                let g = self.columns[dofs[c]].as_ref().expect("computed above")[dofs[a]];
                if g != 0.0 {
                    for b in 0..k {
                        m[a * k + b] += g * e[c * k + b];
                    }
                }
            }
            m[a * k + a] += 1.0;
        }
        self.lu = DenseLu::new(m, k).ok_or(LinalgError::Singular { index: None })?;
        self.dofs = dofs;
        self.e = e;
        Ok(())
    }

    /// Turns x₀ = J₀⁻¹ b (in place) into J⁻¹ b.
    pub fn correct(&self, x: &mut [f64]) {
        let k = self.dofs.len();
        if k == 0 {
            return;
        }
        let mut y: Vec<f64> = self.dofs.iter().map(|&d| x[d]).collect();
        self.lu.solve(&mut y);
        // x −= Z (E y).
        for (c, &d) in self.dofs.iter().enumerate() {
            let ey: f64 = (0..k).map(|b| self.e[c * k + b] * y[b]).sum();
            if ey != 0.0 {
                let z = self.columns[d].as_ref().expect("computed in update");
                x.iter_mut().zip(z.iter()).for_each(|(xi, zi)| *xi -= ey * zi);
            }
        }
    }
}

/// A small dense LU with partial pivoting (row-major).
#[derive(Default)]
struct DenseLu {
    lu: Vec<f64>,
    pivots: Vec<usize>,
    k: usize,
}

impl DenseLu {
    /// None if a pivot vanishes.
    fn new(mut a: Vec<f64>, k: usize) -> Option<DenseLu> {
        let mut pivots = Vec::with_capacity(k);
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for c in 0..k {
            let p = (c..k).max_by(|&i, &j| a[i * k + c].abs().total_cmp(&a[j * k + c].abs()))?;
            let pivot = a[p * k + c];
            if pivot.is_nan() || pivot.abs() <= 1e-14 * scale {
                return None;
            }
            pivots.push(p);
            if p != c {
                for x in 0..k {
                    a.swap(c * k + x, p * k + x);
                }
            }
            for r in c + 1..k {
                let f = a[r * k + c] / pivot;
                a[r * k + c] = f;
                if f != 0.0 {
                    for x in c + 1..k {
                        a[r * k + x] -= f * a[c * k + x];
                    }
                }
            }
        }
        Some(DenseLu { lu: a, pivots, k })
    }

    fn solve(&self, y: &mut [f64]) {
        let (a, k) = (&self.lu, self.k);
        for (c, &p) in self.pivots.iter().enumerate() {
            y.swap(c, p);
        }
        for r in 0..k {
            let s: f64 = (0..r).map(|x| a[r * k + x] * y[x]).sum();
            y[r] -= s;
        }
        for r in (0..k).rev() {
            let s: f64 = (r + 1..k).map(|x| a[r * k + x] * y[x]).sum();
            y[r] = (y[r] - s) / a[r * k + r];
        }
    }
}
