//! Element matrices of the compiled elasticity forms against hand values and exact properties:
//! 1D P1 stiffness and mass, symmetry and rigid-body modes of P2 stiffness in 2D and 3D, and
//! mass sums equal to ρ·|T|·d on straight and curved cells (|T| computed independently, by
//! Green's or the divergence theorem on the cell boundary).

use signorini::runtime::fem::element::ElementKind;
use signorini::runtime::fem::kernel::{Coef, Tabulation, cell_matrix};

signorini::forms!("forms/elasticity.wf");

use elasticity::{Coefficients, Mass, Params, Stiffness};

fn coefs(d: usize) -> Coefficients {
    Coefficients { f: Coef::constant(vec![0.0; d]) }
}

fn params(e: f64, nu: f64, rho: f64) -> Params {
    Params::default().with("E", e).unwrap().with("nu", nu).unwrap().with("rho", rho).unwrap()
}

fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol * b.abs().max(1.0), "{what}: {a} vs {b}");
}

#[test]
fn p1_interval_stiffness_and_mass_are_the_textbook_matrices() {
    let (e, rho, h) = (3.0, 2.5, 0.4);
    let p = params(e, 0.0, rho);
    let coords = [[1.0], [1.0 + h]];
    let zero = [[0.0; 1]; 2];
    let tab = Tabulation::<1, 2>::cell(ElementKind::IntervalP1, 2).unwrap();
    let k = cell_matrix(&Stiffness::new(&p, &coefs(1)), &tab, &coords, &[&zero], 0, 0.0);
    let m = cell_matrix(&Mass::new(&p, &coefs(1)), &tab, &coords, &[&zero], 0, 0.0);
    let k_exact = [[1.0, -1.0], [-1.0, 1.0]].map(|r| r.map(|x| e / h * x));
    let m_exact = [[2.0, 1.0], [1.0, 2.0]].map(|r| r.map(|x| rho * h / 6.0 * x));
    for i in 0..2 {
        for j in 0..2 {
            assert_close(k[i][j], k_exact[i][j], 1e-14, "stiffness");
            assert_close(m[i][j], m_exact[i][j], 1e-14, "mass");
        }
    }
}

/// A P2 triangle with its edge (0,1) bulging outwards (a circular arc through the midpoint).
fn curved_triangle() -> [[f64; 2]; 6] {
    let (a, b, c) = ([0.0, 0.0], [2.0, 0.3], [0.4, 1.7]);
    let mid = |p: [f64; 2], q: [f64; 2]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
    let m01 = mid(a, b);
    // Push the midpoint of edge (0,1) away from the opposite vertex.
    let bulge = [m01[0] + 0.08, m01[1] - 0.25];
    [a, b, c, bulge, mid(b, c), mid(c, a)]
}

fn straight_triangle() -> [[f64; 2]; 6] {
    let (a, b, c) = ([0.1, -0.2], [1.3, 0.1], [0.2, 0.9]);
    let mid = |p: [f64; 2], q: [f64; 2]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
    [a, b, c, mid(a, b), mid(b, c), mid(c, a)]
}

/// Area of a P2 triangle by Green's theorem along its three quadratic edges.
fn triangle_area(x: &[[f64; 2]; 6]) -> f64 {
    let edges = [(0, 3, 1), (1, 4, 2), (2, 5, 0)];
    let gauss = [(0.5 - 0.5 / 3f64.sqrt(), 0.5), (0.5 + 0.5 / 3f64.sqrt(), 0.5)];
    let mut area = 0.0;
    for (a, m, b) in edges {
        for (s, w) in gauss {
            // Quadratic through a (s=0), m (s=1/2), b (s=1).
            let l = [(1.0 - s) * (1.0 - 2.0 * s), 4.0 * s * (1.0 - s), s * (2.0 * s - 1.0)];
            let dl = [4.0 * s - 3.0, 4.0 - 8.0 * s, 4.0 * s - 1.0];
            let p = |k: usize| l[0] * x[a][k] + l[1] * x[m][k] + l[2] * x[b][k];
            let dp = |k: usize| dl[0] * x[a][k] + dl[1] * x[m][k] + dl[2] * x[b][k];
            area += w * 0.5 * (p(0) * dp(1) - p(1) * dp(0));
        }
    }
    area
}

fn matvec(m: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    m.iter().map(|r| r.iter().zip(v).map(|(a, b)| a * b).sum()).collect()
}

fn check_symmetric_with_rigid_modes<const D: usize, const N: usize>(k: &[Vec<f64>], coords: &[[f64; D]; N]) {
    let scale = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for i in 0..N * D {
        for j in 0..N * D {
            assert!((k[i][j] - k[j][i]).abs() <= 1e-13 * scale, "not symmetric at ({i}, {j})");
        }
    }
    // Translations and infinitesimal rotations: e_a and x ↦ x_b e_a − x_a e_b.
    let mut modes: Vec<Vec<f64>> = Vec::new();
    for a in 0..D {
        modes.push((0..N * D).map(|r| if r % D == a { 1.0 } else { 0.0 }).collect());
        for b in a + 1..D {
            modes.push(
                (0..N * D)
                    .map(|r| {
                        let (node, comp) = (r / D, r % D);
                        if comp == a {
                            coords[node][b]
                        } else if comp == b {
                            -coords[node][a]
                        } else {
                            0.0
                        }
                    })
                    .collect(),
            );
        }
    }
    assert_eq!(modes.len(), D * (D + 1) / 2);
    for (i, m) in modes.iter().enumerate() {
        let r = matvec(k, m);
        let norm = r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        assert!(norm <= 1e-12 * scale, "rigid mode {i} not in the kernel: |K r| = {norm}");
    }
    // And nothing else: a non-rigid field has positive energy.
    let stretch: Vec<f64> = (0..N * D).map(|r| if r % D == 0 { coords[r / D][0] } else { 0.0 }).collect();
    let energy: f64 = stretch.iter().zip(matvec(k, &stretch)).map(|(a, b)| a * b).sum();
    assert!(energy > 1e-6 * scale);
}

#[test]
fn p2_triangle_stiffness_is_symmetric_with_three_rigid_modes() {
    let p = params(2.0, 0.3, 1.0);
    let tab = Tabulation::<2, 6>::cell(ElementKind::TriangleP2, 6).unwrap();
    for coords in [straight_triangle(), curved_triangle()] {
        let k = cell_matrix(&Stiffness::new(&p, &coefs(2)), &tab, &coords, &[&[[0.0; 2]; 6]], 0, 0.0);
        check_symmetric_with_rigid_modes(&k, &coords);
    }
}

/// A P2 tetrahedron; `bulge` moves the midpoint of edge (0,1) off the straight line.
fn tetrahedron(bulge: f64) -> [[f64; 3]; 10] {
    let v = [[0.0, 0.0, 0.0], [1.2, 0.1, -0.1], [0.2, 1.1, 0.1], [0.1, 0.2, 0.9]];
    let edges = [[0, 1], [1, 2], [0, 2], [0, 3], [2, 3], [1, 3]];
    let mut x = [[0.0; 3]; 10];
    x[..4].copy_from_slice(&v);
    for (e, [a, b]) in edges.iter().enumerate() {
        x[4 + e] = std::array::from_fn(|k| 0.5 * (v[*a][k] + v[*b][k]));
    }
    x[4][1] -= bulge;
    x[4][2] -= 0.5 * bulge;
    x
}

/// Volume of a P2 tetrahedron by the divergence theorem: V = ⅓ ∮ x·n dA over its four
/// quadratic faces (the integrand is a polynomial of degree 4 on each reference face).
fn tet_volume(x: &[[f64; 3]; 10]) -> f64 {
    let kind = ElementKind::TetrahedronP2;
    let rule = signorini::runtime::fem::quadrature::simplex_rule(2, 4);
    let mut vol = 0.0;
    for f in 0..4 {
        for (s, w) in rule.points.iter().zip(&rule.weights) {
            let (xi, _) = kind.facet_point(f, s);
            let phi = kind.basis(&xi);
            let dphi = kind.basis_gradients(&xi);
            // Tangents of the face: derivatives of x along the face parametrisation.
            let verts = &kind.facets()[f];
            let rv = kind.reference_vertices();
            let t1: Vec<f64> = (0..3).map(|k| rv[verts[1]][k] - rv[verts[0]][k]).collect();
            let t2: Vec<f64> = (0..3).map(|k| rv[verts[2]][k] - rv[verts[0]][k]).collect();
            let pos: Vec<f64> = (0..3).map(|a| (0..10).map(|j| phi[j] * x[j][a]).sum()).collect();
            let dx = |t: &[f64]| -> Vec<f64> {
                (0..3)
                    .map(|a| (0..10).map(|j| x[j][a] * (0..3).map(|b| dphi[j][b] * t[b]).sum::<f64>()).sum())
                    .collect()
            };
            let (a, b) = (dx(&t1), dx(&t2));
            let cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
            // Orient outwards with the reference normal.
            let n_ref = kind.reference_normal(f);
            let jn: f64 = {
                let tn: Vec<f64> = (0..3)
                    .map(|a| (0..10).map(|j| x[j][a] * (0..3).map(|bb| dphi[j][bb] * n_ref[bb]).sum::<f64>()).sum())
                    .collect();
                tn.iter().zip(&cross).map(|(p, q)| p * q).sum()
            };
            let sign = if jn > 0.0 { 1.0 } else { -1.0 };
            vol += w * sign * pos.iter().zip(&cross).map(|(p, c)| p * c).sum::<f64>() / 3.0;
        }
    }
    vol
}

#[test]
fn p2_tetrahedron_stiffness_is_symmetric_with_six_rigid_modes() {
    let p = params(1.5, 0.25, 1.0);
    let tab = Tabulation::<3, 10>::cell(ElementKind::TetrahedronP2, 4).unwrap();
    for bulge in [0.0, 0.15] {
        let coords = tetrahedron(bulge);
        let k = cell_matrix(&Stiffness::new(&p, &coefs(3)), &tab, &coords, &[&[[0.0; 3]; 10]], 0, 0.0);
        check_symmetric_with_rigid_modes(&k, &coords);
    }
}

#[test]
fn mass_entries_sum_to_density_times_measure_times_dimension() {
    let rho = 1.7;
    let p = params(1.0, 0.3, rho);
    let tab2 = Tabulation::<2, 6>::cell(ElementKind::TriangleP2, 6).unwrap();
    for coords in [straight_triangle(), curved_triangle()] {
        let m = cell_matrix(&Mass::new(&p, &coefs(2)), &tab2, &coords, &[&[[0.0; 2]; 6]], 0, 0.0);
        let sum: f64 = m.iter().flatten().sum();
        assert_close(sum, rho * triangle_area(&coords) * 2.0, 1e-13, "P2 triangle mass sum");
    }
    let tab3 = Tabulation::<3, 10>::cell(ElementKind::TetrahedronP2, 6).unwrap();
    for bulge in [0.0, 0.15] {
        let coords = tetrahedron(bulge);
        let m = cell_matrix(&Mass::new(&p, &coefs(3)), &tab3, &coords, &[&[[0.0; 3]; 10]], 0, 0.0);
        let sum: f64 = m.iter().flatten().sum();
        assert_close(sum, rho * tet_volume(&coords) * 3.0, 1e-13, "P2 tetrahedron mass sum");
    }
    // The curved cells really are curved: their measure differs from the straight one.
    let straight_area = {
        let x = curved_triangle();
        0.5 * ((x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]))
    };
    assert!((triangle_area(&curved_triangle()) - straight_area).abs() > 0.05);
    assert!((tet_volume(&tetrahedron(0.15)) - tet_volume(&tetrahedron(0.0))).abs() > 1e-3);
}

#[test]
fn params_reject_values_outside_their_declared_range() {
    assert!(Params::default().with("nu", 0.5).is_err());
    assert!(Params::default().with("E", -1.0).is_err());
    assert!(Params::default().with("E", f64::NAN).is_err());
    assert!(Params::default().with("nope", 1.0).is_err());
    assert_eq!(Params::default().with("nu", 0.25).unwrap().nu(), 0.25);
    assert_eq!(Params::default().E(), 1.0);
}
