//! Problems posed in files: a library problem copied elsewhere runs by path with the same bits;
//! a user coef (a graded density) is supplied by the problem and the free fall it poses stays
//! exact; an interpreted contact law agrees with the compiled one on a library problem.

use std::path::{Path, PathBuf};

use signorini::driver::{Setting, Setup};
use signorini::problem::run::{Options, Run, run};

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("signorini-problems-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn short(problem: &str) -> Options {
    let mut o = Options::new(problem);
    o.t_end = Some(7.0);
    o.setup.params.push(Setting { name: "h".into(), value: 2.0, origin: "test".into() });
    o
}

fn bits(r: &Run) -> Vec<(u64, Vec<u64>)> {
    r.rows.iter().map(|(t, v)| (t.to_bits(), v.iter().map(|x| x.to_bits()).collect())).collect()
}

#[test]
fn a_library_problem_copied_elsewhere_runs_by_path_with_the_same_bits() {
    let dir = temp_dir("copy");
    let file = dir.join("my_disc.wf");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("forms/problems/disc.wf"), &file).unwrap();
    let library = run(&short("disc")).unwrap();
    let by_path = run(&short(file.to_str().unwrap())).unwrap();
    assert_eq!(library.columns, by_path.columns);
    assert!(library.rows.len() > 300);
    assert_eq!(bits(&library), bits(&by_path), "the same problem, by name and by path");
    // The impact is in the run: the comparison covers contact, not only the free fall.
    assert!(library.column("active_points").unwrap().iter().any(|&a| a > 0.0));
}

#[test]
fn a_user_coef_set_by_the_problem_reaches_the_forms() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    let mut o = Options::new(here.join("graded_density.wf").to_str().unwrap());
    o.setup = Setup { material: here.join("graded_material.wf").display().to_string(), ..Setup::default() };
    let r = run(&o).unwrap();
    // Mass ρζ and load ρζg: the free fall is a rigid translation, u = −g t²/2 at every node.
    let t_star = 40f64.sqrt();
    let (mean, lowest) = (r.column("uy_mean").unwrap(), r.column("uy_lowest").unwrap());
    let mut checked = 0;
    for (i, (t, _)) in r.rows.iter().enumerate() {
        if *t < t_star - 0.1 {
            let exact = -0.05 * t * t;
            assert!((mean[i] - exact).abs() < 1e-11, "t = {t}: mean {} vs {exact}", mean[i]);
            assert!((lowest[i] - exact).abs() < 1e-11, "t = {t}: lowest {} vs {exact}", lowest[i]);
            checked += 1;
        }
    }
    assert!(checked > 100);
    // The graded density is in the forms: the contact then differs from the uniform disc's.
    let mut uniform = Options::new(here.join("graded_density.wf").to_str().unwrap());
    uniform.setup = Setup::default();
    let u = run(&uniform).unwrap();
    let (a, b) = (r.column("uy_mean").unwrap(), u.column("uy_mean").unwrap());
    assert!((a.last().unwrap() - b.last().unwrap()).abs() > 1e-6, "zeta changed nothing after impact");
}

#[test]
fn an_interpreted_contact_law_agrees_with_the_compiled_one() {
    let dir = temp_dir("law");
    let law = dir.join("my_nitsche.wf");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("forms/contact_nitsche.wf"), &law).unwrap();
    let compiled = run(&short("disc")).unwrap();
    let mut o = short("disc");
    o.setup.contact = law.display().to_string();
    let interpreted = run(&o).unwrap();
    let scale = compiled.column("uy_mean").unwrap().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for name in ["uy_mean", "uy_lowest", "fy_contact", "energy_aug"] {
        let (a, b) = (compiled.column(name).unwrap(), interpreted.column(name).unwrap());
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let size = a.iter().fold(scale, |m, x| m.max(x.abs()));
        assert!(worst <= 1e-10 * size, "{name}: {worst:e}");
    }
}

/// A rigid ball of radius R under the disc, its top at the ground's height: its gap differs
/// from the plane's by |x_⊥|²/(2R) + O(R⁻²), so the run tends to the disc's on the ground at
/// order 1 in 1/R (the differences shrink tenfold per decade of R).
#[test]
fn a_ball_obstacle_tends_to_the_plane_as_its_radius_grows() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/disc_on_ball.wf");
    let plane = run(&short("disc")).unwrap();
    let on_ball = |r: f64| {
        let mut o = short(file.to_str().unwrap());
        o.setup.params.push(Setting { name: "R".into(), value: r, origin: "test".into() });
        let b = run(&o).unwrap();
        let (x, y) = (b.column("uy_mean").unwrap(), plane.column("uy_mean").unwrap());
        assert_eq!(x.len(), y.len());
        x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
    };
    let d: Vec<f64> = [200.0, 2000.0, 20000.0].iter().map(|&r| on_ball(r)).collect();
    for w in d.windows(2) {
        let ratio = w[0] / w[1];
        assert!((8.0..12.0).contains(&ratio), "differences {d:?}: ratio {ratio}");
    }
    assert!(d[2] < 1e-5, "{d:?}");
}
