//! Mass redistribution (docs/mathematics.md §4; Khenous–Laborde–Renard): remove the inertia of the contact
//! nodes while keeping the total mass, the centre of gravity and the second moments.
//!
//! On the scalar consistent mass M: D⁰ cancels every entry in a contact row or column; the
//! correction δ, symmetric and supported on the structural nonzeros F between non-contact
//! nodes, is the one of least Frobenius norm with qᵣᵀ(D⁰ + δ)qₛ = 0 for the moment vectors
//! q₀ = 1, q_k = x_k (r ≤ s): δᵢⱼ = Σ Λᵣₛ ½(qᵣ(i)qₛ(j) + qₛ(i)qᵣ(j)), Λ from the small Gram
//! system A W⁻¹ Aᵀ Λ = b, W weighting each off-diagonal unknown by 2. The result must be
//! positive definite on the non-contact dofs (checked by Cholesky).

use crate::fem::mesh::Mesh;
use crate::linalg::{Factorization, LinalgError, Matrix, Structure};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RedistributionError {
    #[error("the moment constraints are degenerate (singular Gram system)")]
    Degenerate,
    #[error("the redistributed mass is not positive definite on the non-contact dofs: {0}")]
    NotPositiveDefinite(LinalgError),
}

/// The redistributed vector mass matrix (same pattern as `mass`), and the largest relative
/// change of a moment qᵣᵀ M qₛ (round-off).
pub struct Redistributed {
    pub matrix: Matrix,
    pub moment_error: f64,
}

/// Redistributes the vector mass `mass` (node-major dofs, components decoupled) of `mesh` away
/// from `contact_nodes`.
pub fn redistribute(mesh: &Mesh, mass: &Matrix, contact_nodes: &[u32]) -> Result<Redistributed, RedistributionError> {
    let d = mesh.dim();
    let nodes = mesh.num_nodes();
    let p = mass.pattern.clone();
    let mut is_contact = vec![false; nodes];
    for &c in contact_nodes {
        is_contact[c as usize] = true;
    }
    // Scalar entries: component 0 of each node pair, as (i, j, value position) with i ≤ j.
    let mut entries: Vec<(usize, usize, f64)> = Vec::new();
    for j in 0..nodes {
        let col = j * d;
        for k in p.col_ptr[col]..p.col_ptr[col + 1] {
            let row = p.row_idx[k];
            if row.is_multiple_of(d) && row / d <= j {
                entries.push((row / d, j, mass.values[k]));
            }
        }
    }
    // Moment vectors q_0 = 1, q_k = x_k, and the index pairs r ≤ s.
    let q: Vec<Vec<f64>> =
        (0..=d).map(|r| (0..nodes).map(|i| if r == 0 { 1.0 } else { mesh.node(i)[r - 1] }).collect()).collect();
    let pairs: Vec<(usize, usize)> = (0..=d).flat_map(|r| (r..=d).map(move |s| (r, s))).collect();
    let m = pairs.len();
    // b_rs = −qᵣᵀ D⁰ qₛ, with D⁰ = −M on contact rows and columns.
    let mut b = vec![0.0; m];
    for &(i, j, v) in &entries {
        if is_contact[i] || is_contact[j] {
            for (c, &(r, s)) in pairs.iter().enumerate() {
                let sym = if i == j { q[r][i] * q[s][i] } else { q[r][i] * q[s][j] + q[r][j] * q[s][i] };
                b[c] += v * sym; // −(−v)
            }
        }
    }
    // Gram matrix over the free pairs: Σ a_c a_c' / w.
    let mut gram = vec![vec![0.0; m]; m];
    let coef = |i: usize, j: usize, r: usize, s: usize| {
        if i == j { q[r][i] * q[s][i] } else { q[r][i] * q[s][j] + q[r][j] * q[s][i] }
    };
    for &(i, j, _) in &entries {
        if is_contact[i] || is_contact[j] {
            continue;
        }
        let w = if i == j { 1.0 } else { 2.0 };
        let a: Vec<f64> = pairs.iter().map(|&(r, s)| coef(i, j, r, s)).collect();
        for c in 0..m {
            for c2 in 0..m {
                gram[c][c2] += a[c] * a[c2] / w;
            }
        }
    }
    let lambda = solve_dense(gram, b).ok_or(RedistributionError::Degenerate)?;
    // M_mod = M + D⁰ + δ, written into a copy of the vector matrix.
    let mut out = mass.clone();
    for j in 0..nodes {
        for comp in 0..d {
            let col = j * d + comp;
            for k in p.col_ptr[col]..p.col_ptr[col + 1] {
                let row = p.row_idx[k];
                let i = row / d;
                if row % d != comp {
                    continue;
                }
                out.values[k] = if is_contact[i] || is_contact[j] {
                    0.0
                } else {
                    let delta: f64 = pairs
                        .iter()
                        .zip(&lambda)
                        .map(|(&(r, s), l)| l * 0.5 * (q[r][i] * q[s][j] + q[s][i] * q[r][j]))
                        .sum();
                    mass.values[k] + delta
                };
            }
        }
    }
    // Moments before and after (component 0).
    let moment = |mat: &Matrix, r: usize, s: usize| -> f64 {
        let mut total = 0.0;
        for j in 0..nodes {
            let col = j * d;
            for k in p.col_ptr[col]..p.col_ptr[col + 1] {
                let row = p.row_idx[k];
                if row.is_multiple_of(d) {
                    total += q[r][row / d] * mat.values[k] * q[s][j];
                }
            }
        }
        total
    };
    let moment_error = pairs
        .iter()
        .map(|&(r, s)| {
            let (a, b) = (moment(mass, r, s), moment(&out, r, s));
            (a - b).abs() / a.abs().max(moment(mass, 0, 0))
        })
        .fold(0.0, f64::max);
    // Positive definite on the non-contact dofs: factor with the identity on contact dofs.
    let mut check = out.clone();
    let dofs: Vec<usize> = (0..nodes * d).filter(|&r| is_contact[r / d]).collect();
    check.constrain(&dofs, 1.0);
    Factorization::new(Structure::SymmetricPositiveDefinite)
        .factor(&check)
        .map_err(RedistributionError::NotPositiveDefinite)?;
    Ok(Redistributed { matrix: out, moment_error })
}

/// Gaussian elimination with partial pivoting on a small dense system.
fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for col in 0..n {
        let piv = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        if a[piv][col].abs() <= 1e-14 * scale {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..n {
            let f = a[r][col] / a[col][col];
            for c in col..n {
                a[r][c] -= f * a[col][c];
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}
