//! Meshes that read but are wrong: repeated or overlapping cells, element types the reader
//! would drop, cells of two dimensions, regions of measure zero. Each must fail, naming where.

use std::path::Path;

use signorini_runtime::fem::element::ElementKind;
use signorini_runtime::fem::mesh::{Facet, Mesh, MeshError, Region, gmsh};

/// An MSH 2.2 file: nodes (x, y, z) numbered from 1, elements as (type, physical, nodes).
fn msh22(nodes: &[[f64; 3]], elements: &[(u32, i64, &[u64])]) -> String {
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    s += &format!("{}\n", nodes.len());
    for (i, x) in nodes.iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, x[0], x[1], x[2]);
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", elements.len());
    for (i, (kind, phys, ns)) in elements.iter().enumerate() {
        let ns: Vec<String> = ns.iter().map(u64::to_string).collect();
        s += &format!("{} {kind} 2 {phys} 1 {}\n", i + 1, ns.join(" "));
    }
    s + "$EndElements\n"
}

const SQUARE: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];

fn parse_err(text: &str) -> String {
    gmsh::parse(text.as_bytes(), "bad.msh").expect_err("the mesh must be refused").to_string()
}

#[test]
fn a_cell_listed_twice_in_another_node_order_is_refused() {
    let text = msh22(&SQUARE, &[(2, 0, &[1, 2, 3]), (2, 0, &[1, 3, 4]), (2, 0, &[3, 1, 2])]);
    let e = parse_err(&text);
    // Element 3 is on line 15 (12 lines of header and nodes before the elements).
    assert!(e.starts_with("bad.msh:15: elements 1 and 3: cells 0 and 2 have the same vertices"), "{e}");
}

#[test]
fn the_reference_disc_with_every_triangle_listed_twice_is_refused() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes/disc_r10_h1_v22.msh");
    let text = std::fs::read_to_string(p).unwrap();
    let (head, rest) = text.split_once("$Elements\n").unwrap();
    let (body, tail) = rest.split_once("$EndElements").unwrap();
    let mut lines = body.lines();
    let n: usize = lines.next().unwrap().trim().parse().unwrap();
    let elements: Vec<&str> = lines.collect();
    let mut doubled = format!("{head}$Elements\n{}\n", 2 * n);
    for l in &elements {
        doubled += &format!("{l}\n");
    }
    for l in &elements {
        // Same element again under a new tag.
        let (tag, rest) = l.split_once(' ').unwrap();
        doubled += &format!("{} {rest}\n", tag.parse::<usize>().unwrap() + n);
    }
    doubled += &format!("$EndElements{tail}");
    let e = gmsh::parse(doubled.as_bytes(), "doubled.msh").unwrap_err().to_string();
    assert!(e.contains("have the same vertices (a cell listed twice)"), "{e}");
    assert!(e.starts_with("doubled.msh:"), "{e}");
}

#[test]
fn a_triangle_over_two_others_is_refused() {
    // The square cut along 1-3, plus triangle 1-2-4 across the cut.
    let text = msh22(&SQUARE, &[(2, 0, &[1, 2, 3]), (2, 0, &[1, 3, 4]), (2, 0, &[1, 2, 4])]);
    let e = parse_err(&text);
    assert!(e.contains("share a facet and lie on the same side of it: they overlap"), "{e}");
    assert!(e.contains("elements 1 and 3") || e.contains("elements 2 and 3"), "{e}");
}

#[test]
fn three_cells_on_one_edge_are_refused() {
    let nodes = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 2.0, 0.0]];
    let text = msh22(&nodes, &[(2, 0, &[1, 2, 3]), (2, 0, &[2, 1, 4]), (2, 0, &[1, 2, 5])]);
    let e = parse_err(&text);
    assert!(e.contains("elements 1, 2, 3: cells 0, 1, 2 share one facet"), "{e}");
}

#[test]
fn overlap_in_a_mesh_built_in_code_names_the_cells() {
    let coords = SQUARE.iter().flat_map(|x| [x[0], x[1]]).collect();
    let m = Mesh::from_cells(ElementKind::TriangleP1, coords, vec![0, 1, 2, 0, 2, 3, 0, 1, 3]);
    assert_eq!(m.validate(), Err(MeshError::SameSide { first: 0, second: 2 }));
    let coords = SQUARE.iter().flat_map(|x| [x[0], x[1]]).collect();
    let m = Mesh::from_cells(ElementKind::TriangleP1, coords, vec![0, 1, 2, 0, 2, 3, 2, 3, 0]);
    assert_eq!(m.validate(), Err(MeshError::DuplicateCell { first: 1, second: 2 }));
}

#[test]
fn a_quadrangle_among_triangles_is_refused() {
    let nodes = [SQUARE[0], SQUARE[1], SQUARE[2], SQUARE[3], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]];
    let text = msh22(&nodes, &[(2, 0, &[1, 2, 3]), (2, 0, &[1, 3, 4]), (3, 0, &[2, 5, 6, 3])]);
    let e = parse_err(&text);
    assert!(e.starts_with("bad.msh:17: element 3 is a quadrangle (type 3, 1 in the file)"), "{e}");
}

#[test]
fn quadrangles_beside_tetrahedra_are_skipped_with_a_warning() {
    let nodes = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]];
    let text = msh22(&nodes, &[(4, 0, &[1, 2, 3, 4]), (3, 0, &[1, 2, 5, 3]), (3, 0, &[1, 2, 5, 3]), (15, 0, &[1])]);
    let m = gmsh::parse(text.as_bytes(), "quads.msh").unwrap();
    assert_eq!(m.num_cells(), 1);
    assert_eq!(m.warnings.len(), 1);
    assert!(m.warnings[0].contains("skipped 2 quadrangle element(s) (type 3)"), "{:?}", m.warnings);
}

#[test]
fn a_tetrahedron_in_a_triangle_mesh_is_refused() {
    let mut nodes = SQUARE.to_vec();
    nodes.push([0.0, 0.0, 1.0]);
    let text = msh22(&nodes, &[(2, 0, &[1, 2, 3]), (2, 0, &[1, 3, 4]), (4, 0, &[1, 2, 3, 5])]);
    let e = parse_err(&text);
    assert!(e.contains("is neither a cell nor a facet of one: the mesh mixes cells of dimensions 2 and 3"), "{e}");
    assert!(e.starts_with("bad.msh:15: element 2"), "{e}");
}

#[test]
fn regions_without_measure_are_refused_when_asked_for() {
    let coords = SQUARE.iter().flat_map(|x| [x[0], x[1]]).collect();
    let mut m = Mesh::from_cells(ElementKind::TriangleP1, coords, vec![0, 1, 2, 0, 2, 3]);
    m.regions.push(Region { name: "contact".into(), facets: Vec::new() });
    let e = m.region("contact").unwrap_err();
    assert_eq!(e.to_string(), "boundary region `contact` has no facets");
    m.add_region_where("bottom", |n, _| n[1] < -0.5);
    assert_eq!(m.region("bottom").unwrap().facets.len(), 1);
    m.add_region_where("nowhere", |n, _| n[1] > 2.0);
    assert!(matches!(m.region("nowhere"), Err(MeshError::EmptyRegion { .. })));
    // A facet out of range, then one of length zero (two coincident nodes).
    m.regions.push(Region { name: "stale".into(), facets: vec![Facet { cell: 7, local: 0 }] });
    assert!(m.region("stale").unwrap_err().to_string().contains("names facet 0 of cell 7"));
    let mut flat = Mesh::from_cells(ElementKind::TriangleP1, vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0], vec![0, 1, 2]);
    flat.regions.push(Region { name: "point".into(), facets: vec![Facet { cell: 0, local: 0 }] });
    assert!(flat.region("point").unwrap_err().to_string().contains("has measure 0e0 over 1 facets"));
}

#[test]
fn the_reference_meshes_pass_every_check() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "msh") {
            let m = gmsh::read(&p).unwrap_or_else(|e| panic!("{e}"));
            m.validate().unwrap();
            assert!(m.warnings.is_empty(), "{:?}", m.warnings);
            for r in &m.regions {
                m.region(&r.name).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            }
            n += 1;
        }
    }
    // The five reference discs, the eight Hertz meshes and the graded sphere.
    assert!(n >= 14);
    let m = gmsh::read(&dir.join("disc_r10_h1_groups_v41.msh")).unwrap();
    m.region("contact").unwrap();
    m.region("free").unwrap();
}
