//! Several bodies in one problem: each with its own param values and initial fields, bound to
//! its own cells. Two discs that never touch each other move each as it would alone, and a
//! Gmsh file's physical surfaces are bodies.

use std::path::Path;

use signorini::driver::Setting;
use signorini::problem::run::{Options, Run, run};

fn problem(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems").join(name).display().to_string()
}

/// `one_disc.wf` with the values of one of `two_discs.wf`'s bodies.
fn alone(x0: f64, young: f64, density: f64, v: [f64; 2]) -> Run {
    let mut o = Options::new(&problem("one_disc.wf"));
    let values = [("x0", x0), ("young", young), ("density", density), ("vx", v[0]), ("vy", v[1])];
    for (name, value) in values {
        o.methods.params.push(Setting { name: name.into(), value, origin: "test".into() });
    }
    run(&o).unwrap()
}

#[test]
fn each_body_moves_as_it_would_alone() {
    let both = run(&Options::new(&problem("two_discs.wf"))).unwrap();
    let left = alone(-15.0, 50.0, 1.0, [-0.3, -1.0]);
    let right = alone(15.0, 120.0, 2.0, [0.5, -2.0]);
    let column = |r: &Run, name: &str| r.column(name).unwrap_or_else(|| panic!("no column {name}"));
    // Newton solves both bodies at once, so its iterates are not those of each body alone: the
    // bodies agree to its tolerance, which on these linear steps is round-off.
    let pairs = [
        ("ux_left", &left, "ux"),
        ("uy_left", &left, "uy"),
        ("ux_right", &right, "ux"),
        ("uy_right", &right, "uy"),
        ("uy_nodes_right", &right, "uy_nodes"),
    ];
    for (mine, alone, theirs) in pairs {
        let (a, b) = (column(&both, mine), column(alone, theirs));
        assert_eq!(a.len(), b.len());
        let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-12 * scale, "{mine} against {theirs} alone: {worst:e} (scale {scale})");
    }
    // Both discs reach the plane in the run, and the active points are each disc's.
    let active = |r: &Run| column(r, "active_points");
    let (a, l, r) = (active(&both), active(&left), active(&right));
    assert!(l.iter().any(|&x| x > 0.0) && r.iter().any(|&x| x > 0.0), "a disc never lands");
    assert!(a.iter().zip(l.iter().zip(&r)).all(|(a, (l, r))| *a == l + r));
    // The mean over both bodies weighs each by its mass: the discs are alike but for ρ (1, 2).
    let (mean, uy_l, uy_r) = (column(&both, "uy_mean"), column(&both, "uy_left"), column(&both, "uy_right"));
    for ((m, l), r) in mean.iter().zip(&uy_l).zip(&uy_r) {
        assert!((m - (l + 2.0 * r) / 3.0).abs() < 1e-12 * r.abs().max(1.0), "{m} against ({l} + 2 {r})/3");
    }
}

#[test]
fn the_physical_surfaces_of_a_mesh_file_are_bodies() {
    let line = signorini::problem::run::check(&problem("two_squares.wf")).unwrap();
    assert!(line.contains("bodies light (2 cells), heavy (2 cells)"), "{line}");
    // Resting on the ground: the contact carries the load of both squares (f = 1 on two unit
    // squares), and the softer square (E = 10 against 30) sinks further.
    let r = run(&Options::new(&problem("two_squares.wf"))).unwrap();
    let fy = r.column("fy").unwrap()[0];
    assert!((fy - 2.0).abs() < 1e-12, "contact force {fy}");
    let (light, heavy) = (r.column("uy_light").unwrap()[0], r.column("uy_heavy").unwrap()[0]);
    assert!(light < heavy && heavy < 0.0, "{light} {heavy}");
}
