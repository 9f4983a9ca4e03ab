//! Two backends, one meaning: every scheme of the library run by path (compiled at run time,
//! its coefficients evaluated from the expression DAG) and every contact law run by path (its
//! forms interpreted) give the compiled library's series on the bar and the disc, 100 steps
//! through impact.

use signorini::cases::{bar, disc};
use signorini::driver::{self, Methods};
use signorini::guard::Guard;
use signorini::problem::run::Options;

fn copy_outside(dir: &std::path::Path, rel: &str) -> String {
    let to = dir.join(std::path::Path::new(rel).file_name().unwrap());
    std::fs::copy(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel), &to).unwrap();
    to.display().to_string()
}

fn worst(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    a.iter().zip(b).map(|(x, y)| (x - y).abs() / scale).fold(0.0, f64::max)
}

#[test]
fn schemes_and_laws_by_path_match_the_compiled_library() {
    let dir = std::env::temp_dir().join(format!("signorini-by-path-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let laws = [
        ("nitsche", copy_outside(&dir, "forms/contact_nitsche.wf")),
        ("penalty", copy_outside(&dir, "forms/contact_penalty.wf")),
    ];
    let mut largest = 0.0f64;
    for scheme in driver::all_schemes() {
        let file = copy_outside(&dir, &format!("forms/schemes/{scheme}.wf"));
        for (law, law_file) in &laws {
            // The two paths compared step by step, also where a scheme is unstable at these
            // steps (IMEX-HHT; central differences above its critical step): no guard.
            let guard = Guard { energy_tolerance: 0.0, allow_unstable_dt: true, ..Guard::default() };
            let compiled = Methods { scheme: scheme.into(), contact: (*law).into(), guard, ..Methods::default() };
            let by_path = Methods { scheme: file.clone(), contact: law_file.clone(), guard, ..Methods::default() };
            // The bar: 100 steps of 0.03 (first impact at t = 1).
            let bar_run = |methods: Methods| {
                let o = Options { methods, dt: Some(0.03), t_end: Some(3.0), ..bar::options() };
                bar::run(&o).unwrap_or_else(|e| panic!("{scheme} {law}: {e}"))
            };
            let (a, b) = (bar_run(compiled.clone()), bar_run(by_path.clone()));
            assert_eq!(b.summary.interpreted.len(), 2, "{:?}", b.summary.interpreted);
            assert_eq!(a.series.len(), 101);
            for f in [|r: &bar::Row| r.u_c, |r: &bar::Row| r.lambda, |r: &bar::Row| r.energy_aug] {
                let (x, y): (Vec<f64>, Vec<f64>) = a.series.iter().zip(&b.series).map(|(p, q)| (f(p), f(q))).unzip();
                let w = worst(&x, &y);
                assert!(w <= 1e-10, "bar {scheme} {law}: {w:e}");
                largest = largest.max(w);
            }
            // The disc: 100 steps of 0.08 on the coarse built-in mesh (impact at t ≈ 6.3).
            let disc_run = |methods: Methods| {
                let o = Options { methods: methods.set("h", 2.0), dt: Some(0.08), t_end: Some(8.0), ..disc::options() };
                disc::run(&o)
            };
            match (disc_run(compiled), disc_run(by_path)) {
                (Ok(a), Ok(b)) => {
                    assert!(a.summary.first_contact.is_some(), "disc {scheme} {law}: no impact");
                    for f in [
                        |r: &disc::Row| r.u_vertical_mean,
                        |r: &disc::Row| r.f_vertical_contact,
                        |r: &disc::Row| r.energy_aug,
                    ] {
                        let (x, y): (Vec<f64>, Vec<f64>) =
                            a.series.iter().zip(&b.series).map(|(p, q)| (f(p), f(q))).unzip();
                        let w = worst(&x, &y);
                        assert!(w <= 1e-10, "disc {scheme} {law}: {w:e}");
                        largest = largest.max(w);
                    }
                }
                // A scheme that fails here (explicit contact at a large step) fails alike.
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "disc {scheme} {law}"),
                (a, b) => panic!("disc {scheme} {law}: compiled {:?}, by path {:?}", a.is_ok(), b.is_ok()),
            }
        }
    }
    eprintln!("largest relative difference, by path vs compiled: {largest:e}");
    let _ = std::fs::remove_dir_all(&dir);
}
