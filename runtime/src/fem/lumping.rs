//! Lumped (diagonal) mass matrices for explicit dynamics: the row sums for P1 elements, and
//! the diagonal scaled to the element's mass (Hinton–Rock–Zienkiewicz) for P2, whose vertex
//! rows sum to zero or less (no node may be massless or of negative mass). Both keep each
//! component's total mass, eᵀ M_L e = eᵀ M e for the unit field e along an axis.

use crate::linalg::Matrix;

/// The lumped form of the consistent mass `mass` of a `dim`-vector field of `degree`, on the
/// same pattern (its off-diagonal entries zero).
pub fn lumped(mass: &Matrix, degree: u32, dim: usize) -> Matrix {
    let n = mass.size();
    let p = &mass.pattern;
    let mut row_sums = vec![0.0; n];
    let mut diagonal = vec![0.0; n];
    for j in 0..n {
        for k in p.col_ptr[j]..p.col_ptr[j + 1] {
            let i = p.row_idx[k];
            row_sums[i] += mass.values[k];
            if i == j {
                diagonal[i] = mass.values[k];
            }
        }
    }
    let lumped: Vec<f64> = if degree <= 1 {
        row_sums
    } else {
        // Per component: the diagonal scaled so that its sum is the component's total mass.
        let mut scale = vec![0.0; dim];
        for c in 0..dim {
            let total: f64 = row_sums.iter().skip(c).step_by(dim).sum();
            let diag: f64 = diagonal.iter().skip(c).step_by(dim).sum();
            scale[c] = total / diag;
        }
        diagonal.iter().enumerate().map(|(i, m)| m * scale[i % dim]).collect()
    };
    let mut out = Matrix::zeros(p.clone());
    for (j, m) in lumped.into_iter().enumerate() {
        let rows = &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]];
        if let Ok(k) = rows.binary_search(&j) {
            out.values[p.col_ptr[j] + k] = m;
        }
    }
    out
}
