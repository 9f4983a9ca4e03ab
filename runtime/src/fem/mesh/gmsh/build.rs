//! Raw nodes and elements to a mesh: node and cell numbering by tag, the cells of the highest
//! dimension, physical groups as boundary regions (matched to cell facets) and cell groups,
//! and the geometry validated.

use std::collections::{BTreeMap, HashMap};

use super::{At, Raw, RawElement, element_info, err, other_element_info};
use crate::fem::element::ElementKind;
use crate::fem::mesh::boundary::facet_key;
use crate::fem::mesh::{CellSize, Facet, Mesh, MeshError, Region};

pub(super) fn build(mut raw: Raw, file: &str) -> Result<Mesh, MeshError> {
    // Node numbering by increasing tag; tags must be distinct.
    raw.nodes.sort_by_key(|(tag, _, _)| *tag);
    for w in raw.nodes.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(err(file, w[1].2, format!("node tag {} is repeated", w[1].0)));
        }
    }
    let index_of = |tag: u64| raw.nodes.binary_search_by_key(&tag, |(t, _, _)| *t).ok();
    let dim = raw.elements.iter().filter_map(|e| element_info(e.kind)).map(|(d, _)| d).max().unwrap_or(0);
    let warnings = skipped_elements(&raw, dim, file)?;
    if dim == 0 {
        return Err(MeshError::File {
            file: file.to_string(),
            reason: "no lines, triangles or tetrahedra in `$Elements`".into(),
        });
    }
    let mut cells: Vec<&RawElement> =
        raw.elements.iter().filter(|e| element_info(e.kind).is_some_and(|(d, _)| d == dim)).collect();
    cells.sort_by_key(|e| e.tag);
    let kind = match ElementKind::from_gmsh(cells[0].kind) {
        Some(kind) => kind,
        None => {
            let k = cells[0].kind;
            let supported: Vec<String> =
                crate::fem::element::ELEMENTS.iter().map(|e| format!("{} ({})", e.name, e.gmsh)).collect();
            return Err(err(
                file,
                cells[0].at,
                format!("element type {k} cannot be a cell (supported: {})", supported.join(", ")),
            ));
        }
    };
    if let Some(other) = cells.iter().find(|e| e.kind != cells[0].kind) {
        return Err(err(
            file,
            other.at,
            format!("mixed cell types ({} and {}): one element kind per mesh", cells[0].kind, other.kind),
        ));
    }
    for w in cells.windows(2) {
        if w[0].tag == w[1].tag {
            return Err(err(file, w[1].at, format!("element tag {} is repeated", w[1].tag)));
        }
    }
    // Keep only the nodes cells use, in tag order.
    let mut used = vec![false; raw.nodes.len()];
    let mut cell_nodes: Vec<usize> = Vec::new();
    for e in &cells {
        for &t in &e.nodes {
            let i = index_of(t).ok_or_else(|| {
                err(file, e.at, format!("element {} refers to node {t}, which is not in `$Nodes`", e.tag))
            })?;
            used[i] = true;
            cell_nodes.push(i);
        }
    }
    let mut new_index = vec![u32::MAX; raw.nodes.len()];
    let mut coords = Vec::new();
    for (i, (_, x, at)) in raw.nodes.iter().enumerate() {
        if used[i] {
            new_index[i] = (coords.len() / dim as usize) as u32;
            if x[dim as usize..].iter().any(|v| *v != 0.0) {
                return Err(err(
                    file,
                    *at,
                    format!("a {dim}D mesh must lie in the plane of its first {dim} coordinates (this node has {x:?})"),
                ));
            }
            coords.extend_from_slice(&x[..dim as usize]);
        }
    }
    let cells_flat: Vec<u32> = cell_nodes.iter().map(|&i| new_index[i]).collect();
    let mut mesh = Mesh {
        kind,
        coords,
        cells: cells_flat,
        regions: Vec::new(),
        cell_groups: Vec::new(),
        bodies: Vec::new(),
        warnings,
        cell_size: CellSize::Diameter,
        sizes: Vec::new(),
    };
    mesh.validate().map_err(|e| located(e, &cells, file))?;
    let name_of = |d: u32, tag: i64| raw.names.get(&(d, tag)).cloned().unwrap_or_else(|| format!("physical_{tag}"));
    // Cell groups.
    let mut groups: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    for (c, e) in cells.iter().enumerate() {
        for &p in &e.physicals {
            groups.entry(name_of(dim, p)).or_default().push(c as u32);
        }
    }
    mesh.cell_groups = groups.into_iter().collect();
    // Elements one dimension below the cells must be facets of cells: anything else is a cell
    // of another dimension mixed in (triangles beside a tetrahedron), which would be dropped.
    // Those in physical groups become boundary regions, matched by vertices.
    let facet_elements: Vec<&RawElement> =
        raw.elements.iter().filter(|e| element_info(e.kind).is_some_and(|(d, _)| d + 1 == dim)).collect();
    if !facet_elements.is_empty() {
        // Some(facet) on the boundary, None inside.
        let mut facet_of: HashMap<[u32; 3], Option<Facet>> = HashMap::new();
        for c in 0..mesh.num_cells() {
            let cell = mesh.cell(c);
            for (f, verts) in kind.info().facets.iter().enumerate() {
                let vs: Vec<u32> = verts.iter().map(|&v| cell[v]).collect();
                facet_of
                    .entry(facet_key(&vs))
                    .and_modify(|e| *e = None)
                    .or_insert(Some(Facet { cell: c as u32, local: f as u8 }));
            }
        }
        let mixed = |e: &RawElement| {
            err(
                file,
                e.at,
                format!(
                    "element {} (type {}, dimension {}) is neither a cell nor a facet of one: \
                     the mesh mixes cells of dimensions {} and {dim}",
                    e.tag,
                    e.kind,
                    dim - 1,
                    dim - 1
                ),
            )
        };
        let mut regions: BTreeMap<String, Vec<Facet>> = BTreeMap::new();
        let vertices = dim as usize; // a facet of a d-simplex has d vertices
        for e in facet_elements {
            let mut vs = Vec::with_capacity(vertices);
            for &t in e.nodes.iter().take(vertices) {
                let i = index_of(t).ok_or_else(|| {
                    err(file, e.at, format!("element {} refers to node {t}, which is not in `$Nodes`", e.tag))
                })?;
                if new_index[i] == u32::MAX {
                    if e.physicals.is_empty() {
                        return Err(mixed(e));
                    }
                    return Err(err(
                        file,
                        e.at,
                        format!("boundary element {} uses node {t}, which no cell uses", e.tag),
                    ));
                }
                vs.push(new_index[i]);
            }
            let found = facet_of.get(&facet_key(&vs));
            if e.physicals.is_empty() {
                if found.is_none() {
                    return Err(mixed(e));
                }
                continue;
            }
            let f = found
                .copied()
                .flatten()
                .ok_or_else(|| err(file, e.at, format!("element {} is not a boundary facet of any cell", e.tag)))?;
            for &p in &e.physicals {
                regions.entry(name_of(dim - 1, p)).or_default().push(f);
            }
        }
        for (name, mut facets) in regions {
            facets.sort_unstable();
            facets.dedup();
            mesh.regions.push(Region { name, facets });
        }
    }
    // A named boundary group without elements stays a region, empty: a case that asks for it
    // then says so, instead of falling back to a default choice of facets.
    let mut declared: Vec<&String> =
        raw.names.iter().filter(|((d, _), _)| *d + 1 == dim).map(|(_, name)| name).collect();
    declared.sort();
    for name in declared {
        if !mesh.has_region(name) {
            mesh.regions.push(Region { name: name.clone(), facets: Vec::new() });
        }
    }
    Ok(mesh)
}

/// A validation error at the line (byte) of the element it names, with element tags (Gmsh
/// numbers) beside our cell numbers.
fn located(e: MeshError, cells: &[&RawElement], file: &str) -> MeshError {
    let tags = |cs: &[usize]| -> Vec<String> { cs.iter().map(|&c| cells[c].tag.to_string()).collect() };
    match e {
        MeshError::Degenerate { cell, .. } | MeshError::Inverted { cell } => {
            err(file, cells[cell].at, format!("element {}: {e}", cells[cell].tag))
        }
        MeshError::DuplicateCell { first, second } | MeshError::SameSide { first, second } => {
            let t = tags(&[first, second]);
            err(file, cells[second].at, format!("elements {} and {}: {e}", t[0], t[1]))
        }
        MeshError::FacetSharedByMany { cells: ref cs } if !cs.is_empty() => {
            let at = cells[cs[cs.len() - 1]].at;
            err(file, at, format!("elements {}: {e}", tags(cs).join(", ")))
        }
        other => MeshError::File { file: file.to_string(), reason: other.to_string() },
    }
}

/// Elements of types we do not use. Those of the cells' dimension or above are part of the
/// body: dropping them would leave a hole, so they are an error. Lower ones (quadrangle faces
/// beside tetrahedra) only lose their physical groups: a warning, by type and count.
fn skipped_elements(raw: &Raw, dim: u32, file: &str) -> Result<Vec<String>, MeshError> {
    let mut by_kind: BTreeMap<u32, (usize, u64, At)> = BTreeMap::new();
    for &(kind, tag, at) in &raw.skipped {
        by_kind.entry(kind).or_insert((0, tag, at)).0 += 1;
    }
    let mut warnings = Vec::new();
    for (kind, (count, tag, at)) in by_kind {
        let Some((d, _, name)) = other_element_info(kind) else { continue };
        if d >= dim {
            return Err(err(
                file,
                at,
                format!(
                    "element {tag} is a {name} (type {kind}, {count} in the file): cells must be \
                     lines, triangles or tetrahedra (one kind per mesh), and dropping it would leave a hole"
                ),
            ));
        }
        let w = format!(
            "{file}: skipped {count} {name} element(s) (type {kind}), which a {dim}D simplex mesh does not use"
        );
        tracing::warn!("{w}");
        warnings.push(w);
    }
    Ok(warnings)
}
