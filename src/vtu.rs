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
    let d = mesh.dim();
    let (nodes, cells) = (mesh.num_nodes(), mesh.num_cells());
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    let _ = writeln!(s, "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{nodes}\" NumberOfCells=\"{cells}\">");
    s.push_str("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for i in 0..nodes {
        let p = mesh.node(i);
        let _ = writeln!(s, "{} {} {}", p[0], p.get(1).copied().unwrap_or(0.0), p.get(2).copied().unwrap_or(0.0));
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    // VTK's node order (its cell type's), from the element catalogue.
    let info = mesh.kind.info();
    for c in 0..cells {
        let cell = mesh.cell(c);
        let ids: Vec<String> = info.vtk_order.iter().map(|&k| cell[k].to_string()).collect();
        let _ = writeln!(s, "{}", ids.join(" "));
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    let npc = mesh.kind.nodes();
    let offsets: Vec<String> = (1..=cells).map(|c| (c * npc).to_string()).collect();
    let _ = writeln!(s, "{}", offsets.join(" "));
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let _ = writeln!(s, "{}", vec![info.vtk.to_string(); cells].join(" "));
    s.push_str("</DataArray>\n</Cells>\n");
    let arrays = |s: &mut String, fields: &[Field], count: usize| {
        for f in fields {
            let padded = if f.components == d && d < 3 { 3 } else { f.components };
            let _ = writeln!(
                s,
                "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{padded}\" format=\"ascii\">",
                f.name
            );
            for i in 0..count {
                let mut tuple: Vec<String> =
                    f.values[i * f.components..(i + 1) * f.components].iter().map(|v| v.to_string()).collect();
                tuple.resize(padded, "0".into());
                let _ = writeln!(s, "{}", tuple.join(" "));
            }
            s.push_str("</DataArray>\n");
        }
    };
    s.push_str("<PointData>\n");
    arrays(&mut s, point_data, nodes);
    s.push_str("</PointData>\n<CellData>\n");
    arrays(&mut s, cell_data, cells);
    s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    crate::output::write_atomic(path, s.as_bytes())
}

/// Writes a PVD collection of (time, file relative to the PVD's directory).
pub fn write_collection(path: &Path, entries: &[(f64, String)]) -> std::io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (t, file) in entries {
        let _ = writeln!(s, "<DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{file}\"/>");
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    crate::output::write_atomic(path, s.as_bytes())
}
