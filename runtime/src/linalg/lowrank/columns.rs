//! W's columns as the corrections use them: dense over the union of their nodes, or sparse
//! node by node, with the products a solve's correction is made of.

use faer::Mat;
use faer::linalg::solvers::{PartialPivLu, Solve};

use crate::linalg::block_factor::SparseColumn;

/// Columns of W over a common set of nodes (the union of their supports: the ancestors of the
/// corrected dofs in the elimination tree, which their paths to the root share: for the disc's
/// contact dofs at 12 490 unknowns, 748 nodes for 222 columns of about 430 nodes each). Dense
/// dot products and updates stream where the sparse ones gather node by node.
pub(super) struct DenseColumns {
    pub(super) nodes: Vec<u32>,
    /// m × k, column-major (m = nodes × d).
    pub(super) values: Vec<f64>,
}

/// Dense columns are used while they hold at most this many times the sparse columns' values.
const DENSE_FILL: usize = 3;

/// ... and at most this many bytes.
const DENSE_BYTES: usize = 64 << 20;

impl DenseColumns {
    /// The columns over the union of their nodes (sorted), if that holds at most
    /// [`DENSE_FILL`] times their `entries` and [`DENSE_BYTES`]; stored in `spare`'s memory (the
    /// previous correction's, so an update allocates none).
    pub(super) fn new(
        columns: &[&SparseColumn],
        d: usize,
        nodes: usize,
        entries: usize,
        spare: &mut Vec<f64>,
    ) -> Option<DenseColumns> {
        let mut seen = vec![false; nodes];
        let mut union: Vec<u32> = Vec::new();
        for c in columns {
            for &node in &c.nodes {
                if !seen[node as usize] {
                    seen[node as usize] = true;
                    union.push(node);
                }
            }
        }
        let (m, k) = (union.len() * d, columns.len());
        if m * k > DENSE_FILL.saturating_mul(entries) || 8 * m * k > DENSE_BYTES {
            return None;
        }
        union.sort_unstable();
        let mut values = std::mem::take(spare);
        values.clear();
        values.reserve(m * k);
        for col in columns {
            // Merged with the union (both increasing, the union holding the column's nodes):
            // written once, zeros and values in turn.
            debug_assert!(col.nodes.is_sorted(), "a sparse column's nodes increase");
            let mut pairs = col.nodes.iter().zip(col.values.chunks_exact(d)).peekable();
            for &node in &union {
                match pairs.next_if(|(n, _)| **n == node) {
                    Some((_, v)) => values.extend_from_slice(v),
                    None => values.extend(std::iter::repeat_n(0.0, d)),
                }
            }
        }
        Some(DenseColumns { nodes: union, values })
    }

    /// z ← z − W E M⁻¹ Wᵀ z, with M's LU factors and E (row-major); given `rho`, writes
    /// Wᵀz − y there for the new z and the small system's solution y.
    pub(super) fn correct(
        &self,
        z: &mut [f64],
        d: usize,
        lu: &PartialPivLu<f64>,
        e: &[f64],
        rho: Option<&mut Vec<f64>>,
    ) {
        let m = self.nodes.len() * d;
        let k = self.values.len() / m;
        let mut zu = vec![0.0; m];
        for (i, &node) in self.nodes.iter().enumerate() {
            zu[i * d..][..d].copy_from_slice(&z[node as usize * d..][..d]);
        }
        let mut y = Mat::from_fn(k, 1, |c, _| dot(&self.values[c * m..(c + 1) * m], &zu));
        lu.solve_in_place(y.as_mut());
        let ey: Vec<f64> = (0..k).map(|c| (0..k).map(|x| e[c * k + x] * y[(x, 0)]).sum()).collect();
        // zu ← W (E y), four columns per pass over zu.
        zu.iter_mut().for_each(|v| *v = 0.0);
        let mut c = 0;
        while c + 4 <= k {
            let w: [&[f64]; 4] = std::array::from_fn(|l| &self.values[(c + l) * m..(c + l + 1) * m]);
            let a: [f64; 4] = std::array::from_fn(|l| ey[c + l]);
            for (i, v) in zu.iter_mut().enumerate() {
                *v += (a[0] * w[0][i] + a[1] * w[1][i]) + (a[2] * w[2][i] + a[3] * w[3][i]);
            }
            c += 4;
        }
        for c in c..k {
            let w = &self.values[c * m..(c + 1) * m];
            zu.iter_mut().zip(w).for_each(|(v, x)| *v += ey[c] * x);
        }
        for (i, &node) in self.nodes.iter().enumerate() {
            z[node as usize * d..][..d].iter_mut().zip(&zu[i * d..][..d]).for_each(|(a, b)| *a -= b);
        }
        if let Some(rho) = rho {
            for (i, &node) in self.nodes.iter().enumerate() {
                zu[i * d..][..d].copy_from_slice(&z[node as usize * d..][..d]);
            }
            rho.clear();
            rho.extend((0..k).map(|c| dot(&self.values[c * m..(c + 1) * m], &zu) - y[(c, 0)]));
        }
    }
}

/// z ← z − W E M⁻¹ Wᵀ z, with W's columns node by node; given `rho`, writes Wᵀz − y there
/// (as [`DenseColumns::correct`]).
pub(super) fn correct_sparse(
    cols: &[&SparseColumn],
    d: usize,
    lu: &PartialPivLu<f64>,
    e: &[f64],
    z: &mut [f64],
    rho: Option<&mut Vec<f64>>,
) {
    let k = cols.len();
    let mut y = Mat::from_fn(k, 1, |a, _| gather(cols[a], d, z));
    lu.solve_in_place(y.as_mut());
    for (c, col) in cols.iter().enumerate() {
        let ey: f64 = (0..k).map(|x| e[c * k + x] * y[(x, 0)]).sum();
        if ey != 0.0 {
            axpy(col, d, -ey, z);
        }
    }
    if let Some(rho) = rho {
        rho.clear();
        rho.extend(cols.iter().enumerate().map(|(a, col)| gather(col, d, z) - y[(a, 0)]));
    }
}

/// Σ a·b with eight independent sums.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f64 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += x[l] * y[l];
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// Σ w·x over the column's nodes.
pub(super) fn gather(w: &SparseColumn, d: usize, x: &[f64]) -> f64 {
    match d {
        1 => gather_d::<1>(w, x),
        2 => gather_d::<2>(w, x),
        _ => gather_d::<3>(w, x),
    }
}

/// Four independent sums per block entry (nodes taken four at a time): one dependent chain of
/// additions would hold each load back by the latency of the previous addition.
fn gather_d<const D: usize>(w: &SparseColumn, x: &[f64]) -> f64 {
    let mut acc = [[0.0f64; D]; 4];
    let (nodes, values) = (&w.nodes, &w.values[..w.nodes.len() * D]);
    let quads = nodes.len() / 4;
    for q in 0..quads {
        for (l, a) in acc.iter_mut().enumerate() {
            let node = nodes[4 * q + l] as usize;
            let (v, xs) = (&values[(4 * q + l) * D..][..D], &x[node * D..][..D]);
            for m in 0..D {
                a[m] += v[m] * xs[m];
            }
        }
    }
    for i in 4 * quads..nodes.len() {
        let node = nodes[i] as usize;
        for m in 0..D {
            acc[0][m] += values[i * D + m] * x[node * D + m];
        }
    }
    acc.iter().flatten().sum()
}

/// x += a·w.
fn axpy(w: &SparseColumn, d: usize, a: f64, x: &mut [f64]) {
    match d {
        1 => axpy_d::<1>(w, a, x),
        2 => axpy_d::<2>(w, a, x),
        _ => axpy_d::<3>(w, a, x),
    }
}

fn axpy_d<const D: usize>(w: &SparseColumn, a: f64, x: &mut [f64]) {
    for (&node, v) in w.nodes.iter().zip(w.values.chunks_exact(D)) {
        let xs = &mut x[node as usize * D..][..D];
        for m in 0..D {
            xs[m] += a * v[m];
        }
    }
}

pub(super) fn scatter(w: &SparseColumn, d: usize, x: &mut [f64]) {
    for (&node, v) in w.nodes.iter().zip(w.values.chunks_exact(d)) {
        x[node as usize * d..][..d].copy_from_slice(v);
    }
}

pub(super) fn unscatter(w: &SparseColumn, d: usize, x: &mut [f64]) {
    for &node in &w.nodes {
        x[node as usize * d..][..d].iter_mut().for_each(|v| *v = 0.0);
    }
}
