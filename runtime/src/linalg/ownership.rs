//! Which process owns each node of a run split across processes (`mpirun`), and the exchange
//! that keeps every process's vectors whole.
//!
//! Each process assembles the cells that touch a node it owns (`Mesh::part`), so its rows of
//! those nodes are complete; its other rows hold only part of their sums. A product or an
//! assembly on such a pattern is right at the owned rows, and [`Ownership::complete`] then
//! copies every process's owned rows to all the others: values are copied, never added, so
//! every process holds the same whole vector, bit for bit, and takes the same decisions from it
//! (Newton's norms, step cuts, the energy guard) without a reduction.

use std::sync::{Arc, Mutex};

use crate::linalg::pattern::{Connectivity, Owners};
use crate::linalg::{LinalgError, ranks};

#[derive(Debug)]
pub struct Ownership {
    rank: usize,
    dim: usize,
    /// Per node, the process that owns it.
    owner: Vec<u32>,
    /// Every process's dofs, increasing, process by process: process p's are
    /// `dofs[offsets[p]..offsets[p + 1]]`.
    dofs: Vec<u32>,
    offsets: Vec<usize>,
    /// Scratch for `complete`: this process's values, and everyone's.
    work: Mutex<(Vec<f64>, Vec<f64>)>,
}

impl Ownership {
    /// The nodes of `cells` split among the processes of this run (METIS's partition of the
    /// graph of nodes that share a cell, the same on every process); None in a run of one.
    /// `cells` is plain data, so that this layer knows nothing of meshes: `fem` converts a
    /// `&Mesh` into it (`Mesh::connectivity`).
    pub fn of<'c>(cells: impl Into<Connectivity<'c>>) -> Result<Option<Arc<Ownership>>, LinalgError> {
        let cells: Connectivity = cells.into();
        let (rank, size) = ranks::world();
        if size == 1 {
            return Ok(None);
        }
        #[cfg(feature = "petsc")]
        {
            let owner = crate::linalg::petsc::partition_nodes(&cells, size)?;
            // Each process partitioned alone: a process whose METIS (another build, another
            // machine of a cluster) split otherwise would exchange the wrong rows, silently.
            let ownership = Ownership::new(owner, cells.dim, rank, size);
            let mut first = ownership.fingerprint().to_le_bytes().to_vec();
            ranks::broadcast(&mut first)?;
            if ranks::any(first != ownership.fingerprint().to_le_bytes())? {
                return Err(LinalgError::Other(format!(
                    "the processes split the mesh's {} nodes differently (METIS gave rank {rank} other parts than rank 0): every process must run the same build",
                    cells.num_nodes
                )));
            }
            Ok(Some(Arc::new(ownership)))
        }
        #[cfg(not(feature = "petsc"))]
        Err(LinalgError::Other(format!(
            "{size} processes, in a build without MPI (rank {rank}, {} nodes)",
            cells.num_nodes
        )))
    }

    /// The ownership of nodes by `owner` (node → process, `size` processes), seen from process
    /// `rank`, for `dim` dofs per node.
    pub fn new(owner: Vec<u32>, dim: usize, rank: usize, size: usize) -> Ownership {
        let mut offsets = vec![0usize; size + 1];
        for &p in &owner {
            offsets[p as usize + 1] += dim;
        }
        for p in 0..size {
            offsets[p + 1] += offsets[p];
        }
        let mut next = offsets.clone();
        let mut dofs = vec![0u32; owner.len() * dim];
        for (node, &p) in owner.iter().enumerate() {
            for c in 0..dim {
                dofs[next[p as usize]] = (node * dim + c) as u32;
                next[p as usize] += 1;
            }
        }
        Ownership { rank, dim, owner, dofs, offsets, work: Mutex::new((Vec::new(), Vec::new())) }
    }

    /// The value of an exchange, or the end of every process with its error: the exchanges sit
    /// inside products and sums, which cannot fail, and there is no state to go on from.
    fn or_end<T>(&self, result: Result<T, LinalgError>) -> T {
        result.unwrap_or_else(|e| {
            eprintln!("error (rank {} of {}): {e}", self.rank, self.offsets.len() - 1);
            ranks::abort(1)
        })
    }

    /// This process's dofs, increasing.
    pub fn mine(&self) -> &[u32] {
        &self.dofs[self.offsets[self.rank]..self.offsets[self.rank + 1]]
    }

    /// A 64-bit FNV-1a hash of the partition (node → process): the same on every process of a
    /// run, and in every run on as many processes of the same mesh and build.
    pub fn fingerprint(&self) -> u64 {
        self.owner
            .iter()
            .flat_map(|p| p.to_le_bytes())
            .fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
    }
}

impl Owners for Ownership {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.offsets.len() - 1
    }

    fn dim(&self) -> usize {
        self.dim
    }

    fn owners(&self) -> &[u32] {
        &self.owner
    }

    /// Whether `flag` holds on any process. Collective; an MPI failure ends every process.
    fn any(&self, flag: bool) -> bool {
        self.or_end(ranks::any(flag))
    }

    /// The sum of every process's `x`, added in rank order (the same bits on every process).
    /// Collective; an MPI failure ends every process.
    fn sum(&self, x: f64) -> f64 {
        self.or_end(ranks::sum(x))
    }

    /// Makes `y`, right at this process's dofs, whole: every process's dofs take their owner's
    /// values. Collective: every process calls it at the same point. An MPI failure ends every
    /// process (there is no state to go on from).
    fn complete(&self, y: &mut [f64]) {
        let mut work = self.work.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let (mine, all) = &mut *work;
        mine.clear();
        mine.extend(self.mine().iter().map(|&i| y[i as usize]));
        all.resize(self.dofs.len(), 0.0);
        self.or_end(ranks::gather_parts(mine, &self.offsets, all));
        for (&i, &v) in self.dofs.iter().zip(all.iter()) {
            y[i as usize] = v;
        }
    }
}
