//! VTU and PVD output of the disc, read back by an independent reader (vtkio): cell types,
//! point and cell counts, data arrays and the collection's times.

use signorini::cases::disc;
use signorini::problem::run::Options;
use vtkio::model::{Attribute, CellType, DataSet, Piece, VertexNumbers};

#[test]
fn snapshots_read_back_with_vtkio() {
    let out = std::env::temp_dir().join(format!("signorini-vtu-{}", std::process::id()));
    let methods = disc::options().methods.set("h", 2.0);
    let opts = Options { methods, t_end: Some(1.0), vtu_every: 25, out: Some(out.clone()), ..disc::options() };
    let run = disc::run(&opts).unwrap();
    // The problem's mesh at h = 2: the built-in curved disc of radius 10 about (0, 12).
    let mesh = signorini::runtime::fem::mesh::disc::disc(10.0, [0.0, 12.0], 2.0);
    // The collection: one entry per snapshot, with the physical times.
    let pvd = std::fs::read_to_string(out.join("disc.pvd")).unwrap();
    let times: Vec<f64> =
        pvd.split("timestep=\"").skip(1).map(|s| s[..s.find('"').unwrap()].parse().unwrap()).collect();
    assert_eq!(times, vec![0.0, 0.5, 1.0]);
    assert_eq!(run.summary.steps, 50);
    for (k, name) in ["disc_000000.vtu", "disc_000025.vtu", "disc_000050.vtu"].iter().enumerate() {
        assert!(pvd.contains(&format!("file=\"vtu/{name}\"")));
        let vtk = vtkio::Vtk::import(out.join("vtu").join(name)).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("{name}: not an unstructured grid") };
        let Piece::Inline(piece) = &pieces[0] else { panic!("{name}: piece not inline") };
        assert_eq!(piece.num_points(), mesh.num_nodes());
        assert_eq!(piece.cells.types.len(), mesh.num_cells());
        assert!(piece.cells.types.iter().all(|t| *t == CellType::QuadraticTriangle));
        let VertexNumbers::XML { connectivity, offsets } = &piece.cells.cell_verts else {
            panic!("{name}: not XML cells")
        };
        assert_eq!(connectivity.len(), 6 * mesh.num_cells());
        assert_eq!(*offsets.last().unwrap() as usize, 6 * mesh.num_cells());
        let names = |attrs: &[Attribute]| -> Vec<(String, usize)> {
            attrs
                .iter()
                .filter_map(|a| match a {
                    Attribute::DataArray(d) => Some((d.name.clone(), d.data.len())),
                    _ => None,
                })
                .collect()
        };
        assert_eq!(
            names(&piece.data.point),
            vec![("displacement".into(), 3 * mesh.num_nodes()), ("velocity".into(), 3 * mesh.num_nodes())]
        );
        assert_eq!(
            names(&piece.data.cell),
            vec![("von_mises".into(), mesh.num_cells()), ("body".into(), mesh.num_cells())]
        );
        // Free fall: the displacement is uniform, −½ g t² vertically.
        let Attribute::DataArray(u) = &piece.data.point[0] else { unreachable!() };
        let values: Vec<f64> = u.data.clone().cast_into::<f64>().unwrap();
        let t = times[k];
        assert!((values[1] + 0.05 * t * t).abs() < 1e-10, "{name}: u_y = {}", values[1]);
    }
}

/// VTK's quadratic tetrahedron numbers its edge nodes (0,1), (1,2), (2,0), (0,3), (1,3), (2,3)
/// (VTK's VTK_QUADRATIC_TETRA), unlike Gmsh: on a straight P2 mesh every edge node written must
/// be the midpoint of the vertices VTK pairs it with.
#[test]
fn quadratic_tetrahedra_follow_vtk_node_order() {
    let unit = [0.0, 1.0];
    let mesh = signorini::runtime::fem::mesh::structured::cuboid([2, 2, 2], unit, unit, unit, 2);
    let path = std::env::temp_dir().join(format!("signorini-tet10-{}.vtu", std::process::id()));
    signorini::vtu::write(&path, &mesh, &[], &[]).unwrap();
    let vtk = vtkio::Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let Piece::Inline(piece) = &pieces[0] else { panic!("piece not inline") };
    assert!(piece.cells.types.iter().all(|t| *t == CellType::QuadraticTetra));
    let VertexNumbers::XML { connectivity, .. } = &piece.cells.cell_verts else { panic!("not XML cells") };
    let points: Vec<f64> = piece.points.clone().cast_into::<f64>().unwrap();
    let p = |i: u64| &points[3 * i as usize..3 * i as usize + 3];
    const VTK_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
    for cell in connectivity.chunks(10) {
        for (k, [a, b]) in VTK_EDGES.iter().enumerate() {
            let (m, pa, pb) = (p(cell[4 + k]), p(cell[*a]), p(cell[*b]));
            for j in 0..3 {
                assert!((m[j] - 0.5 * (pa[j] + pb[j])).abs() < 1e-14, "edge node {} of {cell:?}", 4 + k);
            }
        }
    }
    let _ = std::fs::remove_file(path);
}
