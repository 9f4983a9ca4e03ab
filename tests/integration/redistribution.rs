//! Mass redistribution (spec §5): the contact nodes lose their inertia, total mass, first and
//! second moments are preserved to round-off, and the result is positive definite on the other
//! dofs (1D P1 and the curved 2D P2 disc).

use signorini::runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::mesh::{Mesh, disc::disc, structured};
use signorini::runtime::fem::redistribute::redistribute;
use signorini::runtime::linalg::Matrix;

signorini::forms!("forms/elasticity.wf");

fn mass(mesh: &Mesh) -> (Assembler<'_>, Matrix) {
    let asm = Assembler::new(mesh);
    let p = elasticity::Params::default();
    let c = elasticity::Coefficients { f: Coef::constant(vec![0.0; mesh.dim()]) };
    let mut m = asm.zero_matrix();
    asm.cell_tangent(
        CellIntegral::all(&elasticity::Mass::new(&p, &c), Quadrature::default()),
        &[&vec![0.0; asm.size()]],
        0,
        0.0,
        &mut m,
    );
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

/// Lumping (`--mass lumped`): a diagonal mass, every node of positive mass (P2 vertices too,
/// whose consistent rows sum to zero or less), each component's total mass kept; on P1 the
/// row sums.
#[test]
fn lumping_keeps_the_mass_with_a_positive_diagonal() {
    use signorini::runtime::fem::lumping::lumped;
    for degree in [1, 2] {
        let mesh = structured::rectangle(6, 4, [0.0, 3.0], [0.0, 2.0], structured::Diagonal::Right, degree);
        let (_, m) = mass(&mesh);
        let l = lumped(&m, degree, 2);
        for c in 0..2 {
            let e: Vec<f64> = (0..m.size()).map(|i| if i % 2 == c { 1.0 } else { 0.0 }).collect();
            let (whole, lumped_whole) = (m.quad(&e, &e), l.quad(&e, &e));
            // The area, 6, for ρ = 1.
            assert!((whole - 6.0).abs() < 1e-12 && (lumped_whole - whole).abs() < 1e-12, "P{degree}: {lumped_whole}");
        }
        let mut row = vec![0.0; m.size()];
        for j in 0..l.size() {
            assert!(l.get(j, j) > 0.0, "P{degree}: dof {j} has mass {}", l.get(j, j));
            let e: Vec<f64> = (0..m.size()).map(|i| if i == j { 1.0 } else { 0.0 }).collect();
            l.mul_vec(&e, &mut row);
            assert!(row.iter().enumerate().all(|(i, v)| i == j || *v == 0.0), "P{degree}: column {j} is not diagonal");
            if degree == 1 {
                m.mul_vec(&vec![1.0; m.size()], &mut row);
                assert!((l.get(j, j) - row[j]).abs() < 1e-15, "P1: dof {j} is not its row sum");
            }
        }
    }
}

/// With the lumped mass, Crank–Nicolson keeps the disc's augmented energy (½uᵀKu + ½vᵀM_L v −
/// Fᵀu + the contact law's energy) to round-off through its free fall: the scheme's energy law
/// holds for the mass it steps with. The fall is no longer the exact parabola at every node (a
/// P2 vertex's load is not its lumped mass times g), so Nitsche's unswitched term stores a
/// little energy of its own.
#[test]
fn crank_nicolson_with_the_lumped_mass_keeps_the_augmented_energy() {
    use signorini::problem::run::{Options, run};
    use signorini::simulation::MassChoice;
    let mut o = Options::new("disc");
    o.mass = MassChoice::Lumped;
    o.t_end = Some(6.0);
    let r = run(&o).unwrap();
    let (energy_aug, kinetic_max) = (r.column("energy_aug").unwrap(), r.summary.number("kinetic_energy_max").unwrap());
    let drift = energy_aug.iter().map(|e| e.abs()).fold(0.0, f64::max);
    assert!(kinetic_max > 50.0 && drift < 1e-12 * kinetic_max, "drift {drift:e} of {kinetic_max}");
    assert_eq!(r.summary.get("mass").and_then(|m| m.as_str()), Some("lumped"));
}
