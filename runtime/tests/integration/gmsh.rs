//! The Gmsh reader on the reference meshes of `assets/meshes` (the same mesh in MSH 2.2
//! ASCII, 4.1 ASCII and 4.1 binary) and on a corpus of malformed files.

use std::path::{Path, PathBuf};

use signorini_runtime::fem::element::ElementKind;
use signorini_runtime::fem::mesh::{Mesh, MeshError, gmsh};

/// A reference mesh of `assets/meshes`.
fn shared(name: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes").join(name);
    assert!(p.exists(), "{} is missing: the reference meshes live in assets/meshes", p.display());
    Some(p)
}

#[test]
fn the_three_formats_read_to_identical_meshes() {
    let Some(v22) = shared("disc_r10_h1_v22.msh") else {
        return;
    };
    let a = gmsh::read(&v22).unwrap();
    let b = gmsh::read(&shared("disc_r10_h1_v41.msh").unwrap()).unwrap();
    let c = gmsh::read(&shared("disc_r10_h1_v41_binary.msh").unwrap()).unwrap();
    assert_eq!(a.kind, ElementKind::TriangleP2);
    assert_eq!((a.num_nodes(), a.num_cells()), (1625, 780));
    assert_eq!(a.coords, b.coords);
    assert_eq!(a.coords, c.coords);
    assert_eq!(a.cells, b.cells);
    assert_eq!(a.cells, c.cells);
    // Curved P2 disc of radius 10: boundary nodes on the circle, area close to 100π.
    let boundary = a.boundary_facets();
    assert_eq!(boundary.len(), 64);
    let mut on_circle = 0;
    for f in &boundary {
        let cell = a.cell(f.cell as usize);
        for i in ElementKind::TriangleP2.facet_nodes(f.local as usize) {
            let p = a.node(cell[i] as usize);
            let r = (p[0] * p[0] + (p[1] - 12.0).powi(2)).sqrt();
            assert!((r - 10.0).abs() < 1e-6, "boundary node at radius {r}");
            on_circle += 1;
        }
    }
    assert_eq!(on_circle, 3 * 64);
    assert!((a.measure() - 100.0 * std::f64::consts::PI).abs() < 1e-3);
}

#[test]
fn physical_groups_become_regions() {
    let Some(p) = shared("disc_r10_h1_groups_v41.msh") else {
        return;
    };
    let m = gmsh::read(&p).unwrap();
    let contact = m.region("contact").unwrap();
    let free = m.region("free").unwrap();
    assert_eq!(contact.facets.len() + free.facets.len(), m.boundary_facets().len());
    for f in &contact.facets {
        let (n, _) = m.facet_normal_and_centroid(*f);
        assert!(n[1] < 0.0, "a `contact` facet faces up: {n:?}");
    }
    assert_eq!(m.cell_groups.len(), 1);
    assert_eq!(m.cell_groups[0].0, "body");
    assert_eq!(m.cell_groups[0].1.len(), m.num_cells());
    assert!(matches!(m.region("nope"), Err(MeshError::NoSuchRegion { .. })));
}

#[test]
fn the_fine_mesh_reads() {
    let Some(p) = shared("disc_r10_h05_v22.msh") else {
        return;
    };
    let m: Mesh = gmsh::read(&p).unwrap();
    assert_eq!(m.num_nodes() * 2, 12490);
}

/// Every malformed file fails with the file name, a position (line or byte) where there is
/// one, and the reason; none panics.
#[test]
fn malformed_files_fail_with_position_and_reason() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gmsh_bad");
    let expected: &[(&str, &str)] = &[
        ("binary_22.msh", ":2: MSH 2.2 binary files are not supported"),
        ("boundary_element_not_a_facet.msh", ":17: element 1 is not a boundary facet of any cell"),
        ("degenerate_cell.msh", ":19: element 3: cell 1 is degenerate"),
        ("empty.msh", ":1: not a Gmsh mesh"),
        ("huge_count.msh", ":14: expected a node tag, found `$EndNodes`"),
        ("inverted_p2_cell.msh", ":15: element 1: cell 0 is inverted"),
        ("missing_end_nodes.msh", ":14: expected `$EndNodes`, found `$Elements`"),
        ("mixed_cell_types.msh", ":20: mixed cell types (2 and 9)"),
        ("node_count_too_large.msh", ":14: expected a node tag, found `$EndNodes` (a count does not match the data)"),
        ("node_count_too_small.msh", ":13: expected `$EndNodes`, found `4 0 1 0`"),
        ("node_out_of_range.msh", ":19: element 3 refers to node 9, which is not in `$Nodes`"),
        ("non_finite_coordinate.msh", ":12: y is not finite"),
        ("not_a_number.msh", ":12: expected y (a number), found `one`"),
        ("not_gmsh.msh", ":1: expected a section such as `$Nodes`"),
        ("not_planar.msh", ":13: a 2D mesh must lie in the plane"),
        ("repeated_node_tag.msh", ":13: node tag 3 is repeated"),
        ("truncated_nodes.msh", ":12: unexpected end of file: expected a node tag"),
        ("unknown_element_type.msh", ":19: unknown element type 99"),
        ("unknown_version.msh", ":2: unsupported MSH version 3.0"),
        ("v41_binary_bad_endianness.msh", "at byte 20: the endianness check is not the integer 1"),
        ("v41_binary_truncated.msh", "at byte 195: unexpected end of file"),
        ("v41_block_count_mismatch.msh", ":9: the header announces 5 nodes, the blocks hold 4"),
        ("v41_element_dimension_mismatch.msh", ":22: element type 2 has dimension 2, but its block says 3"),
    ];
    let mut files: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    files.sort();
    assert!(files.len() >= 15);
    assert_eq!(
        files,
        expected.iter().map(|(f, _)| f.to_string()).collect::<Vec<_>>(),
        "every corpus file has an expectation"
    );
    for (name, want) in expected {
        let path = dir.join(name);
        let e = gmsh::read(&path).expect_err(name).to_string();
        assert!(e.contains(name), "{name}: the message does not name the file: {e}");
        assert!(e.contains(want), "{name}: expected `{want}` in `{e}`");
    }
}

#[test]
fn small_meshes_in_every_format_read_alike() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let a = gmsh::read(&dir.join("gmsh_good_22.msh")).unwrap();
    let b = gmsh::read(&dir.join("gmsh_good_41.msh")).unwrap();
    let c = gmsh::read(&dir.join("gmsh_good_binary.msh")).unwrap();
    assert_eq!((a.coords.clone(), a.cells.clone()), (b.coords.clone(), b.cells.clone()));
    assert_eq!((a.coords.clone(), a.cells.clone()), (c.coords, c.cells));
    assert_eq!(a.region("bottom").unwrap().facets.len(), 1);
    let (n, _) = a.facet_normal_and_centroid(a.region("bottom").unwrap().facets[0]);
    assert_eq!(n, vec![0.0, -1.0]);
}

/// Truncations and byte flips of a valid file never panic.
#[test]
fn damaged_files_never_panic() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    for name in ["gmsh_good_22.msh", "gmsh_good_41.msh", "gmsh_good_binary.msh"] {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        for cut in 0..bytes.len() {
            let _ = gmsh::parse(&bytes[..cut], name);
        }
        for i in 0..bytes.len() {
            for flip in [0x01u8, 0x20, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[i] ^= flip;
                let _ = gmsh::parse(&b, name);
            }
        }
    }
}
