//! Cell loops: residuals and tangents added block by block in the order of [`CellOrder`],
//! functionals cell by cell in mesh order.

use super::order::{CellOrder, Disjoint};
use super::{Job, gather, locals, with_refs};
use crate::fem::kernel::{CellCtx, FormKernel, FunctionalKernel, LocalMatrix, Tabulation};
use crate::linalg::pattern::Pattern;

impl<K> Job<'_, K> {
    /// Whether a loop visits cell `c` (or the facets it carries).
    #[inline]
    pub(super) fn visits(&self, c: usize) -> bool {
        self.cells.is_none_or(|cells| cells[c])
    }

    fn tabulation<const D: usize, const N: usize>(&self) -> Tabulation<D, N> {
        Tabulation::<D, N>::cell(self.mesh.kind, self.degree).expect("kind matches D and N")
    }
}

/// Adds the cells' residuals into `out`.
pub(super) fn cell_residual<const D: usize, const N: usize, K: FormKernel<D, N> + Sync>(
    job: &Job<'_, K>,
    order: &CellOrder,
    out: &mut [f64],
) {
    let (mesh, tab, t) = (job.mesh, job.tabulation::<D, N>(), job.t);
    let len = out.len();
    let target = Disjoint::new(out);
    order.for_each_block(
        || locals::<D, N>(job.fields.len()),
        |local, cells| {
            for c in cells.filter(|&c| job.visits(c)) {
                let cell = mesh.cell(c);
                let coords = mesh.cell_coords::<D, N>(c);
                gather(cell, job.fields, local);
                let mut re = [[0.0; D]; N];
                with_refs(local, |refs| {
                    job.kernel.cell_residual(&CellCtx { tab: &tab, coords: &coords, t }, refs, &mut re)
                });
                for j in 0..N {
                    for a in 0..D {
                        let i = cell[j] as usize * D + a;
                        assert!(i < len);
                        // SAFETY: in bounds of `out`, which outlives the loop, and the other
                        // blocks of this colour have none of this cell's nodes.
                        unsafe { target.add_at(i, re[j][a]) };
                    }
                }
            }
        },
    );
}

/// Adds the cells' tangents with respect to field `wrt` into `values` (of `pattern`).
pub(super) fn cell_tangent<const D: usize, const N: usize, K: FormKernel<D, N> + Sync>(
    job: &Job<'_, K>,
    order: &CellOrder,
    pattern: &Pattern,
    wrt: usize,
    values: &mut [f64],
) {
    let (mesh, tab, t) = (job.mesh, job.tabulation::<D, N>(), job.t);
    let len = values.len();
    let target = Disjoint::new(values);
    order.for_each_block(
        || (locals::<D, N>(job.fields.len()), Box::new([[[[0.0; D]; N]; D]; N])),
        |(local, ke): &mut (_, Box<LocalMatrix<D, N>>), cells| {
            for c in cells.filter(|&c| job.visits(c)) {
                let cell = mesh.cell(c);
                let coords = mesh.cell_coords::<D, N>(c);
                gather(cell, job.fields, local);
                **ke = [[[[0.0; D]; N]; D]; N];
                with_refs(local, |refs| {
                    job.kernel.cell_tangent(&CellCtx { tab: &tab, coords: &coords, t }, refs, wrt, ke)
                });
                pattern.scatter_with(c, cell, ke, |i, v| {
                    assert!(i < len);
                    // SAFETY: in bounds of `values`, which outlives the loop, and the entries of
                    // this cell's node pairs belong to no other block of its colour.
                    unsafe { target.add_at(i, v) }
                });
            }
        },
    );
}

/// The functional's integral over each cell, in mesh order.
pub(super) fn cell_values<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(job: &Job<'_, K>) -> Vec<f64> {
    let (mesh, tab, t) = (job.mesh, job.tabulation::<D, N>(), job.t);
    let mut local = locals::<D, N>(job.fields.len());
    (0..mesh.num_cells())
        .map(|c| {
            if !job.visits(c) {
                return 0.0;
            }
            let coords = mesh.cell_coords::<D, N>(c);
            gather(mesh.cell(c), job.fields, &mut local);
            with_refs(&local, |refs| job.kernel.cell_value(&CellCtx { tab: &tab, coords: &coords, t }, refs))
        })
        .collect()
}
