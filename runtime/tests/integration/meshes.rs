//! Structured and disc meshes: measures, boundary facets, regions, node placement, validity.

use signorini_runtime::fem::element::ElementKind;
use signorini_runtime::fem::mesh::{Mesh, disc::disc, structured};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

#[test]
fn rectangles_have_the_right_measure_boundary_and_sides() {
    for diag in [structured::Diagonal::Right, structured::Diagonal::Left] {
        for degree in [1, 2] {
            let m = structured::rectangle(4, 3, [0.0, 2.0], [1.0, 2.5], diag, degree);
            m.validate().unwrap();
            assert_eq!(m.num_cells(), 24);
            assert!(close(m.measure(), 3.0, 1e-14));
            assert_eq!(m.boundary_facets().len(), 2 * (4 + 3));
            assert_eq!(m.region("left").unwrap().facets.len(), 3);
            assert_eq!(m.region("top").unwrap().facets.len(), 4);
            let expected_nodes = if degree == 1 { 5 * 4 } else { 9 * 7 };
            assert_eq!(m.num_nodes(), expected_nodes);
            for f in &m.region("bottom").unwrap().facets {
                let (n, x) = m.facet_normal_and_centroid(*f);
                assert!(close(n[1], -1.0, 1e-14) && close(x[1], 1.0, 1e-14));
            }
        }
    }
}

#[test]
fn boxes_have_positive_tetrahedra_and_six_sides() {
    for degree in [1, 2] {
        let m = structured::cuboid([2, 3, 2], [0.0, 1.0], [0.0, 1.5], [0.0, 0.5], degree);
        m.validate().unwrap();
        assert_eq!(m.num_cells(), 6 * 12);
        assert!(close(m.measure(), 0.75, 1e-13), "volume {}", m.measure());
        assert_eq!(m.boundary_facets().len(), 2 * 2 * (2 * 3 + 3 * 2 + 2 * 2));
        assert_eq!(m.region("bottom").unwrap().facets.len(), 2 * 6);
        assert_eq!(m.region("back").unwrap().facets.len(), 2 * 4);
    }
}

#[test]
fn interval_regions_are_its_ends() {
    let m = structured::interval(5, 0.0, 1.0);
    m.validate().unwrap();
    assert_eq!(m.boundary_facets().len(), 2);
    let (n, x) = m.facet_normal_and_centroid(m.region("left").unwrap().facets[0]);
    assert_eq!((n[0], x[0]), (-1.0, 0.0));
}

#[test]
fn disc_is_curved_p2_with_its_boundary_on_the_circle() {
    let (r, c) = (10.0, [0.0, 12.0]);
    let m: Mesh = disc(r, c, 1.0);
    m.validate().unwrap();
    assert_eq!(m.kind, ElementKind::TriangleP2);
    assert_eq!(m.num_cells(), 600);
    // Isoparametric P2 area is within O(h^4) of the disc's.
    let area = m.measure();
    assert!((area - std::f64::consts::PI * r * r).abs() < 1e-3 * area, "area {area}");
    let boundary = m.region("boundary").unwrap();
    assert_eq!(boundary.facets.len(), 60);
    for node in m.region_nodes(boundary) {
        let p = m.node(node as usize);
        assert!(close(((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt(), r, 1e-14));
    }
    let contact = m.region("contact").unwrap();
    assert_eq!(contact.facets.len(), 30);
    let lowest = m.region_nodes(contact).iter().map(|&n| m.node(n as usize)[1]).fold(f64::INFINITY, f64::min);
    assert!(close(lowest, 2.0, 1e-12));
}

/// GetFEM's cell size on straight triangles: J = (x₁ − x₀, x₂ − x₀) from the unit-leg simplex is
/// constant, and h/√2 = σ_min(J) must satisfy σ_min·σ_max = |det J| and
/// σ_min² + σ_max² = ‖J‖²_F; on P2 cells with straight edges the same value.
#[test]
fn getfem_cell_size_of_straight_triangles() {
    use signorini_runtime::fem::mesh::CellSize;
    use signorini_runtime::fem::mesh::structured::{Diagonal, rectangle};
    for degree in [1, 2] {
        let mut mesh = rectangle(4, 2, [0.0, 1.0], [0.0, 0.3], Diagonal::Right, degree);
        mesh.set_cell_size(CellSize::GetFem);
        for c in 0..mesh.num_cells() {
            let v: Vec<&[f64]> = mesh.cell(c).iter().take(3).map(|&n| mesh.node(n as usize)).collect();
            let (a, b) = ([v[1][0] - v[0][0], v[1][1] - v[0][1]], [v[2][0] - v[0][0], v[2][1] - v[0][1]]);
            let det = (a[0] * b[1] - a[1] * b[0]).abs();
            let frob2 = a[0] * a[0] + a[1] * a[1] + b[0] * b[0] + b[1] * b[1];
            let smin = mesh.cell_size(c) / 2f64.sqrt();
            let smax = det / smin;
            assert!(smin <= smax + 1e-15, "P{degree} cell {c}");
            assert!((smin * smin + smax * smax - frob2).abs() < 1e-13, "P{degree} cell {c}: {smin} {smax} {frob2}");
        }
    }
}
