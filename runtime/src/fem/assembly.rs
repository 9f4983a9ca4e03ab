//! Assembly of compiled forms into global vectors and matrices.
//!
//! Dofs are node-major (`node * d + component`, one vector Lagrange node per mesh node). The
//! sparsity pattern of a mesh is built once; for each cell it stores, for every pair of its
//! nodes (i, j), the offset of node i's first row inside node j's columns, so element matrices
//! are added in place without searching.
//!
//! Cell loops run on rayon's threads, colour by colour: the cells of a colour share no node,
//! so they add into disjoint entries, and every entry receives its cells' contributions in
//! colour order whatever the number of threads: results have the same bits on one thread or
//! many. Facet loops visit a region's facets in their order (contact regions are small).

use std::sync::{Arc, OnceLock};

use rayon::prelude::*;

use crate::fem::element::ElementKind;
use crate::fem::kernel::{
    CellCtx, FacetCtx, FacetTabulation, Form, FormKernel, FormMeta, FunctionalKernel, LocalMatrix, LocalVector,
    Tabulation,
};
use crate::fem::mesh::{Facet, Mesh, MeshError};
use crate::fem::quadrature::Rule;
use crate::linalg::Matrix;
use crate::linalg::element_matrices::ElementMatrices;
pub use crate::linalg::pattern::Pattern;

/// A kernel usable on every element kind of the catalogue (every generated form is).
pub trait Kernel:
    Form + FormKernel<1, 2> + FormKernel<2, 3> + FormKernel<2, 6> + FormKernel<3, 4> + FormKernel<3, 10> + Sync
{
}
impl<K> Kernel for K where
    K: Form + FormKernel<1, 2> + FormKernel<2, 3> + FormKernel<2, 6> + FormKernel<3, 4> + FormKernel<3, 10> + Sync
{
}

/// A functional usable on every element kind of the catalogue.
pub trait Functional:
    Form
    + FunctionalKernel<1, 2>
    + FunctionalKernel<2, 3>
    + FunctionalKernel<2, 6>
    + FunctionalKernel<3, 4>
    + FunctionalKernel<3, 10>
    + Sync
{
}
impl<K> Functional for K where
    K: Form
        + FunctionalKernel<1, 2>
        + FunctionalKernel<2, 3>
        + FunctionalKernel<2, 6>
        + FunctionalKernel<3, 4>
        + FunctionalKernel<3, 10>
        + Sync
{
}

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

/// Assembles forms on one mesh into vectors and matrices sharing one pattern.
pub struct Assembler<'m> {
    // Private: the colours and the pattern's cell offsets belong to this mesh, and the threaded
    // cell loops rely on that (their writes are disjoint only for the mesh they were built for).
    mesh: &'m Mesh,
    pattern: Arc<Pattern>,
    /// The cells by colour (computed on first use).
    colours: OnceLock<Vec<Vec<u32>>>,
}

impl<'m> Assembler<'m> {
    pub fn new(mesh: &'m Mesh) -> Self {
        Assembler { mesh, pattern: Arc::new(Pattern::new(&mesh.connectivity())), colours: OnceLock::new() }
    }

    /// The cells grouped so that no two cells of a group share a node, each group in
    /// increasing order.
    pub fn colours(&self) -> &[Vec<u32>] {
        self.colours.get_or_init(|| colour_cells(self.mesh))
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

    /// Adds the volume part of `k`'s residual at `fields` to `out`.
    pub fn cell_residual<K: Kernel>(&self, k: &K, q: Quadrature, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        let degree = q.cell_degree(k.meta(), self.mesh.kind);
        dispatch!(self.mesh.kind, cell_residual::<K>(self.mesh, self.colours(), k, degree, fields, t, out))
    }

    /// Adds the volume part of `k`'s tangent with respect to field `wrt` to `m`.
    pub fn cell_tangent<K: Kernel>(&self, k: &K, q: Quadrature, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix) {
        let degree = q.cell_degree(k.meta(), self.mesh.kind);
        dispatch!(
            self.mesh.kind,
            cell_tangent::<K>(self.mesh, self.colours(), &self.pattern, k, degree, fields, wrt, t, &mut m.values)
        )
    }

    /// Adds the residual of `k`'s integral over `region` (a name of `K::META.facets`) on the
    /// mesh facets `facets`.
    #[allow(clippy::too_many_arguments)]
    pub fn facet_residual<K: Kernel>(
        &self,
        k: &K,
        region: &str,
        facets: &[Facet],
        q: Quadrature,
        fields: &[&[f64]],
        t: f64,
        out: &mut [f64],
    ) {
        let Some(r) = region_index(k.meta(), region) else { return };
        let degree = q.facet_degree(k.meta(), self.mesh.kind, r);
        dispatch!(self.mesh.kind, facet_residual::<K>(self.mesh, k, r, facets, degree, fields, t, out))
    }

    /// Adds the tangent of `k`'s integral over `region` on `facets` to `m`.
    #[allow(clippy::too_many_arguments)]
    pub fn facet_tangent<K: Kernel>(
        &self,
        k: &K,
        region: &str,
        facets: &[Facet],
        q: Quadrature,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        m: &mut Matrix,
    ) {
        let Some(r) = region_index(k.meta(), region) else { return };
        let degree = q.facet_degree(k.meta(), self.mesh.kind, r);
        dispatch!(
            self.mesh.kind,
            facet_tangent::<K>(self.mesh, &self.pattern, k, r, facets, degree, fields, wrt, t, &mut m.values)
        )
    }

    /// Appends the element matrices of the tangent of `k`'s integral over `region`, one per
    /// facet of `facets` (over its cell's dofs), to `out`; with `m`, also adds them into `m` as
    /// [`Assembler::facet_tangent`] does (one evaluation for both).
    #[allow(clippy::too_many_arguments)]
    pub fn facet_tangent_elements<K: Kernel>(
        &self,
        k: &K,
        region: &str,
        facets: &[Facet],
        q: Quadrature,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        m: Option<&mut Matrix>,
        out: &mut ElementMatrices,
    ) {
        let Some(r) = region_index(k.meta(), region) else { return };
        let degree = q.facet_degree(k.meta(), self.mesh.kind, r);
        let scatter = m.map(|m| (self.pattern.as_ref(), m.values.as_mut_slice()));
        dispatch!(
            self.mesh.kind,
            facet_tangent_elements::<K>(self.mesh, k, r, facets, degree, fields, wrt, t, scatter, out)
        )
    }

    /// Appends the active-set switches of `k`'s integral over `region` on `facets`.
    #[allow(clippy::too_many_arguments)]
    pub fn facet_switches<K: Kernel>(
        &self,
        k: &K,
        region: &str,
        facets: &[Facet],
        q: Quadrature,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        out: &mut Vec<bool>,
    ) {
        let Some(r) = region_index(k.meta(), region) else { return };
        let degree = q.facet_degree(k.meta(), self.mesh.kind, r);
        dispatch!(self.mesh.kind, facet_switches::<K>(self.mesh, k, r, facets, degree, fields, wrt, t, out))
    }

    /// The volume integral of a functional at `fields`.
    pub fn cell_value<K: Functional>(&self, k: &K, q: Quadrature, fields: &[&[f64]], t: f64) -> f64 {
        let degree = q.cell_degree(k.meta(), self.mesh.kind);
        dispatch!(self.mesh.kind, cell_value::<K>(self.mesh, k, degree, fields, t))
    }

    /// The volume integral of a functional on each cell.
    pub fn cell_values<K: Functional>(&self, k: &K, q: Quadrature, fields: &[&[f64]], t: f64) -> Vec<f64> {
        let degree = q.cell_degree(k.meta(), self.mesh.kind);
        dispatch!(self.mesh.kind, cell_values::<K>(self.mesh, k, degree, fields, t))
    }

    /// The integral of a functional over its boundary region `region` on the mesh `facets`.
    #[allow(clippy::too_many_arguments)]
    pub fn facet_value<K: Functional>(
        &self,
        k: &K,
        region: &str,
        facets: &[Facet],
        q: Quadrature,
        fields: &[&[f64]],
        t: f64,
    ) -> f64 {
        let Some(r) = region_index(k.meta(), region) else { return 0.0 };
        let degree = q.facet_degree(k.meta(), self.mesh.kind, r);
        dispatch!(self.mesh.kind, facet_value::<K>(self.mesh, k, r, facets, degree, fields, t))
    }

    /// The integrand of a functional's boundary region `region` at the points of `rule` (a rule
    /// on the reference facet) on each of `facets`, with the point, the outward normal and the
    /// weight that integrates over the physical facet: a contact pressure profile, say.
    #[allow(clippy::too_many_arguments)]
    pub fn facet_point_values<K: Functional>(
        &self,
        k: &K,
        region: &str,
        facets: &[Facet],
        rule: &Rule,
        fields: &[&[f64]],
        t: f64,
    ) -> Vec<PointValue> {
        let Some(r) = region_index(k.meta(), region) else { return Vec::new() };
        dispatch!(self.mesh.kind, facet_points::<K>(self.mesh, k, r, facets, rule, fields, t))
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

/// Greedy colouring of the cells: each takes the smallest colour none of the cells sharing one
/// of its nodes has taken.
fn colour_cells(mesh: &Mesh) -> Vec<Vec<u32>> {
    let (inc_ptr, inc) = crate::linalg::pattern::cells_of_nodes(&mesh.connectivity());
    let mut colour = vec![u32::MAX; mesh.num_cells()];
    // taken[k] == c + 1: colour k is used by a neighbour of cell c.
    let mut taken: Vec<usize> = Vec::new();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for c in 0..mesh.num_cells() {
        for &n in mesh.cell(c) {
            for &other in &inc[inc_ptr[n as usize]..inc_ptr[n as usize + 1]] {
                let k = colour[other as usize];
                if k != u32::MAX {
                    taken[k as usize] = c + 1;
                }
            }
        }
        let k = (0..taken.len()).find(|&k| taken[k] != c + 1).unwrap_or(taken.len());
        if k == taken.len() {
            taken.push(0);
            groups.push(Vec::new());
        }
        colour[c] = k as u32;
        groups[k].push(c as u32);
    }
    groups
}

/// Cells per rayon task.
const CELLS_PER_TASK: usize = 64;

/// A vector or matrix's values written by the cells of one colour from several threads.
#[derive(Clone, Copy)]
struct Disjoint(*mut f64);
// SAFETY: the cells of a colour share no node, so the entries they add into are disjoint: no
// two threads touch the same value (see `add_at`).
unsafe impl Send for Disjoint {}
unsafe impl Sync for Disjoint {}

impl Disjoint {
    /// Adds `v` to entry `i`.
    ///
    /// # Safety
    /// `i` is in bounds and no other thread accesses entry `i` concurrently.
    #[inline]
    unsafe fn add_at(self, i: usize, v: f64) {
        unsafe { *self.0.add(i) += v }
    }
}

#[allow(clippy::too_many_arguments)]
fn cell_residual<const D: usize, const N: usize, K: FormKernel<D, N> + Sync>(
    mesh: &Mesh,
    colours: &[Vec<u32>],
    k: &K,
    degree: u32,
    fields: &[&[f64]],
    t: f64,
    out: &mut [f64],
) {
    let tab = Tabulation::<D, N>::cell(mesh.kind, degree).expect("kind matches D and N");
    let len = out.len();
    let target = Disjoint(out.as_mut_ptr());
    for cells in colours {
        cells.par_chunks(CELLS_PER_TASK).for_each_init(
            || locals::<D, N>(fields.len()),
            |local, chunk| {
                for &c in chunk {
                    let (c, cell) = (c as usize, mesh.cell(c as usize));
                    let coords = mesh.cell_coords::<D, N>(c);
                    gather(cell, fields, local);
                    let mut re = [[0.0; D]; N];
                    with_refs(local, |refs| k.cell_residual(&CellCtx { tab: &tab, coords: &coords, t }, refs, &mut re));
                    for j in 0..N {
                        for a in 0..D {
                            let i = cell[j] as usize * D + a;
                            assert!(i < len);
                            // SAFETY: in bounds, and this colour's other cells have other nodes.
                            unsafe { target.add_at(i, re[j][a]) };
                        }
                    }
                }
            },
        );
    }
}

#[inline]
fn add_local<const D: usize, const N: usize>(cell: &[u32], re: &LocalVector<D, N>, out: &mut [f64]) {
    for j in 0..N {
        let n = cell[j] as usize;
        for k in 0..D {
            out[n * D + k] += re[j][k];
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn cell_tangent<const D: usize, const N: usize, K: FormKernel<D, N> + Sync>(
    mesh: &Mesh,
    colours: &[Vec<u32>],
    pattern: &Pattern,
    k: &K,
    degree: u32,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    values: &mut [f64],
) {
    let tab = Tabulation::<D, N>::cell(mesh.kind, degree).expect("kind matches D and N");
    let len = values.len();
    let target = Disjoint(values.as_mut_ptr());
    for cells in colours {
        cells.par_chunks(CELLS_PER_TASK).for_each_init(
            || (locals::<D, N>(fields.len()), Box::new([[[[0.0; D]; N]; D]; N])),
            |(local, ke), chunk| {
                for &c in chunk {
                    let (c, cell) = (c as usize, mesh.cell(c as usize));
                    let coords = mesh.cell_coords::<D, N>(c);
                    gather(cell, fields, local);
                    **ke = [[[[0.0; D]; N]; D]; N];
                    with_refs(local, |refs| k.cell_tangent(&CellCtx { tab: &tab, coords: &coords, t }, refs, wrt, ke));
                    pattern.scatter_with(c, cell, ke, |i, v| {
                        assert!(i < len);
                        // SAFETY: in bounds, and the entries of this cell's node pairs belong to
                        // no other cell of its colour.
                        unsafe { target.add_at(i, v) }
                    });
                }
            },
        );
    }
}

fn facet_ctx<'a, const D: usize, const N: usize>(
    mesh: &Mesh,
    tabs: &'a FacetTabulation<D, N>,
    f: Facet,
    coords: &'a [[f64; D]; N],
    t: f64,
) -> FacetCtx<'a, D, N> {
    let (tab, ref_normal) = &tabs.facets[f.local as usize];
    FacetCtx { tab, ref_normal, coords, h: mesh.cell_size(f.cell as usize), t }
}

#[allow(clippy::too_many_arguments)]
fn facet_residual<const D: usize, const N: usize, K: FormKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    region: usize,
    facets: &[Facet],
    degree: u32,
    fields: &[&[f64]],
    t: f64,
    out: &mut [f64],
) {
    let tabs = FacetTabulation::<D, N>::shared(mesh.kind, degree).expect("kind matches D and N");
    let mut local = locals::<D, N>(fields.len());
    for &f in facets {
        let c = f.cell as usize;
        let cell = mesh.cell(c);
        let coords = mesh.cell_coords::<D, N>(c);
        gather(cell, fields, &mut local);
        let mut re = [[0.0; D]; N];
        with_refs(&local, |refs| k.facet_residual(region, &facet_ctx(mesh, &tabs, f, &coords, t), refs, &mut re));
        add_local(cell, &re, out);
    }
}

/// Calls `each(cell index, cell nodes, element matrix)` with the tangent of `k`'s integral over
/// `region` on each of `facets`.
#[allow(clippy::too_many_arguments)]
fn for_facet_tangents<const D: usize, const N: usize, K: FormKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    region: usize,
    facets: &[Facet],
    degree: u32,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    mut each: impl FnMut(usize, &[u32], &LocalMatrix<D, N>),
) {
    let tabs = FacetTabulation::<D, N>::shared(mesh.kind, degree).expect("kind matches D and N");
    let mut local = locals::<D, N>(fields.len());
    let mut ke: Box<LocalMatrix<D, N>> = Box::new([[[[0.0; D]; N]; D]; N]);
    for &f in facets {
        let c = f.cell as usize;
        let cell = mesh.cell(c);
        let coords = mesh.cell_coords::<D, N>(c);
        gather(cell, fields, &mut local);
        *ke = [[[[0.0; D]; N]; D]; N];
        with_refs(&local, |refs| k.facet_tangent(region, &facet_ctx(mesh, &tabs, f, &coords, t), refs, wrt, &mut ke));
        each(c, cell, &ke);
    }
}

#[allow(clippy::too_many_arguments)]
fn facet_tangent<const D: usize, const N: usize, K: FormKernel<D, N>>(
    mesh: &Mesh,
    pattern: &Pattern,
    k: &K,
    region: usize,
    facets: &[Facet],
    degree: u32,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    values: &mut [f64],
) {
    for_facet_tangents(mesh, k, region, facets, degree, fields, wrt, t, |c, cell, ke| {
        pattern.scatter(c, cell, ke, values)
    });
}

/// Appends the element matrices of the tangent of `k`'s integral over `region` on `facets` to
/// `out`, and with `scatter` also adds each into those values of the pattern (one evaluation
/// for both).
#[allow(clippy::too_many_arguments)]
fn facet_tangent_elements<const D: usize, const N: usize, K: FormKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    region: usize,
    facets: &[Facet],
    degree: u32,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    mut scatter: Option<(&Pattern, &mut [f64])>,
    out: &mut ElementMatrices,
) {
    out.size = N * D;
    for_facet_tangents(mesh, k, region, facets, degree, fields, wrt, t, |c, cell, ke| {
        if let Some((pattern, values)) = scatter.as_mut() {
            pattern.scatter(c, cell, ke, values);
        }
        out.dofs.extend(cell.iter().flat_map(|&node| (0..D).map(move |m| node as usize * D + m)));
        // [test node][test component][trial node][trial component]: row-major (N·D)².
        out.values.extend(ke.iter().flatten().flatten().flatten());
    });
}

#[allow(clippy::too_many_arguments)]
fn facet_switches<const D: usize, const N: usize, K: FormKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    region: usize,
    facets: &[Facet],
    degree: u32,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    out: &mut Vec<bool>,
) {
    let tabs = FacetTabulation::<D, N>::shared(mesh.kind, degree).expect("kind matches D and N");
    let mut local = locals::<D, N>(fields.len());
    for &f in facets {
        let c = f.cell as usize;
        let coords = mesh.cell_coords::<D, N>(c);
        gather(mesh.cell(c), fields, &mut local);
        with_refs(&local, |refs| k.facet_switches(region, &facet_ctx(mesh, &tabs, f, &coords, t), refs, wrt, out));
    }
}

fn cell_value<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    degree: u32,
    fields: &[&[f64]],
    t: f64,
) -> f64 {
    cell_values::<D, N, K>(mesh, k, degree, fields, t).iter().sum()
}

fn cell_values<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    degree: u32,
    fields: &[&[f64]],
    t: f64,
) -> Vec<f64> {
    let tab = Tabulation::<D, N>::cell(mesh.kind, degree).expect("kind matches D and N");
    let mut local = locals::<D, N>(fields.len());
    (0..mesh.num_cells())
        .map(|c| {
            let coords = mesh.cell_coords::<D, N>(c);
            gather(mesh.cell(c), fields, &mut local);
            with_refs(&local, |refs| k.cell_value(&CellCtx { tab: &tab, coords: &coords, t }, refs))
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn facet_points<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    region: usize,
    facets: &[Facet],
    rule: &Rule,
    fields: &[&[f64]],
    t: f64,
) -> Vec<PointValue> {
    let tabs = FacetTabulation::<D, N>::with_rule(mesh.kind, rule).expect("kind matches D and N");
    // One-point tabulations of unit weight: the kernel's facet integral is then the integrand
    // at that point times the facet's measure scaling there.
    let single: Vec<Vec<Tabulation<D, N>>> = tabs
        .facets
        .iter()
        .map(|(tab, _)| {
            (0..tab.len())
                .map(|q| Tabulation { weights: vec![1.0], phi: vec![tab.phi[q]], dphi: vec![tab.dphi[q]] })
                .collect()
        })
        .collect();
    let mut local = locals::<D, N>(fields.len());
    let mut out = Vec::with_capacity(facets.len() * rule.weights.len());
    for &f in facets {
        let c = f.cell as usize;
        let coords = mesh.cell_coords::<D, N>(c);
        gather(mesh.cell(c), fields, &mut local);
        let (tab, ref_normal) = &tabs.facets[f.local as usize];
        for (q, one) in single[f.local as usize].iter().enumerate() {
            let jac = crate::fem::geometry::jacobian(&coords, &tab.dphi[q]);
            let (normal, scale) = crate::fem::geometry::facet_normal(&jac, ref_normal);
            let ctx = FacetCtx { tab: one, ref_normal, coords: &coords, h: mesh.cell_size(c), t };
            let value = with_refs(&local, |refs| k.facet_value(region, &ctx, refs)) / scale;
            let x = crate::fem::geometry::interpolate(&coords, &tab.phi[q]);
            out.push(PointValue { x: x.to_vec(), normal: normal.to_vec(), weight: tab.weights[q] * scale, value });
        }
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn facet_value<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(
    mesh: &Mesh,
    k: &K,
    region: usize,
    facets: &[Facet],
    degree: u32,
    fields: &[&[f64]],
    t: f64,
) -> f64 {
    let tabs = FacetTabulation::<D, N>::shared(mesh.kind, degree).expect("kind matches D and N");
    let mut local = locals::<D, N>(fields.len());
    let mut total = 0.0;
    for &f in facets {
        let c = f.cell as usize;
        let coords = mesh.cell_coords::<D, N>(c);
        gather(mesh.cell(c), fields, &mut local);
        total += with_refs(&local, |refs| k.facet_value(region, &facet_ctx(mesh, &tabs, f, &coords, t), refs));
    }
    total
}
