//! A form written by hand against the kernel interface, so the runtime is tested without the
//! compiler: ∫ ρ u·v + k ∇u : ∇v (vector-valued, every component alike).

use signorini_runtime::descriptors::Borrowed;
use signorini_runtime::fem::geometry::{gradient, interpolate, jacobian, physical_gradients};
use signorini_runtime::fem::kernel::{CellCtx, Form, FormKernel, FormMeta, LocalMatrix, LocalVector};

pub struct MassStiffness {
    pub rho: f64,
    pub k: f64,
}

const META: FormMeta = FormMeta {
    name: Borrowed("mass_stiffness"),
    fields: Borrowed(&[Borrowed("u")]),
    test: Borrowed("v"),
    linear: true,
    piecewise: false,
    previous: false,
    cell_degree: Some([2, 4]),
    facets: Borrowed(&[]),
    facet_sites: Borrowed(&[]),
    tangential: None,
};

impl Form for MassStiffness {
    fn meta(&self) -> &FormMeta {
        &META
    }
}

impl<const D: usize, const N: usize> FormKernel<D, N> for MassStiffness {
    fn cell_residual(&self, ctx: &CellCtx<'_, D, N>, fields: &[&LocalVector<D, N>], out: &mut LocalVector<D, N>) {
        for q in 0..ctx.tab.len() {
            let jac = jacobian(ctx.coords, &ctx.tab.dphi[q]);
            let w = ctx.tab.weights[q] * jac.det.abs();
            let g = physical_gradients(&jac, &ctx.tab.dphi[q]);
            let u = interpolate(fields[0], &ctx.tab.phi[q]);
            let gu = gradient(fields[0], &g);
            for i in 0..N {
                for a in 0..D {
                    let mut s = self.rho * u[a] * ctx.tab.phi[q][i];
                    for l in 0..D {
                        s += self.k * gu[a][l] * g[i][l];
                    }
                    out[i][a] += w * s;
                }
            }
        }
    }

    fn cell_tangent(
        &self,
        ctx: &CellCtx<'_, D, N>,
        _fields: &[&LocalVector<D, N>],
        _wrt: usize,
        out: &mut LocalMatrix<D, N>,
    ) {
        for q in 0..ctx.tab.len() {
            let jac = jacobian(ctx.coords, &ctx.tab.dphi[q]);
            let w = ctx.tab.weights[q] * jac.det.abs();
            let g = physical_gradients(&jac, &ctx.tab.dphi[q]);
            let phi = &ctx.tab.phi[q];
            for i in 0..N {
                for j in 0..N {
                    let dot: f64 = (0..D).map(|l| g[i][l] * g[j][l]).sum();
                    let s = w * (self.rho * phi[i] * phi[j] + self.k * dot);
                    for a in 0..D {
                        out[i][a][j][a] += s;
                    }
                }
            }
        }
    }
}

/// A deterministic pseudo-random vector in [−1, 1].
#[allow(dead_code)] // each test crate compiles this module; not all of them use this
pub fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}
