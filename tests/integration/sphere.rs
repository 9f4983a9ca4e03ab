//! The bouncing sphere, the disc in 3D (curved P2 tetrahedra on the built-in ball): free fall
//! is exact before the first contact, which happens just after t* = √40, and
//! Crank–Nicolson with Nitsche θ = 1 keeps E_aug on every step whose active set is unchanged.

use signorini::cases::disc;
use signorini::driver::Methods;
use signorini::problem::run::Options;

use super::disc::gravity;

fn sphere(scheme: &str, h: f64, t_end: f64) -> disc::Run {
    let methods = Methods { scheme: scheme.into(), ..Methods::default() };
    let methods = methods.set("h", h);
    disc::run(&Options { problem: "sphere".into(), methods, t_end: Some(t_end), ..disc::options() }).unwrap()
}

#[test]
fn free_fall_is_exact_and_contact_starts_in_the_right_step() {
    let g = gravity("sphere");
    let t_star = (2.0 * 2.0 / g).sqrt();
    for scheme in ["newmark", "trbdf2", "hybrid"] {
        let r = sphere(scheme, 5.0, 6.5);
        assert_eq!(r.summary.case, "sphere");
        for row in r.series.iter().filter(|row| row.t < t_star - 0.05) {
            let exact = -0.5 * g * row.t * row.t;
            assert!(
                (row.u_vertical_mean - exact).abs() < 1e-10,
                "{scheme} t = {}: mean u_z {} vs {exact}",
                row.t,
                row.u_vertical_mean
            );
            assert!((row.u_vertical_lowest - exact).abs() < 1e-10, "{scheme} t = {}: lowest point", row.t);
            assert!(
                (row.v_vertical_mean + g * row.t).abs() < 1e-10,
                "{scheme} t = {}: v_z {}",
                row.t,
                row.v_vertical_mean
            );
            assert_eq!(row.active_points, 0);
        }
        // The contact quadrature points nearest the pole sit above it by about (facet size)²/2R
        // (≈ 0.06 for h = 5), which the sphere covers in a few steps after t*.
        let first = r.summary.first_contact.expect("the sphere reaches the ground");
        assert!(t_star <= first && first <= t_star + 0.1, "{scheme}: first contact at {first}, t* = {t_star}");
    }
}

#[test]
fn crank_nicolson_keeps_the_augmented_energy_while_the_active_set_is_kept() {
    let r = sphere("newmark", 5.0, 10.0);
    let scale = r.series.iter().map(|row| row.energy.abs()).fold(0.0, f64::max);
    let (mut kept, mut changed, mut largest) = (0, 0, 0.0f64);
    for w in r.series.windows(2) {
        if w[0].switches == w[1].switches {
            kept += 1;
            largest = largest.max((w[1].energy_aug - w[0].energy_aug).abs() / scale);
        } else {
            changed += 1;
        }
    }
    assert!(kept > 400 && changed > 3, "kept {kept}, changed {changed}");
    assert!(largest < 1e-9, "largest |ΔE_aug| on kept steps: {largest:e}");
    // In contact: a positive contact area and an upward force.
    assert!(r.series.iter().any(|row| row.contact_area > 0.0 && row.f_vertical_contact > 0.0));
}

/// The iterative path (CG for θ = 1, BiCGStab for the unsymmetric θ = −1) gives the direct
/// path's series to Newton's tolerance.
#[test]
fn iterative_and_direct_solvers_agree() {
    use signorini::runtime::linalg::Solver;
    use signorini::runtime::nonlinear::newton::NewtonOptions;
    for theta in [1.0, -1.0] {
        let run = |solver| {
            let methods = Methods::default().set("theta", theta);
            let newton = NewtonOptions { solver, ..NewtonOptions::default() };
            disc::run(&Options {
                problem: "sphere".into(),
                methods: methods.set("h", 5.0),
                t_end: Some(8.0),
                newton,
                ..disc::options()
            })
            .unwrap()
        };
        let (d, i) = (run(Solver::Direct), run(Solver::Iterative));
        assert_eq!(d.summary.krylov_iterations, 0);
        assert!(i.summary.krylov_iterations > 0);
        let scale = d.series.iter().map(|r| r.energy.abs()).fold(0.0, f64::max);
        for (a, b) in d.series.iter().zip(&i.series) {
            assert!((a.energy_aug - b.energy_aug).abs() < 1e-6 * scale, "θ = {theta}, t = {}", a.t);
            assert!((a.u_vertical_mean - b.u_vertical_mean).abs() < 1e-9, "θ = {theta}, t = {}", a.t);
            assert_eq!(a.active_points, b.active_points, "θ = {theta}, t = {}", a.t);
        }
    }
}

/// The committed graded ball (assets/meshes/sphere_graded.geo, made with Gmsh): free fall is
/// exact on it too, from its lowest point at the pole z = 2.
#[test]
fn the_graded_gmsh_ball_falls_exactly() {
    let mesh = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/sphere_graded.msh");
    let m = signorini::runtime::fem::mesh::gmsh::read(&mesh).unwrap();
    let lowest = (0..m.num_nodes()).map(|i| m.node(i)[2]).fold(f64::INFINITY, f64::min);
    assert!((lowest - 2.0).abs() < 1e-9, "the mesh's lowest point is at z = {lowest}");
    let opts = Options { problem: "sphere".into(), mesh: Some(mesh), t_end: Some(0.4), ..disc::options() };
    let g = gravity("sphere");
    let r = disc::run(&opts).unwrap();
    assert!(r.summary.dofs > 20_000);
    for row in &r.series {
        let exact = -0.5 * g * row.t * row.t;
        assert!(
            (row.u_vertical_mean - exact).abs() < 1e-10,
            "t = {}: mean u_z {} vs {exact}",
            row.t,
            row.u_vertical_mean
        );
        assert!((row.u_vertical_lowest - exact).abs() < 1e-10, "t = {}: lowest point", row.t);
    }
}
