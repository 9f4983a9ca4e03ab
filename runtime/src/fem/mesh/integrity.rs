//! Topological integrity: a mesh must be a conforming partition of its domain, or measures,
//! boundaries and contact zones come out silently wrong (a file listing every cell twice has
//! twice the mass and no boundary at all).
//!
//! The checks, all on vertex numbers and straight (vertex) simplices, in O(n log n):
//! - no two cells have the same vertex set (duplicates, in any node order);
//! - a facet bounds at most two cells, and two cells sharing a facet lie on opposite sides of
//!   it. This is the test for overlap: in a conforming mesh whose cells do not overlap, the
//!   cells around an interior facet fill the two half-spaces it separates, one cell each.
//!   A third cell, or a second cell on the same side, covers points already covered.
//!
//! A global comparison of the cells' measure with the measure the boundary encloses
//! (divergence theorem, Σ x·n/d over boundary facets) adds nothing here: with each boundary
//! facet's normal taken outward from its own cell, the sum equals Σ cell measures minus the
//! interior facets that do not cancel, which are exactly the same-side pairs caught above.
//! What stays undetected is overlap between cells that share no facet (a detached layer of
//! cells with nodes of its own, lying over the mesh): that needs a geometric search.

use super::{Mesh, MeshError};

/// Runs the checks above; errors name the cells involved.
pub(super) fn check(mesh: &Mesh) -> Result<(), MeshError> {
    duplicates(mesh)?;
    shared_facets(mesh)
}

/// Sorted vertex numbers of a cell, padded with `u32::MAX`.
fn vertex_key(mesh: &Mesh, c: usize) -> [u32; 4] {
    let nv = mesh.kind.vertices();
    let mut key = [u32::MAX; 4];
    key[..nv].copy_from_slice(&mesh.cell(c)[..nv]);
    key[..nv].sort_unstable();
    key
}

fn duplicates(mesh: &Mesh) -> Result<(), MeshError> {
    let mut keys: Vec<([u32; 4], u32)> = (0..mesh.num_cells()).map(|c| (vertex_key(mesh, c), c as u32)).collect();
    keys.sort_unstable();
    match keys.windows(2).find(|w| w[0].0 == w[1].0) {
        Some(w) => Err(MeshError::DuplicateCell { first: w[0].1 as usize, second: w[1].1 as usize }),
        None => Ok(()),
    }
}

fn shared_facets(mesh: &Mesh) -> Result<(), MeshError> {
    let local = mesh.kind.facets();
    let mut all: Vec<([u32; 3], u32, u8)> = Vec::with_capacity(mesh.num_cells() * local.len());
    for c in 0..mesh.num_cells() {
        let cell = mesh.cell(c);
        for (f, verts) in local.iter().enumerate() {
            let mut vs = [0; 3];
            for (k, &v) in verts.iter().enumerate() {
                vs[k] = cell[v];
            }
            all.push((super::facet_key(&vs[..verts.len()]), c as u32, f as u8));
        }
    }
    all.sort_unstable();
    let mut i = 0;
    while i < all.len() {
        let mut j = i + 1;
        while j < all.len() && all[j].0 == all[i].0 {
            j += 1;
        }
        match j - i {
            1 => {}
            2 => {
                let (a, b) = (all[i], all[i + 1]);
                let (sa, sb) =
                    (side(mesh, &a.0, a.1, &local[a.2 as usize]), side(mesh, &b.0, b.1, &local[b.2 as usize]));
                // A zero side is a flat vertex simplex (a curved cell's chord): undecided.
                if sa * sb > 0.0 {
                    return Err(MeshError::SameSide { first: a.1 as usize, second: b.1 as usize });
                }
            }
            _ => {
                let cells = all[i..j].iter().map(|e| e.1 as usize).collect();
                return Err(MeshError::FacetSharedByMany { cells });
            }
        }
        i = j;
    }
    Ok(())
}

/// The side of the facet `key` (its vertices in sorted order) on which the vertex of cell `c`
/// opposite its local facet (`facet`, local vertex numbers) lies: +1, -1, or 0 when the vertex simplex is nearly flat.
fn side(mesh: &Mesh, key: &[u32; 3], c: u32, facet: &[usize]) -> f64 {
    let d = mesh.dim();
    let cell = mesh.cell(c as usize);
    let Some(opp) = (0..=d).find(|v| !facet.contains(v)) else { return 0.0 };
    let p = mesh.node(cell[opp] as usize);
    let o = mesh.node(key[0] as usize);
    let mut m = [[0.0; 3]; 3];
    for k in 0..d {
        for (r, &v) in key[1..d].iter().enumerate() {
            m[r][k] = mesh.node(v as usize)[k] - o[k];
        }
        m[d - 1][k] = p[k] - o[k];
    }
    let det = super::det(&m, d);
    let h = mesh.cell_diameter(c as usize);
    if det.abs() <= 1e-12 * h.powi(d as i32) { 0.0 } else { det.signum() }
}
