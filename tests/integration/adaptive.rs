//! Adaptive time steps (issue 56): the step follows the scheme's local error estimate, the run
//! lands on the first contact, the energy guard still holds, and bad settings are refused.

use signorini::problem::run::{Options, StepOptions};

fn plucked(scheme: &str, tolerance: Option<f64>) -> signorini::problem::run::Run {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/plucked_bar.wf");
    let mut o = Options::new(file.to_str().unwrap());
    o.methods.scheme = scheme.into();
    o.chosen.scheme = true;
    o.steps = StepOptions { adaptive: tolerance, ..StepOptions::default() };
    signorini::problem::run::run(&o).unwrap_or_else(|e| panic!("{scheme}, {tolerance:?}: {e}"))
}

/// On the struck bar (a smooth solution: one mode) a second-order scheme's steps go as
/// TOL^(1/3) and its error at the middle node, against the semi-discrete solution, as TOL^(2/3):
/// over two decades of tolerance, steps ×10^(2/3) ≈ 4.6 and error ÷10^(4/3) ≈ 21.5.
#[test]
fn the_step_follows_the_tolerance() {
    for scheme in ["newmark", "hht", "genalpha", "trbdf2", "central"] {
        let runs: Vec<(f64, f64)> = [1e-3, 1e-5]
            .iter()
            .map(|&tol| {
                let r = plucked(scheme, Some(tol));
                (r.summary.number("steps").unwrap(), r.summary.number("error_max").unwrap())
            })
            .collect();
        let steps = runs[1].0 / runs[0].0;
        let error = runs[0].1 / runs[1].1;
        assert!((3.0..7.0).contains(&steps), "{scheme}: steps ×{steps} over two decades ({runs:?})");
        assert!(error > 8.0, "{scheme}: error ÷{error} over two decades ({runs:?})");
    }
}

/// The coarse disc dropped from rest: the adaptive run lands on the first contact within its
/// event tolerance (Δt/20 = 10⁻³) of a fixed run at Δt = 2·10⁻⁴ (itself within that of the
/// contact), in far fewer steps than the fixed Δt = 0.02, with the energy guard's account at
/// round-off (Crank–Nicolson conserves).
#[test]
fn an_adaptive_disc_lands_on_its_first_contact() {
    let disc = |adaptive: Option<f64>, t0: f64, dt: f64| {
        let mut o = signorini::cases::disc::options();
        o.methods = o.methods.set("h", 2.0);
        (o.t_start, o.t_end, o.dt) = (Some(t0), Some(8.5), Some(dt));
        o.steps.adaptive = adaptive;
        signorini::problem::run::run(&o).unwrap()
    };
    let fine = disc(None, 6.2, 2e-4).summary.number("first_contact").unwrap();
    let fixed = disc(None, 0.0, 0.02).summary;
    let adaptive = disc(Some(1e-3), 0.0, 0.02).summary;
    let first = adaptive.number("first_contact").unwrap();
    assert!((first - fine).abs() <= 1e-3 + 2e-4, "first contact {first}, fine {fine}");
    let steps = adaptive.number("steps").unwrap();
    assert!(3.0 * steps <= fixed.number("steps").unwrap(), "{steps} steps");
    assert!(adaptive.number("energy_growth").unwrap() < 1e-10);
    let counts = adaptive.get("adaptive").expect("the adaptive counts");
    assert!(counts["events"].as_u64().unwrap() >= 1, "{counts}");
    assert!(counts["dt_max"].as_f64().unwrap() > 0.02, "{counts}");
}

/// A tolerance that is not a positive number, a bound without adaptive steps, a scheme without
/// an estimate: refused before the run; a step control that needs Δt below its minimum stops
/// with the time and the cause, its outputs written.
#[test]
fn adaptive_steps_refuse_bad_settings() {
    let refused = |steps: StepOptions, scheme: &str| {
        let mut o = signorini::cases::disc::options();
        o.methods.scheme = scheme.into();
        o.steps = steps;
        match signorini::problem::run::run(&o) {
            Ok(_) => panic!("{steps:?} ran"),
            Err(e) => e.to_string(),
        }
    };
    let e = refused(StepOptions { adaptive: Some(-1.0), ..Default::default() }, "newmark");
    assert!(e.contains("--adaptive") && e.contains("positive"), "{e}");
    let e = refused(StepOptions { adaptive: Some(f64::NAN), ..Default::default() }, "newmark");
    assert!(e.contains("positive"), "{e}");
    let e = refused(StepOptions { dt_min: Some(1e-3), ..Default::default() }, "newmark");
    assert!(e.contains("give --adaptive"), "{e}");
    let e = refused(
        StepOptions { adaptive: Some(1e-3), dt_min: Some(1.0), dt_max: Some(0.5), ..Default::default() },
        "newmark",
    );
    assert!(e.contains("exceeds"), "{e}");
    let e = refused(StepOptions { adaptive: Some(1e-3), ..Default::default() }, "midpoint");
    assert!(e.contains("declares no `estimate`"), "{e}");

    let out = std::env::temp_dir().join(format!("signorini-adaptive-stop-{}", std::process::id()));
    let mut o = signorini::cases::disc::options();
    o.methods = o.methods.set("h", 2.0);
    o.t_end = Some(8.5);
    o.steps = StepOptions { adaptive: Some(1e-9), dt_min: Some(1e-2), ..Default::default() };
    o.out = Some(out.clone());
    let stopped = match signorini::problem::run::run(&o) {
        Ok(_) => panic!("the run needs steps below the minimum"),
        Err(e) => e.to_string(),
    };
    assert!(stopped.contains("below the minimum") && stopped.contains("× the tolerance"), "{stopped}");
    assert!(out.join("series.csv").exists() && out.join("summary.json").exists());
    let _ = std::fs::remove_dir_all(&out);
}
