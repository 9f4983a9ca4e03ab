//! A sparse Cholesky factor stored in node blocks, for the solves a time step spends its time
//! in.
//!
//! faer computes the factorization; this keeps a copy of L laid out for the solves: the
//! unknowns are ordered node by node (the fill-reducing ordering is computed on the node graph
//! and each node's d dofs kept together), so L is made of d×d blocks, stored per node column
//! with a u32 row index per block. A solve pair then reads 8 bytes per entry of L plus one
//! index per d² entries, where faer's simplicial solve reads 16 bytes per entry (an index per
//! value); measured on the disc's factors, it is 1.5 times faster (`bench disc`).
//!
//! The columns of a supernode share their rows (each has the one before's but its last), which
//! are stored once: 43 492 indices for 192 804 blocks at 12 482 unknowns.
//!
//! Each column's blocks are stored with rows decreasing: the backward pass, which visits the
//! columns from the last, then reads the whole factor downwards in memory while still summing
//! each column's rows in increasing order (criterion solve pair 561–589 against 623–645 µs at
//! 12 482 unknowns; unchanged at 3 362, where the factor fits the cache). The forward pass
//! reads upwards, each column's parent block (stored last) first.
//!
//! It also solves L w = e_k for a unit vector, touching only the columns where w is nonzero:
//! the ancestors of k's node in the elimination tree (a few percent of the columns on a 2D
//! mesh). The low-rank corrections of a changed Jacobian are built from these (`lowrank`).

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};

/// L in node blocks, with the ordering it was computed in.
#[derive(Clone, Debug)]
pub struct BlockFactor {
    d: usize,
    /// `order[k]` is the dof at position k of the elimination; `position` its inverse.
    order: Vec<u32>,
    position: Vec<u32>,
    /// Per node column J: its diagonal block (d×d, row-major, upper part zero; the pivots
    /// stored as their reciprocals, so that the chain of dependent operations from one column
    /// to the next multiplies instead of dividing) and its
    /// `ptr[J + 1] − ptr[J]` blocks below, `values[ptr[J]·d²..]` d×d each, column-major (both
    /// passes then work on a block's rows side by side), at the node rows
    /// `rows[row_start[J]..]` (decreasing): `values[(ptr[J] + k)·d² + c·d + r] =
    /// L[rows[row_start[J] + k]·d + r, J·d + c]`. A column whose rows are the previous
    /// column's but its last (the next column of a supernode) reads them there: the rows of
    /// a supernode are stored once, an index per block of its first column only.
    diag: Vec<f64>,
    ptr: Vec<usize>,
    row_start: Vec<usize>,
    rows: Vec<u32>,
    values: Vec<f64>,
}

/// A sparse vector over the factor's node positions (d values per listed node, the nodes
/// increasing), such as L⁻¹ e_k: nonzero only on the ancestors of k's node, listed from k's up.
#[derive(Clone, Debug, Default)]
pub struct SparseColumn {
    pub nodes: Vec<u32>,
    pub values: Vec<f64>,
}

impl BlockFactor {
    /// Copies faer's numeric factor `values` of `symbolic` into node blocks of size `d`. None if
    /// the ordering does not keep each node's dofs together in order (then faer's own solves
    /// are used).
    pub fn new(symbolic: &SymbolicCholesky<usize>, values: &[f64], d: usize) -> Option<BlockFactor> {
        Self::reusing(symbolic, values, d, None)
    }

    /// As [`BlockFactor::new`], storing into `old`'s buffers (a refactorization then allocates
    /// nothing).
    pub fn reusing(
        symbolic: &SymbolicCholesky<usize>,
        values: &[f64],
        d: usize,
        old: Option<BlockFactor>,
    ) -> Option<BlockFactor> {
        let n = symbolic.nrows();
        // Node blocks of 1 to 3 dofs (the solves are compiled for those).
        if !(1..=3).contains(&d) || !n.is_multiple_of(d) {
            return None;
        }
        let order: Vec<u32> = match symbolic.perm() {
            Some(p) => p.arrays().0.iter().map(|&i| i as u32).collect(),
            None => (0..n as u32).collect(),
        };
        // Each node's dofs consecutive, in order.
        if order
            .chunks_exact(d)
            .any(|c| !(c[0] as usize).is_multiple_of(d) || c.iter().enumerate().any(|(m, &i)| i != c[0] + m as u32))
        {
            return None;
        }
        let mut position = vec![0u32; n];
        order.iter().enumerate().for_each(|(k, &i)| position[i as usize] = k as u32);
        let mut blocks = match old {
            Some(BlockFactor { mut diag, mut ptr, mut row_start, mut rows, mut values, .. }) => {
                diag.clear();
                diag.resize(n * d, 0.0);
                ptr.clear();
                row_start.clear();
                rows.clear();
                values.clear();
                Blocks { d, diag, ptr, row_start, rows, values, column: Vec::new() }
            }
            // faer's values bound the blocks' (its supernodes are stored whole, upper parts
            // included): reserved at once, the copy never reallocates.
            None => Blocks {
                d,
                diag: vec![0.0; n * d],
                ptr: Vec::with_capacity(n / d + 1),
                row_start: Vec::with_capacity(n / d),
                rows: Vec::with_capacity(values.len() / (d * d)),
                values: Vec::with_capacity(values.len()),
                column: Vec::new(),
            },
        };
        blocks.ptr.push(0);
        match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let (col_ptr, row_idx) = (s.col_ptr(), s.row_idx());
                for node in 0..n / d {
                    let column = |j: usize| (&row_idx[col_ptr[j]..col_ptr[j + 1]], &values[col_ptr[j]..col_ptr[j + 1]]);
                    blocks.push(node, column)?;
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                // A supernode's columns b..e share their rows: b..e, then its pattern; each is
                // stored whole (column-major, nrows × (e − b)), the part above the diagonal unused.
                let mut rows = Vec::new();
                for sn in 0..s.n_supernodes() {
                    let (b, e) = (s.supernode_begin()[sn], s.supernode_end()[sn]);
                    if b % d != 0 || e % d != 0 {
                        return None;
                    }
                    rows.clear();
                    rows.extend(b..e);
                    rows.extend_from_slice(s.supernode(sn).pattern());
                    let nrows = rows.len();
                    let block = &values[s.col_ptr_for_val()[sn]..][..nrows * (e - b)];
                    for node in b / d..e / d {
                        // Column j from its diagonal down.
                        let column =
                            |j: usize| (&rows[j - b..], &block[(j - b) * nrows + (j - b)..(j - b + 1) * nrows]);
                        blocks.push(node, column)?;
                    }
                }
            }
        }
        let Blocks { diag, ptr, row_start, rows, values, .. } = blocks;
        Some(BlockFactor { d, order, position, diag, ptr, row_start, rows, values })
    }

    pub fn size(&self) -> usize {
        self.order.len()
    }

    /// Dofs per node (the block size).
    pub fn dim(&self) -> usize {
        self.d
    }

    /// Stored entries of L (the diagonal blocks' lower triangles and the blocks below).
    pub fn nnz(&self) -> usize {
        let nodes = self.ptr.len() - 1;
        nodes * self.d * (self.d + 1) / 2 + self.values.len()
    }

    /// Node column `node`'s rows below its diagonal block (decreasing).
    #[inline(always)]
    fn rows_of(&self, node: usize) -> &[u32] {
        &self.rows[self.row_start[node]..][..self.ptr[node + 1] - self.ptr[node]]
    }

    /// The position of dof `i` in the elimination.
    pub fn position(&self, i: usize) -> usize {
        self.position[i] as usize
    }

    /// Solves L Lᵀ x = b in place.
    pub fn solve_in_place(&self, b: &mut [f64], work: &mut Vec<f64>) {
        self.solve_with(b, work, |_| {});
    }

    /// Solves in place as `solve_in_place`, with `between` applied to L⁻¹ b (in elimination
    /// order) before the backward pass: L⁻ᵀ between(L⁻¹ b).
    pub fn solve_with(&self, b: &mut [f64], work: &mut Vec<f64>, between: impl FnOnce(&mut [f64])) {
        work.clear();
        work.extend(self.order.iter().map(|&i| b[i as usize]));
        self.forward(work);
        between(work);
        self.backward(work);
        for (x, &i) in work.iter().zip(&self.order) {
            b[i as usize] = *x;
        }
    }

    /// x ← L⁻¹ x (elimination order).
    pub fn forward(&self, x: &mut [f64]) {
        match self.d {
            1 => self.forward_d::<1>(x),
            2 => self.forward_d::<2>(x),
            _ => self.forward_d::<3>(x),
        }
    }

    /// x ← L⁻ᵀ x (elimination order).
    pub fn backward(&self, x: &mut [f64]) {
        match self.d {
            1 => self.backward_d::<1>(x),
            2 => self.backward_d::<2>(x),
            _ => self.backward_d::<3>(x),
        }
    }

    fn forward_d<const D: usize>(&self, x: &mut [f64]) {
        // x by node: one bounds check per block rather than two.
        let (x, _) = x.as_chunks_mut::<D>();
        // Column after column: the factor is read in one stream, upwards (a supernode's columns
        // side by side, each shared row updated by all of them at once, read many short
        // streams: criterion's forward pass 34 against 38 µs from the cache at 3 362 unknowns,
        // 461–483 against 750–836 µs from memory at 12 482; the same bits).
        for node in 0..self.ptr.len() - 1 {
            // A zero column changes nothing: a sparse right-hand side (a residual on a few
            // dofs) visits the ancestors of its nonzeros only.
            if x[node].iter().all(|c| *c == 0.0) {
                continue;
            }
            self.forward_column::<D>(x, node);
        }
    }

    /// The forward pass at one column: solved, then applied to its rows below.
    #[inline(always)]
    fn forward_column<const D: usize>(&self, x: &mut [[f64; D]], node: usize) {
        let xj: [f64; D] = diag_solve::<D>(&self.diag[node * D * D..][..D * D], &x[node]);
        x[node] = xj;
        let range = self.ptr[node]..self.ptr[node + 1];
        let values = &self.values[range.start * D * D..range.end * D * D];
        // The parent (stored last) first: the next column's diagonal solve waits on it.
        // Each block updates its own row, so the order leaves the bits alone.
        let rows = self.rows_of(node);
        if let Some((&parent, rest)) = rows.split_last() {
            let (others, last) = values.split_at(rest.len() * D * D);
            update::<D>(&mut x[parent as usize], last, &xj);
            for (&row, block) in rest.iter().zip(others.chunks_exact(D * D)) {
                update::<D>(&mut x[row as usize], block, &xj);
            }
        }
    }

    fn backward_d<const D: usize>(&self, x: &mut [f64]) {
        let (x, _) = x.as_chunks_mut::<D>();
        for node in (0..self.ptr.len() - 1).rev() {
            let range = self.ptr[node]..self.ptr[node + 1];
            let values = &self.values[range.start * D * D..range.end * D * D];
            // D² independent sums rather than D dependent chains.
            let mut acc = [[0.0f64; D]; D];
            // The parent (the smallest row, stored last) last: the sum over the other rows,
            // increasing (the memory read downwards), need not wait on the column solved just
            // before, which is the parent more often than not.
            let rows = self.rows_of(node);
            if let Some((&parent, rest)) = rows.split_last() {
                let (others, last) = values.split_at(rest.len() * D * D);
                for (&row, block) in rest.iter().rev().zip(others.rchunks_exact(D * D)) {
                    accumulate::<D>(&mut acc, block, &x[row as usize]);
                }
                accumulate::<D>(&mut acc, last, &x[parent as usize]);
            }
            let dg = &self.diag[node * D * D..][..D * D];
            let xj = &mut x[node];
            for c in (0..D).rev() {
                let mut s = xj[c] - acc[c].iter().sum::<f64>();
                for r in c + 1..D {
                    s -= dg[r * D + c] * xj[r];
                }
                xj[c] = s * dg[c * D + c];
            }
        }
    }

    /// L⁻¹ e_k for the unit vector at elimination position `k`: only the ancestors of k's node
    /// are visited. `work` must be zero on entry (length `size()`); it is zero again on exit.
    pub fn forward_unit(&self, k: usize, work: &mut [f64]) -> SparseColumn {
        self.forward_units(&[k], work).pop().expect("one column")
    }

    /// L⁻¹ e_k for each of `ks`, elimination positions of one node's dofs (at most d): the
    /// ancestors of that node are visited once, each block read once for all the columns,
    /// which are the same bits as one by one. `work` must be zero on entry (length
    /// `ks.len() · size()`, one vector per column); it is zero again on exit.
    pub fn forward_units(&self, ks: &[usize], work: &mut [f64]) -> Vec<SparseColumn> {
        let (d, n, m) = (self.d, self.size(), ks.len());
        assert!((1..=d).contains(&m) && ks.iter().all(|k| k / d == ks[0] / d), "dofs of one node");
        let mut out: Vec<SparseColumn> = (0..m).map(|_| SparseColumn::default()).collect();
        let (work, _) = work.split_at_mut(m * n);
        ks.iter().zip(work.chunks_exact_mut(n)).for_each(|(&k, w)| w[k] = 1.0);
        let mut node = ks[0] / d;
        loop {
            let dg = &self.diag[node * d * d..][..d * d];
            let mut xj = [[0.0f64; 3]; 3];
            for ((x, column), w) in xj.iter_mut().zip(out.iter_mut()).zip(work.chunks_exact_mut(n)) {
                column.nodes.push(node as u32);
                for r in 0..d {
                    let mut s = w[node * d + r];
                    for c in 0..r {
                        s -= dg[r * d + c] * x[c];
                    }
                    x[r] = s * dg[r * d + r];
                }
                for r in 0..d {
                    column.values.push(x[r]);
                    w[node * d + r] = 0.0;
                }
            }
            let range = self.ptr[node]..self.ptr[node + 1];
            if range.is_empty() {
                break;
            }
            for (i, &row) in self.rows_of(node).iter().enumerate() {
                let block = &self.values[(range.start + i) * d * d..][..d * d];
                for (x, w) in xj.iter().zip(work.chunks_exact_mut(n)) {
                    for r in 0..d {
                        let mut s = 0.0;
                        for c in 0..d {
                            s += block[c * d + r] * x[c];
                        }
                        w[row as usize * d + r] -= s;
                    }
                }
            }
            // The parent in the elimination tree: the first row below the diagonal block (stored
            // last).
            node = self.rows_of(node)[range.len() - 1] as usize;
        }
        out
    }
}

/// xi −= block · xj (a block below the diagonal in the forward pass).
#[inline(always)]
fn update<const D: usize>(xi: &mut [f64; D], block: &[f64], xj: &[f64; D]) {
    // Started from the first product, not from 0.0 (an addition the compiler must keep, for
    // the sign of zero). Column by column, the rows side by side: one vector operation per
    // column rather than a scalar one per entry.
    let mut s: [f64; D] = std::array::from_fn(|r| block[r] * xj[0]);
    for c in 1..D {
        for r in 0..D {
            s[r] += block[c * D + r] * xj[c];
        }
    }
    for r in 0..D {
        xi[r] -= s[r];
    }
}

/// acc[c] += block[:, c] ⊙ xi (a block below the diagonal in the backward pass: D² sums,
/// added up per column at the end).
#[inline(always)]
fn accumulate<const D: usize>(acc: &mut [[f64; D]; D], block: &[f64], xi: &[f64; D]) {
    for c in 0..D {
        for r in 0..D {
            acc[c][r] += block[c * D + r] * xi[r];
        }
    }
}

/// The solve of a lower-triangular diagonal block.
#[inline(always)]
fn diag_solve<const D: usize>(dg: &[f64], b: &[f64]) -> [f64; D] {
    let mut x = [0.0; D];
    for r in 0..D {
        let mut s = b[r];
        for c in 0..r {
            s -= dg[r * D + c] * x[c];
        }
        x[r] = s * dg[r * D + r];
    }
    x
}

/// The node blocks of L as they are copied in, node column by node column.
struct Blocks {
    d: usize,
    diag: Vec<f64>,
    ptr: Vec<usize>,
    row_start: Vec<usize>,
    rows: Vec<u32>,
    values: Vec<f64>,
    /// The column being copied's node rows.
    column: Vec<u32>,
}

impl Blocks {
    /// Copies node column `node`, given its d dof columns from their diagonal down (rows
    /// increasing, and the values at those rows). None unless they are made of whole node
    /// blocks: the first column's rows below the node are those of every later column.
    fn push<'c>(&mut self, node: usize, column: impl Fn(usize) -> (&'c [usize], &'c [f64])) -> Option<()> {
        let d = self.d;
        let (first_rows, _) = column(node * d);
        if first_rows.len() < d || (0..d).any(|m| first_rows[m] != node * d + m) {
            return None;
        }
        let below = &first_rows[d..];
        if below.len() % d != 0 {
            return None;
        }
        let start = self.values.len();
        self.values.resize(start + below.len() * d, 0.0);
        let mut last = node;
        self.column.clear();
        for group in below.chunks_exact(d) {
            // Whole nodes, in increasing order (the first is the parent in the elimination tree).
            if group[0] % d != 0 || group[0] / d <= last || group.iter().enumerate().any(|(m, &r)| r != group[0] + m) {
                return None;
            }
            last = group[0] / d;
            self.column.push(last as u32);
        }
        // Stored in decreasing order: the backward pass, which visits the columns from the
        // last, then reads the whole factor downwards in memory.
        self.column.reverse();
        let blocks = below.len() / d;
        // The previous column's rows but its last, which is this node: read there.
        let shares = node > 0 && {
            let before = &self.rows[self.row_start[node - 1]..][..self.ptr[node] - self.ptr[node - 1]];
            before.len() == blocks + 1 && before[blocks] == node as u32 && before[..blocks] == self.column[..]
        };
        if shares {
            self.row_start.push(self.row_start[node - 1]);
        } else {
            self.row_start.push(self.rows.len());
            self.rows.extend_from_slice(&self.column);
        }
        for c in 0..d {
            let (col_rows, col_values) = column(node * d + c);
            // Rows node·d + c.. of the diagonal block, then exactly the node's rows below.
            if col_rows.len() != (d - c) + below.len()
                || col_rows[d - c..] != *below
                || col_values.len() != col_rows.len()
            {
                return None;
            }
            for r in c..d {
                self.diag[(node * d + r) * d + c] = if r == c { 1.0 / col_values[r - c] } else { col_values[r - c] };
            }
            for (k, v) in col_values[d - c..].iter().enumerate() {
                let (block, r) = (blocks - 1 - k / d, k % d);
                self.values[start + (block * d + c) * d + r] = *v;
            }
        }
        self.ptr.push(self.values.len() / (d * d));
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::assembly::Assembler;
    use crate::fem::mesh::structured::{Diagonal, cuboid, interval, rectangle};
    use crate::fem::test_matrices::diagonally_dominant;
    use crate::linalg::factorization::node_ordering;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::linalg::cholesky::{self, LltRef, SymmetricOrdering};
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    use faer::{Conj, MatMut, Par, Side};

    #[test]
    fn block_solves_match_faers_for_simplicial_and_supernodal_factors() {
        let unit = [0.0, 1.0];
        let meshes = [
            interval(30, 0.0, 1.0),
            rectangle(9, 7, unit, unit, Diagonal::Right, 2),
            cuboid([3, 3, 2], unit, unit, unit, 2),
        ];
        for mesh in &meshes {
            let asm = Assembler::new(mesh);
            let a = diagonally_dominant(&asm);
            let n = a.size();
            let p = &a.pattern;
            let sym = SymbolicSparseColMatRef::new_checked(n, n, &p.col_ptr, None, &p.row_idx);
            let (order, inverse) = node_ordering(p).unwrap();
            for threshold in [SupernodalThreshold::FORCE_SIMPLICIAL, SupernodalThreshold::FORCE_SUPERNODAL] {
                let symbolic = cholesky::factorize_symbolic_cholesky(
                    sym,
                    Side::Lower,
                    SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&order, &inverse, n)),
                    cholesky::CholeskySymbolicParams {
                        supernodal_flop_ratio_threshold: threshold,
                        ..Default::default()
                    },
                )
                .unwrap();
                let mut values = vec![0.0; symbolic.len_val()];
                let mut mem =
                    MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
                symbolic
                    .factorize_numeric_llt(
                        &mut values,
                        SparseColMatRef::new(sym, &a.values),
                        Side::Lower,
                        Default::default(),
                        Par::Seq,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .unwrap();
                let block = BlockFactor::new(&symbolic, &values, p.dim()).expect("node blocks");
                let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 101) as f64 / 101.0 - 0.4).collect();
                let mut expected = b.clone();
                let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
                LltRef::new(&symbolic, &values).solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(&mut expected, n, 1),
                    Par::Seq,
                    MemStack::new(&mut mem),
                );
                let mut x = b.clone();
                block.solve_in_place(&mut x, &mut Vec::new());
                // The forward pass skips the columns still zero when it reaches them (a sparse
                // right-hand side): the bits of every column applied.
                let mut sparse = vec![0.0; n];
                (sparse[n / 2], sparse[n - 1]) = (1.0, -0.5);
                let (mut skipped, mut every) = (sparse.clone(), sparse);
                block.forward(&mut skipped);
                match p.dim() {
                    1 => (0..n).for_each(|j| block.forward_column::<1>(every.as_chunks_mut().0, j)),
                    2 => (0..n / 2).for_each(|j| block.forward_column::<2>(every.as_chunks_mut().0, j)),
                    _ => (0..n / 3).for_each(|j| block.forward_column::<3>(every.as_chunks_mut().0, j)),
                }
                assert_eq!(skipped, every, "{} {threshold:?}: forward pass skipping zeros", mesh.kind.name());
                assert!(skipped.iter().filter(|v| **v != 0.0).count() < n, "some columns skipped");
                if threshold == SupernodalThreshold::FORCE_SUPERNODAL {
                    assert!(block.rows.len() < block.values.len() / (p.dim() * p.dim()), "some rows shared");
                }
                let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let err = x.iter().zip(&expected).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale;
                assert!(err < 1e-13, "{} {threshold:?}: differs by {err:.1e}", mesh.kind.name());
                // L⁻¹ e_k: the full forward solve, nonzero only where the sparse one visits.
                let mut work = vec![0.0; n];
                for k in [0, n / 3, n - 1] {
                    let column = block.forward_unit(k, &mut work);
                    assert!(work.iter().all(|w| *w == 0.0), "work left zero");
                    let mut dense = vec![0.0; n];
                    dense[k] = 1.0;
                    block.forward(&mut dense);
                    let mut sparse = vec![0.0; n];
                    let d = p.dim();
                    for (i, &node) in column.nodes.iter().enumerate() {
                        sparse[node as usize * d..][..d].copy_from_slice(&column.values[i * d..][..d]);
                    }
                    assert_eq!(sparse, dense, "forward_unit({k}) is the forward solve of e_k");
                    // With the node's other dofs, in one visit: the same columns.
                    let d = p.dim();
                    let node: Vec<usize> = (k / d * d..(k / d + 1) * d).collect();
                    let mut works = vec![0.0; d * n];
                    let together = block.forward_units(&node, &mut works);
                    assert!(works.iter().all(|w| *w == 0.0), "work left zero");
                    for (&j, c) in node.iter().zip(&together) {
                        let alone = block.forward_unit(j, &mut work);
                        assert_eq!((&c.nodes, &c.values), (&alone.nodes, &alone.values), "forward_units at {j}");
                    }
                }
            }
        }
    }
}
