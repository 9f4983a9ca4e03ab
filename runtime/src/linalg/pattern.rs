//! The sparsity pattern of a vector field on a mesh, shared by assembly (which adds element
//! matrices into it) and linear algebra (whose matrices live on it).
//!
//! For each cell it stores, for every pair of its nodes (i, j), the offset of node i's first
//! row inside node j's columns, so element matrices are added in place without searching.

use std::sync::Arc;

/// Element matrix: `[test node][test component][trial node][trial component]`, the same
/// memory as a row-major (N·D)×(N·D) matrix.
pub type LocalMatrix<const D: usize, const N: usize> = [[[[f64; D]; N]; D]; N];

/// The cells whose nodes a pattern couples: `nodes_per_cell` node indices per cell, `dim`
/// components per node.
#[derive(Clone, Copy, Debug)]
pub struct Connectivity<'a> {
    pub dim: usize,
    pub num_nodes: usize,
    pub nodes_per_cell: usize,
    pub cells: &'a [u32],
}

impl Connectivity<'_> {
    pub fn num_cells(&self) -> usize {
        self.cells.len() / self.nodes_per_cell
    }

    pub fn cell(&self, c: usize) -> &[u32] {
        &self.cells[c * self.nodes_per_cell..(c + 1) * self.nodes_per_cell]
    }
}

/// Who owns the rows of a pattern that holds one process's part of a system, in a run split
/// across processes (`linalg::ownership::Ownership`, which exchanges over MPI). Every method
/// but the first four is collective.
pub trait Owners: std::fmt::Debug + Send + Sync {
    /// This process.
    fn rank(&self) -> usize;
    /// The number of processes.
    fn size(&self) -> usize;
    /// Dofs per node.
    fn dim(&self) -> usize;
    /// Per node, the process that owns it.
    fn owners(&self) -> &[u32];
    /// Whether this process owns `node`.
    fn owns(&self, node: usize) -> bool {
        self.owners()[node] as usize == self.rank()
    }
    /// Makes `y`, right at this process's dofs, whole: every dof takes its owner's value.
    fn complete(&self, y: &mut [f64]);
    /// Whether `flag` holds on any process.
    fn any(&self, flag: bool) -> bool;
    /// The sum of every process's `x`, added in rank order (the same bits everywhere).
    fn sum(&self, x: f64) -> f64;
}

/// The sparsity pattern of a vector field on a mesh (CSC, rows sorted in each column).
#[derive(Debug)]
pub struct Pattern {
    dim: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    /// Node adjacency (sorted neighbours of each node, itself included): column `j·d + m` holds,
    /// in this order, the d rows of each neighbour of node j.
    node_ptr: Vec<usize>,
    node_adj: Vec<u32>,
    /// Per cell, `[j][i]`: offset of node i's first row within the columns of node j.
    cell_offsets: Vec<u32>,
    /// In a run split across processes, who owns which rows: this process's rows are complete,
    /// the others partial, and products make their result whole ([`Owners::complete`]).
    ownership: Option<Arc<dyn Owners>>,
    /// The position of each stored entry's transpose, once asked for.
    transposed: std::sync::OnceLock<Vec<usize>>,
}

/// Some entries of a pattern: their indices among the stored values, and their columns.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Entries {
    pub indices: Vec<usize>,
    pub columns: Vec<u32>,
}

/// Each node's neighbours (the nodes it shares a cell with, and itself), sorted: node
/// i's are `adj[ptr[i]..ptr[i + 1]]`.
pub fn node_adjacency(mesh: &Connectivity) -> (Vec<usize>, Vec<u32>) {
    node_adjacency_with(mesh, &[])
}

/// As [`node_adjacency`], with the node pairs `extra` coupled too (both ways): nodes of two
/// bodies that may come into contact.
fn node_adjacency_with(mesh: &Connectivity, extra: &[(u32, u32)]) -> (Vec<usize>, Vec<u32>) {
    // The extra neighbours of each node (CSR).
    let mut extra_ptr = vec![0usize; mesh.num_nodes + 1];
    for &(a, b) in extra {
        extra_ptr[a as usize + 1] += 1;
        extra_ptr[b as usize + 1] += 1;
    }
    for i in 0..mesh.num_nodes {
        extra_ptr[i + 1] += extra_ptr[i];
    }
    let mut fill = extra_ptr.clone();
    let mut extra_adj = vec![0u32; 2 * extra.len()];
    for &(a, b) in extra {
        extra_adj[fill[a as usize]] = b;
        fill[a as usize] += 1;
        extra_adj[fill[b as usize]] = a;
        fill[b as usize] += 1;
    }
    let (inc_ptr, inc) = cells_of_nodes(mesh);
    let mut adj_ptr = Vec::with_capacity(mesh.num_nodes + 1);
    adj_ptr.push(0usize);
    let mut adj: Vec<u32> = Vec::with_capacity(mesh.num_nodes * 2 * mesh.nodes_per_cell);
    let mut scratch: Vec<u32> = Vec::new();
    for n in 0..mesh.num_nodes {
        scratch.clear();
        // A node of no cell (in one process's part of a mesh, a node it neither owns nor
        // touches) still has its diagonal block: every node neighbours itself.
        scratch.push(n as u32);
        for &c in &inc[inc_ptr[n]..inc_ptr[n + 1]] {
            scratch.extend_from_slice(mesh.cell(c as usize));
        }
        scratch.extend_from_slice(&extra_adj[extra_ptr[n]..extra_ptr[n + 1]]);
        scratch.sort_unstable();
        scratch.dedup();
        adj.extend_from_slice(&scratch);
        adj_ptr.push(adj.len());
    }
    (adj_ptr, adj)
}

/// The cells of each node: node i's are `cells[ptr[i]..ptr[i + 1]]`, in increasing order.
pub(crate) fn cells_of_nodes(mesh: &Connectivity) -> (Vec<usize>, Vec<u32>) {
    let nodes = mesh.num_nodes;
    let mut ptr = vec![0usize; nodes + 1];
    for &n in mesh.cells {
        ptr[n as usize + 1] += 1;
    }
    for i in 0..nodes {
        ptr[i + 1] += ptr[i];
    }
    let mut fill = ptr.clone();
    let mut cells = vec![0u32; mesh.cells.len()];
    for c in 0..mesh.num_cells() {
        for &n in mesh.cell(c) {
            cells[fill[n as usize]] = c as u32;
            fill[n as usize] += 1;
        }
    }
    (ptr, cells)
}

impl Pattern {
    /// Couples every pair of nodes sharing a cell.
    pub fn new(mesh: &Connectivity) -> Pattern {
        Pattern::with_couplings(mesh, &[])
    }

    /// Couples every pair of nodes sharing a cell, and the node pairs `extra` (both ways): the
    /// nodes of two bodies' facets that face each other, whose contact couples them.
    pub fn with_couplings(mesh: &Connectivity, extra: &[(u32, u32)]) -> Pattern {
        let d = mesh.dim;
        let npc = mesh.nodes_per_cell;
        let nodes = mesh.num_nodes;
        let cells = mesh.num_cells();
        let (adj_ptr, adj) = node_adjacency_with(mesh, extra);
        // Columns: node j's d columns each hold rows (i, k) for i adjacent to j.
        let size = nodes * d;
        let mut col_ptr = Vec::with_capacity(size + 1);
        col_ptr.push(0usize);
        let mut row_idx = Vec::with_capacity(adj.len() * d * d);
        for j in 0..nodes {
            let neighbours = &adj[adj_ptr[j]..adj_ptr[j + 1]];
            for _m in 0..d {
                for &i in neighbours {
                    for k in 0..d {
                        row_idx.push(i as usize * d + k);
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        let mut cell_offsets = Vec::with_capacity(cells * npc * npc);
        for c in 0..cells {
            let cell = mesh.cell(c);
            for &nj in cell {
                let neighbours = &adj[adj_ptr[nj as usize]..adj_ptr[nj as usize + 1]];
                for &ni in cell {
                    let pos = neighbours.binary_search(&ni).expect("nodes of a cell are adjacent");
                    cell_offsets.push((pos * d) as u32);
                }
            }
        }
        Pattern {
            dim: d,
            col_ptr,
            row_idx,
            node_ptr: adj_ptr,
            node_adj: adj,
            cell_offsets,
            ownership: None,
            transposed: Default::default(),
        }
    }

    /// This pattern, of one process's cells in a run split across processes.
    pub fn owned_by(mut self, ownership: Arc<dyn Owners>) -> Pattern {
        self.ownership = Some(ownership);
        self
    }

    /// Who owns the rows, in a run split across processes.
    pub fn ownership(&self) -> Option<&Arc<dyn Owners>> {
        self.ownership.as_ref()
    }

    /// Makes a vector that is right at this process's rows whole (nothing to do in a run of
    /// one process). Collective in a split run.
    pub fn complete(&self, y: &mut [f64]) {
        if let Some(o) = &self.ownership {
            o.complete(y);
        }
    }

    /// For each stored entry (i, j), the position of (j, i) (the pattern is symmetric): one
    /// pass over the columns, each column's cursor moving down its rows as j grows.
    pub fn transposed(&self) -> &[usize] {
        self.transposed.get_or_init(|| {
            let mut cursor = self.col_ptr[..self.col_ptr.len() - 1].to_vec();
            let mut at = vec![0; self.row_idx.len()];
            for j in 0..cursor.len() {
                for (k, &i) in self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]].iter().enumerate() {
                    debug_assert_eq!(self.row_idx[cursor[i]], j, "symmetric pattern");
                    at[self.col_ptr[j] + k] = cursor[i];
                    cursor[i] += 1;
                }
            }
            at
        })
    }

    /// Number of rows (= columns).
    pub fn size(&self) -> usize {
        self.col_ptr.len() - 1
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    pub fn dim(&self) -> usize {
        self.dim
    }

    pub fn num_nodes(&self) -> usize {
        self.node_ptr.len() - 1
    }

    /// The nodes coupled to node `j`, sorted (`j` among them).
    pub fn neighbours(&self, j: usize) -> &[u32] {
        &self.node_adj[self.node_ptr[j]..self.node_ptr[j + 1]]
    }

    /// The entries whose row and column are both dofs of flagged nodes, column by column.
    pub fn entries_among(&self, nodes: &[bool]) -> Entries {
        let d = self.dim;
        let mut out = Entries::default();
        for j in (0..self.num_nodes()).filter(|&j| nodes[j]) {
            for m in 0..d {
                let col = j * d + m;
                for (t, &i) in self.neighbours(j).iter().enumerate() {
                    if nodes[i as usize] {
                        let start = self.col_ptr[col] + t * d;
                        out.indices.extend(start..start + d);
                        out.columns.extend(std::iter::repeat_n(col as u32, d));
                    }
                }
            }
        }
        out
    }

    /// The position among the values of entry (row `i`, column `j`), if stored.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let d = self.dim;
        let t = self.neighbours(j / d).binary_search(&((i / d) as u32)).ok()?;
        Some(self.col_ptr[j] + t * d + i % d)
    }

    /// Calls `add(position, v)` for each entry of an element matrix over any `nodes` (a pair
    /// element: the nodes of two cells facing each other), `ke` row-major over the nodes'
    /// dofs, `ke[(a·d + k)·n·d + b·d + m]` coupling dof k of `nodes[a]` to dof m of `nodes[b]`.
    /// The blocks of two nodes the pattern does not couple are left out, and the first such pair
    /// is returned.
    pub fn scatter_nodes(&self, nodes: &[u32], ke: &[f64], mut add: impl FnMut(usize, f64)) -> Result<(), (u32, u32)> {
        let (d, n) = (self.dim, nodes.len());
        debug_assert_eq!(ke.len(), n * d * n * d);
        let mut missing = None;
        for (b, &nb) in nodes.iter().enumerate() {
            let neighbours = self.neighbours(nb as usize);
            for (a, &na) in nodes.iter().enumerate() {
                let Ok(t) = neighbours.binary_search(&na) else {
                    missing = missing.or(Some((na, nb)));
                    continue;
                };
                for m in 0..d {
                    let o = self.col_ptr[nb as usize * d + m] + t * d;
                    for k in 0..d {
                        add(o + k, ke[(a * d + k) * n * d + b * d + m]);
                    }
                }
            }
        }
        missing.map_or(Ok(()), Err)
    }

    /// Adds an element matrix of cell `c` with nodes `cell` into `values`.
    #[inline]
    pub(crate) fn scatter<const D: usize, const N: usize>(
        &self,
        c: usize,
        cell: &[u32],
        ke: &LocalMatrix<D, N>,
        values: &mut [f64],
    ) {
        self.scatter_with(c, cell, ke, |i, v| values[i] += v);
    }

    /// Calls `add(i, v)` for each entry `v` of an element matrix of cell `c` and its position
    /// `i` among the values.
    #[inline]
    pub(crate) fn scatter_with<const D: usize, const N: usize>(
        &self,
        c: usize,
        cell: &[u32],
        ke: &LocalMatrix<D, N>,
        mut add: impl FnMut(usize, f64),
    ) {
        let off = &self.cell_offsets[c * N * N..(c + 1) * N * N];
        for j in 0..N {
            let nj = cell[j] as usize;
            for m in 0..D {
                let base = self.col_ptr[nj * D + m];
                for i in 0..N {
                    let o = base + off[j * N + i] as usize;
                    for k in 0..D {
                        add(o + k, ke[i][k][j][m]);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles sharing no node (two bodies): their nodes are coupled only where asked,
    /// both ways, and a pair element over nodes of both lands where a dense matrix puts it.
    #[test]
    fn couplings_between_cells_are_stored_both_ways_and_receive_pair_elements() {
        let cells = [0, 1, 2, 3, 4, 5];
        let mesh = Connectivity { dim: 2, num_nodes: 6, nodes_per_cell: 3, cells: &cells };
        let plain = Pattern::new(&mesh);
        assert_eq!(plain.position(2, 2 * 4), None, "the bodies are not coupled");
        let coupled = Pattern::with_couplings(&mesh, &[(1, 4), (2, 4)]);
        // Two pairs, each both ways, a 2 × 2 block each.
        assert_eq!(coupled.nnz(), plain.nnz() + 2 * 2 * 2 * 2);
        for (a, b) in [(1, 4), (4, 1), (2, 4), (4, 2)] {
            for (k, m) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                assert!(coupled.position(2 * a + k, 2 * b + m).is_some(), "({a}, {b})");
            }
        }
        assert!(coupled.position(0, 2 * 5).is_none());
        // The transpose of every entry is stored (the pattern stays symmetric).
        let t = coupled.transposed();
        assert!(t.iter().enumerate().all(|(e, &f)| t[f] == e));
        // A pair element over nodes 1, 2 (one body) and 4 (the other).
        let nodes = [1u32, 2, 4];
        let ke: Vec<f64> = (0..36).map(|x| x as f64 + 1.0).collect();
        let mut values = vec![0.0; coupled.nnz()];
        coupled.scatter_nodes(&nodes, &ke, |i, v| values[i] += v).unwrap();
        for a in 0..3 {
            for b in 0..3 {
                for (k, m) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    let (row, col) = (2 * nodes[a] as usize + k, 2 * nodes[b] as usize + m);
                    let at = coupled.position(row, col).unwrap();
                    assert_eq!(values[at], ke[(a * 2 + k) * 6 + b * 2 + m]);
                }
            }
        }
        assert_eq!(values.iter().filter(|v| **v != 0.0).count(), 36);
        // Nodes the pattern does not couple: their blocks left out, the pair named; each node's
        // own block added.
        let mut partial = vec![0.0; coupled.nnz()];
        assert_eq!(coupled.scatter_nodes(&[0, 5], &[1.0; 16], |i, v| partial[i] += v), Err((5, 0)));
        assert_eq!(partial.iter().filter(|v| **v != 0.0).count(), 8);
    }
}
