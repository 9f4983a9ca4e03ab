//! Facet loops: one visitor ([`visit`]) gathers each facet's cell, fields and context in the
//! order of the facets given; the residual, tangent, element-matrix, switch, value and
//! point-value loops are what they do with them. Contact regions are small, so the loops are
//! serial.

use super::{Job, PointValue, gather, locals, with_refs};
use crate::fem::kernel::{
    FacetCtx, FacetTabulation, FormKernel, FunctionalKernel, LocalMatrix, LocalVector, Tabulation,
};
use crate::fem::mesh::Facet;
use crate::fem::quadrature::Rule;
use crate::linalg::element_matrices::ElementMatrices;
use crate::linalg::pattern::Pattern;

/// A facet loop: a job on the facets of one of its kernel's regions.
pub(super) struct FacetJob<'a, K> {
    pub job: Job<'a, K>,
    /// The region's index among the kernel's facet regions.
    pub region: usize,
    pub facets: &'a [Facet],
}

impl<K> FacetJob<'_, K> {
    /// Calls `each(facet, its cell's nodes, context, local fields)` on each facet in order (of
    /// the job's cells), with the tabulations `tabs`.
    fn visit<const D: usize, const N: usize>(
        &self,
        tabs: &FacetTabulation<D, N>,
        mut each: impl FnMut(Facet, &[u32], &FacetCtx<'_, D, N>, &[&LocalVector<D, N>]),
    ) {
        let mesh = self.job.mesh;
        let mut local = locals::<D, N>(self.job.fields.len());
        for &f in self.facets.iter().filter(|f| self.job.visits(f.cell as usize)) {
            let c = f.cell as usize;
            let cell = mesh.cell(c);
            let coords = mesh.cell_coords::<D, N>(c);
            gather(cell, self.job.fields, &mut local);
            let (tab, ref_normal) = &tabs.facets[f.local as usize];
            let ctx = FacetCtx { tab, ref_normal, coords: &coords, h: mesh.cell_size(c), t: self.job.t };
            with_refs(&local, |refs| each(f, cell, &ctx, refs));
        }
    }

    /// As [`FacetJob::visit`], with the tabulations of the job's quadrature degree.
    fn visit_shared<const D: usize, const N: usize>(
        &self,
        each: impl FnMut(Facet, &[u32], &FacetCtx<'_, D, N>, &[&LocalVector<D, N>]),
    ) {
        let tabs = FacetTabulation::<D, N>::shared(self.job.mesh.kind, self.job.degree).expect("kind matches D and N");
        self.visit(&tabs, each);
    }

    /// Calls `each(cell index, cell nodes, element matrix)` with each facet's tangent with
    /// respect to field `wrt`.
    fn tangents<const D: usize, const N: usize>(
        &self,
        wrt: usize,
        mut each: impl FnMut(usize, &[u32], &LocalMatrix<D, N>),
    ) where
        K: FormKernel<D, N>,
    {
        let mut ke: Box<LocalMatrix<D, N>> = Box::new([[[[0.0; D]; N]; D]; N]);
        self.visit_shared::<D, N>(|f, cell, ctx, refs| {
            *ke = [[[[0.0; D]; N]; D]; N];
            self.job.kernel.facet_tangent(self.region, ctx, refs, wrt, &mut ke);
            each(f.cell as usize, cell, &ke);
        });
    }
}

/// Adds the facets' residuals into `out`.
pub(super) fn facet_residual<const D: usize, const N: usize, K: FormKernel<D, N>>(
    job: &FacetJob<'_, K>,
    out: &mut [f64],
) {
    job.visit_shared::<D, N>(|_, cell, ctx, refs| {
        let mut re = [[0.0; D]; N];
        job.job.kernel.facet_residual(job.region, ctx, refs, &mut re);
        for j in 0..N {
            let n = cell[j] as usize;
            for a in 0..D {
                out[n * D + a] += re[j][a];
            }
        }
    });
}

/// Adds the facets' tangents with respect to field `wrt` into `values` (of `pattern`).
pub(super) fn facet_tangent<const D: usize, const N: usize, K: FormKernel<D, N>>(
    job: &FacetJob<'_, K>,
    wrt: usize,
    pattern: &Pattern,
    values: &mut [f64],
) {
    job.tangents::<D, N>(wrt, |c, cell, ke| pattern.scatter(c, cell, ke, values));
}

/// Appends the facets' tangents with respect to field `wrt` to `out`, and with `scatter` also
/// adds each into those values of the pattern (one evaluation for both).
pub(super) fn facet_tangent_elements<const D: usize, const N: usize, K: FormKernel<D, N>>(
    job: &FacetJob<'_, K>,
    wrt: usize,
    mut scatter: Option<(&Pattern, &mut [f64])>,
    out: &mut ElementMatrices,
) {
    out.size = N * D;
    job.tangents::<D, N>(wrt, |c, cell, ke| {
        if let Some((pattern, values)) = scatter.as_mut() {
            pattern.scatter(c, cell, ke, values);
        }
        out.dofs.extend(cell.iter().flat_map(|&node| (0..D).map(move |m| node as usize * D + m)));
        // [test node][test component][trial node][trial component]: row-major (N·D)².
        out.values.extend(ke.iter().flatten().flatten().flatten());
    });
}

/// Appends the facets' active-set switches of field `wrt` to `out`; whether the tangent
/// depends on the fields only through them on every facet (`FormKernel::facet_switches`).
pub(super) fn facet_switches<const D: usize, const N: usize, K: FormKernel<D, N>>(
    job: &FacetJob<'_, K>,
    wrt: usize,
    out: &mut Vec<bool>,
) -> bool {
    let mut piecewise = true;
    job.visit_shared::<D, N>(|_, _, ctx, refs| {
        piecewise &= job.job.kernel.facet_switches(job.region, ctx, refs, wrt, out);
    });
    piecewise
}

/// The functional's integral over the facets, summed in their order.
pub(super) fn facet_value<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(job: &FacetJob<'_, K>) -> f64 {
    let mut total = 0.0;
    job.visit_shared::<D, N>(|_, _, ctx, refs| total += job.job.kernel.facet_value(job.region, ctx, refs));
    total
}

/// The functional's integrand at the points of `rule` on each facet (see
/// [`super::Assembler::facet_point_values`]).
pub(super) fn facet_point_values<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(
    job: &FacetJob<'_, K>,
    rule: &Rule,
) -> Vec<PointValue> {
    let tabs = FacetTabulation::<D, N>::with_rule(job.job.mesh.kind, rule).expect("kind matches D and N");
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
    let mut out = Vec::with_capacity(job.facets.len() * rule.weights.len());
    job.visit(&tabs, |f, _, ctx, refs| {
        for (q, one) in single[f.local as usize].iter().enumerate() {
            let jac = crate::fem::geometry::jacobian(ctx.coords, &ctx.tab.dphi[q]);
            let (normal, scale) = crate::fem::geometry::facet_normal(&jac, ctx.ref_normal);
            let value = job.job.kernel.facet_value(job.region, &FacetCtx { tab: one, ..*ctx }, refs) / scale;
            let x = crate::fem::geometry::interpolate(ctx.coords, &ctx.tab.phi[q]);
            out.push(PointValue { x: x.to_vec(), normal: normal.to_vec(), weight: ctx.tab.weights[q] * scale, value });
        }
    });
    out
}
