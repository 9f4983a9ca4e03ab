//! The order in which cell loops visit the cells: blocks of consecutive cells in mesh order,
//! the blocks coloured so that two blocks of one colour share no node.
//!
//! A loop runs colour by colour; the blocks of a colour run in parallel, and each block is
//! visited by one thread from its first cell to its last. An entry of a global vector or
//! matrix thus receives its cells' contributions in one order, (colour of the block, cell),
//! whatever the number of threads: results have the same bits on one thread or many. Within a
//! block the cells are visited in mesh order, so consecutive cells add into nearby entries as
//! in a plain serial loop (colouring single cells spreads each colour over the whole mesh, and
//! every colour's pass then misses the cache on every cell: 2.4× slower on one thread).

use std::ops::Range;

use rayon::prelude::*;

use crate::fem::mesh::Mesh;

/// Cells per block on a mesh of `cells` cells: a 64th of the mesh, within 256..=65 536.
///
/// A node shared by blocks of two colours has its entries brought into the cache once per
/// colour, so blocks must be long against the distance, in mesh order, between cells sharing a
/// node (a row of cells on a structured mesh), and a colour must still hold enough blocks to
/// share among threads. P2 stiffness on one thread at N = 512 (1 024 cells a row; the serial
/// loop in mesh order took 0.42–0.43 µs/cell in the same minutes): 455-cell blocks 0.60–0.67
/// µs/cell, 2 048 0.53, 8 192 0.46–0.48, 32 768 0.42–0.49. 64 blocks make two colours of 32
/// blocks there.
pub(crate) fn cells_per_block(cells: usize) -> usize {
    cells.div_ceil(64).clamp(256, 65_536)
}

/// Blocks of consecutive cells and their colours.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CellOrder {
    cells: usize,
    /// Cells per block (the last block may hold fewer).
    block: usize,
    /// Blocks by colour, each colour's in increasing order.
    colours: Vec<Vec<u32>>,
}

impl CellOrder {
    /// Blocks of `block` consecutive cells of `mesh`, coloured greedily in block order: each
    /// takes the smallest colour none of the blocks sharing one of its nodes has taken.
    pub fn new(mesh: &Mesh, block: usize) -> CellOrder {
        let block = block.max(1);
        let cells = mesh.num_cells();
        let blocks = cells.div_ceil(block);
        // The blocks of each node (CSR), each listed once, in increasing order.
        let nodes = mesh.num_nodes();
        let mut last = vec![u32::MAX; nodes];
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for b in 0..blocks {
            for c in b * block..((b + 1) * block).min(cells) {
                for &n in mesh.cell(c) {
                    if last[n as usize] != b as u32 {
                        last[n as usize] = b as u32;
                        pairs.push((n, b as u32));
                    }
                }
            }
        }
        let mut ptr = vec![0usize; nodes + 1];
        for &(n, _) in &pairs {
            ptr[n as usize + 1] += 1;
        }
        for i in 0..nodes {
            ptr[i + 1] += ptr[i];
        }
        let mut fill = ptr.clone();
        let mut of_node = vec![0u32; pairs.len()];
        for &(n, b) in &pairs {
            of_node[fill[n as usize]] = b;
            fill[n as usize] += 1;
        }
        let mut colour = vec![u32::MAX; blocks];
        // taken[k] == b + 1: colour k is used by a neighbour of block b.
        let mut taken: Vec<usize> = Vec::new();
        let mut colours: Vec<Vec<u32>> = Vec::new();
        for b in 0..blocks {
            for c in b * block..((b + 1) * block).min(cells) {
                for &n in mesh.cell(c) {
                    for &other in &of_node[ptr[n as usize]..ptr[n as usize + 1]] {
                        let k = colour[other as usize];
                        if k != u32::MAX {
                            taken[k as usize] = b + 1;
                        }
                    }
                }
            }
            let k = (0..taken.len()).find(|&k| taken[k] != b + 1).unwrap_or(taken.len());
            if k == taken.len() {
                taken.push(0);
                colours.push(Vec::new());
            }
            colour[b] = k as u32;
            colours[k].push(b as u32);
        }
        CellOrder { cells, block, colours }
    }

    /// The order of cell loops on `mesh`: blocks of [`cells_per_block`] cells.
    pub fn of(mesh: &Mesh) -> CellOrder {
        CellOrder::new(mesh, cells_per_block(mesh.num_cells()))
    }

    pub fn num_blocks(&self) -> usize {
        self.cells.div_ceil(self.block)
    }

    /// The cells of block `b`.
    pub fn block(&self, b: usize) -> Range<usize> {
        b * self.block..((b + 1) * self.block).min(self.cells)
    }

    /// The blocks by colour: no two blocks of a colour share a node.
    pub fn colours(&self) -> &[Vec<u32>] {
        &self.colours
    }

    /// Calls `each(state, cells)` on every block, colour by colour, the blocks of a colour in
    /// parallel (each on one thread, its cells in increasing order), with a state made by
    /// `init` for each thread's run of blocks. On one thread the blocks run in the same order
    /// with one state.
    pub(crate) fn for_each_block<S>(&self, init: impl Fn() -> S + Sync, each: impl Fn(&mut S, Range<usize>) + Sync) {
        if rayon::current_num_threads() == 1 {
            let mut state = init();
            for colour in &self.colours {
                for &b in colour {
                    each(&mut state, self.block(b as usize));
                }
            }
            return;
        }
        for colour in &self.colours {
            colour.par_iter().for_each_init(&init, |state, &b| each(state, self.block(b as usize)));
        }
    }
}

/// A vector or matrix's values written by the blocks of one colour from several threads.
#[derive(Clone, Copy)]
pub(crate) struct Disjoint(*mut f64);

// SAFETY: the blocks of a colour share no node, so the entries their cells add into are
// disjoint: no two threads touch the same value (see `add_at`).
unsafe impl Send for Disjoint {}
// SAFETY: as for `Send`: shared references only ever write disjoint entries.
unsafe impl Sync for Disjoint {}

impl Disjoint {
    pub(crate) fn new(values: &mut [f64]) -> Disjoint {
        Disjoint(values.as_mut_ptr())
    }

    /// Adds `v` to entry `i`.
    ///
    /// # Safety
    /// `i` is in bounds of the values this was made from, they outlive the call, and no other
    /// thread accesses entry `i` concurrently.
    #[inline]
    pub(crate) unsafe fn add_at(self, i: usize, v: f64) {
        // SAFETY: the caller's guarantees: in bounds, alive, and this thread's alone.
        unsafe { *self.0.add(i) += v }
    }
}
