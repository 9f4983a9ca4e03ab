//! How a system is split across processes: its nodes are partitioned (METIS, on the graph of
//! the nodes that share a cell: the run's partition, or the matrix's) and renumbered so that each process owns a contiguous range of
//! PETSc's rows, a node's dofs staying together.

use std::sync::{Arc, Mutex, Weak};

use super::{petsc_int, sys};
use crate::linalg::LinalgError;
use crate::linalg::pattern::{Connectivity, Pattern};

pub(super) struct Layout {
    /// PETSc's index of each dof.
    pub(super) to_petsc: Vec<sys::PetscInt>,
    /// The dofs this process owns, in PETSc's order: PETSc's rows `first..first + mine.len()`.
    pub(super) mine: Vec<usize>,
    pub(super) first: usize,
}

/// The last pattern split and its layout: a solver built again for the same matrix (a new
/// time step, a cut step) does not partition it again.
static LAST: Mutex<Option<(Weak<Pattern>, Arc<Layout>)>> = Mutex::new(None);

impl Layout {
    /// The layout of `pattern`: the last one, if it was for this pattern, or a new one.
    pub(super) fn of(pattern: &Arc<Pattern>, rank: usize, size: usize) -> Result<Arc<Self>, LinalgError> {
        let mut last = LAST.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some((p, layout)) = last.as_ref()
            && p.upgrade().is_some_and(|p| Arc::ptr_eq(&p, pattern))
        {
            return Ok(layout.clone());
        }
        let layout = Arc::new(Layout::new(pattern, rank, size)?);
        *last = Some((Arc::downgrade(pattern), layout.clone()));
        Ok(layout)
    }

    /// Partitions the nodes of `pattern` (blocks of `pattern.dim()` dofs) over the `size`
    /// processes; every process calls it with the same pattern and gets the same
    /// numbering.
    fn new(pattern: &Pattern, rank: usize, size: usize) -> Result<Self, LinalgError> {
        let dim = pattern.dim().max(1);
        let n = pattern.col_ptr.len() - 1;
        if !n.is_multiple_of(dim) {
            return Err(LinalgError::Other(format!("{n} unknowns are not blocks of {dim}: cannot split them by node")));
        }
        let nodes = n / dim;
        // A split run's pattern carries its partition; otherwise the matrix's graph is split.
        let owner: Vec<u32> = match pattern.ownership() {
            Some(o) => o.owners().to_vec(),
            None => partition(nodes, |node| pattern.neighbours(node), size)?,
        };
        // Each process's nodes in their own order, after those of the processes before it.
        let mut next = vec![0usize; size];
        for &r in &owner {
            next[r as usize] += 1;
        }
        let mut start = 0;
        for count in &mut next {
            (*count, start) = (start, start + *count);
        }
        let first = next[rank] * dim;
        let (mut to_petsc, mut mine) = (vec![0; n], Vec::new());
        for (node, &r) in owner.iter().enumerate() {
            let r = r as usize;
            for c in 0..dim {
                to_petsc[node * dim + c] = petsc_int(next[r] * dim + c)?;
                if r == rank {
                    mine.push(node * dim + c);
                }
            }
            next[r] += 1;
        }
        Ok(Layout { to_petsc, mine, first })
    }
}

/// The process that owns each node of `cells` among `size`: see [`partition`]. Every process
/// computes it alone, and gets the same.
pub fn partition_nodes(cells: &Connectivity, size: usize) -> Result<Vec<u32>, LinalgError> {
    let (ptr, adj) = crate::linalg::pattern::node_adjacency(cells);
    partition(cells.num_nodes, |node| &adj[ptr[node]..ptr[node + 1]], size)
}

/// The process that owns each node: METIS's partition into `size` parts of the graph whose
/// edges join the nodes that share a cell (`neighbours`, sorted, the node itself among them).
/// Every process computes it alone, from its own copy of the graph: METIS's seed is fixed, so
/// each gets the same parts on every run (PT-Scotch's partition across processes, PETSc's,
/// changed from run to run, and with it the bits).
fn partition<'g>(nodes: usize, neighbours: impl Fn(usize) -> &'g [u32], size: usize) -> Result<Vec<u32>, LinalgError> {
    let index = |i: usize| {
        metis::Idx::try_from(i).map_err(|_| LinalgError::Other(format!("{i} nodes are too many for METIS's indices")))
    };
    let mut offsets = Vec::with_capacity(nodes + 1);
    let mut adjacent = Vec::new();
    offsets.push(0);
    for node in 0..nodes {
        for &other in neighbours(node) {
            if other as usize != node {
                adjacent.push(index(other as usize)?);
            }
        }
        offsets.push(index(adjacent.len())?);
    }
    let failed = |e: &dyn std::fmt::Display| LinalgError::Other(format!("METIS cannot split the mesh's graph: {e}"));
    let mut part = vec![0; nodes];
    let clock = std::time::Instant::now();
    let cut = metis::Graph::new(1, index(size)?, &offsets, &adjacent)
        .map_err(|e| failed(&e))?
        .part_kway(&mut part)
        .map_err(|e| failed(&e))?;
    // Partition quality: the edges cut among all (each edge is listed from both ends).
    let edges = adjacent.len() / 2;
    tracing::info!(nodes, parts = size, cut, edges, seconds = clock.elapsed().as_secs_f64(), "METIS partition");
    Ok(part.into_iter().map(|p| p.max(0) as u32).collect())
}
