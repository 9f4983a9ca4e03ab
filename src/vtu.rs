//! ParaView output of our own: VTU (XML UnstructuredGrid, ASCII) with P1/P2 cells, point and
//! cell data, and a PVD collection carrying the physical times. Files are written whole or not
//! at all.

use std::fmt::Write;
use std::path::Path;

use crate::runtime::fem::mesh::Mesh;

/// A data array: name, components, values (`len = count × components`).
pub struct Field<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

/// Writes one VTU file. Point fields have one tuple per node; vector fields of the mesh's
/// dimension are padded to 3 components, as ParaView expects.
pub fn write(path: &Path, mesh: &Mesh, point_data: &[Field], cell_data: &[Field]) -> std::io::Result<()> {
    write_cells(path, mesh, None, point_data, cell_data)
}

/// Writes one process's piece of a snapshot: the mesh's cells `cells` (cell fields have one
/// tuple per listed cell) and the nodes they use, renumbered in increasing order (point fields
/// have one tuple per node of the whole mesh).
pub fn write_piece(
    path: &Path,
    mesh: &Mesh,
    cells: &[usize],
    point_data: &[Field],
    cell_data: &[Field],
) -> std::io::Result<()> {
    write_cells(path, mesh, Some(cells), point_data, cell_data)
}

/// Writes the parallel file (PVTU) of a snapshot's pieces (files relative to its directory),
/// declaring the fields each piece holds.
pub fn write_parallel(
    path: &Path,
    dim: usize,
    pieces: &[String],
    point_data: &[Field],
    cell_data: &[Field],
) -> std::io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PUnstructuredGrid GhostLevel=\"0\">\n",
    );
    s.push_str("<PPoints>\n<PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n</PPoints>\n");
    let declare = |s: &mut String, tag: &str, fields: &[Field]| {
        let _ = writeln!(s, "<{tag}>");
        for f in fields {
            let _ = writeln!(
                s,
                "<PDataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\"/>",
                f.name,
                padded(f, dim)
            );
        }
        let _ = writeln!(s, "</{tag}>");
    };
    declare(&mut s, "PPointData", point_data);
    declare(&mut s, "PCellData", cell_data);
    for piece in pieces {
        let _ = writeln!(s, "<Piece Source=\"{piece}\"/>");
    }
    s.push_str("</PUnstructuredGrid>\n</VTKFile>\n");
    crate::output::write_atomic(path, s.as_bytes())
}

/// The components a field is written with: vectors of the mesh's dimension padded to 3.
fn padded(f: &Field, dim: usize) -> usize {
    if f.components == dim && dim < 3 { 3 } else { f.components }
}

/// Writes `cells` of the mesh (all, in order, with every node, if None).
fn write_cells(
    path: &Path,
    mesh: &Mesh,
    cells: Option<&[usize]>,
    point_data: &[Field],
    cell_data: &[Field],
) -> std::io::Result<()> {
    let d = mesh.dim();
    // The nodes written, in order, and each node's index among them.
    let (used, index): (Vec<usize>, Vec<u32>) = match cells {
        None => ((0..mesh.num_nodes()).collect(), (0..mesh.num_nodes() as u32).collect()),
        Some(cells) => {
            let mut seen = vec![false; mesh.num_nodes()];
            cells.iter().for_each(|&c| mesh.cell(c).iter().for_each(|&n| seen[n as usize] = true));
            let used: Vec<usize> = (0..seen.len()).filter(|&i| seen[i]).collect();
            let mut index = vec![u32::MAX; seen.len()];
            used.iter().enumerate().for_each(|(k, &i)| index[i] = k as u32);
            (used, index)
        }
    };
    let listed: Vec<usize> = match cells {
        None => (0..mesh.num_cells()).collect(),
        Some(cells) => cells.to_vec(),
    };
    let (nodes, cells) = (used.len(), listed.len());
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    let _ = writeln!(s, "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{nodes}\" NumberOfCells=\"{cells}\">");
    s.push_str("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for &i in &used {
        let p = mesh.node(i);
        let _ = writeln!(s, "{} {} {}", p[0], p.get(1).copied().unwrap_or(0.0), p.get(2).copied().unwrap_or(0.0));
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    // VTK's node order (its cell type's), from the element catalogue.
    let info = mesh.kind.info();
    for &c in &listed {
        let cell = mesh.cell(c);
        let ids: Vec<String> = info.vtk_order.iter().map(|&k| index[cell[k] as usize].to_string()).collect();
        let _ = writeln!(s, "{}", ids.join(" "));
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    let npc = mesh.kind.nodes();
    let offsets: Vec<String> = (1..=cells).map(|c| (c * npc).to_string()).collect();
    let _ = writeln!(s, "{}", offsets.join(" "));
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let _ = writeln!(s, "{}", vec![info.vtk.to_string(); cells].join(" "));
    s.push_str("</DataArray>\n</Cells>\n");
    // Point fields are read at the written nodes, cell fields in order.
    let arrays = |s: &mut String, fields: &[Field], at: &mut dyn Iterator<Item = usize>| {
        let at: Vec<usize> = at.collect();
        for f in fields {
            let padded = padded(f, d);
            let _ = writeln!(
                s,
                "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{padded}\" format=\"ascii\">",
                f.name
            );
            for &i in &at {
                let mut tuple: Vec<String> =
                    f.values[i * f.components..(i + 1) * f.components].iter().map(|v| v.to_string()).collect();
                tuple.resize(padded, "0".into());
                let _ = writeln!(s, "{}", tuple.join(" "));
            }
            s.push_str("</DataArray>\n");
        }
    };
    s.push_str("<PointData>\n");
    arrays(&mut s, point_data, &mut used.iter().copied());
    s.push_str("</PointData>\n<CellData>\n");
    arrays(&mut s, cell_data, &mut (0..cells));
    s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    crate::output::write_atomic(path, s.as_bytes())
}

/// Writes a PVD collection of (time, file relative to the PVD's directory).
pub fn write_collection(path: &Path, entries: &[(f64, String)]) -> std::io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (t, file) in entries {
        let t = crate::numbers::time(*t);
        let _ = writeln!(s, "<DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{file}\"/>");
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    crate::output::write_atomic(path, s.as_bytes())
}
