//! Point values of fields: at the quadrature points of boundary facets (for penetration and
//! contact pressure) and at nodes.

use crate::kernel::FacetTabulation;
use crate::mesh::{Facet, Mesh};

/// A field sampled at a facet quadrature point.
#[derive(Clone, Debug, PartialEq)]
pub struct FacetSample {
    pub x: Vec<f64>,
    pub value: Vec<f64>,
    /// Quadrature weight times the facet's measure scaling at the point.
    pub weight: f64,
}

/// Values of a vector field (node-major, `dim` components) at the facet quadrature points of
/// degree `degree` on `facets`.
pub fn facet_samples(mesh: &Mesh, facets: &[Facet], degree: u32, field: &[f64]) -> Vec<FacetSample> {
    dispatch!(mesh.kind, samples(mesh, facets, degree, field))
}

fn samples<const D: usize, const N: usize>(
    mesh: &Mesh,
    facets: &[Facet],
    degree: u32,
    field: &[f64],
) -> Vec<FacetSample> {
    let tabs = FacetTabulation::<D, N>::new(mesh.kind, degree).expect("kind matches D and N");
    let mut out = Vec::new();
    for f in facets {
        let c = f.cell as usize;
        let coords = mesh.cell_coords::<D, N>(c);
        let cell = mesh.cell(c);
        let (tab, normal) = &tabs.facets[f.local as usize];
        for q in 0..tab.len() {
            let phi = &tab.phi[q];
            let jac = crate::geometry::jacobian(&coords, &tab.dphi[q]);
            let (_, scale) = crate::geometry::facet_normal(&jac, normal);
            let x = crate::geometry::interpolate(&coords, phi);
            let mut value = vec![0.0; D];
            for j in 0..N {
                for k in 0..D {
                    value[k] += phi[j] * field[cell[j] as usize * D + k];
                }
            }
            out.push(FacetSample {
                x: x.to_vec(),
                value,
                weight: tab.weights[q] * scale,
            });
        }
    }
    out
}
