//! Boundary facets found topologically: a facet shared by two cells is interior, a facet of one
//! cell is on the boundary. Facets are identified by their sorted vertex numbers.

use std::collections::HashMap;

use super::{Facet, Mesh};

/// Sorted vertex numbers of a facet, padded with `u32::MAX` (1, 2 or 3 vertices).
pub fn facet_key(vertices: &[u32]) -> [u32; 3] {
    let mut key = [u32::MAX; 3];
    key[..vertices.len()].copy_from_slice(vertices);
    key[..vertices.len()].sort_unstable();
    key
}

pub(super) fn boundary_facets(mesh: &Mesh) -> Vec<Facet> {
    let local = mesh.kind.facets();
    let mut count: HashMap<[u32; 3], (u32, Facet)> = HashMap::with_capacity(mesh.num_cells() * local.len());
    for c in 0..mesh.num_cells() {
        let cell = mesh.cell(c);
        for (f, verts) in local.iter().enumerate() {
            let vs: Vec<u32> = verts.iter().map(|&v| cell[v]).collect();
            let entry = count.entry(facet_key(&vs)).or_insert((0, Facet { cell: c as u32, local: f as u8 }));
            entry.0 += 1;
        }
    }
    let mut out: Vec<Facet> = count.into_values().filter(|(n, _)| *n == 1).map(|(_, f)| f).collect();
    out.sort_unstable();
    out
}
