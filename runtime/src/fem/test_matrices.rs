//! Matrices with known properties on a mesh's pattern, for tests and benchmarks.

use crate::fem::assembly::Assembler;
use crate::linalg::Matrix;

/// A symmetric, strictly diagonally dominant (so positive definite) matrix on the mesh's
/// pattern, whose off-diagonal values differ entry by entry.
pub fn diagonally_dominant(asm: &Assembler) -> Matrix {
    let mut a = asm.zero_matrix();
    let p = a.pattern.clone();
    for j in 0..a.size() {
        let mut off = 0.0;
        for k in p.col_ptr[j]..p.col_ptr[j + 1] {
            let i = p.row_idx[k];
            if i != j {
                let (lo, hi) = (i.min(j), i.max(j));
                a.values[k] = -1.0 / (1.0 + ((lo * 7 + hi * 13) % 17) as f64);
                off += a.values[k].abs();
            }
        }
        let diag = p.col_ptr[j] + p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]].binary_search(&j).expect("a diagonal");
        a.values[diag] = 1.0 + 2.0 * off;
    }
    a
}
