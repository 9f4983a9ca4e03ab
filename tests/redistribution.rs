//! Mass redistribution (spec §5): the contact nodes lose their inertia, total mass, first and
//! second moments are preserved to round-off, and the result is positive definite on the other
//! dofs (1D P1 and the curved 2D P2 disc).

use signorini::runtime::assembly::{Assembler, Quadrature};
use signorini::runtime::kernel::Coef;
use signorini::runtime::linalg::Matrix;
use signorini::runtime::mesh::{Mesh, disc::disc, structured};
use signorini::runtime::redistribute::redistribute;

signorini::forms!("forms/elasticity.wf");

fn mass(mesh: &Mesh) -> (Assembler<'_>, Matrix) {
    let asm = Assembler::new(mesh);
    let p = elasticity::Params::default();
    let c = elasticity::Coefficients { f: Coef::constant(vec![0.0; mesh.dim()]) };
    let mut m = asm.zero_matrix();
    asm.cell_tangent(&elasticity::Mass::new(&p, &c), Quadrature::default(), &[&vec![0.0; asm.size()]], 0, 0.0, &mut m);
    (asm, m)
}

/// qᵀ M q for q = x_r x_s (r, s = 0: the constant), on component `comp`.
fn moment(mesh: &Mesh, m: &Matrix, r: usize, s: usize, comp: usize) -> f64 {
    let d = mesh.dim();
    let q = |i: usize, k: usize| if k == 0 { 1.0 } else { mesh.node(i)[k - 1] };
    let mut total = 0.0;
    for i in 0..mesh.num_nodes() {
        for j in 0..mesh.num_nodes() {
            total += q(i, r) * m.get(i * d + comp, j * d + comp) * q(j, s);
        }
    }
    total
}

fn check(mesh: &Mesh, region: &str) {
    let d = mesh.dim();
    let (_asm, m) = mass(mesh);
    let contact = mesh.region_nodes(mesh.region(region).unwrap());
    let r = redistribute(mesh, &m, &contact).unwrap();
    assert!(r.moment_error < 1e-12, "moment error {}", r.moment_error);
    for comp in 0..d {
        for a in 0..=d {
            for b in a..=d {
                let (before, after) = (moment(mesh, &m, a, b, comp), moment(mesh, &r.matrix, a, b, comp));
                assert!(
                    (before - after).abs() <= 1e-12 * before.abs().max(1.0),
                    "moment ({a},{b}) comp {comp}: {before} → {after}"
                );
            }
        }
    }
    // No inertia on the contact nodes; symmetric.
    for &c in &contact {
        for j in 0..mesh.num_nodes() * d {
            assert_eq!(r.matrix.get(c as usize * d, j), 0.0);
        }
    }
    let n = mesh.num_nodes() * d;
    for i in (0..n).step_by(7) {
        for j in 0..n {
            assert!((r.matrix.get(i, j) - r.matrix.get(j, i)).abs() < 1e-15);
        }
    }
}

#[test]
fn one_dimensional_p1() {
    for ne in [10, 100] {
        check(&structured::interval(ne, 0.0, 1.0), "left");
    }
}

#[test]
fn curved_p2_disc() {
    check(&disc(10.0, [0.0, 12.0], 2.0), "contact");
}
