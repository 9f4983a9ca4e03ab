//! The user's crate: its binary runs the bar and a Gmsh disc; its compiled scheme equals the
//! same file run by path (interpreted); with αB = 0 WBZ-α is Newmark.

use signorini::cases::bar;
use signorini::driver::Methods;
use signorini::problem::run::Options;

signorini::forms!(mod wbz = "wbz.wf");

fn series(methods: Methods) -> Vec<f64> {
    let opts = Options { methods, t_end: Some(3.0), ..bar::options() };
    bar::run(&opts).unwrap().series.iter().map(|r| r.u_c).collect()
}

fn compiled() -> Methods {
    Methods { scheme: "wbz".into(), compiled: vec![&wbz::UNIT], ..Methods::default() }
}

#[test]
fn the_binary_runs_the_bar_and_a_gmsh_disc() {
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/disc_r10_h1_groups_v41.msh");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_user-scheme")).arg(mesh).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("bar: err_u") && text.contains("disc: 3250 dofs, first contact at t = 6.3"), "{text}");
}

#[test]
fn compiled_by_path_and_newmark_agree() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/wbz.wf");
    let by_path = Methods { scheme: file.into(), ..Methods::default() };
    let (a, b) = (series(compiled().set("alpha_b", -0.2)), series(by_path.set("alpha_b", -0.2)));
    assert_eq!(a, b, "compiled vs interpreted");
    let newmark = series(Methods { scheme: "newmark".into(), ..Methods::default() });
    let wbz0 = series(compiled().set("alpha_b", 0.0));
    let scale = newmark.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for (k, (x, y)) in wbz0.iter().zip(&newmark).enumerate() {
        assert!((x - y).abs() <= 1e-12 * scale, "step {k}: {x} vs {y}");
    }
}
