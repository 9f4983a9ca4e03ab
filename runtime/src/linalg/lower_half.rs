//! Products with a symmetric matrix read from its lower half: half the values the full
//! product reads, and the product is memory-bound (`benches/linalg.rs`).
//!
//! The node blocks below the diagonal are stored by column, in a reverse Cuthill–McKee order
//! of the nodes, so column p's blocks lie in a band of rows just after p, and the products
//! y_i += A_ip x_p that a column sends to other rows land near it. The columns are cut into
//! tasks of a fixed number of nodes; each task sums into its own buffer, which covers its rows
//! and the band after them, and the buffers are added in task order: the same bits for any
//! number of threads.

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::linalg::matrix::Matrix;
use crate::linalg::pattern::{Owners, Pattern};

/// Columns (nodes) per task: fixed, so the sums do not depend on the number of threads.
const NODES_PER_TASK: usize = 512;

/// Below this many stored values one thread does it all.
const PARALLEL_VALUES: usize = 200_000;

/// The lower half of a pattern in node blocks, in reverse Cuthill–McKee order; shared by the
/// matrices on that pattern.
#[derive(Debug)]
pub struct HalfPattern {
    d: usize,
    /// `order[p]` is the node at position p.
    order: Vec<u32>,
    /// Column p's blocks below the diagonal: rows (positions > p, increasing) `rows[ptr[p]..ptr[p + 1]]`.
    ptr: Vec<usize>,
    rows: Vec<u32>,
    /// Where each block is in the full pattern: the offset of its first value within each of
    /// node `order[p]`'s columns.
    source: Vec<usize>,
    tasks: Vec<Task>,
    /// The pattern's owners of rows, in a run split across processes.
    ownership: Option<Arc<dyn Owners>>,
}

/// Columns `start..end`; the task's buffer covers positions `start..reach`.
#[derive(Debug, Clone, Copy)]
struct Task {
    start: usize,
    end: usize,
    reach: usize,
}

impl HalfPattern {
    pub fn new(p: &Pattern) -> HalfPattern {
        let d = p.dim();
        let order = reverse_cuthill_mckee(p);
        let mut position = vec![0u32; order.len()];
        order.iter().enumerate().for_each(|(q, &node)| position[node as usize] = q as u32);
        let (mut ptr, mut rows, mut source) = (vec![0usize], Vec::new(), Vec::new());
        let mut column: Vec<(u32, usize)> = Vec::new();
        for &node in &order {
            let j = node as usize;
            let here = position[j];
            column.clear();
            for (k, &i) in p.neighbours(j).iter().enumerate() {
                if position[i as usize] > here {
                    column.push((position[i as usize], k * d));
                }
            }
            column.sort_unstable();
            rows.extend(column.iter().map(|c| c.0));
            source.extend(column.iter().map(|c| c.1));
            ptr.push(rows.len());
        }
        let nodes = order.len();
        let tasks = (0..nodes.div_ceil(NODES_PER_TASK))
            .map(|t| {
                let (start, end) = (t * NODES_PER_TASK, ((t + 1) * NODES_PER_TASK).min(nodes));
                let reach = rows[ptr[start]..ptr[end]].iter().map(|&r| r as usize + 1).fold(end, usize::max);
                Task { start, end, reach }
            })
            .collect();
        HalfPattern { d, order, ptr, rows, source, tasks, ownership: p.ownership().cloned() }
    }

    fn nodes(&self) -> usize {
        self.order.len()
    }

    /// Doubles of work space a product of `m` matrices needs: the m vectors and y in position
    /// order, and the task buffers.
    fn work_len(&self, m: usize) -> usize {
        self.d * ((m + 1) * self.nodes() + self.tasks.iter().map(|t| t.reach - t.start).sum::<usize>())
    }
}

/// The lower halves (diagonal blocks whole) of a few symmetric matrices on one pattern, their
/// blocks interleaved, for products Σ c_m A_m x_m in one pass: the pattern, the buffers and the
/// sums into y are shared (a stage's linear terms, M a + K u for Newmark, cost one product).
///
/// A matrix whose every block is a multiple of the identity (a vector field's mass matrix) is
/// stored with one value per block, a quarter of the bytes in 2D: such matrices come first in
/// the storage (`order`), the others after them, each group in the caller's order.
#[derive(Debug)]
pub struct LowerHalf {
    pattern: Arc<HalfPattern>,
    /// How many matrices, and how many of them are stored by one value per block.
    m: usize,
    scalars: usize,
    /// `order[s]` is the caller's index of the matrix in storage slot s.
    order: Vec<usize>,
    /// Per position, the matrices' diagonal blocks: one value for each of the first `scalars`
    /// slots, then d×d row-major for each other.
    diag: Vec<f64>,
    /// Per block below the diagonal, the matrices' blocks laid out as `diag`'s: with `stride`
    /// = scalars + (m − scalars)·d², block k's values for full slot s start at
    /// `k·stride + scalars + (s − scalars)·d²`, where `[r·d + c]` is A[rows[k]·d + r, p·d + c]
    /// (in position order).
    values: Vec<f64>,
    work: Mutex<Vec<f64>>,
}

/// Matrices a product fuses at most: the kernels are compiled for each count.
pub const MAX_FUSED: usize = 4;

impl LowerHalf {
    /// The lower half of `a`, which must be symmetric on `half`'s pattern (only the lower half
    /// is read).
    pub fn new(a: &Matrix, half: &Arc<HalfPattern>) -> LowerHalf {
        LowerHalf::fused(&[a], half)
    }

    /// The lower halves of `matrices` (1 to [`MAX_FUSED`], symmetric, on `half`'s pattern).
    pub fn fused(matrices: &[&Matrix], half: &Arc<HalfPattern>) -> LowerHalf {
        assert!((1..=MAX_FUSED).contains(&matrices.len()), "1 to {MAX_FUSED} matrices");
        let h = half.as_ref();
        let (d, m) = (h.d, matrices.len());
        let scalar: Vec<bool> = matrices.iter().map(|a| d > 1 && identity_multiples(a, h)).collect();
        let order: Vec<usize> = (0..m).filter(|&l| scalar[l]).chain((0..m).filter(|&l| !scalar[l])).collect();
        let scalars = scalar.iter().filter(|s| **s).count();
        let stride = scalars + (m - scalars) * d * d;
        let mut diag = vec![0.0; h.nodes() * stride];
        let mut values = vec![0.0; h.rows.len() * stride];
        for (slot, &l) in order.iter().enumerate() {
            let (a, offset) = (matrices[l], if slot < scalars { slot } else { scalars + (slot - scalars) * d * d });
            for (q, block) in blocks(a, h) {
                let out = match block {
                    Block::Diagonal(_) => &mut diag[q * stride + offset..],
                    Block::Below(k, _) => &mut values[k * stride + offset..],
                };
                let (Block::Diagonal(columns) | Block::Below(_, columns)) = block;
                if slot < scalars {
                    out[0] = columns[0][0];
                } else {
                    for (c, column) in columns[..d].iter().enumerate() {
                        for (r, v) in column.iter().enumerate() {
                            out[r * d + c] = *v;
                        }
                    }
                }
            }
        }
        let work = Mutex::new(vec![0.0; h.work_len(m)]);
        LowerHalf { pattern: half.clone(), m, scalars, order, diag, values, work }
    }

    /// How many matrices.
    pub fn count(&self) -> usize {
        self.m
    }

    /// `y = A x` (one matrix).
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        self.mul_sum(&[(1.0, x)], y);
    }

    /// `y = Σ c_l A_l x_l`, one (c_l, x_l) per matrix.
    pub fn mul_sum(&self, terms: &[(f64, &[f64])], y: &mut [f64]) {
        assert_eq!(terms.len(), self.m, "one vector per matrix");
        macro_rules! kernels {
            ($(($d:literal, $m:literal, $s:literal)),*) => {
                match (self.pattern.d.min(3), self.m, self.scalars) {
                    $(($d, $m, $s) => self.mul_sum_d::<$d, $m, $s>(terms, y),)*
                    _ => unreachable!("1 to {MAX_FUSED} matrices, scalar ones only for d > 1"),
                }
            };
        }
        // (d, matrices, scalar ones): d = 1 stores every matrix whole.
        #[rustfmt::skip]
        kernels!(
            (1, 1, 0), (1, 2, 0), (1, 3, 0), (1, 4, 0),
            (2, 1, 0), (2, 2, 0), (2, 3, 0), (2, 4, 0), (2, 1, 1), (2, 2, 1), (2, 3, 1), (2, 4, 1),
            (2, 2, 2), (2, 3, 2), (2, 4, 2), (2, 3, 3), (2, 4, 3), (2, 4, 4),
            (3, 1, 0), (3, 2, 0), (3, 3, 0), (3, 4, 0), (3, 1, 1), (3, 2, 1), (3, 3, 1), (3, 4, 1),
            (3, 2, 2), (3, 3, 2), (3, 4, 2), (3, 3, 3), (3, 4, 3), (3, 4, 4)
        );
        if let Some(o) = &self.pattern.ownership {
            o.complete(y);
        }
    }

    /// The product for d = D, M matrices of which the first S (in storage order) are scalar.
    fn mul_sum_d<const D: usize, const M: usize, const S: usize>(&self, terms: &[(f64, &[f64])], y: &mut [f64]) {
        let h = self.pattern.as_ref();
        let n = h.nodes() * D;
        // A poisoned lock only means another product panicked; the buffer is overwritten anyway.
        let mut work = self.work.lock().unwrap_or_else(|e| e.into_inner());
        let (xp, rest) = work.split_at_mut(n * M);
        let (yp, mut bufs) = rest.split_at_mut(n);
        // The scaled vectors in position order, interleaved per node in storage order.
        let xs: [(f64, &[[f64; D]]); M] = std::array::from_fn(|l| {
            let (c, x) = terms[self.order[l]];
            (c, x.as_chunks::<D>().0)
        });
        let (to, _) = xp.as_chunks_mut::<D>();
        for (to, &node) in to.chunks_exact_mut(M).zip(&h.order) {
            for (to, (c, x)) in to.iter_mut().zip(xs) {
                *to = x[node as usize].map(|v| c * v);
            }
        }
        let mut slices = Vec::with_capacity(h.tasks.len());
        for t in &h.tasks {
            let (buf, tail) = std::mem::take(&mut bufs).split_at_mut((t.reach - t.start) * D);
            slices.push((t, buf));
            bufs = tail;
        }
        let xp = &*xp;
        let run = |(t, buf): &mut (&Task, &mut [f64])| self.task::<D, M, S>(t, xp, buf);
        if self.values.len() < PARALLEL_VALUES || rayon::current_num_threads() == 1 {
            slices.iter_mut().for_each(run);
        } else {
            slices.par_iter_mut().for_each(run);
        }
        yp.iter_mut().for_each(|v| *v = 0.0);
        for (t, buf) in &slices {
            yp[t.start * D..t.reach * D].iter_mut().zip(buf.iter()).for_each(|(a, b)| *a += b);
        }
        let ((y, _), (yp, _)) = (y.as_chunks_mut::<D>(), yp.as_chunks::<D>());
        for (v, &node) in yp.iter().zip(&h.order) {
            y[node as usize] = *v;
        }
    }

    /// The task's columns' products, into `buf` (positions `t.start..t.reach`); `x` holds the
    /// M vectors interleaved per node, in storage order (the S scalar matrices first).
    fn task<const D: usize, const M: usize, const S: usize>(&self, t: &Task, x: &[f64], buf: &mut [f64]) {
        let h = self.pattern.as_ref();
        let stride = S + (M - S) * D * D;
        buf.iter_mut().for_each(|v| *v = 0.0);
        // Vectors by node: one bounds check per block rather than two.
        let (x, _) = x.as_chunks::<D>();
        let (buf, _) = buf.as_chunks_mut::<D>();
        for p in t.start..t.end {
            let xj: [[f64; D]; M] = std::array::from_fn(|l| x[p * M + l]);
            // Σ_l (A_l,ip)ᵀ x_l,i summed over the column: D² independent sums.
            let mut acc = [[0.0f64; D]; D];
            let range = h.ptr[p]..h.ptr[p + 1];
            let values = &self.values[range.start * stride..range.end * stride];
            for (&i, blocks) in h.rows[range].iter().zip(values.chunks_exact(stride)) {
                let i = i as usize;
                let yi = &mut buf[i - t.start];
                let (scalars, full) = blocks.split_at(S);
                // a·I: the full product's sums without its products by zero.
                for (l, &a) in scalars.iter().enumerate() {
                    let xi = &x[i * M + l];
                    for r in 0..D {
                        acc[r][r] += a * xi[r];
                        yi[r] += a * xj[l][r];
                    }
                }
                for (f, a) in full.chunks_exact(D * D).enumerate() {
                    let l = S + f;
                    let xi = &x[i * M + l];
                    for r in 0..D {
                        // Started from the first product, not from 0.0 (an addition the
                        // compiler must keep, for the sign of zero).
                        acc[0][r] += a[r * D] * xi[r];
                        let mut s = a[r * D] * xj[l][0];
                        for c in 1..D {
                            acc[c][r] += a[r * D + c] * xi[r];
                            s += a[r * D + c] * xj[l][c];
                        }
                        yi[r] += s;
                    }
                }
            }
            let dg = &self.diag[p * stride..][..stride];
            let yj = &mut buf[p - t.start];
            for c in 0..D {
                // Σ_l (A_l,pp x_l,p)_c in storage order, then the column's sums.
                let mut own = -0.0;
                for l in 0..S {
                    own += dg[l] * xj[l][c];
                }
                for l in S..M {
                    let b = &dg[S + (l - S) * D * D..][..D * D];
                    let mut row = b[c * D] * xj[l][0];
                    for k in 1..D {
                        row += b[c * D + k] * xj[l][k];
                    }
                    own += row;
                }
                let mut column = acc[c][0];
                for v in &acc[c][1..] {
                    column += v;
                }
                yj[c] += own + column;
            }
        }
    }
}

/// A symmetric matrix's lower-half blocks with their position: the diagonal block of position
/// q, or block k below it (in `HalfPattern::rows`); each as its d columns, d values each.
enum Block<'a> {
    Diagonal([&'a [f64]; 3]),
    Below(usize, [&'a [f64]; 3]),
}

/// `a`'s lower-half blocks, position by position: (q, block).
fn blocks<'a>(a: &'a Matrix, h: &'a HalfPattern) -> impl Iterator<Item = (usize, Block<'a>)> + 'a {
    let (p, d) = (&a.pattern, h.d);
    h.order.iter().enumerate().flat_map(move |(q, &node)| {
        let node = node as usize;
        let own = p.neighbours(node).binary_search(&(node as u32)).expect("a node neighbours itself");
        let columns = move |offset: usize| -> [&'a [f64]; 3] {
            std::array::from_fn(|c| if c < d { &a.values[p.col_ptr[node * d + c]..][offset..offset + d] } else { &[] })
        };
        std::iter::once((q, Block::Diagonal(columns(own * d))))
            .chain((h.ptr[q]..h.ptr[q + 1]).map(move |k| (q, Block::Below(k, columns(h.source[k])))))
    })
}

/// Whether every lower-half block of `a` is a multiple of the identity (zero off its diagonal,
/// the same value along it), exactly.
fn identity_multiples(a: &Matrix, h: &HalfPattern) -> bool {
    blocks(a, h).all(|(_, block)| {
        let (Block::Diagonal(columns) | Block::Below(_, columns)) = block;
        (0..h.d).all(|c| (0..h.d).all(|r| columns[c][r] == if r == c { columns[0][0] } else { 0.0 }))
    })
}

/// Reverse Cuthill–McKee order of the pattern's nodes: breadth-first from a pseudo-peripheral
/// node of each connected component, neighbours by increasing degree, reversed.
fn reverse_cuthill_mckee(p: &Pattern) -> Vec<u32> {
    let nodes = p.num_nodes();
    let degree = |i: usize| p.neighbours(i).len();
    let mut order = Vec::with_capacity(nodes);
    let mut visited = vec![false; nodes];
    let mut level = vec![usize::MAX; nodes];
    let mut queue: Vec<u32> = Vec::new();
    // Breadth-first levels from `root` (within its component); returns the visited nodes.
    let bfs = |root: usize, level: &mut Vec<usize>, queue: &mut Vec<u32>| {
        queue.clear();
        queue.push(root as u32);
        level[root] = 0;
        let mut head = 0;
        while head < queue.len() {
            let j = queue[head] as usize;
            head += 1;
            for &i in p.neighbours(j) {
                if level[i as usize] == usize::MAX {
                    level[i as usize] = level[j] + 1;
                    queue.push(i);
                }
            }
        }
    };
    for seed in 0..nodes {
        if visited[seed] {
            continue;
        }
        // Pseudo-peripheral root: repeat from the lowest-degree node of the last level while
        // the eccentricity grows.
        let mut root = seed;
        let mut depth = 0;
        for _ in 0..8 {
            bfs(root, &mut level, &mut queue);
            let last = queue.iter().map(|&i| level[i as usize]).max().unwrap_or(0);
            let far = queue
                .iter()
                .filter(|&&i| level[i as usize] == last)
                .min_by_key(|&&i| (degree(i as usize), i))
                .map_or(root, |&i| i as usize);
            queue.iter().for_each(|&i| level[i as usize] = usize::MAX);
            if last <= depth && depth > 0 {
                break;
            }
            depth = last;
            root = far;
        }
        // Cuthill–McKee from the root.
        let start = order.len();
        order.push(root as u32);
        visited[root] = true;
        let mut head = start;
        let mut next: Vec<u32> = Vec::new();
        while head < order.len() {
            let j = order[head] as usize;
            head += 1;
            next.clear();
            next.extend(p.neighbours(j).iter().copied().filter(|&i| !visited[i as usize]));
            next.sort_unstable_by_key(|&i| (degree(i as usize), i));
            for &i in &next {
                visited[i as usize] = true;
                order.push(i);
            }
        }
    }
    order.reverse();
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::assembly::Assembler;
    use crate::fem::mesh::structured::{Diagonal, cuboid, interval, rectangle};
    use crate::fem::test_matrices::diagonally_dominant;

    #[test]
    fn the_lower_half_product_is_the_full_product_for_any_number_of_threads() {
        let unit = [0.0, 1.0];
        // The large mesh has several tasks and takes the threaded path.
        let meshes = [
            interval(700, 0.0, 1.0),
            rectangle(9, 7, unit, unit, Diagonal::Right, 2),
            rectangle(60, 60, unit, unit, Diagonal::Right, 2),
            cuboid([3, 4, 2], unit, unit, unit, 2),
        ];
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        for mesh in &meshes {
            let a = diagonally_dominant(&Assembler::new(mesh));
            let half = Arc::new(HalfPattern::new(&a.pattern));
            let lower = LowerHalf::new(&a, &half);
            let n = a.size();
            let x: Vec<f64> = (0..n).map(|i| ((i * 31) % 101) as f64 / 101.0 - 0.5).collect();
            let (mut full, mut y) = (vec![0.0; n], vec![0.0; n]);
            a.mul_vec(&x, &mut full);
            lower.mul_vec(&x, &mut y);
            let scale = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (i, (f, h)) in full.iter().zip(&y).enumerate() {
                assert!((f - h).abs() <= 1e-13 * scale, "{n} unknowns, row {i}: {f} against {h}");
            }
            let mut threaded = vec![0.0; n];
            pool.install(|| lower.mul_vec(&x, &mut threaded));
            assert_eq!(y, threaded, "{n} unknowns");
        }
    }

    #[test]
    fn a_fused_product_is_the_sum_of_the_full_products() {
        let unit = [0.0, 1.0];
        for mesh in [
            interval(50, 0.0, 1.0),
            rectangle(9, 7, unit, unit, Diagonal::Right, 2),
            cuboid([3, 2, 2], unit, unit, unit, 1),
        ] {
            let a = diagonally_dominant(&Assembler::new(&mesh));
            let n = a.size();
            let half = Arc::new(HalfPattern::new(&a.pattern));
            let d = a.pattern.dim();
            // Symmetric matrices with different values: entrywise functions of a symmetric one,
            // and (odd k) ones whose blocks are multiples of the identity, stored by one value
            // per block wherever they stand among the others.
            let mut others = vec![a.clone()];
            for k in 1..2 * MAX_FUSED {
                let mut b = a.clone();
                let p = &a.pattern;
                for j in 0..n {
                    for e in p.col_ptr[j]..p.col_ptr[j + 1] {
                        let i = p.row_idx[e];
                        b.values[e] = match k % 2 {
                            0 => (b.values[e] * k as f64).sin(),
                            _ if i % d != j % d => 0.0,
                            _ => (((i / d).min(j / d) * 7 + (i / d).max(j / d) * 13 + k) as f64).cos(),
                        };
                    }
                }
                others.push(b);
            }
            let xs: Vec<Vec<f64>> = (0..2 * MAX_FUSED)
                .map(|k| (0..n).map(|i| (((i + 7 * k) * 31) % 101) as f64 / 101.0 - 0.5).collect())
                .collect();
            let coefs = [1.0, -2.5, 0.75, 3.0, 0.5, -1.25, 2.0, -0.375];
            // Every subset of up to MAX_FUSED of the matrices, in increasing order.
            for subset in (1..1usize << others.len()).filter(|s| s.count_ones() as usize <= MAX_FUSED) {
                let chosen: Vec<usize> = (0..others.len()).filter(|l| subset >> l & 1 == 1).collect();
                let matrices: Vec<&Matrix> = chosen.iter().map(|&l| &others[l]).collect();
                let fused = LowerHalf::fused(&matrices, &half);
                let scalars = chosen.iter().filter(|&&l| d > 1 && l % 2 == 1).count();
                assert_eq!(fused.scalars, scalars, "{chosen:?}: matrices stored by one value per block");
                let mut expected = vec![0.0; n];
                let mut product = vec![0.0; n];
                for &l in &chosen {
                    others[l].mul_vec(&xs[l], &mut product);
                    expected.iter_mut().zip(&product).for_each(|(e, p)| *e += coefs[l] * p);
                }
                let terms: Vec<(f64, &[f64])> = chosen.iter().map(|&l| (coefs[l], xs[l].as_slice())).collect();
                let mut y = vec![0.0; n];
                fused.mul_sum(&terms, &mut y);
                let scale = expected.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                let err = y.iter().zip(&expected).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
                assert!(err <= 1e-13 * scale, "{n} unknowns, matrices {chosen:?}: differs by {err:.1e} of {scale:.1e}");
            }
        }
    }

    #[test]
    fn reverse_cuthill_mckee_narrows_the_band_of_a_scrambled_mesh() {
        // A strip of 41 × 4 nodes, numbered along it: neighbours across it are 41 apart.
        let mesh = rectangle(40, 3, [0.0, 40.0], [0.0, 3.0], Diagonal::Right, 1);
        let a = diagonally_dominant(&Assembler::new(&mesh));
        let half = HalfPattern::new(&a.pattern);
        let mut seen = half.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..mesh.num_nodes() as u32).collect::<Vec<_>>(), "a permutation");
        // A 41×4-node strip: RCM levels run across the strip, each a few nodes wide.
        let band = (0..half.nodes())
            .flat_map(|p| half.rows[half.ptr[p]..half.ptr[p + 1]].iter().map(move |&r| r as usize - p))
            .max();
        assert!(band.unwrap() <= 8, "band {band:?}");
    }
}
