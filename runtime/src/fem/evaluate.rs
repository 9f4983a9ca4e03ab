//! Point values of fields: at the quadrature points of boundary facets (for penetration and
//! contact pressure) and at nodes.

use crate::fem::kernel::FacetTabulation;
use crate::fem::mesh::{Facet, Mesh};

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
            let jac = crate::fem::geometry::jacobian(&coords, &tab.dphi[q]);
            let (_, scale) = crate::fem::geometry::facet_normal(&jac, normal);
            let x = crate::fem::geometry::interpolate(&coords, phi);
            let mut value = vec![0.0; D];
            for j in 0..N {
                for k in 0..D {
                    value[k] += phi[j] * field[cell[j] as usize * D + k];
                }
            }
            out.push(FacetSample { x: x.to_vec(), value, weight: tab.weights[q] * scale });
        }
    }
    out
}

/// An exact solution: value and gradient (`[component][direction]`, row-major) at a point.
pub type ExactSolution = dyn Fn(&[f64]) -> (Vec<f64>, Vec<f64>);

/// ‖u_h − u‖_L2 and |u_h − u|_H1 of a vector field against an exact solution, whose value and
/// gradient (`[component][direction]`, row-major) `exact(x)` returns; integrated with the cell
/// rule of `degree` on the isoparametric cells.
pub fn errors(mesh: &Mesh, field: &[f64], degree: u32, exact: &ExactSolution) -> (f64, f64) {
    dispatch!(mesh.kind, cell_errors(mesh, field, degree, exact))
}

fn cell_errors<const D: usize, const N: usize>(
    mesh: &Mesh,
    field: &[f64],
    degree: u32,
    exact: &ExactSolution,
) -> (f64, f64) {
    let tab = crate::fem::kernel::Tabulation::<D, N>::cell(mesh.kind, degree).expect("kind matches D and N");
    let (mut l2, mut h1) = (0.0, 0.0);
    for c in 0..mesh.num_cells() {
        let coords = mesh.cell_coords::<D, N>(c);
        let cell = mesh.cell(c);
        let local: [[f64; D]; N] = std::array::from_fn(|j| std::array::from_fn(|k| field[cell[j] as usize * D + k]));
        for q in 0..tab.len() {
            let jac = crate::fem::geometry::jacobian(&coords, &tab.dphi[q]);
            let w = tab.weights[q] * jac.det.abs();
            let dphi = crate::fem::geometry::physical_gradients(&jac, &tab.dphi[q]);
            let x = crate::fem::geometry::interpolate(&coords, &tab.phi[q]);
            let uh = crate::fem::geometry::interpolate(&local, &tab.phi[q]);
            let gh = crate::fem::geometry::gradient(&local, &dphi);
            let (u, g) = exact(&x);
            for k in 0..D {
                l2 += w * (uh[k] - u[k]).powi(2);
                for l in 0..D {
                    h1 += w * (gh[k][l] - g[k * D + l]).powi(2);
                }
            }
        }
    }
    (l2.sqrt(), h1.sqrt())
}
