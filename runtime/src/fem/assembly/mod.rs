//! Assembly of compiled forms into global vectors and matrices.
//!
//! Dofs are node-major (`node * d + component`, one vector Lagrange node per mesh node). The
//! sparsity pattern of a mesh is built once; for each cell it stores, for every pair of its
//! nodes (i, j), the offset of node i's first row inside node j's columns, so element matrices
//! are added in place without searching.
//!
//! Cell loops (module `cells`) run on rayon's threads in the order of [`CellOrder`]: blocks of
//! consecutive cells, colour by colour, the blocks of a colour sharing no node and each run by
//! one thread in mesh order. Every entry receives its cells' contributions in one order
//! whatever the number of threads, so results have the same bits on one thread or many, and a
//! block adds into nearby entries as a serial loop would. Facet loops (module `facets`) visit a
//! region's facets in their order (contact regions are small), through one visitor.

mod cells;
mod facets;
mod order;

use std::sync::{Arc, OnceLock};

use self::cells::{cell_residual, cell_tangent, cell_values};
use self::facets::{
    FacetJob, facet_point_values, facet_residual, facet_switches, facet_tangent, facet_tangent_elements, facet_value,
};
pub use self::order::CellOrder;
use crate::fem::element::ElementKind;
use crate::fem::kernel::{Form, FormKernel, FormMeta, FunctionalKernel, LocalVector};
use crate::fem::mesh::{Facet, Mesh, MeshError};
use crate::fem::quadrature::Rule;
use crate::linalg::Matrix;
use crate::linalg::element_matrices::ElementMatrices;
use crate::linalg::pattern::Owners;
pub use crate::linalg::pattern::Pattern;

on_every_element_kind!(
    /// A kernel usable on every element kind of the catalogue (every generated form is).
    Kernel: FormKernel
);
on_every_element_kind!(
    /// A functional usable on every element kind of the catalogue.
    Functional: FunctionalKernel
);

/// Quadrature degrees chosen for a form: its suggestion for the element degree unless
/// overridden.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Quadrature {
    pub cell: Option<u32>,
    pub facet: Option<u32>,
}

impl Quadrature {
    pub fn degrees(cell: u32, facet: u32) -> Self {
        Quadrature { cell: Some(cell), facet: Some(facet) }
    }

    fn cell_degree(&self, meta: &FormMeta, kind: ElementKind) -> u32 {
        self.cell.unwrap_or_else(|| meta.cell_degree.map_or(1, |d| d[kind.degree() as usize - 1]))
    }

    fn facet_degree(&self, meta: &FormMeta, kind: ElementKind, region: usize) -> u32 {
        self.facet.unwrap_or_else(|| meta.facets.get(region).map_or(1, |(_, d)| d[kind.degree() as usize - 1]))
    }
}

/// One of a form's boundary integrals, on some mesh facets: the integral over `region` (a name
/// among the form's facet regions, `FormMeta::facets`) evaluated on `facets`, with `quadrature`.
pub struct FacetIntegral<'a, K> {
    pub kernel: &'a K,
    pub region: &'a str,
    pub facets: &'a [Facet],
    pub quadrature: Quadrature,
    /// Only the facets of these cells, if given (a body's: per cell, whether it is one).
    pub cells: Option<&'a [bool]>,
}

/// A form's volume integral: over every cell of the mesh, or over a body's (`cells`: per cell,
/// whether it is one).
pub struct CellIntegral<'a, K> {
    pub kernel: &'a K,
    pub quadrature: Quadrature,
    pub cells: Option<&'a [bool]>,
}

impl<'a, K> CellIntegral<'a, K> {
    /// Over every cell.
    pub fn all(kernel: &'a K, quadrature: Quadrature) -> Self {
        CellIntegral { kernel, quadrature, cells: None }
    }
}

/// Assembles forms on one mesh into vectors and matrices sharing one pattern.
pub struct Assembler<'m> {
    // Private: the cell order and the pattern's cell offsets belong to this mesh, and the
    // threaded cell loops rely on that (their writes are disjoint only for the mesh they were
    // built for).
    mesh: &'m Mesh,
    pattern: Arc<Pattern>,
    /// The blocks of cells and their colours (computed on first use).
    order: OnceLock<CellOrder>,
    /// The cells this process counts in volume integrals: the mesh's first `owned` (all of them
    /// unless the run is split across processes, `Mesh::part`).
    owned: usize,
}

/// What a loop over cells or facets evaluates: a kernel at some fields and a time, with a
/// quadrature degree, on a mesh.
pub(crate) struct Job<'a, K> {
    mesh: &'a Mesh,
    /// The cells a cell loop visits, if not all (a body's).
    cells: Option<&'a [bool]>,
    kernel: &'a K,
    degree: u32,
    fields: &'a [&'a [f64]],
    t: f64,
}

impl<'m> Assembler<'m> {
    pub fn new(mesh: &'m Mesh) -> Self {
        let pattern = Arc::new(Pattern::new(&mesh.connectivity()));
        Assembler { mesh, pattern, order: OnceLock::new(), owned: mesh.num_cells() }
    }

    /// As `new`, with the node pairs `extra` coupled too: the cells of two bodies' surfaces that
    /// may touch (`PairForm::couplings`).
    pub fn with_couplings(mesh: &'m Mesh, extra: &[(u32, u32)]) -> Self {
        let pattern = Arc::new(Pattern::with_couplings(&mesh.connectivity(), extra));
        Assembler { mesh, pattern, order: OnceLock::new(), owned: mesh.num_cells() }
    }

    /// One process's assembler in a run split across processes: `mesh` is its part of the
    /// whole (`Mesh::part`), whose first `owned` cells it owns. Residuals and products are then
    /// whole on every process (`Owners::complete`), volume integrals sum the owned cells of
    /// every process, and facet integrals are computed whole by each.
    pub fn split(mesh: &'m Mesh, ownership: Arc<dyn Owners>, owned: usize) -> Self {
        Assembler::split_with_couplings(mesh, ownership, owned, &[])
    }

    /// As `split`, with the node pairs `extra` coupled too (`with_couplings`): a contact pair's
    /// surfaces, which every process keeps whole.
    pub fn split_with_couplings(
        mesh: &'m Mesh,
        ownership: Arc<dyn Owners>,
        owned: usize,
        extra: &[(u32, u32)],
    ) -> Self {
        let pattern = Arc::new(Pattern::with_couplings(&mesh.connectivity(), extra).owned_by(ownership));
        Assembler { mesh, pattern, order: OnceLock::new(), owned }
    }

    /// The cells whose volume integrals this process counts: the mesh's first `owned_cells()`.
    pub fn owned_cells(&self) -> usize {
        self.owned
    }

    /// The order of the cell loops: blocks of consecutive cells, coloured so that no two blocks
    /// of a colour share a node.
    pub fn cell_order(&self) -> &CellOrder {
        self.order.get_or_init(|| CellOrder::of(self.mesh))
    }

    pub fn mesh(&self) -> &'m Mesh {
        self.mesh
    }

    /// The sparsity pattern of every matrix assembled here.
    pub fn pattern(&self) -> &Arc<Pattern> {
        &self.pattern
    }

    /// Number of dofs.
    pub fn size(&self) -> usize {
        self.pattern.size()
    }

    pub fn zero_matrix(&self) -> Matrix {
        Matrix::zeros(self.pattern.clone())
    }

    fn cell_job<'a, K: Form>(&'a self, on: CellIntegral<'a, K>, fields: &'a [&'a [f64]], t: f64) -> Job<'a, K> {
        let (k, q) = (on.kernel, on.quadrature);
        Job { mesh: self.mesh, cells: on.cells, kernel: k, degree: q.cell_degree(k.meta(), self.mesh.kind), fields, t }
    }

    /// The loop over `on`'s facets, or `None` if its kernel has no such region.
    fn facet_job<'a, K: Form>(
        &'a self,
        on: &FacetIntegral<'a, K>,
        fields: &'a [&'a [f64]],
        t: f64,
    ) -> Option<FacetJob<'a, K>> {
        let (k, kind) = (on.kernel, self.mesh.kind);
        let region = region_index(k.meta(), on.region)?;
        let degree = on.quadrature.facet_degree(k.meta(), kind, region);
        let job = Job { mesh: self.mesh, cells: on.cells, kernel: k, degree, fields, t };
        Some(FacetJob { job, region, facets: on.facets })
    }

    /// Adds the volume part of `on`'s residual at `fields` to `out`.
    pub fn cell_residual<K: Kernel>(&self, on: CellIntegral<'_, K>, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        let job = self.cell_job(on, fields, t);
        dispatch!(self.mesh.kind, cell_residual::<K>(&job, self.cell_order(), out));
        self.pattern.complete(out);
    }

    /// Adds the volume part of `on`'s tangent with respect to field `wrt` to `m`.
    pub fn cell_tangent<K: Kernel>(
        &self,
        on: CellIntegral<'_, K>,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        m: &mut Matrix,
    ) {
        let job = self.cell_job(on, fields, t);
        dispatch!(self.mesh.kind, cell_tangent::<K>(&job, self.cell_order(), &self.pattern, wrt, &mut m.values))
    }

    /// Adds the residual of the boundary integral `on` at `fields` to `out`.
    pub fn facet_residual<K: Kernel>(&self, on: FacetIntegral<'_, K>, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        let Some(job) = self.facet_job(&on, fields, t) else { return };
        dispatch!(self.mesh.kind, facet_residual::<K>(&job, out))
    }

    /// Adds the tangent of the boundary integral `on` with respect to field `wrt` to `m`.
    pub fn facet_tangent<K: Kernel>(
        &self,
        on: FacetIntegral<'_, K>,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        m: &mut Matrix,
    ) {
        let Some(job) = self.facet_job(&on, fields, t) else { return };
        dispatch!(self.mesh.kind, facet_tangent::<K>(&job, wrt, &self.pattern, &mut m.values))
    }

    /// Appends the element matrices of the tangent of the boundary integral `on`, one per facet
    /// (over its cell's dofs), to `out`; with `m`, also adds them into `m` as
    /// [`Assembler::facet_tangent`] does (one evaluation for both).
    pub fn facet_tangent_elements<K: Kernel>(
        &self,
        on: FacetIntegral<'_, K>,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        m: Option<&mut Matrix>,
        out: &mut ElementMatrices,
    ) {
        let Some(job) = self.facet_job(&on, fields, t) else { return };
        let scatter = m.map(|m| (self.pattern.as_ref(), m.values.as_mut_slice()));
        dispatch!(self.mesh.kind, facet_tangent_elements::<K>(&job, wrt, scatter, out))
    }

    /// Appends the active-set switches of the boundary integral `on` (field `wrt`) to `out`;
    /// whether the tangent depends on the fields only through them there.
    pub fn facet_switches<K: Kernel>(
        &self,
        on: FacetIntegral<'_, K>,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        out: &mut Vec<bool>,
    ) -> bool {
        let Some(job) = self.facet_job(&on, fields, t) else { return true };
        dispatch!(self.mesh.kind, facet_switches::<K>(&job, wrt, out))
    }

    /// The volume integral of a functional at `fields` (collective in a split run).
    pub fn cell_value<K: Functional>(&self, on: CellIntegral<'_, K>, fields: &[&[f64]], t: f64) -> f64 {
        let mine: f64 = self.cell_values(on, fields, t)[..self.owned].iter().sum();
        match self.pattern.ownership() {
            Some(o) => o.sum(mine),
            None => mine,
        }
    }

    /// The volume integral of a functional on each cell (of this process's part, in a split
    /// run; zero on the cells `on` does not visit).
    pub fn cell_values<K: Functional>(&self, on: CellIntegral<'_, K>, fields: &[&[f64]], t: f64) -> Vec<f64> {
        let job = self.cell_job(on, fields, t);
        dispatch!(self.mesh.kind, cell_values::<K>(&job))
    }

    /// The boundary integral `on` of a functional at `fields`.
    pub fn facet_value<K: Functional>(&self, on: FacetIntegral<'_, K>, fields: &[&[f64]], t: f64) -> f64 {
        let Some(job) = self.facet_job(&on, fields, t) else { return 0.0 };
        dispatch!(self.mesh.kind, facet_value::<K>(&job))
    }

    /// The integrand of a functional's boundary region `region` at the points of `rule` (a rule
    /// on the reference facet) on each of `facets`, with the point, the outward normal and the
    /// weight that integrates over the physical facet: a contact pressure profile, say.
    pub fn facet_point_values<K: Functional>(
        &self,
        on: FacetIntegral<'_, K>,
        rule: &Rule,
        fields: &[&[f64]],
        t: f64,
    ) -> Vec<PointValue> {
        let Some(region) = region_index(on.kernel.meta(), on.region) else { return Vec::new() };
        // The degree is unused: `rule` gives the points.
        let job = Job { mesh: self.mesh, cells: on.cells, kernel: on.kernel, degree: 0, fields, t };
        dispatch!(self.mesh.kind, facet_point_values::<K>(&FacetJob { job, region, facets: on.facets }, rule))
    }

    /// Facets of a named mesh region.
    pub fn region(&self, name: &str) -> Result<&'m [Facet], MeshError> {
        Ok(&self.mesh.region(name)?.facets)
    }
}

/// A functional's integrand at one point of a boundary facet.
#[derive(Clone, Debug, PartialEq)]
pub struct PointValue {
    pub x: Vec<f64>,
    /// The outward unit normal of the (curved) facet at `x`.
    pub normal: Vec<f64>,
    /// The rule's weight times the facet's measure scaling at `x`.
    pub weight: f64,
    pub value: f64,
}

fn region_index(meta: &FormMeta, region: &str) -> Option<usize> {
    meta.facets.iter().position(|(name, _)| *name == region)
}

/// Copies the values of global fields at a cell's nodes into local arrays.
#[inline]
fn gather<const D: usize, const N: usize>(cell: &[u32], fields: &[&[f64]], local: &mut [LocalVector<D, N>]) {
    for (f, l) in fields.iter().zip(local.iter_mut()) {
        for j in 0..N {
            let n = cell[j] as usize;
            l[j].copy_from_slice(&f[n * D..n * D + D]);
        }
    }
}

fn locals<const D: usize, const N: usize>(count: usize) -> Vec<LocalVector<D, N>> {
    vec![[[0.0; D]; N]; count]
}

/// Calls `f` with references to the local fields, without allocating for up to three fields.
#[inline]
fn with_refs<const D: usize, const N: usize, R>(
    local: &[LocalVector<D, N>],
    f: impl FnOnce(&[&LocalVector<D, N>]) -> R,
) -> R {
    match local {
        [] => f(&[]),
        [a] => f(&[a]),
        [a, b] => f(&[a, b]),
        [a, b, c] => f(&[a, b, c]),
        _ => f(&local.iter().collect::<Vec<_>>()),
    }
}
